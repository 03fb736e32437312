// present.cpp - see present.h.
#include "viewer/present.h"

#include <unistd.h>

#include <algorithm>
#include <cstring>

namespace sr {
namespace {

uint32_t swapRedBlue(uint32_t p)
{
    return (p & 0xff00ff00u) | ((p & 0xffu) << 16) | ((p >> 16) & 0xffu);
}

void imageBarrier(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to,
                  VkAccessFlags srcAccess, VkAccessFlags dstAccess)
{
    VkImageMemoryBarrier b{};
    b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    b.srcAccessMask = srcAccess;
    b.dstAccessMask = dstAccess;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr,
                         0, nullptr, 1, &b);
}

// The shared buffer's ownership between the external API (the device writing it) and the queue
// family `family` that copies from it: acquired before the copy, released after it. The acquisition's
// first scope is the transfer stage, at which the submission waits on the device's semaphore, so that
// it follows the wait.
void externalBarrier(VkCommandBuffer cmd, VkBuffer buffer, uint32_t family, bool acquire)
{
    VkBufferMemoryBarrier b{};
    b.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER;
    b.srcAccessMask = acquire ? 0 : VK_ACCESS_TRANSFER_READ_BIT;
    b.dstAccessMask = acquire ? VK_ACCESS_TRANSFER_READ_BIT : 0;
    b.srcQueueFamilyIndex = acquire ? VK_QUEUE_FAMILY_EXTERNAL : family;
    b.dstQueueFamilyIndex = acquire ? family : VK_QUEUE_FAMILY_EXTERNAL;
    b.buffer = buffer;
    b.offset = 0;
    b.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT,
                         acquire ? VK_PIPELINE_STAGE_TRANSFER_BIT : VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0,
                         0, nullptr, 1, &b, 0, nullptr);
}

void closeFd(int fd)
{
    if (fd >= 0) close(fd);
}

}  // namespace

Result<std::unique_ptr<Presenter>> Presenter::create(const PresentTarget& target, int deviceIndex)
{
    std::unique_ptr<Presenter> p(new Presenter());
    p->owned_ = std::make_unique<VulkanContext>();
    p->context_ = p->owned_.get();
    SR_TRY(p->context_->init(deviceIndex, QueueKind::Compute, &target));
    SR_TRY(p->init());
    return p;
}

Result<std::unique_ptr<Presenter>> Presenter::createOn(VulkanContext& shared)
{
    if (shared.surface() == VK_NULL_HANDLE)
        return makeError(ExitCode::Runtime, "view: the compute device was not made on the window");
    std::unique_ptr<Presenter> p(new Presenter());
    p->context_ = &shared;
    p->gpuFrames_ = true;
    SR_TRY(p->init());
    return p;
}

Result<std::unique_ptr<Presenter>> Presenter::createShared(const PresentTarget* target, int deviceIndex,
                                                           const FrameShareSource& source, size_t frameBytes)
{
    std::unique_ptr<Presenter> p(new Presenter());
    p->offscreen_ = target == nullptr;
    p->gpuFrames_ = true;
    p->owned_ = std::make_unique<VulkanContext>();
    p->context_ = p->owned_.get();
    ExternalSharing sharing{source.deviceUuid};
    SR_TRY(p->context_->init(deviceIndex, QueueKind::Compute, target, &sharing));
    SR_TRY(p->init());
    // A binary semaphore: per frame the device signals it once and the presenter's submission waits on it
    // once, and the host orders the two (the signal is queued before the wait is submitted, and the next
    // signal only after that submission's fence), which is all a binary semaphore needs; a timeline
    // semaphore would add nothing but a counter.
    SR_TRY(p->context_->createExportableSemaphore(p->frameReady_));
    p->source_ = source;
    SR_TRY(p->ensureShared(std::max<VkDeviceSize>(frameBytes, kMinBufferBytes)));
    return p;
}

