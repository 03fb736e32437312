// setup_triangle.glsl - the triangle half of stage setup, which stage clusters shares: the build's
// constants, emitTriangle (rasterize a small triangle, bin a big one) and setupInputTriangle (one input
// triangle from its clip positions). Included by setup.comp and clusters.comp after buffers.glsl and
// bin.glsl; both declare local_size_x themselves.
#ifndef RASTER_SETUP_TRIANGLE_GLSL
#define RASTER_SETUP_TRIANGLE_GLSL

// Whether the alpha test of MASK materials is built in (SPEC_MATERIALS).
layout(constant_id = SPEC_MATERIALS) const bool MATERIALS = true;
// Samples per pixel (SPEC_SAMPLES, RasterParams.sampleCount): the one-sample build has no MSAA loop.
layout(constant_id = SPEC_SAMPLES) const uint SAMPLES = 1u;
// SETUP_LINES_POINTS (a preprocessor definition, 0 or 1): whether the line and point paths are built
// in. This shader is compiled twice (CMakeLists.txt), and scenes of triangles alone run the module
// without them: with the point code in the same module (behind a run-time branch) NVIDIA's compiler
// ran the triangle path 35-95% slower on the H100 (measured; docs/benchmark-log.md, "Performance pass").
#ifndef SETUP_LINES_POINTS
#define SETUP_LINES_POINTS 0
#endif
// Whether a big triangle is stored as a record. On a GPU only a clipped one is (the others cost no
// memory and are set up again per tile); the CPU builds (SR_CPU_BUILD) store every big triangle, so that
// raster_tiles' CPU build fetches each with three texel gathers (VIEW_SETUP_TRIS) instead of setting it
// up from the scene in every tile, one lane at a time.
#if defined(SR_CPU_BUILD)
#define STORED_AS_RECORD(clipped) true
#else
#define STORED_AS_RECORD(clipped) (clipped)
#endif

// The statistics that setup and clusters count for every primitive (COUNTER_SMALL, COUNTER_BIG,
// COUNTER_CULLED, COUNTER_SPLIT, COUNTER_CLIPPED, COUNTER_INVALID, COUNTER_LINES, COUNTER_POINTS), through
// countPrimitive, go to the subgroup's shard of them (COUNTER_SHARD_WORD, raster_shared.h), which the host
// folds into one. The three that nearly every triangle reaches, small, big and culled, are counted in the
// invocation's ThreadCounts, and each subgroup adds its sums once (addThreadCounts: at the end of setup's
// invocation, after each round of clusters); the rare others are one atomic each. Every subgroup's adds
// to one word were served one after another by one L2 slice (cuda/setup.cuh; docs/benchmark.md, "Fourth
// pass" to "Sixth pass"). The including shader enables GL_KHR_shader_subgroup_basic and
// GL_KHR_shader_subgroup_arithmetic.

// The subgroup's shard: its index in the dispatch (COUNTER_SHARD_WORD takes it modulo COUNTER_SHARDS).
uint statShard()
{
    return gl_WorkGroupID.x * gl_NumSubgroups + gl_SubgroupID;
}

// Adds `n` to statistic `counter` in the subgroup's shard (cuda/setup.cuh's addStat).
void addStat(uint counter, uint n)
{
    atomicAdd(counters[COUNTER_SHARD_WORD(statShard(), counter)], n);
}

// Small, big and culled in 10-bit fields of one register. Between two addThreadCounts an invocation counts
// one primitive in setup, or one cluster's share of triangles in clusters (ceil(CLUSTER_MAX_TRIANGLES /
// CLUSTER_LANES) = 4), each at most MAX_CLIP_VERTS - 2 = 7 sub-triangles: 28, far below a field's 1023.
#define THREAD_COUNT_SMALL 0
#define THREAD_COUNT_BIG 10
#define THREAD_COUNT_CULLED 20
struct ThreadCounts {
    uint bits;
};

uint threadCount(ThreadCounts counts, uint field)
{
    return (counts.bits >> field) & 1023u;
}

// Counts one primitive for statistic `counter` (a constant at every call site).
void countPrimitive(inout ThreadCounts counts, uint counter)
{
    if (counter == COUNTER_SMALL)
        counts.bits += 1u << THREAD_COUNT_SMALL;
    else if (counter == COUNTER_BIG)
        counts.bits += 1u << THREAD_COUNT_BIG;
    else if (counter == COUNTER_CULLED)
        counts.bits += 1u << THREAD_COUNT_CULLED;
    else
        addStat(counter, 1u);
}

