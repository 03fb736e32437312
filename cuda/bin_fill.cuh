// bin_fill.cuh - stage `bin_fill`: per piece of a big triangle, write its ref into the bin of every
// screen tile of the piece that the triangle touches, at the slots the scanned counts reserved (the walk
// is in bin.cuh). Afterwards binEnd(tile) is the end of the tile's bin and binEnd(tile - 1) its start.
// One thread per piece, striding; blocks = RasterParams.binGroups.
namespace sr {

template <uint kMethod>
__device__ inline void binFillStage(const RasterParams& params, const Buffers& b)
{
    binPieces<true, kMethod>(params, b);
}

}  // namespace sr