Status Presenter::ensureShared(VkDeviceSize bytes)
{
    if (writer_ && shared_.capacity >= bytes) return okStatus();
    // The device's end first: it maps the memory about to be freed.
    context_->waitIdle();
    writer_.reset();
    if (shared_.buffer != VK_NULL_HANDLE) context_->destroyBuffer(shared_);
    VkDeviceSize memoryBytes = 0;
    bool dedicated = false;
    SR_TRY(context_->allocateExportableBuffer(
        shared_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, memoryBytes,
        dedicated));
    Result<int> memoryFd = context_->exportMemoryFd(shared_);
    if (!memoryFd.ok()) return memoryFd.error();
    Result<int> semaphoreFd = context_->exportSemaphoreFd(frameReady_);
    if (!semaphoreFd.ok()) {
        closeFd(*memoryFd);
        return semaphoreFd.error();
    }
    SharedFrameHandles handles;
    handles.memoryFd = *memoryFd;
    handles.memoryBytes = memoryBytes;
    handles.bufferBytes = bytes;
    handles.dedicated = dedicated;
    handles.semaphoreFd = *semaphoreFd;
    // The importer takes both descriptors, whether or not it succeeds.
    auto writer = source_->import(handles);
    if (!writer.ok()) return writer.error();
    writer_ = std::move(*writer);
    return okStatus();
}

Result<std::unique_ptr<Presenter>> Presenter::createOffscreen(VulkanContext* shared, int deviceIndex)
{
    std::unique_ptr<Presenter> p(new Presenter());
    p->offscreen_ = true;
    if (shared != nullptr) {
        p->context_ = shared;
    } else {
        p->owned_ = std::make_unique<VulkanContext>();
        p->context_ = p->owned_.get();
        SR_TRY(p->context_->init(deviceIndex, QueueKind::Compute));
    }
    SR_TRY(p->init());
    return p;
}

Status Presenter::init()
{
    info_ = context_->deviceInfo("vulkan");
    VkFenceCreateInfo fenceInfo{};
    fenceInfo.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    SR_VK_CHECK(vkCreateFence(context_->device(), &fenceInfo, nullptr, &acquired_));
    return okStatus();
}

Presenter::~Presenter()
{
    if (context_ == nullptr || context_->device() == VK_NULL_HANDLE) return;
    context_->waitIdle();
    destroySwapchain();
    context_->destroyBuffer(pixels_);
    context_->destroyImage(rgba_);
    context_->destroyImage(target_);
    writer_.reset();  // the device's end unmaps the memory before Vulkan frees it
    context_->destroyBuffer(shared_);
    if (frameReady_ != VK_NULL_HANDLE) vkDestroySemaphore(context_->device(), frameReady_, nullptr);
    if (acquired_ != VK_NULL_HANDLE) vkDestroyFence(context_->device(), acquired_, nullptr);
}

void Presenter::releaseSwapchain()
{
    if (context_ == nullptr || swapchain_ == VK_NULL_HANDLE) return;
    context_->waitIdle();
    destroySwapchain();
}

void Presenter::destroySwapchain()
{
    if (swapchain_ != VK_NULL_HANDLE) vkDestroySwapchainKHR(context_->device(), swapchain_, nullptr);
    swapchain_ = VK_NULL_HANDLE;
    images_.clear();
}

