// vulkan_device_test.cpp - the Vulkan ComputeDevice on the machine's first suitable device
// (lavapipe in CI) with validation on: device selection, buffers and transfers, the clear stage,
// timings, memory accounting and the error paths. No Vulkan device is a failure, never a skip.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "render/compute_device.h"
#include "vulkan/vulkan_device_internal.h"

namespace sr {
namespace {

// ctest sets this too; setting it here keeps validation on when the binary is run by hand.
void enableValidation()
{
    setenv("SR_VULKAN_VALIDATION", "1", 1);
}

std::vector<uint8_t> randomBytes(size_t count, uint32_t seed)
{
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> byte(0, 255);
    std::vector<uint8_t> bytes(count);
    for (uint8_t& b : bytes) b = static_cast<uint8_t>(byte(rng));
    return bytes;
}

bool isOneLine(const std::string& message)
{
    return !message.empty() && message.find('\n') == std::string::npos;
}

class VulkanDeviceTest : public ::testing::Test {
protected:
    void SetUp() override
    {
        enableValidation();
        errorsBefore_ = vulkanValidationErrorCount();
        auto device = makeVulkanDevice(-1);
        ASSERT_TRUE(device.ok()) << device.error().message;
        device_ = std::move(device.value());
    }

    void TearDown() override
    {
        device_.reset();
        // Leaked objects are reported while the device is destroyed, where no call can fail.
        EXPECT_EQ(vulkanValidationErrorCount(), errorsBefore_ + injectedErrors_);
    }

    std::vector<uint8_t> download(uint32_t buffer, size_t bytes)
    {
        std::vector<uint8_t> data(bytes);
        Status status = device_->download(buffer, data.data(), bytes);
        EXPECT_TRUE(status.ok()) << status.error().message;
        return data;
    }

