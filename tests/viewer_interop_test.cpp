// viewer_interop_test.cpp - the pieces of the CUDA backend's shared framebuffer (render/frame_share.h)
// that run without a CUDA GPU, on whatever Vulkan device there is (lavapipe in CI) under the validation
// layer: the presenter's context picks its device by UUID and says in one line when no device has it;
// buffer memory and semaphores are exported as file descriptors where the device can (lavapipe exports
// memory but not semaphores), and the presenter falls back in one line where it cannot; without CUDA
// the view asking for the shared path refuses in one line. The shared path itself runs on a CUDA GPU:
// ViewerInterop.CudaSharedBufferShowsTheRender in viewer_test.cpp (ci/gpu-viewer).
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "render/frame_share.h"
#include "test_util.h"
#include "viewer/present.h"
#include "vulkan/vulkan_context.h"

namespace sr::test {
namespace {

bool vulkanMayBeMissing()
{
    const char* allowed = std::getenv("SR_ALLOW_MISSING_BACKENDS");
    return allowed != nullptr && (std::string(",") + allowed + ",").find(",vulkan,") != std::string::npos;
}

// A compute context on the first Vulkan device with validation on, optionally made for sharing; null
// with `skip` set where Vulkan is absent and allowed to be.
std::unique_ptr<VulkanContext> openContext(bool& skip, const ExternalSharing* sharing = nullptr)
{
    skip = false;
    setenv("SR_VULKAN_VALIDATION", "1", 0);
    auto context = std::make_unique<VulkanContext>();
    Status status = context->init(-1, QueueKind::Compute, nullptr, sharing);
    if (status.ok()) return context;
    if (vulkanMayBeMissing()) {
        skip = true;
        return nullptr;
    }
    ADD_FAILURE() << status.error().message;
    return nullptr;
}

#define OPEN_CONTEXT(name, ...)                                                                    \
    bool name##Skip = false;                                                                       \
    auto name = openContext(name##Skip, ##__VA_ARGS__);                                            \
    if (name##Skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)"; \
    ASSERT_TRUE(name)

bool oneLine(const std::string& text)
{
    return !text.empty() && text.find('\n') == std::string::npos;
}

bool openFd(int fd)
{
    return fd >= 0 && fcntl(fd, F_GETFD) != -1;
}

// The presenter's context for the GPU whose UUID the importer gives: the first device's UUID finds that
// device again.
TEST(ViewerInterop, TheSharingContextIsTheDeviceOfTheUuid)
{
    OPEN_CONTEXT(plain);
    ExternalSharing sharing{plain->deviceUuid()};
    OPEN_CONTEXT(shared, &sharing);
    EXPECT_EQ(shared->deviceUuid(), plain->deviceUuid());
    EXPECT_STREQ(shared->properties().deviceName, plain->properties().deviceName);
    EXPECT_TRUE(shared->validationStatus().ok()) << shared->validationStatus().error().message;
}

// No Vulkan device is the importer's GPU (lavapipe beside a CUDA GPU, a window on another GPU): one line
// that names the UUID, whether the device is looked for or named by index.
TEST(ViewerInterop, NoDeviceOfTheUuidIsOneLine)
{
    OPEN_CONTEXT(plain);  // a Vulkan device exists (or the test is skipped)
    ExternalSharing nowhere;
    nowhere.deviceUuid.fill(0xab);
    for (int index : {-1, 0}) {
        SCOPED_TRACE(index);
        VulkanContext context;
        Status status = context.init(index, QueueKind::Compute, nullptr, &nowhere);
        ASSERT_FALSE(status.ok());
        EXPECT_TRUE(oneLine(status.error().message)) << status.error().message;
        EXPECT_NE(status.error().message.find("abababab-abab-abab-abab-abababababab"), std::string::npos)
            << status.error().message;
    }
}

// Buffer memory exported as an OPAQUE_FD (lavapipe offers VK_KHR_external_memory_fd): each export is a new
// descriptor of its caller's; the allocation covers the buffer.
TEST(ViewerInterop, BufferMemoryIsExportedAsAnFd)
{
    OPEN_CONTEXT(plain);
    ExternalSharing sharing{plain->deviceUuid()};
    OPEN_CONTEXT(context, &sharing);
    GpuBuffer buffer;
    VkDeviceSize memoryBytes = 0;
    bool dedicated = false;
    const VkDeviceSize bytes = 1920 * 1080 * 4;
    Status status = context->allocateExportableBuffer(
        buffer, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, memoryBytes,
        dedicated);
    if (!status.ok()) {
        context->destroyBuffer(buffer);
        EXPECT_TRUE(oneLine(status.error().message));
        GTEST_SKIP() << "this device does not export memory: " << status.error().message;
    }
    EXPECT_GE(memoryBytes, bytes);
    EXPECT_EQ(buffer.capacity, bytes);
    Result<int> fd = context->exportMemoryFd(buffer);
    Result<int> again = context->exportMemoryFd(buffer);
    ASSERT_TRUE(fd.ok()) << fd.error().message;
    ASSERT_TRUE(again.ok()) << again.error().message;
    EXPECT_TRUE(openFd(*fd));
    EXPECT_TRUE(openFd(*again));
    EXPECT_NE(*fd, *again);
    close(*fd);
    close(*again);
    context->waitIdle();
    context->destroyBuffer(buffer);
    EXPECT_TRUE(context->validationStatus().ok()) << context->validationStatus().error().message;
}

// A binary semaphore exported as an OPAQUE_FD where the device can (NVIDIA), else one line saying why
// (lavapipe: no VK_KHR_external_semaphore_fd); a context not made for sharing exports nothing.
TEST(ViewerInterop, SemaphoreExportWorksOrSaysWhyNot)
{
    OPEN_CONTEXT(plain);
    VkSemaphore none = VK_NULL_HANDLE;
    Status refused = plain->createExportableSemaphore(none);
    ASSERT_FALSE(refused.ok());
    EXPECT_NE(refused.error().message.find("VK_KHR_external_semaphore_fd"), std::string::npos)
        << refused.error().message;

    ExternalSharing sharing{plain->deviceUuid()};
    OPEN_CONTEXT(context, &sharing);
    VkSemaphore semaphore = VK_NULL_HANDLE;
    Status status = context->createExportableSemaphore(semaphore);
    if (!status.ok()) {
        EXPECT_TRUE(oneLine(status.error().message)) << status.error().message;
        EXPECT_NE(status.error().message.find("semaphore"), std::string::npos) << status.error().message;
        std::printf("%s: %s\n", context->properties().deviceName, status.error().message.c_str());
        return;
    }
    Result<int> fd = context->exportSemaphoreFd(semaphore);
    ASSERT_TRUE(fd.ok()) << fd.error().message;
    EXPECT_TRUE(openFd(*fd));
    close(*fd);
    vkDestroySemaphore(context->device(), semaphore, nullptr);
    EXPECT_TRUE(context->validationStatus().ok()) << context->validationStatus().error().message;
}

// The fallback decision: Presenter::createShared fails in one line, without calling the importer, where
// no Vulkan device is the source's GPU.
TEST(ViewerInterop, ThePresenterRefusesASourceOnNoVulkanDevice)
{
    OPEN_CONTEXT(plain);
    bool imported = false;
    FrameShareSource source;
    source.deviceUuid.fill(0xab);
    source.import = [&](SharedFrameHandles&) -> Result<std::unique_ptr<SharedFrameWriter>> {
        imported = true;
        return makeError(ExitCode::Runtime, "test: not reached");
    };
    auto presenter = Presenter::createShared(nullptr, -1, source, 64 * 48 * 4);
    ASSERT_FALSE(presenter.ok());
    EXPECT_FALSE(imported);
    EXPECT_TRUE(oneLine(presenter.error().message)) << presenter.error().message;
    EXPECT_NE(presenter.error().message.find("no Vulkan device is the GPU"), std::string::npos)
        << presenter.error().message;
}

// On the source's GPU, the presenter either exports both handles to the importer (which owns them: here
// it checks and closes them, and refuses, so the presenter fails with its message) or, where the device
// cannot export a semaphore (lavapipe), fails in one line before importing anything.
TEST(ViewerInterop, ThePresenterExportsToTheSourceOrSaysWhyNot)
{
    OPEN_CONTEXT(plain);
    const size_t frameBytes = 64 * 48 * 4;
    bool imported = false;
    SharedFrameHandles seen;
    bool fdsOpen = false;
    FrameShareSource source;
    source.deviceUuid = plain->deviceUuid();
    source.import = [&](SharedFrameHandles& handles) -> Result<std::unique_ptr<SharedFrameWriter>> {
        imported = true;
        seen = handles;
        fdsOpen = openFd(handles.memoryFd) && openFd(handles.semaphoreFd);
        close(handles.memoryFd);
        close(handles.semaphoreFd);
        handles.memoryFd = handles.semaphoreFd = -1;
        return makeError(ExitCode::Runtime, "test: import refused");
    };
    auto presenter = Presenter::createShared(nullptr, -1, source, frameBytes);
    ASSERT_FALSE(presenter.ok());
    const std::string& message = presenter.error().message;
    EXPECT_TRUE(oneLine(message)) << message;
    if (!imported) {
        EXPECT_NE(message.find("semaphore"), std::string::npos) << message;
        std::printf("%s: %s\n", plain->properties().deviceName, message.c_str());
        return;
    }
    EXPECT_EQ(message, "test: import refused");
    EXPECT_TRUE(fdsOpen);
    EXPECT_GE(seen.bufferBytes, frameBytes);
    EXPECT_GE(seen.memoryBytes, seen.bufferBytes);
}

// A device that is not CUDA's has no frames to share.
class NotCuda final : public ComputeDevice {
public:
    const DeviceInfo& info() const override { return info_; }
    Status resize(uint32_t, size_t) override { return okStatus(); }
    size_t size(uint32_t) const override { return 0; }
    Status upload(uint32_t, const void*, size_t) override { return okStatus(); }
    Status download(uint32_t, void*, size_t, size_t) override { return okStatus(); }
    Status run(const RasterParams&, const std::vector<Dispatch>&, std::vector<double>&) override
    {
        return okStatus();
    }
    size_t allocatedBytes() const override { return 0; }
    size_t peakAllocatedBytes() const override { return 0; }

private:
    DeviceInfo info_;
};

TEST(ViewerInterop, OnlyACudaDeviceSharesItsFrames)
{
    NotCuda device;
    EXPECT_FALSE(cudaFrameShareSource(device).has_value());
}

// Without CUDA (this build or this machine), asking for the shared path is a one-line usage error.
TEST(ViewerInterop, WithoutCudaTheSharedPathRefusesInOneLine)
{
    if (makeCudaDevice(-1).ok()) GTEST_SKIP() << "CUDA present: CudaSharedBufferShowsTheRender runs the path";
    ScratchDir dir("view_interop");
    std::ofstream(dir.file("script.txt")) << "frame\n";
    ToolRun run =
        runTool("view --backend cuda --present shared --offscreen --width 32 --height 24 --script " +
                dir.file("script.txt"));
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_EQ(std::count(run.stderrText.begin(), run.stderrText.end(), '\n'), 1) << run.stderrText;
    EXPECT_NE(run.stderrText.find("cuda"), std::string::npos) << run.stderrText;
}

}  // namespace
}  // namespace sr::test
