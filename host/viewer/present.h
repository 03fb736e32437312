// present.h - showing a rendered frame in the viewer's window through a Vulkan swapchain.
//
// The presenter owns a Vulkan context of its own on the window's surface (any Vulkan device that can
// present to it: lavapipe under Xvfb, a GPU with a display). Each frame the resolved sRGB image goes
// into a host-visible buffer, is copied into the acquired swapchain image on that device and
// presented; with `readback`, the swapchain image is copied back before presentation, so a test sees
// exactly the pixels the window shows. Frames come from either backend through the host (the renderer
// downloads every frame's image anyway); sharing the compute device's framebuffer with the swapchain is
// the faster path this leaves for later (docs/viewer.md says what it would save).
#ifndef RASTER_VIEWER_PRESENT_H
#define RASTER_VIEWER_PRESENT_H

#include <cstdint>
#include <memory>

#include "base/result.h"
#include "io/image_io.h"
#include "render/compute_device.h"
#include "vulkan/vulkan_context.h"

namespace sr {

class Presenter {
public:
    // A presenter for the window `target` describes, on Vulkan device `deviceIndex` (-1: the first that
    // can present to it).
    static Result<std::unique_ptr<Presenter>> create(const PresentTarget& target, int deviceIndex);
    ~Presenter();
    Presenter(const Presenter&) = delete;
    Presenter& operator=(const Presenter&) = delete;

    // Shows `image` (RGBA8, sRGB-encoded, R in the low byte) in a window whose framebuffer is
    // windowWidth x windowHeight: copied to the top-left corner, the rest cleared to black. The
    // swapchain follows the window's size. With `readback`, it receives the presented image.
    Status present(const RgbaImage& image, uint32_t windowWidth, uint32_t windowHeight, RgbaImage* readback);

    const DeviceInfo& info() const { return info_; }

private:
    Presenter() = default;
    Status createSwapchain(uint32_t width, uint32_t height);
    void destroySwapchain();
    Status presentOnce(const RgbaImage& image, RgbaImage* readback, bool& outOfDate);

    VulkanContext context_;
    DeviceInfo info_;
    VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
    std::vector<VkImage> images_;
    VkFormat format_ = VK_FORMAT_UNDEFINED;
    bool swapRedBlue_ = false;  // the swapchain is BGRA: bytes swizzled on the way in and out
    bool canRead_ = false;      // the swapchain images allow transfers out (readback)
    VkExtent2D extent_{0, 0};
    VkFence acquired_ = VK_NULL_HANDLE;
    GpuBuffer pixels_;  // host-visible: the frame going in, the readback coming out
};

}  // namespace sr

#endif  // RASTER_VIEWER_PRESENT_H
