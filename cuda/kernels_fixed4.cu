// kernels_fixed4.cu - the fixed4 raster method's builds of setup, bin_count, bin_fill and raster_tiles
// (kernels.cuh), in a translation unit of their own.
#include "kernels.cuh"

namespace sr {

template cudaError_t launchMethodStage<RASTER_FIXED4>(uint, uint, bool, const RasterParams&, const Buffers&,
                                                      cudaStream_t);

}  // namespace sr
