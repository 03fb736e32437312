// interpolate.h - the CUDA launch of nvdiffrast's interpolate (cuda/interpolate.cu), for CudaDevice.
#ifndef RASTER_CUDA_INTERPOLATE_H
#define RASTER_CUDA_INTERPOLATE_H

#include <cuda_runtime.h>

#include "render/compute_device.h"

namespace sr {

// One thread per pixel of `job` on `stream`; bad[0] and bad[1] (device memory, set to ~0 first by the
// caller) take the smallest bad pixel and bad triangle (InterpolateJob).
cudaError_t launchInterpolate(const InterpolateJob& job, unsigned long long* bad, cudaStream_t stream);

}  // namespace sr

#endif  // RASTER_CUDA_INTERPOLATE_H
