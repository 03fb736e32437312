// raster_tiles.comp - stage `raster_tiles`: one group per (big triangle, TILE_SIZE^2 tile) work item,
// one thread per pixel, so a large triangle spreads over as many groups as it has tiles.
// Work item k belongs to the last big triangle whose scanned offset is <= k (binary search).
// Grid-stride loop over counters[COUNTER_TILES] items; groups = RasterParams.rasterGroups.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(local_size_x = TILE_SIZE * TILE_SIZE) in;

// Index of the big triangle owning work item `item`.
uint findBigTriangle(uint item, uint bigCount)
{
    uint lo = 0u;
    uint hi = bigCount - 1u;
    while (lo < hi) {
        uint mid = (lo + hi + 1u) >> 1u;
        if (bigOffsets[mid] <= item) lo = mid;
        else hi = mid - 1u;
    }
    return lo;
}

void main()
{
    uint total = counters[COUNTER_TILES];
    uint bigCount = counters[COUNTER_BIG];
    uint lane = gl_LocalInvocationID.x;
    for (uint item = gl_WorkGroupID.x; item < total; item += gl_NumWorkGroups.x) {
        uint big = findBigTriangle(item, bigCount);
        TriSetup t = setupTris[bigTris[big]];
        ivec4 bounds = setupPixelBounds(t, params.width, params.height);
        ivec2 p = tilePixel(bounds, item - bigOffsets[big], lane);
        float depth;
        if (p.x >= bounds.x && p.x <= bounds.z && p.y >= bounds.y && p.y <= bounds.w &&
            rasterPixel(t, p.x, p.y, depth))
            mergeFragment(uint(p.y) * params.width + uint(p.x), depth, setupTriId(t));
    }
}
