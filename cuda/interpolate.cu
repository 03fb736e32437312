// interpolate.cu - nvdiffrast's interpolate on a CUDA device: one thread per pixel of rasterize's output,
// the pixel's triangle's attributes weighted by its (u, v) with shared/interpolate.h's formula, the same
// bits as the host's loop (host/api/raster.cpp).
#include "interpolate.h"

#include "raster_shared.h"
#include "shared/interpolate.h"

namespace sr {
namespace {

constexpr unsigned kInterpolateGroup = 256;

__global__ void interpolateKernel(InterpolateJob job, unsigned long long* bad)
{
    const unsigned long long p = blockIdx.x * static_cast<unsigned long long>(blockDim.x) + threadIdx.x;
    const unsigned long long pixels = static_cast<unsigned long long>(job.views) * job.pixelsPerView;
    if (p >= pixels) return;
    float* dst = job.out + p * job.channels;
    const uint slot = interpolateSlot(job.rast[4 * p + 3], uint(job.triangleCount));
    uint corner[3] = {0u, 0u, 0u};
    bool drawn = slot != 0u && slot != INTERPOLATE_BAD_SLOT;
    if (slot == INTERPOLATE_BAD_SLOT) atomicMin(&bad[0], p);
    if (drawn) {
        for (int k = 0; k < 3; ++k) corner[k] = job.triangles[3 * size_t(slot - 1u) + k];
        if (corner[0] >= job.vertices || corner[1] >= job.vertices || corner[2] >= job.vertices) {
            atomicMin(&bad[1], static_cast<unsigned long long>(slot - 1u));
            drawn = false;
        }
    }
    if (!drawn) {
        for (size_t c = 0; c < job.channels; ++c) dst[c] = 0.0f;
        return;
    }
    const float u = job.rast[4 * p], v = job.rast[4 * p + 1];
    const float* view =
        job.attr + (job.attrViews == 1 ? 0 : p / job.pixelsPerView) * job.vertices * job.channels;
    const float* a0 = view + size_t(corner[0]) * job.channels;
    const float* a1 = view + size_t(corner[1]) * job.channels;
    const float* a2 = view + size_t(corner[2]) * job.channels;
    for (size_t c = 0; c < job.channels; ++c) dst[c] = interpolateValue(u, v, a0[c], a1[c], a2[c]);
}

}  // namespace

cudaError_t launchInterpolate(const InterpolateJob& job, unsigned long long* bad, cudaStream_t stream)
{
    const unsigned long long pixels = static_cast<unsigned long long>(job.views) * job.pixelsPerView;
    if (pixels == 0) return cudaSuccess;
    const unsigned long long groups = (pixels + kInterpolateGroup - 1) / kInterpolateGroup;
    if (groups > 0x7FFFFFFFull) return cudaErrorInvalidValue;
    interpolateKernel<<<unsigned(groups), kInterpolateGroup, 0, stream>>>(job, bad);
    return cudaGetLastError();
}

}  // namespace sr
