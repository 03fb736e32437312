// setup.comp - stage `setup`: per input triangle, cull, clip and snap; a small (sub-)triangle (bbox at
// most SMALL_TRI_SPAN pixels wide and high) is rasterized right here by its thread, the one-thread fast
// path that needs no record; a big one is appended as a TriSetup record for raster_tiles.
// One thread per triangle; groups = ceil(triangleCount / GROUP_SIZE).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(local_size_x = GROUP_SIZE) in;

// Rasterizes a small triangle (every pixel centre of its bbox) or appends a big one. A full list still
// counts the record, so the host sees the overflow, grows the buffers and redraws; nothing is written
// past the capacity.
void emitTriangle(TriSetup t)
{
    ivec4 bounds = setupPixelBounds(t, params.width, params.height);
    if (isSmallTriangle(bounds)) {
        atomicAdd(counters[COUNTER_SMALL], 1u);
        uint id = setupTriId(t);
        for (int y = bounds.y; y <= bounds.w; ++y) {
            for (int x = bounds.x; x <= bounds.z; ++x) {
                float depth;
                if (rasterPixel(t, x, y, depth)) mergeFragment(uint(y) * params.width + uint(x), depth, id);
            }
        }
        return;
    }
    uint slot = atomicAdd(counters[COUNTER_SETUP], 1u);
    if (slot >= params.setupCapacity) return;
    setupTris[slot] = t;
    uint i = atomicAdd(counters[COUNTER_BIG], 1u);
    bigTris[i] = slot;
    bigOffsets[i] = tileCount(bounds);
}

void main()
{
    uint tri = gl_GlobalInvocationID.x;
    if (tri >= params.triangleCount) return;
    uint i0 = indices[3u * tri];
    uint i1 = indices[3u * tri + 1u];
    uint i2 = indices[3u * tri + 2u];
    if (max(i0, max(i1, i2)) >= params.vertexCount) {
        atomicAdd(counters[COUNTER_INVALID], 1u);
        return;
    }
    vec4 poly[MAX_CLIP_VERTS];
    uint count;
    bool stored = params.transformInSetup == 0u;
    vec4 c0 = setupClipPosition(params, positions[i0], stored ? clipPos[i0] : vec4(0.0f));
    vec4 c1 = setupClipPosition(params, positions[i1], stored ? clipPos[i1] : vec4(0.0f));
    vec4 c2 = setupClipPosition(params, positions[i2], stored ? clipPos[i2] : vec4(0.0f));
    uint kind = prepareTriangle(c0, c1, c2, params.guardBand, poly, count);
    if (kind == PREPARE_INVALID) {
        atomicAdd(counters[COUNTER_INVALID], 1u);
        return;
    }
    if (kind == PREPARE_CLIPPED) atomicAdd(counters[COUNTER_CLIPPED], 1u);
    bool doubleSided = (triFlags[tri] & TRI_FLAG_DOUBLE_SIDED) != 0u;
    uint emitted = 0u;
    for (uint k = 1u; k + 1u < count; ++k) {
        TriSetup t;
        if (setupTriangle(poly[0], poly[k], poly[k + 1u], tri, doubleSided, params.cullMode, params.width,
                          params.height, t)) {
            emitTriangle(t);
            ++emitted;
        }
    }
    if (emitted == 0u) atomicAdd(counters[COUNTER_CULLED], 1u);
}
