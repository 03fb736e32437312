// vulkan_present_source.h - the Vulkan compute device as the viewer's presentation source: made on the
// window's surface (its context gets the surface, a queue that can present and VK_KHR_swapchain), it
// lets the viewer copy its own framebuffer buffer (BUF_FRAMEBUFFER) into the swapchain on the GPU,
// with no round trip through the host (host/viewer/present.h).
#ifndef RASTER_VULKAN_PRESENT_SOURCE_H
#define RASTER_VULKAN_PRESENT_SOURCE_H

#include <memory>
#include <optional>

#include "base/result.h"
#include "render/compute_device.h"
#include "vulkan/vulkan_context.h"

namespace sr {

struct VulkanPresentSource {
    VulkanContext* context;  // the device's context (on the window's surface when made for one)
    VkBuffer framebuffer;    // BUF_FRAMEBUFFER as the last run left it (output width x height words)
};

// A Vulkan compute device on device `index` that can present to `target`'s window.
Result<std::unique_ptr<ComputeDevice>> makeVulkanPresentingDevice(int index, const PresentTarget& target);

// The context and framebuffer of `device` when it is a Vulkan device, else nothing.
std::optional<VulkanPresentSource> vulkanPresentSource(ComputeDevice& device);

}  // namespace sr

#endif  // RASTER_VULKAN_PRESENT_SOURCE_H
