// setup.cuh - stage `setup`: per input primitive. A triangle is culled, clipped and snapped; a
// small (sub-)triangle (bbox at most SMALL_TRI_SPAN pixels wide and high) is rasterized right here by
// its thread, the one-thread fast path that needs no memory; a big one is cut into pieces of
// consecutive bbox tiles (pieceCount) for bin_count and bin_fill. Only a clipped big sub-triangle is
// stored (a TriSetup record); every other big triangle is named by its input index and set up again
// where it is needed. A line segment is clipped and snapped like a triangle and becomes its rectangle's
// two triangles (setupLine), which take the same two paths (a long line's pieces spread over many
// threads like a big triangle's), stored as records when big. A point is culled by its vertex, snapped
// and rasterized by its thread (every sample of its square).
// One thread per primitive, triangles, then line segments, then points, from setupFirstPrimitive (with
// clusters the triangles are stage clusters' work); blocks = ceil((triangleCount + lineCount +
// pointCount - setupFirstPrimitive) / GROUP_SIZE).
namespace sr {

// The statistics that setup and clusters count for every primitive (COUNTER_SMALL, COUNTER_BIG,
// COUNTER_SPLIT, COUNTER_CULLED, COUNTER_CLIPPED, COUNTER_INVALID, COUNTER_LINES, COUNTER_POINTS,
// COUNTER_CLUSTERS_CULLED) go to the warp's shard of them (COUNTER_SHARD_WORD, raster_shared.h), which the
// host folds into one. Every warp's adds to one word were served one after another by one L2 slice: with
// a million small triangles setup's time did not move when its occupancy rose from 22% to 32%, and fell 45%
// when they were summed per block in shared memory and added once per block (H200; docs/benchmark.md,
// "Fourth pass"); the shards spread the adds without the block's sums and barriers ("Sixth pass").
__device__ inline uint* statCounter(const Buffers& b, uint counter)
{
    uint warp = (blockIdx.x * blockDim.x + threadIdx.x) >> 5;
    return &b.counters[COUNTER_SHARD_WORD(warp, counter)];
}

// Counts one for statistic `counter`: the threads of a warp that reach it together with the same counter
// add once, their number.
__device__ inline void countStat(const Buffers& b, uint counter)
{
    uint peers = __match_any_sync(__activemask(), counter);
    if ((threadIdx.x & 31u) == uint(__ffs(peers) - 1))
        atomicAdd(statCounter(b, counter), uint(__popc(peers)));
}

__device__ inline void addStat(const Buffers& b, uint counter, uint n)
{
    atomicAdd(statCounter(b, counter), n);
}

// The sum of `n` over the 32 threads of the warp, all of which call it.
__device__ inline uint warpSum(uint n)
{
#if __CUDA_ARCH__ >= 800
    return __reduce_add_sync(0xffffffffu, n);
#else
    for (int d = 16; d > 0; d >>= 1) n += __shfl_xor_sync(0xffffffffu, n, d);
    return n;
#endif
}

// Rasterizes a small triangle (every sample of its bbox) or appends a big one's pieces. A full
// list still counts the appends, so the host sees the overflow, grows the lists and redraws; nothing is
// written past a capacity.
template <bool kMaterials, bool kMultisample, bool kLinesPoints, uint kMethod>
__device__ inline void emitTriangle(const RasterParams& params, const Buffers& b, const TriSetup& t,
                                    bool clipped)
{
    ivec4 bounds = methodPixelBounds<kMethod>(t, params.width, params.height, params.sampleBounds);
    uint id = setupTriId(t);
    // With one sample per pixel, a fixed-point method's small triangle whose corners spread too far for
    // the 32-bit test (smallEdgesFit fails: a sliver reaching far past the viewport) takes the big path,
    // whose exact test (raster_tiles, methodPixel) gives the same bits. A 64-bit pixel loop of its own
    // here held 24 of setup's 94 registers in every launch for that rare case (ptxas 13.0, sm_90).
    if (isSmallTriangle(bounds) && (kMultisample || kMethod >= RASTER_FLOAT || smallEdgesFit(t))) {
        countStat(b, COUNTER_SMALL);
        // Lines have no alpha test (and no triangle flags).
        bool masked = kMaterials && params.materialCount != 0u &&
                      (!kLinesPoints || id < params.triangleCount) &&
                      (b.triFlags[id] & TRI_FLAG_ALPHA_MASK) != 0u;
        if (!kMultisample) {
            if constexpr (kMethod < RASTER_FLOAT) {
                // The fixed-point methods' pixel test in 32-bit integers (SmallEdges): the same bits.
                SmallEdges s = smallEdges(t, bounds.x, bounds.y);
                ivec3 row = s.start;
                for (int y = bounds.y; y <= bounds.w; ++y) {
                    ivec3 e = row;
                    for (int x = bounds.x; x <= bounds.z; ++x) {
                        float depth;
                        if (smallEdgesPixel(t, s, e, depth) &&
                            (!masked || alphaMaskCovers(params, b, id, x, y)))
                            mergeFragment(params, b, uint(y) * params.width + uint(x), depth, id);
                        e += s.stepX;
                    }
                    row += s.stepY;
                }
            } else {
                for (int y = bounds.y; y <= bounds.w; ++y) {
                    for (int x = bounds.x; x <= bounds.z; ++x) {
                        float depth;
                        if (methodPixel<kMethod>(t, x, y, depth) &&
                            (!masked || alphaMaskCovers(params, b, id, x, y)))
                            mergeFragment(params, b, uint(y) * params.width + uint(x), depth, id);
                    }
                }
            }
        } else {
            // MSAA, in a build of its own so that the one-sample loop compiles as it did without it: the
            // alpha test runs once per pixel, at its centre, as hardware shades a pixel.
            for (int y = bounds.y; y <= bounds.w; ++y) {
                for (int x = bounds.x; x <= bounds.z; ++x) {
                    uint mask = methodCoverage<kMethod>(t, params.sampleCount, x, y);
                    if (mask == 0u || (masked && !alphaMaskCovers(params, b, id, x, y))) continue;
                    uint pixel = uint(y) * params.width + uint(x);
                    for (uint s = 0u; s < params.sampleCount; ++s) {
                        float depth;
                        if ((mask & (1u << s)) != 0u &&
                            methodSample<kMethod>(t, samplePosition(params.sampleCount, s, x, y), depth))
                            mergeFragment(params, b, s * params.samplePlane + pixel, depth, id);
                    }
                }
            }
        }
        return;
    }
    countStat(b, COUNTER_BIG);
    uint ref = id;
    if (clipped) {
        uint slot = atomicAdd(&b.counters[COUNTER_SETUP], 1u);
        if (slot >= params.setupCapacity) return;
        b.setupTris[slot] = t;
        ref = slot | BIN_REF_RECORD;
    }
    uint tiles = tileCount(bounds);
    uint n = pieceCount(tiles);
    uint base = atomicAdd(&b.counters[COUNTER_PIECES], n);
    // Piece indices are uint: a frame that needs 2^31 of them is reported, never wrapped.
    if (base >= 0x80000000u) b.counters[COUNTER_WORK_OVERFLOW] = 1u;
    if (n == 1u) {  // counted here, while the triangle is at hand; bin_count skips the piece
        if (base >= params.pieceCapacity) return;  // counts must match what bin_fill will find
        b.pieces[base] = uvec2(ref, PIECE_COUNTED);
        binTiles<false, kMethod>(params, b, t, bounds, ref, 0u, tiles);
        return;
    }
    countStat(b, COUNTER_SPLIT);
    for (uint k = 0u; k < n && base + k < params.pieceCapacity; ++k)
        b.pieces[base + k] = uvec2(ref, k * pieceTiles(tiles));
}

// Rasterizes point k (primitive triangleCount + lineCount + k) by its thread: every sample of the pixels its
// square reaches, merged like a small triangle's. Points are opaque and have no facing.
template <bool kMultisample>
__device__ inline void rasterPoint(const RasterParams& params, const Buffers& b, uint k)
{
    uint v = b.points[k];
    if (v >= params.vertexCount) {
        countStat(b, COUNTER_INVALID);
        return;
    }
    vec4 c = loadClipPosition(params, b, v);
    if (!isFinite(c.x) || !isFinite(c.y) || !isFinite(c.z) || !isFinite(c.w)) {
        countStat(b, COUNTER_INVALID);
        return;
    }
    PointSetup pt;
    ivec4 r = ivec4(0, 0, -1, -1);
    if (setupPoint(c, params.pointSize, params.width, params.height, pt))
        r = pointPixelBounds(pt, params.width, params.height, params.sampleBounds);
    if (r.x > r.z || r.y > r.w) {
        countStat(b, COUNTER_CULLED);
        return;
    }
    countStat(b, COUNTER_POINTS);
    uint id = params.triangleCount + params.lineCount + k;
    uint samples = kMultisample ? params.sampleCount : 1u;
    for (int y = r.y; y <= r.w; ++y) {
        for (int x = r.x; x <= r.z; ++x) {
            uint pixel = uint(y) * params.width + uint(x);
            for (uint s = 0u; s < samples; ++s)
                if (pointCoversSample(pt, samplePosition(samples, s, x, y)))
                    mergeFragment(params, b, s * params.samplePlane + pixel, pt.depth, id);
        }
    }
}

// The build with the line and point paths (kLinesPoints). A line segment (primitive triangleCount + k)
// is clipped like a triangle, snapped, and takes the triangles' own loop below as the fan of its
// rectangle's four corners: its two triangles (never named by input index: they are not input
// triangles) reach the same single inlined emitTriangle as a triangle's. compute_glsl/setup.comp gives
// lines a function of their own; in CUDA that form (a second inlined emitTriangle) ran lines-1m's
// setup 2.5x slower on the H100 with the same instruction count, its warps stalled on memory (0.39 ->
// 1.00 ms; docs/benchmark-log.md, "Performance pass"), so this build keeps one loop for both.
template <bool kMaterials, bool kMultisample, uint kMethod>
__device__ inline void setupStageWithLinesPoints(const RasterParams& params, const Buffers& b)
{
    uint prim = params.setupFirstPrimitive + globalThreadId();
    uint lineEnd = params.triangleCount + params.lineCount;
    if (prim >= lineEnd) {
        if (prim < lineEnd + params.pointCount) rasterPoint<kMultisample>(params, b, prim - lineEnd);
        return;
    }
    bool line = prim >= params.triangleCount;
    vec4 poly[MAX_CLIP_VERTS];
    uint count = 0u;
    uint kind;
    LineQuad q;
    if (line) {
        vec4 c0, c1;
        vec2 u;
        kind = loadClipLine(params, b, prim - params.triangleCount, c0, c1)
                   ? prepareLine(c0, c1, params.guardBand, poly[0], poly[1], u)
                   : PREPARE_INVALID;
        if (kind != PREPARE_INVALID && kind != PREPARE_CULLED &&
            setupLine(poly[0], poly[1], params.lineWidth, params.lineDepthBias, params.width, params.height,
                      q))
            count = 4u;
    } else {
        vec4 c0, c1, c2;
        kind = loadClipTriangle(params, b, prim, c0, c1, c2)
                   ? prepareTriangle(c0, c1, c2, params.guardBand, poly, count)
                   : PREPARE_INVALID;
    }
    if (kind == PREPARE_INVALID) {
        countStat(b, COUNTER_INVALID);
        return;
    }
    if (kind == PREPARE_CLIPPED) countStat(b, COUNTER_CLIPPED);
    bool doubleSided = line || (b.triFlags[prim] & TRI_FLAG_DOUBLE_SIDED) != 0u;
    uint emitted = 0u;
    for (uint k = 1u; k + 1u < count; ++k) {
        TriSetup t;
        bool drawn = line ? methodLineTriangle<kMethod>(q, k - 1u, prim, params.width, params.height,
                                                        params.sampleBounds, t)
                          : methodSetupTriangle<kMethod>(poly[0], poly[k], poly[k + 1u], prim, doubleSided,
                                                         params.cullMode, params.width, params.height,
                                                         params.sampleBounds, t);
        if (drawn) {
            emitTriangle<kMaterials, kMultisample, true, kMethod>(params, b, t,
                                                                  line || kind == PREPARE_CLIPPED);
            ++emitted;
        }
    }
    if (emitted == 0u)
        countStat(b, COUNTER_CULLED);
    else if (line)
        countStat(b, COUNTER_LINES);
}

// Input triangle `tri` with clip positions c0, c1, c2: classified, clipped, set up, and each of its
// (sub-)triangles rasterized or binned (emitTriangle). Stage clusters calls it too, with the positions it
// transformed once per cluster: the same function, the same bits. A triangle that needs no clipping is
// set up from c0, c1, c2 in registers; only a clipped one fills the polygon, which lives in local memory
// (ncu, sweep-0.5px: 9% of setup's stalls waited on reading back the three corners from there).
template <bool kMaterials, bool kMultisample, uint kMethod>
__device__ inline void setupInputTriangle(const RasterParams& params, const Buffers& b, uint tri, vec4 c0,
                                          vec4 c1, vec4 c2)
{
    uint planes;
    uint kind = classifyTriangle(c0, c1, c2, params.guardBand, planes);
    if (kind == PREPARE_INVALID) {
        countStat(b, COUNTER_INVALID);
        return;
    }
    bool clipped = kind == PREPARE_CLIPPED;
    vec4 poly[MAX_CLIP_VERTS];
    uint count = kind == PREPARE_DIRECT ? 3u : 0u;
    if (clipped) {
        countStat(b, COUNTER_CLIPPED);
        count = clipTriangle(c0, c1, c2, planes, params.guardBand, poly);
    }
    bool doubleSided = (b.triFlags[tri] & TRI_FLAG_DOUBLE_SIDED) != 0u;
    uint emitted = 0u;
    for (uint k = 1u; k + 1u < count; ++k) {
        vec4 a = c0, p1 = c1, p2 = c2;
        if (clipped) {
            a = poly[0];
            p1 = poly[k];
            p2 = poly[k + 1u];
        }
        TriSetup t;
        if (methodSetupTriangle<kMethod>(a, p1, p2, tri, doubleSided, params.cullMode, params.width,
                                         params.height, params.sampleBounds, t)) {
            emitTriangle<kMaterials, kMultisample, false, kMethod>(params, b, t, clipped);
            ++emitted;
        }
    }
    if (emitted == 0u) countStat(b, COUNTER_CULLED);
}

// A triangle that classifyTriangle found PREPARE_CLIPPED: clipped, and each piece of its fan set up and
// rasterized or binned, as setupInputTriangle does. Stage clusters calls it for the clipped triangles of
// its snapped-once path: through setupInputTriangle's loop, whose corners come from registers or from the
// polygon, ptxas gave clustersKernel 128 registers instead of 96 (occupancy 25% instead of 31%), and the
// 100M-triangle sphere ran 14% slower on the H100. The fan loop is kept twice on purpose: with
// setupInputTriangle calling this function for its clipped triangles (two emitTriangle sites in setup)
// NVIDIA's Vulkan compiler ran layers-16's setup three times as slow (0.044 -> 0.137 ms, H100).
template <bool kMaterials, bool kMultisample, uint kMethod>
__device__ inline void setupClippedTriangle(const RasterParams& params, const Buffers& b, uint tri, vec4 c0,
                                            vec4 c1, vec4 c2)
{
    uint planes;
    classifyTriangle(c0, c1, c2, params.guardBand, planes);
    countStat(b, COUNTER_CLIPPED);
    vec4 poly[MAX_CLIP_VERTS];
    uint count = clipTriangle(c0, c1, c2, planes, params.guardBand, poly);
    bool doubleSided = (b.triFlags[tri] & TRI_FLAG_DOUBLE_SIDED) != 0u;
    uint emitted = 0u;
    for (uint k = 1u; k + 1u < count; ++k) {
        TriSetup t;
        if (methodSetupTriangle<kMethod>(poly[0], poly[k], poly[k + 1u], tri, doubleSided, params.cullMode,
                                         params.width, params.height, params.sampleBounds, t)) {
            emitTriangle<kMaterials, kMultisample, false, kMethod>(params, b, t, true);
            ++emitted;
        }
    }
    if (emitted == 0u) countStat(b, COUNTER_CULLED);
}

// kLinesPoints: whether the line and point paths are built in (SETUP_LINES_POINTS of setup.comp); the
// triangle-only build is the code below.
template <bool kMaterials, bool kMultisample, bool kLinesPoints, uint kMethod>
__device__ inline void setupPrimitive(const RasterParams& params, const Buffers& b)
{
    if constexpr (kLinesPoints) {
        setupStageWithLinesPoints<kMaterials, kMultisample, kMethod>(params, b);
        return;
    }
    uint tri = globalThreadId();
    if (tri >= params.triangleCount) return;
    vec4 c0, c1, c2;
    if (!loadClipTriangle(params, b, tri, c0, c1, c2)) {
        countStat(b, COUNTER_INVALID);
        return;
    }
    setupInputTriangle<kMaterials, kMultisample, kMethod>(params, b, tri, c0, c1, c2);
}

}  // namespace sr