// Every invocation of a subgroup together: adds the subgroup's ThreadCounts to its shard, one atomic per
// statistic it has, and zeroes them.
void addThreadCounts(inout ThreadCounts counts)
{
    uint small = subgroupAdd(threadCount(counts, THREAD_COUNT_SMALL));
    uint big = subgroupAdd(threadCount(counts, THREAD_COUNT_BIG));
    uint culled = subgroupAdd(threadCount(counts, THREAD_COUNT_CULLED));
    if (subgroupElect()) {
        if (small != 0u) addStat(COUNTER_SMALL, small);
        if (big != 0u) addStat(COUNTER_BIG, big);
        if (culled != 0u) addStat(COUNTER_CULLED, culled);
    }
    counts.bits = 0u;
}

// Rasterizes a small triangle (every sample of its bbox) or appends a big one's pieces: a record
// (BIN_REF_RECORD) when `clipped` (STORED_AS_RECORD: always in the CPU builds), else its input index. A full
// list still counts the appends, so the host sees the overflow, grows the lists and redraws; nothing is
// written past a capacity.
void emitTriangle(TriSetup t, bool clipped, inout ThreadCounts counts)
{
    ivec4 bounds = methodPixelBounds(t, params.width, params.height, params.sampleBounds);
    uint id = setupTriId(t);
    // With one sample per pixel, a fixed-point method's small triangle whose corners spread too far for
    // the 32-bit test (smallEdgesFit fails: a sliver reaching far past the viewport) takes the big path,
    // whose exact test (raster_tiles, methodPixel) gives the same bits, rather than a 64-bit pixel loop
    // of its own here for that rare case (in CUDA that loop held 24 of setup's 94 registers).
    bool small = isSmallTriangle(bounds);
#if METHOD_INTEGER_EDGES
    small = small && (SAMPLES != 1u || smallEdgesFit(t));
#endif
    if (small) {
        countPrimitive(counts, COUNTER_SMALL);
        // Lines have no alpha test (and no triangle flags).
        bool masked = MATERIALS && params.materialCount != 0u &&
                      (SETUP_LINES_POINTS == 0 || id < params.triangleCount) &&
                      (triFlags[id] & TRI_FLAG_ALPHA_MASK) != 0u;
        if (SAMPLES == 1u) {
#if METHOD_INTEGER_EDGES
            // The fixed-point methods' pixel test in 32-bit integers (SmallEdges): the same bits.
            SmallEdges s = smallEdges(t, bounds.x, bounds.y);
            ivec3 row = s.start;
            for (int y = bounds.y; y <= bounds.w; ++y) {
                ivec3 e = row;
                for (int x = bounds.x; x <= bounds.z; ++x) {
                    float depth;
                    if (smallEdgesPixel(t, s, e, depth) && (!masked || alphaMaskCovers(id, x, y)))
                        mergeFragment(uint(y) * params.width + uint(x), depth, id);
                    e += s.stepX;
                }
                row += s.stepY;
            }
#else
            for (int y = bounds.y; y <= bounds.w; ++y) {
                for (int x = bounds.x; x <= bounds.z; ++x) {
                    float depth;
                    if (methodPixel(t, x, y, depth) && (!masked || alphaMaskCovers(id, x, y)))
                        mergeFragment(uint(y) * params.width + uint(x), depth, id);
                }
            }
#endif
            return;
        }
        // MSAA, in a build of its own so that the one-sample loop compiles as it did without it: the alpha
        // test runs once per pixel, at its centre, as hardware shades a pixel.
        for (int y = bounds.y; y <= bounds.w; ++y) {
            for (int x = bounds.x; x <= bounds.z; ++x) {
                uint mask = methodCoverage(t, SAMPLES, x, y);
                if (mask == 0u || (masked && !alphaMaskCovers(id, x, y))) continue;
                uint pixel = uint(y) * params.width + uint(x);
                for (uint s = 0u; s < SAMPLES; ++s) {
                    float depth;
                    if ((mask & (1u << s)) != 0u && methodSample(t, samplePosition(SAMPLES, s, x, y), depth))
                        mergeFragment(s * params.samplePlane + pixel, depth, id);
                }
            }
        }
        return;
    }
    countPrimitive(counts, COUNTER_BIG);
    uint ref = id;
    if (clipped) {
        uint slot = atomicAdd(counters[COUNTER_SETUP], 1u);
        if (slot >= params.setupCapacity) return;
        setupTris[slot] = t;
        ref = slot | BIN_REF_RECORD;
    }
    uint tiles = tileCount(bounds);
    uint n = pieceCount(tiles);
    uint base = atomicAdd(counters[COUNTER_PIECES], n);
    // Piece indices are uint: a frame that needs 2^31 of them is reported, never wrapped.
    if (base >= 0x80000000u) counters[COUNTER_WORK_OVERFLOW] = 1u;
    if (n == 1u) {  // counted here, while the triangle is at hand; bin_count skips the piece
        if (base >= params.pieceCapacity) return;  // counts must match what bin_fill will find
        pieces[base] = uvec2(ref, PIECE_COUNTED);
        binTiles(t, bounds, ref, 0u, tiles, false);
        return;
    }
    countPrimitive(counts, COUNTER_SPLIT);
    for (uint k = 0u; k < n && base + k < params.pieceCapacity; ++k)
        pieces[base + k] = uvec2(ref, k * pieceTiles(tiles));
}

