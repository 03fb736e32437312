// clear.cuh - stage `clear`: every pixel's visibility key to empty (~0) (and hit count to 0 when
// counting), every counter and every screen tile's bin count to 0.
// One thread per pixel; blocks = ceil(width * height / GROUP_SIZE).
namespace sr {

__device__ inline void clearStage(const RasterParams& params, const Buffers& b)
{
    uint i = globalThreadId();
    if (i < uint(COUNTER_COUNT)) b.counters[i] = 0u;
    if (i < params.tilesX * params.tilesY) b.tileBins[i] = 0u;
    if (i >= params.width * params.height) return;
    b.visibility[i] = ~0ull;
    if ((params.debugFlags & DEBUG_COUNT_HITS) != 0u) b.hitCount[i] = 0u;
}

}  // namespace sr
