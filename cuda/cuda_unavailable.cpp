// cuda_unavailable.cpp - makeCudaDevice for builds without nvcc: the CUDA backend reports itself absent.
#include "render/compute_device.h"

namespace sr {

Result<std::unique_ptr<ComputeDevice>> makeCudaDevice(int)
{
    return makeError(ExitCode::Usage, "cuda backend unavailable: this build has no CUDA support");
}

}  // namespace sr
