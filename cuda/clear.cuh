// clear.cuh - stage `clear`: every sample's visibility key to empty (~0) (and hit count to 0 when
// counting), every counter and every screen tile's bin count to 0. Each thread clears CLEAR_SPAN
// elements GROUP_SIZE apart, so every store of a block is contiguous and a frame needs an eighth of
// the blocks (launching a block per 128 pixels cost more than the stores).
// blocks = ceil(max(samples, tiles, COUNTER_WORDS) / (GROUP_SIZE * CLEAR_SPAN)), samples = samplePlane *
// sampleCount.
namespace sr {

__device__ inline void clearStage(const RasterParams& params, const Buffers& b)
{
    uint first = blockIdx.x * uint(GROUP_SIZE * CLEAR_SPAN) + threadIdx.x;
    for (uint k = 0u; k < uint(CLEAR_SPAN); ++k) {
        uint i = first + k * uint(GROUP_SIZE);
        if (i < uint(COUNTER_WORDS)) b.counters[i] = 0u;
        if (i < params.tilesX * params.tilesY) b.tileBins[i] = 0u;
        // No early return: a frame of fewer samples than COUNTER_WORDS still clears every counter.
        if (i < params.samplePlane * params.sampleCount) {
            b.visibility[i] = ~0ull;
            if ((params.debugFlags & DEBUG_COUNT_HITS) != 0u) b.hitCount[i] = 0u;
        }
    }
}

}  // namespace sr