Status Presenter::createSwapchain(uint32_t width, uint32_t height)
{
    VkPhysicalDevice physical = context_->physicalDevice();
    if (offscreen_) {
        // The format a GPU's swapchain usually has, so the device path blits as it would there.
        context_->destroyImage(target_);
        format_ = VK_FORMAT_B8G8R8A8_UNORM;
        swapRedBlue_ = true;
        canRead_ = true;
        SR_TRY(context_->allocateImage(
            target_, format_, VK_IMAGE_ASPECT_COLOR_BIT, width, height,
            VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_SAMPLED_BIT));
        extent_ = {width, height};
        images_.assign(1, target_.image);
        return okStatus();
    }
    VkSurfaceKHR surface = context_->surface();
    VkSurfaceCapabilitiesKHR caps{};
    SR_VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical, surface, &caps));
    uint32_t count = 0;
    SR_VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &count, nullptr));
    std::vector<VkSurfaceFormatKHR> formats(count);
    SR_VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &count, formats.data()));
    // UNORM formats: the frame's bytes are already sRGB-encoded and must not be encoded twice.
    auto offered = [&](VkFormat f) {
        return std::any_of(formats.begin(), formats.end(), [&](const VkSurfaceFormatKHR& s) {
            return s.format == f && s.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
        });
    };
    if (offered(VK_FORMAT_R8G8B8A8_UNORM)) {
        format_ = VK_FORMAT_R8G8B8A8_UNORM;
        swapRedBlue_ = false;
    } else if (offered(VK_FORMAT_B8G8R8A8_UNORM)) {
        format_ = VK_FORMAT_B8G8R8A8_UNORM;
        swapRedBlue_ = true;
    } else {
        return makeError(ExitCode::Runtime, "view: the window offers neither R8G8B8A8 nor B8G8R8A8 UNORM");
    }
    if ((caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT) == 0)
        return makeError(ExitCode::Runtime, "view: the window's swapchain images cannot be copied into");
    canRead_ = (caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT) != 0;
    if (gpuFrames_ && swapRedBlue_) {
        // presentBuffer() and presentShared() blit from an RGBA image into the BGRA swapchain image.
        VkFormatProperties src{}, dst{};
        vkGetPhysicalDeviceFormatProperties(physical, VK_FORMAT_R8G8B8A8_UNORM, &src);
        vkGetPhysicalDeviceFormatProperties(physical, format_, &dst);
        if ((src.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_SRC_BIT) == 0 ||
            (dst.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_DST_BIT) == 0)
            return makeError(
                ExitCode::Runtime,
                "view: the device cannot blit into the window's BGRA images; use --present host");
    }
    VkExtent2D extent = caps.currentExtent;
    if (extent.width == 0xFFFFFFFFu) extent = {width, height};
    extent.width = std::clamp(extent.width, caps.minImageExtent.width, caps.maxImageExtent.width);
    extent.height = std::clamp(extent.height, caps.minImageExtent.height, caps.maxImageExtent.height);

    VkSwapchainCreateInfoKHR info{};
    info.sType = VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR;
    info.surface = surface;
    info.minImageCount = caps.maxImageCount == 0 ? caps.minImageCount + 1
                                                 : std::min(caps.minImageCount + 1, caps.maxImageCount);
    info.imageFormat = format_;
    info.imageColorSpace = VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
    info.imageExtent = extent;
    info.imageArrayLayers = 1;
    info.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | (canRead_ ? VK_IMAGE_USAGE_TRANSFER_SRC_BIT : 0);
    info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.preTransform = caps.currentTransform;
    info.compositeAlpha =
        (caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR) != 0
            ? VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR
            : VkCompositeAlphaFlagBitsKHR(caps.supportedCompositeAlpha & -caps.supportedCompositeAlpha);
    info.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // the one mode every device offers
    info.clipped = VK_TRUE;
    info.oldSwapchain = swapchain_;
    VkSwapchainKHR created = VK_NULL_HANDLE;
    SR_VK_CHECK(vkCreateSwapchainKHR(context_->device(), &info, nullptr, &created));
    destroySwapchain();
    swapchain_ = created;
    extent_ = extent;
    SR_VK_CHECK(vkGetSwapchainImagesKHR(context_->device(), swapchain_, &count, nullptr));
    images_.resize(count);
    SR_VK_CHECK(vkGetSwapchainImagesKHR(context_->device(), swapchain_, &count, images_.data()));
    return okStatus();
}

Status Presenter::ensurePixels(VkDeviceSize bytes)
{
    if (pixels_.capacity >= bytes) return okStatus();
    context_->destroyBuffer(pixels_);
    return context_->allocateBuffer(
        pixels_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
        {VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT});
}

