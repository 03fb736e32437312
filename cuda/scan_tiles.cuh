// scan_tiles.cuh - stage `scan_tiles`: the screen tiles' bin counts become bin offsets, in place (an
// exclusive scan), the tiles with a non-empty bin go to the active tile list, and the total to
// counters[COUNTER_BIN_ENTRIES]. One block: each thread sums a run of consecutive tiles, the block scans
// the run totals (Hillis-Steele: after the step with offset d each entry sums its last 2d inputs), and
// each thread writes its run's offsets. One launch instead of a scan per block plus a scan of the
// block totals: at 1080p the whole stage is 32,400 counts, which one block reads in a few microseconds.
// blocks = 1 of SCAN_GROUP_SIZE threads.
namespace sr {

__device__ inline void scanTilesStage(const RasterParams& params, const Buffers& b)
{
    __shared__ uint64_t partial[SCAN_GROUP_SIZE];
    uint lane = threadIdx.x;
    uint tiles = params.tilesX * params.tilesY;
    uint run = (tiles + uint(SCAN_GROUP_SIZE) - 1u) / uint(SCAN_GROUP_SIZE);
    uint first = min(lane * run, tiles);
    uint last = min(first + run, tiles);
    uint64_t sum = 0u;
    for (uint i = first; i < last; ++i) sum += uint64_t(b.tileBins[i]);
    partial[lane] = sum;
    __syncthreads();
    for (uint d = 1u; d < uint(SCAN_GROUP_SIZE); d <<= 1u) {
        uint64_t add = lane >= d ? partial[lane - d] : uint64_t(0);
        __syncthreads();
        partial[lane] += add;
        __syncthreads();
    }
    // Bin offsets are uint; a total past 2^31 is reported instead of wrapping silently.
    uint64_t total = partial[SCAN_GROUP_SIZE - 1];
    if (total >= (uint64_t(1) << 31)) {
        if (lane == 0u) b.counters[COUNTER_WORK_OVERFLOW] = 1u;
        return;
    }
    uint offset = uint(partial[lane] - sum);
    for (uint i = first; i < last; ++i) {
        uint count = b.tileBins[i];
        b.tileBins[i] = offset;
        offset += count;
        if (count > 0u) b.activeTiles[atomicAdd(&b.counters[COUNTER_ACTIVE_TILES], 1u)] = i;
    }
    if (lane == 0u) b.counters[COUNTER_BIN_ENTRIES] = uint(total);
}

}  // namespace sr
