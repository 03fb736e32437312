// cuda_device_internal.h - what the CUDA ComputeDevice (cuda_device.cu) shows the rest of cuda/: its
// GPU, its stream and a buffer's device pointer, for the viewer's shared framebuffer (cuda_interop.cu).
#ifndef RASTER_CUDA_DEVICE_INTERNAL_H
#define RASTER_CUDA_DEVICE_INTERNAL_H

#include <cuda_runtime.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "render/compute_device.h"

namespace sr {

struct CudaDeviceView {
    int ordinal = 0;                 // the CUDA device (cudaSetDevice)
    std::array<uint8_t, 16> uuid{};  // cudaDeviceProp::uuid
    cudaStream_t stream = nullptr;   // every launch of the device runs on it
    void* framebuffer = nullptr;     // BUF_FRAMEBUFFER as the last run left it
    size_t framebufferBytes = 0;
};

// The view of `device` when it is the CUDA backend's, else nothing. Valid until the device's next call.
std::optional<CudaDeviceView> cudaDeviceView(ComputeDevice& device);

}  // namespace sr

#endif  // RASTER_CUDA_DEVICE_INTERNAL_H
