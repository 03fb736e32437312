// setup.cuh - stage `setup`: per input triangle, cull, clip and snap (from the vertex stage's records of
// vertices snapped once each; only a triangle that crosses a clip plane goes back to clip positions).
// A small (sub-)triangle (bbox at most SMALL_TRI_SPAN pixels wide and high) is rasterized right here by
// its thread, the one-thread fast path that needs no memory; a big one is cut into pieces of
// consecutive bbox tiles (pieceCount) for bin_count and bin_fill. Only a clipped big sub-triangle is
// stored (a TriSetup record); every other big triangle is named by its input index and set up again
// where it is needed.
// One thread per triangle; blocks = ceil(triangleCount / GROUP_SIZE).
namespace sr {

// Rasterizes a small triangle (every pixel centre of its bbox) or appends a big one's pieces. A full
// list still counts the appends, so the host sees the overflow, grows the lists and redraws; nothing is
// written past a capacity.
__device__ inline void emitTriangle(const RasterParams& params, const Buffers& b, const TriSetup& t,
                                    bool clipped)
{
    ivec4 bounds = setupPixelBounds(t, params.width, params.height);
    uint id = setupTriId(t);
    if (isSmallTriangle(bounds)) {
        atomicAdd(&b.counters[COUNTER_SMALL], 1u);
        for (int y = bounds.y; y <= bounds.w; ++y) {
            for (int x = bounds.x; x <= bounds.z; ++x) {
                float depth;
                if (rasterPixel(t, x, y, depth))
                    mergeFragment(params, b, uint(y) * params.width + uint(x), depth, id);
            }
        }
        return;
    }
    atomicAdd(&b.counters[COUNTER_BIG], 1u);
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
        binTiles<false>(params, b, t, bounds, ref, 0u, tiles);
        return;
    }
    atomicAdd(&b.counters[COUNTER_SPLIT], 1u);
    for (uint k = 0u; k < n && base + k < params.pieceCapacity; ++k)
        b.pieces[base + k] = uvec2(ref, k * pieceTiles(tiles));
}

__device__ inline void setupStage(const RasterParams& params, const Buffers& b)
{
    uint tri = globalThreadId();
    if (tri >= params.triangleCount) return;
    uint i0, i1, i2;
    if (!loadTriangleIndices(params, b, tri, i0, i1, i2)) {
        atomicAdd(&b.counters[COUNTER_INVALID], 1u);
        return;
    }
    ivec4 s0 = loadSnapped(params, b, i0), s1 = loadSnapped(params, b, i1), s2 = loadSnapped(params, b, i2);
    uint kind = classifySnapped(s0, s1, s2);
    if (kind == PREPARE_INVALID) {
        atomicAdd(&b.counters[COUNTER_INVALID], 1u);
        return;
    }
    bool doubleSided = (b.triFlags[tri] & TRI_FLAG_DOUBLE_SIDED) != 0u;
    uint emitted = 0u;
    TriSetup t;
    if (kind == PREPARE_DIRECT) {
        // The common case: vertices snapped once each by the vertex stage.
        if (setupSnappedRecords(s0, s1, s2, tri, doubleSided, params.cullMode, params.width, params.height,
                                t)) {
            emitTriangle(params, b, t, false);
            ++emitted;
        }
    } else if (kind == PREPARE_CLIPPED) {
        atomicAdd(&b.counters[COUNTER_CLIPPED], 1u);
        vec4 poly[MAX_CLIP_VERTS];
        uint planes = (uint(s0.w) | uint(s1.w) | uint(s2.w)) >> 16u & 0x3fu;
        vec4 c0 = clipPosition(params, b, i0), c1 = clipPosition(params, b, i1),
             c2 = clipPosition(params, b, i2);
        uint count = clipTriangle(c0, c1, c2, planes, params.guardBand, poly);
        for (uint k = 1u; k + 1u < count; ++k) {
            if (setupTriangle(poly[0], poly[k], poly[k + 1u], tri, doubleSided, params.cullMode, params.width,
                              params.height, t)) {
                emitTriangle(params, b, t, true);
                ++emitted;
            }
        }
    }
    if (emitted == 0u) atomicAdd(&b.counters[COUNTER_CULLED], 1u);
}

}  // namespace sr
