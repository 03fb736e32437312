// present.h - showing a rendered frame in the viewer's window through a Vulkan swapchain.
//
// Three paths. The Vulkan compute backend, made on the window's surface, presents from its own
// framebuffer buffer: the frame is copied (or blitted, to reorder the channels) into the acquired
// swapchain image on the GPU, and never leaves the device (createOn, presentBuffer). The CUDA backend
// shares a buffer with the presenter (render/frame_share.h): the presenter's context of its own on the
// same GPU (matched by UUID) exports a buffer and a semaphore, CUDA copies its framebuffer into the
// buffer and signals, and the copy into the swapchain image waits on the signal (createShared,
// presentShared). Any other source presents from the host: the presenter owns a Vulkan context of its
// own on the window (any device that can present to it: lavapipe under Xvfb, a GPU with a display), and
// the frame goes into a host-visible buffer and from there into the swapchain image (create, present).
// With `readback`, the swapchain image is copied back before presentation, so a test sees exactly the
// pixels the window shows.
//
// Every submission waits for its fence before the call returns, so no work of one frame is pending when
// the next begins: in particular the shared buffer's copy into the swapchain image has finished before
// the device is asked to overwrite the buffer with the next frame.
#ifndef RASTER_VIEWER_PRESENT_H
#define RASTER_VIEWER_PRESENT_H

#include <cstdint>
#include <memory>
#include <optional>

#include "base/result.h"
#include "io/image_io.h"
#include "render/compute_device.h"
#include "render/frame_share.h"
#include "vulkan/vulkan_context.h"

namespace sr {

class Presenter {
public:
    // A presenter with a Vulkan context of its own for the window `target` describes, on Vulkan device
    // `deviceIndex` (-1: the first that can present to it): frames come from the host (present()).
    static Result<std::unique_ptr<Presenter>> create(const PresentTarget& target, int deviceIndex);
    // Offscreen (`raster view --offscreen`, machines without a display): the same copies into a B8G8R8A8
    // image the presenter owns instead of a swapchain image, nothing acquired or presented. `shared`: the
    // compute device's context (presentBuffer); null: a context of its own on device `deviceIndex`.
    static Result<std::unique_ptr<Presenter>> createOffscreen(VulkanContext* shared, int deviceIndex);
    // A presenter on `shared`, the context of a Vulkan compute device made on the window
    // (vulkan_present_source.h): frames come from that device's buffers (presentBuffer()).
    static Result<std::unique_ptr<Presenter>> createOn(VulkanContext& shared);
    // A presenter whose frames come from `source`'s device through a shared buffer: a context of its
    // own for the window `target` (null: offscreen) on Vulkan device `deviceIndex` (-1: wherever the
    // source's GPU is), which must be the source's GPU, a buffer of at least `frameBytes` and a
    // semaphore exported to the source and imported there. Fails in one line where any of that cannot
    // be done (no Vulkan device is that GPU, it cannot export, the import fails).
    static Result<std::unique_ptr<Presenter>> createShared(const PresentTarget* target, int deviceIndex,
                                                           const FrameShareSource& source, size_t frameBytes);
    ~Presenter();
    Presenter(const Presenter&) = delete;
    Presenter& operator=(const Presenter&) = delete;

    // Shows `image` (RGBA8, sRGB-encoded, R in the low byte) in a window whose framebuffer is
    // windowWidth x windowHeight: copied to the top-left corner, the rest cleared to black. The
    // swapchain follows the window's size. With `readback`, it receives the presented image.
    Status present(const RgbaImage& image, uint32_t windowWidth, uint32_t windowHeight, RgbaImage* readback);
    // The same from `buffer`, a width x height image of the same words on the shared context's device
    // (the compute device's BUF_FRAMEBUFFER), copied on the GPU: into an RGBA swapchain image directly,
    // into a BGRA one through an RGBA image and a blit, which reorders the channels.
    Status presentBuffer(VkBuffer buffer, uint32_t width, uint32_t height, uint32_t windowWidth,
                         uint32_t windowHeight, RgbaImage* readback);
    // The source's last frame (width x height words), which it copies into the shared buffer (grown
    // first where too small: exported and imported again) and signals; the copy into the swapchain
    // image waits on that signal, and is made as presentBuffer() makes its copy.
    Status presentShared(uint32_t width, uint32_t height, uint32_t windowWidth, uint32_t windowHeight,
                         RgbaImage* readback);
    // Gives the window's swapchain up (another presenter is about to take the window: a window has one
    // swapchain at a time); the next present makes a new one.
    void releaseSwapchain();

    const DeviceInfo& info() const { return info_; }

private:
    Presenter() = default;
    Status init();
    Status createSwapchain(uint32_t width, uint32_t height);
    void destroySwapchain();
    // Acquires an image, clears it where the frame (width x height) does not reach, lets `fill` record
    // the frame's copy into it (layout TRANSFER_DST_OPTIMAL), reads it back if asked, presents it.
    template <typename Fill>
    Status presentFrame(uint32_t width, uint32_t height, uint32_t windowWidth, uint32_t windowHeight,
                        RgbaImage* readback, Fill fill);
    Status ensurePixels(VkDeviceSize bytes);
    // Records the copy of `buffer` (width x height words) into `target`'s top-left w x h pixels.
    Status recordBufferCopy(VkCommandBuffer cmd, VkBuffer buffer, uint32_t width, uint32_t height,
                            VkImage target, uint32_t w, uint32_t h);
    Status ensureShared(VkDeviceSize bytes);

    std::unique_ptr<VulkanContext> owned_;  // the context create() made; empty for createOn()
    VulkanContext* context_ = nullptr;
    DeviceInfo info_;
    VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
    std::vector<VkImage> images_;
    VkFormat format_ = VK_FORMAT_UNDEFINED;
    bool swapRedBlue_ = false;  // the swapchain is BGRA: host frames swizzled on the way in and out
    bool canRead_ = false;      // the swapchain images allow transfers out (readback)
    VkExtent2D extent_{0, 0};
    VkFence acquired_ = VK_NULL_HANDLE;
    GpuBuffer pixels_;  // host-visible: a host frame going in, the readback coming out
    GpuImage rgba_;     // presentBuffer() into a BGRA swapchain: the frame as an RGBA image to blit from
    VkExtent2D rgbaExtent_{0, 0};
    bool offscreen_ = false;
    GpuImage target_;                          // offscreen: the image standing in for the swapchain's
    bool gpuFrames_ = false;                   // frames come from a GPU buffer (presentBuffer, presentShared)
    std::optional<FrameShareSource> source_;   // createShared(): the device that writes shared_
    GpuBuffer shared_;                         // exported to the source, which writes each frame
    VkSemaphore frameReady_ = VK_NULL_HANDLE;  // exported; the source signals it after each copy
    std::unique_ptr<SharedFrameWriter> writer_;  // the source's end of shared_ and frameReady_
    VkSemaphore waitOnSubmit_ = VK_NULL_HANDLE;  // the frame's submission waits on it (shared path)
};

}  // namespace sr

#endif  // RASTER_VIEWER_PRESENT_H