template <typename Fill>
Status Presenter::presentFrame(uint32_t width, uint32_t height, uint32_t windowWidth, uint32_t windowHeight,
                               RgbaImage* readback, Fill fill)
{
    if (windowWidth == 0 || windowHeight == 0) return okStatus();  // minimized: nothing to show
    VkDevice device = context_->device();
    // A window resized since the last frame, or a swapchain the window system declared stale, is
    // made again and the frame presented once more.
    for (int attempt = 0; attempt < 3; ++attempt) {
        if (images_.empty() || extent_.width != windowWidth || extent_.height != windowHeight)
            SR_TRY(createSwapchain(windowWidth, windowHeight));
        SR_TRY(ensurePixels(VkDeviceSize(extent_.width) * extent_.height * 4));
        uint32_t index = 0;
        if (!offscreen_) {
            VkResult acquired =
                vkAcquireNextImageKHR(device, swapchain_, UINT64_MAX, VK_NULL_HANDLE, acquired_, &index);
            if (acquired == VK_ERROR_OUT_OF_DATE_KHR) {
                SR_VK_CHECK(vkDeviceWaitIdle(device));
                destroySwapchain();
                continue;
            }
            if (acquired != VK_SUBOPTIMAL_KHR) SR_VK_CHECK(acquired);
            SR_VK_CHECK(vkWaitForFences(device, 1, &acquired_, VK_TRUE, UINT64_MAX));
            SR_VK_CHECK(vkResetFences(device, 1, &acquired_));
        }

        const uint32_t w = std::min(width, extent_.width), h = std::min(height, extent_.height);
        VkImage target = images_[index];
        SR_TRY(context_->beginCommands());
        VkCommandBuffer cmd = context_->commandBuffer();
        imageBarrier(cmd, target, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
                     VK_ACCESS_TRANSFER_WRITE_BIT);
        if (w < extent_.width || h < extent_.height) {
            VkClearColorValue black{};
            black.float32[3] = 1.0f;
            VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
            vkCmdClearColorImage(cmd, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &black, 1, &range);
            memoryBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                          VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
        }
        if (w > 0 && h > 0) SR_TRY(fill(cmd, target, w, h));
        const bool read = readback != nullptr && canRead_;
        if (read) {
            imageBarrier(cmd, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
                         VK_ACCESS_TRANSFER_READ_BIT);
            // A host frame's copy in read the buffer; the copy out overwrites it.
            memoryBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT,
                          VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
            VkBufferImageCopy region{};
            region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
            region.imageExtent = {extent_.width, extent_.height, 1};
            vkCmdCopyImageToBuffer(cmd, target, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, pixels_.buffer, 1,
                                   &region);
            memoryBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                          VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
        }
        if (!offscreen_)
            imageBarrier(cmd, target,
                         read ? VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL : VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
                         read ? VK_ACCESS_TRANSFER_READ_BIT : VK_ACCESS_TRANSFER_WRITE_BIT, 0);
        // Waited for here, so the presentation below needs no semaphore: the image is complete. A
        // shared frame's copy waits for the device's signal that the frame is in the buffer.
        VkSemaphore wait = waitOnSubmit_;
        waitOnSubmit_ = VK_NULL_HANDLE;
        SR_TRY(context_->submitAndWait(wait, VK_PIPELINE_STAGE_TRANSFER_BIT));
        if (readback != nullptr) {
            if (!read)
                return makeError(ExitCode::Runtime, "view: this window's swapchain cannot be read back");
            readback->width = extent_.width;
            readback->height = extent_.height;
            readback->pixels.resize(size_t(extent_.width) * extent_.height);
            const auto* src = static_cast<const uint32_t*>(pixels_.mapped);
            for (size_t i = 0; i < readback->pixels.size(); ++i)
                readback->pixels[i] = swapRedBlue_ ? swapRedBlue(src[i]) : src[i];
        }

        if (offscreen_) return context_->validationStatus();
        VkPresentInfoKHR info{};
        info.sType = VK_STRUCTURE_TYPE_PRESENT_INFO_KHR;
        info.swapchainCount = 1;
        info.pSwapchains = &swapchain_;
        info.pImageIndices = &index;
        VkResult presented = vkQueuePresentKHR(context_->queue(), &info);
        if (presented == VK_ERROR_OUT_OF_DATE_KHR) {
            SR_VK_CHECK(vkDeviceWaitIdle(device));
            destroySwapchain();
            continue;
        }
        if (presented != VK_SUBOPTIMAL_KHR) SR_VK_CHECK(presented);
        return context_->validationStatus();
    }
    return makeError(ExitCode::Runtime, "view: the window's swapchain stayed out of date");
}

