// scan_sums.cuh - stage `scan_sums`: exclusive scan of the block totals in scanSums, in place, and the
// grand total of bin entries into counters[COUNTER_BIN_ENTRIES]. One block of SCAN_GROUP_SIZE threads.
namespace sr {

__device__ inline void scanSumsStage(const RasterParams& params, const Buffers& b)
{
    __shared__ uint partial[SCAN_GROUP_SIZE];
    uint lane = threadIdx.x;
    uint blocks = (params.tilesX * params.tilesY + uint(SCAN_GROUP_SIZE) - 1u) / uint(SCAN_GROUP_SIZE);
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
        // Bin offsets are uint; a total past 2^31 is reported instead of wrapping silently.
        bool overflow = carry >= (uint64_t(1) << 31);
        b.counters[COUNTER_BIN_ENTRIES] = overflow ? 0u : uint(carry);
        if (overflow) b.counters[COUNTER_WORK_OVERFLOW] = 1u;
    }
}

}  // namespace sr