// Input triangle `tri` with clip positions c0, c1, c2: classified, clipped, set up, and each of its
// (sub-)triangles rasterized or binned. Stage clusters calls it too, with the positions it transformed
// once per cluster: the same function, the same bits. A triangle that needs no clipping is set up from
// c0, c1, c2 directly; only a clipped one fills the polygon (local memory on GPUs).
void setupInputTriangle(uint tri, vec4 c0, vec4 c1, vec4 c2, inout ThreadCounts counts)
{
    uint planes;
    uint kind = classifyTriangle(c0, c1, c2, params.guardBand, planes);
    if (kind == PREPARE_INVALID) {
        countPrimitive(counts, COUNTER_INVALID);
        return;
    }
    bool clipped = kind == PREPARE_CLIPPED;
    vec4 poly[MAX_CLIP_VERTS];
    uint count = kind == PREPARE_DIRECT ? 3u : 0u;
    if (clipped) {
        countPrimitive(counts, COUNTER_CLIPPED);
        count = clipTriangle(c0, c1, c2, planes, params.guardBand, poly);
    }
    bool doubleSided = (triFlags[tri] & TRI_FLAG_DOUBLE_SIDED) != 0u;
    uint emitted = 0u;
    for (uint k = 1u; k + 1u < count; ++k) {
        vec4 a = c0, p1 = c1, p2 = c2;
        if (clipped) {
            a = poly[0];
            p1 = poly[k];
            p2 = poly[k + 1u];
        }
        TriSetup t;
        if (methodSetupTriangle(a, p1, p2, tri, doubleSided, params.cullMode, params.width, params.height,
                                params.sampleBounds, t)) {
            emitTriangle(t, STORED_AS_RECORD(clipped), counts);
            ++emitted;
        }
    }
    if (emitted == 0u) countPrimitive(counts, COUNTER_CULLED);
}

// A triangle that classifyTriangle found PREPARE_CLIPPED: clipped, and each piece of its fan set up and
// rasterized or binned, as setupInputTriangle does. Stage clusters calls it for the clipped triangles of
// its snapped-once path (cuda/setup.cuh: the CUDA twin kept clustersKernel at 96 registers this way).
// setupInputTriangle keeps its own fan loop: calling this function from it (a second emitTriangle site)
// ran layers-16's setup three times as slow on the H100 (0.044 -> 0.137 ms).
void setupClippedTriangle(uint tri, vec4 c0, vec4 c1, vec4 c2, inout ThreadCounts counts)
{
    uint planes;
    classifyTriangle(c0, c1, c2, params.guardBand, planes);
    countPrimitive(counts, COUNTER_CLIPPED);
    vec4 poly[MAX_CLIP_VERTS];
    uint count = clipTriangle(c0, c1, c2, planes, params.guardBand, poly);
    bool doubleSided = (triFlags[tri] & TRI_FLAG_DOUBLE_SIDED) != 0u;
    uint emitted = 0u;
    for (uint k = 1u; k + 1u < count; ++k) {
        TriSetup t;
        if (methodSetupTriangle(poly[0], poly[k], poly[k + 1u], tri, doubleSided, params.cullMode,
                                params.width, params.height, params.sampleBounds, t)) {
            emitTriangle(t, STORED_AS_RECORD(true), counts);
            ++emitted;
        }
    }
    if (emitted == 0u) countPrimitive(counts, COUNTER_CULLED);
}

#endif  // RASTER_SETUP_TRIANGLE_GLSL
