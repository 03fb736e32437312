// backend.cpp - the one place where the compute backend is chosen at run time.
#include "cli/backend.h"

namespace sr {

Result<std::unique_ptr<ComputeDevice>> makeComputeDevice(BackendKind kind, int index)
{
    switch (kind) {
    case BackendKind::Cuda: return makeCudaDevice(index);
    case BackendKind::Vulkan: return makeVulkanDevice(index);
    case BackendKind::Auto: break;
    }
    // Auto: a CUDA GPU when there is one, otherwise Vulkan (a GPU first, else lavapipe).
    auto cuda = makeCudaDevice(index);
    if (cuda.ok()) return cuda;
    return makeVulkanDevice(index);
}

}  // namespace sr