    std::unique_ptr<ComputeDevice> device_;
    size_t errorsBefore_ = 0;
    size_t injectedErrors_ = 0;
};

TEST(VulkanDeviceSelectionTest, ListsGpusFirstAndLavapipeAsCpu)
{
    enableValidation();
    std::vector<DeviceInfo> infos;
    for (int index = 0;; ++index) {
        auto device = makeVulkanDevice(index);
        if (!device.ok()) {
            // The first index past the end: the message says how many devices there are.
            EXPECT_EQ(device.error().code, ExitCode::Usage);
            EXPECT_NE(device.error().message.find(fmt::format("{} suitable device(s)", index)),
                      std::string::npos)
                << device.error().message;
            break;
        }
        infos.push_back((*device)->info());
    }
    ASSERT_FALSE(infos.empty());

    bool sawCpu = false;
    for (const DeviceInfo& info : infos) {
        EXPECT_EQ(info.backend, "vulkan");
        EXPECT_FALSE(info.driver.empty());
        const bool isLavapipe = info.name.find("llvmpipe") != std::string::npos;
        EXPECT_EQ(info.isCpu, isLavapipe) << info.name;
        EXPECT_FALSE(sawCpu && !info.isCpu) << info.name << " is listed after a CPU device";
        sawCpu = sawCpu || info.isCpu;
    }

    auto first = makeVulkanDevice(-1);
    ASSERT_TRUE(first.ok()) << first.error().message;
    EXPECT_EQ((*first)->info().name, infos.front().name);
}

TEST(VulkanDeviceSelectionTest, OutOfRangeIndexIsAnError)
{
    enableValidation();
    for (int index : {1000, -2}) {
        auto device = makeVulkanDevice(index);
        ASSERT_FALSE(device.ok()) << index;
        EXPECT_EQ(device.error().code, ExitCode::Usage);
        EXPECT_TRUE(isOneLine(device.error().message)) << device.error().message;
        EXPECT_NE(device.error().message.find("out of range"), std::string::npos);
    }
}

TEST_F(VulkanDeviceTest, UploadDownloadRoundTripsThroughSeveralBuffers)
{
    // 300 and 1000 are not multiples of the 16-byte allocation granularity.
    const uint32_t buffers[] = {BUF_POSITIONS, BUF_INDICES, BUF_VISIBILITY};
    const size_t sizes[] = {4096, 300, 1000};
    std::vector<std::vector<uint8_t>> contents;
    for (size_t i = 0; i < 3; ++i) {
        ASSERT_TRUE(device_->resize(buffers[i], sizes[i]).ok());
        EXPECT_EQ(device_->size(buffers[i]), sizes[i]);
        contents.push_back(randomBytes(sizes[i], static_cast<uint32_t>(i + 1)));
        Status status = device_->upload(buffers[i], contents[i].data(), sizes[i]);
        ASSERT_TRUE(status.ok()) << status.error().message;
    }
    for (size_t i = 0; i < 3; ++i) EXPECT_EQ(download(buffers[i], sizes[i]), contents[i]) << i;

    // Growing replaces one allocation and leaves the other buffers as they were.
    const size_t grownSize = 100000;
    ASSERT_TRUE(device_->resize(BUF_INDICES, grownSize).ok());
    EXPECT_EQ(device_->size(BUF_INDICES), grownSize);
    std::vector<uint8_t> grown = randomBytes(grownSize, 99);
    ASSERT_TRUE(device_->upload(BUF_INDICES, grown.data(), grownSize).ok());
    EXPECT_EQ(download(BUF_INDICES, grownSize), grown);
    EXPECT_EQ(download(BUF_POSITIONS, sizes[0]), contents[0]);
    EXPECT_EQ(download(BUF_VISIBILITY, sizes[2]), contents[2]);

    // A transfer may cover a prefix of the buffer.
    std::vector<uint8_t> prefix = download(BUF_POSITIONS, 10);
    EXPECT_TRUE(std::equal(prefix.begin(), prefix.end(), contents[0].begin()));
}

TEST_F(VulkanDeviceTest, ShrinkingKeepsTheAllocationButLimitsTransfers)
{
    ASSERT_TRUE(device_->resize(BUF_COLORS, 1024).ok());
    const size_t allocated = device_->allocatedBytes();
    ASSERT_TRUE(device_->resize(BUF_COLORS, 64).ok());
    EXPECT_EQ(device_->size(BUF_COLORS), 64u);
    EXPECT_EQ(device_->allocatedBytes(), allocated);

    std::vector<uint8_t> data = randomBytes(1024, 7);
    EXPECT_FALSE(device_->upload(BUF_COLORS, data.data(), 1024).ok());
    ASSERT_TRUE(device_->upload(BUF_COLORS, data.data(), 64).ok());
    EXPECT_EQ(download(BUF_COLORS, 64), std::vector<uint8_t>(data.begin(), data.begin() + 64));
}

TEST_F(VulkanDeviceTest, TransfersBeyondTheBufferAndBadIndicesAreErrors)
{
    ASSERT_TRUE(device_->resize(BUF_COUNTERS, 64).ok());
    std::vector<uint8_t> data(128);
    for (const Status& status :
         {device_->download(BUF_COUNTERS, data.data(), 128), device_->upload(BUF_COUNTERS, data.data(), 65),
          device_->download(BUF_FRAMEBUFFER, data.data(), 4), device_->upload(BUF_COUNT, data.data(), 4),
          device_->resize(BUF_PARAMS, 64), device_->resize(BUF_COUNT, 64)}) {
        ASSERT_FALSE(status.ok());
        EXPECT_TRUE(isOneLine(status.error().message)) << status.error().message;
    }
    Status tooLarge = device_->download(BUF_COUNTERS, data.data(), 128);
    ASSERT_FALSE(tooLarge.ok());
    EXPECT_NE(tooLarge.error().message.find("128"), std::string::npos) << tooLarge.error().message;

    // The failed calls leave the device usable.
    ASSERT_TRUE(device_->upload(BUF_COUNTERS, data.data(), 64).ok());
    EXPECT_EQ(download(BUF_COUNTERS, 64), std::vector<uint8_t>(data.begin(), data.begin() + 64));
}

TEST_F(VulkanDeviceTest, ClearEmptiesVisibilityAndCounters)
{
    const uint32_t width = 37;
    const uint32_t height = 23;  // 851 pixels: the last group is partly idle
    const size_t pixels = size_t(width) * height;
    const size_t slack = 64;  // entries past the image, which clear must leave alone
    const size_t counterSlots = COUNTER_WORDS + slack;  // the counters and their shards, then slack

    std::vector<uint64_t> visibility(pixels + slack);
    for (size_t i = 0; i < visibility.size(); ++i) visibility[i] = 0x0123456789abcdefull ^ (i * 977);
    std::vector<uint32_t> counters(counterSlots);
    for (size_t i = 0; i < counters.size(); ++i) counters[i] = 0xdeadbeefu + uint32_t(i);
    const size_t visibilityBytes = visibility.size() * sizeof(uint64_t);
    const size_t counterBytes = counters.size() * sizeof(uint32_t);
    ASSERT_TRUE(device_->resize(BUF_VISIBILITY, visibilityBytes).ok());
    ASSERT_TRUE(device_->resize(BUF_COUNTERS, counterBytes).ok());
    ASSERT_TRUE(device_->upload(BUF_VISIBILITY, visibility.data(), visibilityBytes).ok());
    ASSERT_TRUE(device_->upload(BUF_COUNTERS, counters.data(), counterBytes).ok());

    RasterParams params{};
    params.width = width;
    params.height = height;
    params.sampleCount = 1;
    params.samplePlane = width * height;
    const uint32_t groups = uint32_t((pixels + GROUP_SIZE - 1) / GROUP_SIZE);
    std::vector<double> gpuMs;
    Status status = device_->run(params, {{STAGE_CLEAR, groups}}, gpuMs);
    ASSERT_TRUE(status.ok()) << status.error().message;
    ASSERT_EQ(gpuMs.size(), 1u);
    EXPECT_GE(gpuMs[0], 0.0);

    std::vector<uint64_t> clearedVisibility(visibility.size());
    ASSERT_TRUE(device_->download(BUF_VISIBILITY, clearedVisibility.data(), visibilityBytes).ok());
    for (size_t i = 0; i < visibility.size(); ++i)
        ASSERT_EQ(clearedVisibility[i], i < pixels ? ~uint64_t(0) : visibility[i]) << "entry " << i;
    std::vector<uint32_t> clearedCounters(counters.size());
    ASSERT_TRUE(device_->download(BUF_COUNTERS, clearedCounters.data(), counterBytes).ok());
    for (size_t i = 0; i < counters.size(); ++i)
        EXPECT_EQ(clearedCounters[i], i < COUNTER_WORDS ? 0u : counters[i]) << "counter " << i;
}

TEST_F(VulkanDeviceTest, RunTimesEveryDispatchIncludingEmptyOnes)
{
    ASSERT_TRUE(device_->resize(BUF_VISIBILITY, 64 * sizeof(uint64_t)).ok());
    ASSERT_TRUE(device_->resize(BUF_COUNTERS, COUNTER_COUNT * sizeof(uint32_t)).ok());
    RasterParams params{};
    params.width = 8;
    params.height = 8;
    // Zero groups of a stage that would read unset buffers: it must not run, and takes no time.
    const std::vector<Dispatch> dispatches = {{STAGE_CLEAR, 1}, {STAGE_VERTEX, 0}, {STAGE_CLEAR, 1}};
    std::vector<double> gpuMs = {42.0};
    Status status = device_->run(params, dispatches, gpuMs);
    ASSERT_TRUE(status.ok()) << status.error().message;
    ASSERT_EQ(gpuMs.size(), dispatches.size());
    for (double ms : gpuMs) EXPECT_GE(ms, 0.0);
    EXPECT_EQ(gpuMs[1], 0.0);
    // Nothing to run at all.
    ASSERT_TRUE(device_->run(params, {{STAGE_VERTEX, 0}}, gpuMs).ok());
    EXPECT_EQ(gpuMs, std::vector<double>{0.0});

    ASSERT_TRUE(device_->run(params, {}, gpuMs).ok());
    EXPECT_TRUE(gpuMs.empty());
}

TEST_F(VulkanDeviceTest, RunRejectsUnknownStagesAndTooManyGroups)
{
    RasterParams params{};
    std::vector<double> gpuMs;
    Status tooMany = device_->run(params, {{STAGE_CLEAR, UINT32_MAX}}, gpuMs);
    ASSERT_FALSE(tooMany.ok());
    EXPECT_TRUE(isOneLine(tooMany.error().message));
    EXPECT_NE(tooMany.error().message.find("groups"), std::string::npos) << tooMany.error().message;
    Status unknown = device_->run(params, {{STAGE_COUNT, 1}}, gpuMs);
    ASSERT_FALSE(unknown.ok());
    EXPECT_TRUE(isOneLine(unknown.error().message));
}

TEST_F(VulkanDeviceTest, TracksAllocatedAndPeakBytes)
{
    EXPECT_GT(device_->allocatedBytes(), 0u);  // the parameter buffer exists from the start
    ASSERT_TRUE(device_->resize(BUF_VISIBILITY, 1 << 20).ok());
    EXPECT_GE(device_->allocatedBytes(), size_t(1) << 20);
    ASSERT_TRUE(device_->resize(BUF_VISIBILITY, 2 << 20).ok());
    EXPECT_GE(device_->allocatedBytes(), size_t(2) << 20);
    EXPECT_LT(device_->allocatedBytes(), size_t(3) << 20);  // the old allocation was released
    EXPECT_GE(device_->peakAllocatedBytes(), device_->allocatedBytes());

    // A run gives every buffer never resized a placeholder. A download needs staging memory, which is
    // host memory and not counted as device memory.
    const size_t beforeRun = device_->allocatedBytes();
    RasterParams params{};
    std::vector<double> gpuMs;
    ASSERT_TRUE(device_->run(params, {{STAGE_CLEAR, 0}}, gpuMs).ok());
    EXPECT_GE(device_->allocatedBytes(), beforeRun + (BUF_COUNT - 2) * 16);
    const size_t afterRun = device_->allocatedBytes();
    std::vector<uint8_t> data(1 << 20);
    ASSERT_TRUE(device_->download(BUF_VISIBILITY, data.data(), data.size()).ok());
    EXPECT_EQ(device_->allocatedBytes(), afterRun);
    EXPECT_GE(device_->peakAllocatedBytes(), device_->allocatedBytes());
}

TEST_F(VulkanDeviceTest, ValidationErrorFailsEveryLaterCall)
{
    ASSERT_TRUE(injectVulkanValidationError(*device_, "error injected by the test").ok());
    injectedErrors_ = 1;
    std::vector<uint8_t> data(16);
    std::vector<double> gpuMs;
    for (const Status& status :
         {device_->resize(BUF_POSITIONS, 16), device_->upload(BUF_POSITIONS, data.data(), 16),
          device_->download(BUF_POSITIONS, data.data(), 16), device_->run(RasterParams{}, {}, gpuMs)}) {
        ASSERT_FALSE(status.ok());
        const std::string& message = status.error().message;
        EXPECT_TRUE(isOneLine(message)) << message;
        EXPECT_NE(message.find("vulkan validation reported 1 error(s); first:"), std::string::npos)
            << message;
        EXPECT_NE(message.find("error injected by the test"), std::string::npos) << message;
    }
}

}  // namespace
}  // namespace sr
