// raster_tiles.cuh - stage `raster_tiles`: one block per (big triangle, TILE_SIZE^2 tile) work item,
// one thread per pixel, so a large triangle spreads over as many blocks as it has tiles.
// Work item k belongs to the last big triangle whose scanned offset is <= k (binary search).
// Grid-stride loop over counters[COUNTER_TILES] items; blocks = RasterParams.rasterGroups.
namespace sr {

// Index of the big triangle owning work item `item`.
__device__ inline uint findBigTriangle(const Buffers& b, uint item, uint bigCount)
{
    uint lo = 0u;
    uint hi = bigCount - 1u;
    while (lo < hi) {
        uint mid = (lo + hi + 1u) >> 1u;
        if (b.bigOffsets[mid] <= item)
            lo = mid;
        else
            hi = mid - 1u;
    }
    return lo;
}

__device__ inline void rasterTilesStage(const RasterParams& params, const Buffers& b)
{
    uint total = b.counters[COUNTER_TILES];
    uint bigCount = b.counters[COUNTER_BIG];
    uint lane = threadIdx.x;
    for (uint item = blockIdx.x; item < total; item += gridDim.x) {
        uint big = findBigTriangle(b, item, bigCount);
        TriSetup t = b.setupTris[b.bigTris[big]];
        ivec4 bounds = setupPixelBounds(t, params.width, params.height);
        ivec2 p = tilePixel(bounds, item - b.bigOffsets[big], lane);
        float depth;
        if (p.x >= bounds.x && p.x <= bounds.z && p.y >= bounds.y && p.y <= bounds.w &&
            rasterPixel(t, p.x, p.y, depth))
            mergeFragment(params, b, uint(p.y) * params.width + uint(p.x), depth, setupTriId(t));
    }
}

}  // namespace sr
