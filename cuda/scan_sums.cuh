// scan_sums.cuh - stage `scan_sums`: exclusive scan of the block totals in scanSums, in place, and the
// grand total of tile work items into counters[COUNTER_TILES]. One block of SCAN_GROUP_SIZE threads.
namespace sr {

__device__ inline void scanSumsStage(const RasterParams&, const Buffers& b)
{
    __shared__ uint partial[SCAN_GROUP_SIZE];
    uint lane = threadIdx.x;
    uint blocks = (b.counters[COUNTER_BIG] + uint(SCAN_GROUP_SIZE) - 1u) / uint(SCAN_GROUP_SIZE);
    uint64_t carry = 0u;  // every thread keeps the same running total
    for (uint base = 0u; base < blocks; base += uint(SCAN_GROUP_SIZE)) {
        uint i = base + lane;
        uint value = i < blocks ? b.scanSums[i] : 0u;
        partial[lane] = value;
        __syncthreads();
        blockInclusiveScan(partial, lane);
        if (i < blocks) b.scanSums[i] = uint(carry) + partial[lane] - value;
        carry += uint64_t(partial[SCAN_GROUP_SIZE - 1]);
        __syncthreads();
    }
    if (lane == 0u) {
        // Work item indices are uint; a total past 2^31 is reported instead of wrapping silently.
        bool overflow = carry >= (uint64_t(1) << 31);
        b.counters[COUNTER_TILES] = overflow ? 0u : uint(carry);
        b.counters[COUNTER_WORK_OVERFLOW] = overflow ? 1u : 0u;
    }
}

}  // namespace sr
