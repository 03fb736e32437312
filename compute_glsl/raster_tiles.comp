// raster_tiles.comp - stage `raster_tiles`: (big triangle, TILE_SIZE^2 tile) work items, one thread
// per pixel of the tile, so a large triangle spreads over as many groups as it has tiles.
// Work item k belongs to the last big triangle whose scanned offset is <= k (binary search). A group
// takes a batch of up to TILE_SIZE^2 consecutive items: each thread searches the owner of one item at
// once (so the ~log2(n) dependent loads of the searches overlap instead of running back to back), then
// the whole group rasterizes the batch's tiles one after another. With few items the batch shrinks to
// what spreads them over all groups, so they are not serialized in a few.
// Grid-stride loop over the batches of counters[COUNTER_TILES] items; groups = RasterParams.rasterGroups.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(local_size_x = TILE_SIZE * TILE_SIZE) in;

shared uint owner[TILE_SIZE * TILE_SIZE];

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
    uint batch = rasterBatchSize(total, gl_NumWorkGroups.x);
    for (uint base = gl_WorkGroupID.x * batch; base < total; base += gl_NumWorkGroups.x * batch) {
        owner[lane] = lane < batch && base + lane < total ? findBigTriangle(base + lane, bigCount) : 0u;
        barrier();
        uint count = min(batch, total - base);
        for (uint k = 0u; k < count; ++k) {
            uint big = owner[k];
            TriSetup t = setupTris[bigTris[big]];
            ivec4 bounds = setupPixelBounds(t, params.width, params.height);
            ivec2 p = tilePixel(bounds, base + k - bigOffsets[big], lane);
            float depth;
            if (p.x >= bounds.x && p.x <= bounds.z && p.y >= bounds.y && p.y <= bounds.w &&
                rasterPixel(t, p.x, p.y, depth))
                mergeFragment(uint(p.y) * params.width + uint(p.x), depth, setupTriId(t));
        }
        barrier();
    }
}
