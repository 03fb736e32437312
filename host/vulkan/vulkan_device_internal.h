// vulkan_device_internal.h - test hooks of the Vulkan backends (host/vulkan/vulkan_context.cpp,
// host/vulkan/vulkan_device.cpp).
//
// Validation problems that happen while a device is destroyed (leaked objects) cannot be returned
// by any method call, and a correct backend never triggers a validation error on purpose; these two
// functions let tests observe both paths anyway.
#ifndef RASTER_VULKAN_DEVICE_INTERNAL_H
#define RASTER_VULKAN_DEVICE_INTERNAL_H

#include <cstddef>

#include "render/compute_device.h"

namespace sr {

// Validation errors reported so far by the messengers of every Vulkan context of this process (compute
// devices and vulkan-graphics renders), including those reported while a device and its instance
// were being destroyed.
size_t vulkanValidationErrorCount();

// Sends `message` through `device`'s debug messenger as a validation error, exactly as the layer
// would. Fails when `device` is not a Vulkan device or was created without validation.
Status injectVulkanValidationError(ComputeDevice& device, const char* message);

}  // namespace sr

#endif  // RASTER_VULKAN_DEVICE_INTERNAL_H
