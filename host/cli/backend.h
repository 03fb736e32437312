// backend.h - the one place where the compute backend is chosen at run time.
//
// Lives above both backends (cuda/ and host/vulkan/), which implement the factories that
// render/compute_device.h declares, so no lower folder needs to know which backends exist.
#ifndef RASTER_BACKEND_H
#define RASTER_BACKEND_H

#include <memory>

#include "base/result.h"
#include "render/compute_device.h"

namespace sr {

enum class BackendKind { Auto, Cuda, Vulkan };

// Auto = CUDA when a CUDA GPU is present, else Vulkan (a GPU first, else lavapipe).
Result<std::unique_ptr<ComputeDevice>> makeComputeDevice(BackendKind kind, int index);

}  // namespace sr

#endif  // RASTER_BACKEND_H
