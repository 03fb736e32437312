// clear.cuh - stage `clear`: every pixel's visibility key to empty (~0), every counter to 0.
// One thread per pixel; blocks = ceil(width * height / GROUP_SIZE).
namespace sr {

__device__ inline void clearStage(const RasterParams& params, const Buffers& b)
{
    uint i = globalThreadId();
    if (i < uint(COUNTER_COUNT)) b.counters[i] = 0u;
    if (i < params.width * params.height) b.visibility[i] = ~0ull;
}

}  // namespace sr
