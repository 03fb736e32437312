// interpolate.cu - nvdiffrast's interpolate on a CUDA device: one thread per pixel of rasterize's output,
// each shared/interpolate.h's interpolatePixel, as the host's loop (host/api/raster.cpp) runs it: the
// same bits.
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
    const float* view =
        job.attr + (job.attrViews == 1 ? 0 : p / job.pixelsPerView) * job.vertices * job.channels;
    const uint triangles = job.triangleCount < 0xFFFFFFFFull ? uint(job.triangleCount) : 0xFFFFFFFFu;
    const InterpolateFault fault = interpolatePixel(job.rast + 4 * p, view, job.triangles, triangles,
                                                    job.vertices, job.channels, job.out + p * job.channels);
    if (fault.badSlot) atomicMin(&bad[0], p);
    if (fault.badTriangle) atomicMin(&bad[1], static_cast<unsigned long long>(fault.triangle));
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
