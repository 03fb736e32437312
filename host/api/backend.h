// backend.h - the one place where the backend is chosen at run time, below every front end (the public
// API, the command line, batch, the viewer).
//
// Lives above both backends (cuda/ and host/vulkan/), which implement the factories that
// render/compute_device.h declares, so no lower folder needs to know which backends exist.
#ifndef RASTER_API_BACKEND_H
#define RASTER_API_BACKEND_H

#include <memory>
#include <vector>

#include "base/result.h"
#include "render/compute_device.h"
#include "render/renderer.h"

namespace sr {

enum class BackendKind { Auto, Cuda, Vulkan };

// Auto = CUDA when a CUDA GPU is present, else Vulkan (a GPU first, else lavapipe); when neither opens,
// the error gives both reasons.
Result<std::unique_ptr<ComputeDevice>> makeComputeDevice(BackendKind kind, int index);

struct PresentTarget;  // vulkan/vulkan_context.h: a window a Vulkan device can present to

// The compute devices a window can switch between, in order: `preferred` first (Auto: CUDA, as above),
// then the other where it opens. With `window`, the Vulkan device is made on it and presents its own
// framebuffer (vulkan/vulkan_present_source.h); one that cannot present to it (a GPU under Xvfb) still
// renders, and the host presents. A named backend must open; the other is a bonus.
Result<std::vector<std::unique_ptr<ComputeDevice>>> makeSwitchableDevices(BackendKind preferred, int index,
                                                                          const PresentTarget* window);

// The vulkan-graphics reference on Vulkan device `device` (-1: the first): the hardware's (or
// lavapipe's) own rasterizer. A tessellated frame draws the mesh the host's run of the tess_* stages
// generates (bit for bit what the compute backends draw), with the ids mapped back to the scene's
// triangles the same way.
Result<RenderOutput> renderGraphics(const Scene& scene, const CameraMatrices& camera,
                                    const RenderSettings& settings, int device);

}  // namespace sr

#endif  // RASTER_API_BACKEND_H
