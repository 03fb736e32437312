// setup.cuh - stage `setup`: per input triangle, cull, clip and snap; a small (sub-)triangle (bbox at
// most SMALL_TRI_SPAN pixels wide and high) is rasterized right here by its thread, the one-thread fast
// path that needs no record; a big one is appended as a TriSetup record for raster_tiles.
// One thread per triangle; blocks = ceil(triangleCount / GROUP_SIZE).
namespace sr {

// Rasterizes a small triangle (every pixel centre of its bbox) or appends a big one. A full list still
// counts the record, so the host sees the overflow, grows the buffers and redraws; nothing is written
// past the capacity.
__device__ inline void emitTriangle(const RasterParams& params, const Buffers& b, const TriSetup& t)
{
    ivec4 bounds = setupPixelBounds(t, params.width, params.height);
    if (isSmallTriangle(bounds)) {
        atomicAdd(&b.counters[COUNTER_SMALL], 1u);
        uint id = setupTriId(t);
        for (int y = bounds.y; y <= bounds.w; ++y) {
            for (int x = bounds.x; x <= bounds.z; ++x) {
                float depth;
                if (rasterPixel(t, x, y, depth))
                    mergeFragment(params, b, uint(y) * params.width + uint(x), depth, id);
            }
        }
        return;
    }
    uint slot = atomicAdd(&b.counters[COUNTER_SETUP], 1u);
    if (slot >= params.setupCapacity) return;
    b.setupTris[slot] = t;
    uint i = atomicAdd(&b.counters[COUNTER_BIG], 1u);
    b.bigTris[i] = slot;
    b.bigOffsets[i] = tileCount(bounds);
}

__device__ inline void setupStage(const RasterParams& params, const Buffers& b)
{
    uint tri = globalThreadId();
    if (tri >= params.triangleCount) return;
    uint i0 = b.indices[3u * tri];
    uint i1 = b.indices[3u * tri + 1u];
    uint i2 = b.indices[3u * tri + 2u];
    if (max(i0, max(i1, i2)) >= params.vertexCount) {
        atomicAdd(&b.counters[COUNTER_INVALID], 1u);
        return;
    }
    vec4 poly[MAX_CLIP_VERTS];
    uint count;
    bool stored = params.transformInSetup == 0u;
    vec4 c0 = setupClipPosition(params, b.positions[i0], stored ? b.clipPos[i0] : vec4(0.0f));
    vec4 c1 = setupClipPosition(params, b.positions[i1], stored ? b.clipPos[i1] : vec4(0.0f));
    vec4 c2 = setupClipPosition(params, b.positions[i2], stored ? b.clipPos[i2] : vec4(0.0f));
    uint kind = prepareTriangle(c0, c1, c2, params.guardBand, poly, count);
    if (kind == PREPARE_INVALID) {
        atomicAdd(&b.counters[COUNTER_INVALID], 1u);
        return;
    }
    if (kind == PREPARE_CLIPPED) atomicAdd(&b.counters[COUNTER_CLIPPED], 1u);
    bool doubleSided = (b.triFlags[tri] & TRI_FLAG_DOUBLE_SIDED) != 0u;
    uint emitted = 0u;
    for (uint k = 1u; k + 1u < count; ++k) {
        TriSetup t;
        if (setupTriangle(poly[0], poly[k], poly[k + 1u], tri, doubleSided, params.cullMode, params.width,
                          params.height, t)) {
            emitTriangle(params, b, t);
            ++emitted;
        }
    }
    if (emitted == 0u) atomicAdd(&b.counters[COUNTER_CULLED], 1u);
}

}  // namespace sr
