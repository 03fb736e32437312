// cuda_unavailable.cpp - makeCudaDevice for builds without nvcc: the CUDA backend reports itself absent,
// and no device is a CUDA device that could share its frames (render/frame_share.h).
#include "render/compute_device.h"
#include "render/frame_share.h"

namespace sr {

Result<std::unique_ptr<ComputeDevice>> makeCudaDevice(int)
{
    return makeError(ExitCode::Usage, "cuda backend unavailable: this build has no CUDA support");
}

std::optional<FrameShareSource> cudaFrameShareSource(ComputeDevice&)
{
    return std::nullopt;
}

}  // namespace sr
