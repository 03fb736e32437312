// raster_tiles.cuh - stage `raster_tiles`: (big triangle, TILE_SIZE^2 tile) work items, one thread
// per pixel of the tile, so a large triangle spreads over as many blocks as it has tiles.
// Work item k belongs to the last big triangle whose scanned offset is <= k (binary search). A block
// takes a batch of up to TILE_SIZE^2 consecutive items: each thread searches the owner of one item at
// once (so the ~log2(n) dependent loads of the searches overlap instead of running back to back), then
// the whole block rasterizes the batch's tiles one after another. With few items the batch shrinks to
// what spreads them over all blocks, so they are not serialized in a few.
// Grid-stride loop over the batches of counters[COUNTER_TILES] items; blocks = RasterParams.rasterGroups.
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
    __shared__ uint owner[TILE_SIZE * TILE_SIZE];
    uint batch = rasterBatchSize(total, gridDim.x);
    for (uint base = blockIdx.x * batch; base < total; base += gridDim.x * batch) {
        owner[lane] = lane < batch && base + lane < total ? findBigTriangle(b, base + lane, bigCount) : 0u;
        __syncthreads();
        uint count = min(batch, total - base);
        for (uint k = 0u; k < count; ++k) {
            uint big = owner[k];
            TriSetup t = b.setupTris[b.bigTris[big]];
            ivec4 bounds = setupPixelBounds(t, params.width, params.height);
            ivec2 p = tilePixel(bounds, base + k - b.bigOffsets[big], lane);
            float depth;
            if (p.x >= bounds.x && p.x <= bounds.z && p.y >= bounds.y && p.y <= bounds.w &&
                rasterPixel(t, p.x, p.y, depth))
                mergeFragment(params, b, uint(p.y) * params.width + uint(p.x), depth, setupTriId(t));
        }
        __syncthreads();
    }
}

}  // namespace sr
