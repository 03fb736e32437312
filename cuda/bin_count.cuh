// bin_count.cuh - stage `bin_count`: per piece of a big triangle, add one to the bin count of every
// screen tile of the piece that the triangle touches, unless setup counted it (the walk is in bin.cuh).
// One thread per piece, striding; blocks = RasterParams.binGroups.
namespace sr {

template <uint kMethod>
__device__ inline void binCountStage(const RasterParams& params, const Buffers& b)
{
    binPieces<false, kMethod>(params, b);
}

}  // namespace sr