Status Presenter::present(const RgbaImage& image, uint32_t windowWidth, uint32_t windowHeight,
                          RgbaImage* readback)
{
    return presentFrame(image.width, image.height, windowWidth, windowHeight, readback,
                        [&](VkCommandBuffer cmd, VkImage target, uint32_t w, uint32_t h) -> Status {
                            // The frame's rows into the buffer at the swapchain's pitch, cropped to the
                            // window.
                            auto* dst = static_cast<uint32_t*>(pixels_.mapped);
                            for (uint32_t y = 0; y < h; ++y)
                                for (uint32_t x = 0; x < w; ++x) {
                                    uint32_t p = image.pixels[size_t(y) * image.width + x];
                                    dst[size_t(y) * extent_.width + x] = swapRedBlue_ ? swapRedBlue(p) : p;
                                }
                            VkBufferImageCopy region{};
                            region.bufferRowLength = extent_.width;
                            region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                            region.imageExtent = {w, h, 1};
                            vkCmdCopyBufferToImage(cmd, pixels_.buffer, target,
                                                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
                            return okStatus();
                        });
}

Status Presenter::presentBuffer(VkBuffer buffer, uint32_t width, uint32_t height, uint32_t windowWidth,
                                uint32_t windowHeight, RgbaImage* readback)
{
    if (owned_) return makeError(ExitCode::Runtime, "view: a host presenter cannot read a device buffer");
    return presentFrame(width, height, windowWidth, windowHeight, readback,
                        [&](VkCommandBuffer cmd, VkImage target, uint32_t w, uint32_t h) -> Status {
                            return recordBufferCopy(cmd, buffer, width, height, target, w, h);
                        });
}

Status Presenter::presentShared(uint32_t width, uint32_t height, uint32_t windowWidth, uint32_t windowHeight,
                                RgbaImage* readback)
{
    if (!source_) return makeError(ExitCode::Runtime, "view: this presenter has no shared buffer");
    const VkDeviceSize bytes = VkDeviceSize(width) * height * 4;
    SR_TRY(ensureShared(bytes));
    return presentFrame(width, height, windowWidth, windowHeight, readback,
                        [&](VkCommandBuffer cmd, VkImage target, uint32_t w, uint32_t h) -> Status {
                            // Queued on the device's stream now, so that the signal this submission
                            // waits on is pending when it is submitted; only where a copy follows.
                            SR_TRY(writer_->writeFrame(size_t(bytes)));
                            waitOnSubmit_ = frameReady_;
                            const uint32_t family = context_->queueFamily();
                            externalBarrier(cmd, shared_.buffer, family, true);
                            SR_TRY(recordBufferCopy(cmd, shared_.buffer, width, height, target, w, h));
                            externalBarrier(cmd, shared_.buffer, family, false);
                            return okStatus();
                        });
}

Status Presenter::recordBufferCopy(VkCommandBuffer cmd, VkBuffer buffer, uint32_t width, uint32_t height,
                                   VkImage target, uint32_t w, uint32_t h)
{
    VkBufferImageCopy region{};
    region.bufferRowLength = width;
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {w, h, 1};
    if (!swapRedBlue_) {
        vkCmdCopyBufferToImage(cmd, buffer, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        return okStatus();
    }
    // A BGRA swapchain: the words land in an RGBA image, and a blit (which converts between formats by
    // component) writes them into the swapchain image in its order.
    if (rgba_.image == VK_NULL_HANDLE || rgbaExtent_.width != width || rgbaExtent_.height != height) {
        context_->destroyImage(rgba_);
        SR_TRY(context_->allocateImage(
            rgba_, VK_FORMAT_R8G8B8A8_UNORM, VK_IMAGE_ASPECT_COLOR_BIT, width, height,
            VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                VK_IMAGE_USAGE_SAMPLED_BIT));  // the view allocateImage makes needs one
        rgbaExtent_ = {width, height};
    }
    imageBarrier(cmd, rgba_.image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
                 VK_ACCESS_TRANSFER_WRITE_BIT);
    vkCmdCopyBufferToImage(cmd, buffer, rgba_.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    imageBarrier(cmd, rgba_.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                 VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    VkImageBlit blit{};
    blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    blit.srcOffsets[1] = {int32_t(w), int32_t(h), 1};
    blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    blit.dstOffsets[1] = {int32_t(w), int32_t(h), 1};
    vkCmdBlitImage(cmd, rgba_.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target,
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, VK_FILTER_NEAREST);
    return okStatus();
}

}  // namespace sr
