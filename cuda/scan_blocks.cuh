// scan_blocks.cuh - stage `scan_blocks`: exclusive scan of the big triangles' tile counts within each
// block of SCAN_GROUP_SIZE, in place in bigOffsets; each block's total goes to scanSums.
// One thread per big-list entry; blocks = ceil(setupCapacity / SCAN_GROUP_SIZE), idle past the count.
namespace sr {

__device__ inline void scanBlocksStage(const RasterParams&, const Buffers& b)
{
    __shared__ uint partial[SCAN_GROUP_SIZE];
    uint count = b.counters[COUNTER_BIG];
    if (blockIdx.x * uint(SCAN_GROUP_SIZE) >= count) return;  // uniform across the block
    uint i = globalThreadId();
    uint lane = threadIdx.x;
    uint value = i < count ? b.bigOffsets[i] : 0u;
    partial[lane] = value;
    __syncthreads();
    blockInclusiveScan(partial, lane);
    if (i < count) b.bigOffsets[i] = partial[lane] - value;
    if (lane == uint(SCAN_GROUP_SIZE) - 1u) b.scanSums[blockIdx.x] = partial[lane];
}

}  // namespace sr
