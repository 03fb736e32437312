// kernels.h - launching the CUDA stages by id (STAGE_*), the CUDA side of ComputeDevice::run.
#ifndef RASTER_CUDA_KERNELS_H
#define RASTER_CUDA_KERNELS_H

#include <cuda_runtime.h>

#include "buffers.cuh"

namespace sr {

// Enqueues `blocks` blocks of stage `stage` on `stream`, of stageGroupSize(stage) threads each, for
// setup and raster_tiles the build with the alpha test when `alphaTest` (Dispatch::alphaTest), for the
// METHOD stages of the table (setup, bin_count, bin_fill, raster_tiles) the build of raster method
// `rasterMethod` (Dispatch::rasterMethod); returns the launch error, if any.
cudaError_t launchStage(uint stage, uint blocks, bool alphaTest, uint rasterMethod,
                        const RasterParams& params, const Buffers& buffers, cudaStream_t stream);

// The launch of the stages a raster method changes, for method kMethod (kernels.cuh).
template <uint kMethod>
cudaError_t launchMethodStage(uint stage, uint blocks, bool alphaTest, const RasterParams& params,
                              const Buffers& buffers, cudaStream_t stream);

}  // namespace sr

#endif  // RASTER_CUDA_KERNELS_H
