// kernels_float.cu - the float raster method's builds of setup, bin_count, bin_fill and raster_tiles
// (kernels.cuh), in a translation unit of their own.
#include "kernels.cuh"

namespace sr {

template cudaError_t launchMethodStage<RASTER_FLOAT>(uint, uint, bool, const RasterParams&, const Buffers&,
                                                     cudaStream_t);

}  // namespace sr
