// compute_device.cpp - stage names and the one place where the backend is chosen.
#include "render/compute_device.h"

namespace sr {

const char* stageName(uint32_t stage)
{
    static const char* const names[STAGE_COUNT] = {"clear",     "vertex",   "setup",        "scan_blocks",
                                                   "scan_sums", "scan_add", "raster_tiles", "shade"};
    return stage < STAGE_COUNT ? names[stage] : "unknown";
}

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
