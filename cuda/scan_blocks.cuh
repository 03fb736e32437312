// scan_blocks.cuh - stage `scan_blocks`: exclusive scan of the screen tiles' bin counts within each
// block of SCAN_GROUP_SIZE tiles, in place in tileBins; each block's total goes to scanSums, and every
// tile with a non-empty bin to the active tile list that raster_tiles works through.
// One thread per screen tile; blocks = ceil(tilesX * tilesY / SCAN_GROUP_SIZE).
namespace sr {

__device__ inline void scanBlocksStage(const RasterParams& params, const Buffers& b)
{
    __shared__ uint partial[SCAN_GROUP_SIZE];
    uint count = params.tilesX * params.tilesY;
    uint i = globalThreadId();
    uint lane = threadIdx.x;
    uint value = i < count ? b.tileBins[i] : 0u;
    partial[lane] = value;
    __syncthreads();
    blockInclusiveScan(partial, lane);
    if (i < count) b.tileBins[i] = partial[lane] - value;
    if (value > 0u) b.activeTiles[atomicAdd(&b.counters[COUNTER_ACTIVE_TILES], 1u)] = i;
    // Only CPU devices split bins (RasterParams.rasterChunk); a CUDA device never does.
    if (params.rasterChunk != 0u && value > 0u) atomicMax(&b.counters[COUNTER_MAX_BIN], value);
    if (lane == uint(SCAN_GROUP_SIZE) - 1u) b.scanSums[blockIdx.x] = partial[lane];
}

}  // namespace sr
