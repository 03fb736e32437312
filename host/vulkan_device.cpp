// vulkan_device.cpp - the Vulkan backend of ComputeDevice.
//
// One logical device with one compute queue, one storage buffer per BUF_* binding plus a
// host-visible uniform buffer for RasterParams, one descriptor set shared by every stage, and one
// compute pipeline per stage built from the SPIR-V that CMake embeds
// (<builddir>/spirv/<stage>.spv.h). Every public call records one command buffer, submits it and
// waits on a fence: the pipeline is a short chain of dependent dispatches with nothing to overlap,
// and waiting keeps a failure attached to the call that caused it.
//
// Buffer sizes: size() returns the byte count of the last resize(); the allocation behind it is
// that count rounded up to 16 bytes and is only replaced when a resize asks for more than it holds,
// so shrinking keeps the larger allocation. upload() and download() are checked against size().
#include <vulkan/vulkan.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "compute_device.h"
#include "vulkan_device_internal.h"

namespace sr {
namespace {

// The generated headers each define `const uint32_t kSpv_<stage>[]`.
#include "clear.spv.h"
#include "raster_small.spv.h"
#include "raster_tiles.spv.h"
#include "scan_add.spv.h"
#include "scan_blocks.spv.h"
#include "scan_sums.spv.h"
#include "setup.spv.h"
#include "shade.spv.h"
#include "vertex.spv.h"

struct StageSpirv {
    const uint32_t* code;
    size_t bytes;
};

// Indexed by STAGE_*.
const StageSpirv kStageSpirv[] = {
    {kSpv_clear, sizeof kSpv_clear},
    {kSpv_vertex, sizeof kSpv_vertex},
    {kSpv_setup, sizeof kSpv_setup},
    {kSpv_scan_blocks, sizeof kSpv_scan_blocks},
    {kSpv_scan_sums, sizeof kSpv_scan_sums},
    {kSpv_scan_add, sizeof kSpv_scan_add},
    {kSpv_raster_small, sizeof kSpv_raster_small},
    {kSpv_raster_tiles, sizeof kSpv_raster_tiles},
    {kSpv_shade, sizeof kSpv_shade},
};
static_assert(sizeof kStageSpirv / sizeof kStageSpirv[0] == STAGE_COUNT, "one module per stage");

const char* const kValidationLayer = "VK_LAYER_KHRONOS_validation";

// Smallest allocation and allocation granularity. 16 bytes hold one vec4, the largest element of
// any buffer, so a shader indexing element 0 of a placeholder buffer stays in bounds.
constexpr VkDeviceSize kMinBufferBytes = 16;

constexpr VkBufferUsageFlags kStorageUsage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

// Groups launched for the grid-stride raster stages. A GPU needs thousands of groups in flight to
// fill its multiprocessors; lavapipe runs one group per CPU thread at a time, and a few per thread
// are enough to balance the load.
constexpr uint32_t kGpuRasterGroups = 4096;
constexpr uint32_t kCpuRasterGroups = 64;

std::string vkResultName(VkResult result)
{
    switch (result) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_NOT_READY: return "VK_NOT_READY";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    case VK_EVENT_SET: return "VK_EVENT_SET";
    case VK_EVENT_RESET: return "VK_EVENT_RESET";
    case VK_INCOMPLETE: return "VK_INCOMPLETE";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_MEMORY_MAP_FAILED: return "VK_ERROR_MEMORY_MAP_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_TOO_MANY_OBJECTS: return "VK_ERROR_TOO_MANY_OBJECTS";
    case VK_ERROR_FORMAT_NOT_SUPPORTED: return "VK_ERROR_FORMAT_NOT_SUPPORTED";
    case VK_ERROR_FRAGMENTED_POOL: return "VK_ERROR_FRAGMENTED_POOL";
    case VK_ERROR_UNKNOWN: return "VK_ERROR_UNKNOWN";
    case VK_ERROR_OUT_OF_POOL_MEMORY: return "VK_ERROR_OUT_OF_POOL_MEMORY";
    case VK_ERROR_INVALID_EXTERNAL_HANDLE: return "VK_ERROR_INVALID_EXTERNAL_HANDLE";
    case VK_ERROR_FRAGMENTATION: return "VK_ERROR_FRAGMENTATION";
    case VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS: return "VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS";
    case VK_PIPELINE_COMPILE_REQUIRED: return "VK_PIPELINE_COMPILE_REQUIRED";
    case VK_ERROR_VALIDATION_FAILED_EXT: return "VK_ERROR_VALIDATION_FAILED_EXT";
    default: return fmt::format("VkResult {}", static_cast<int>(result));
    }
}

// Last component of a __FILE__ path: CMake passes absolute paths, which would bury the line number.
const char* baseName(const char* path)
{
    const char* slash = std::strrchr(path, '/');
    return slash ? slash + 1 : path;
}

Error vkError(VkResult result, std::string_view what, const char* file, int line)
{
    return makeError(ExitCode::Runtime, "vulkan: {} failed: {} ({}:{})", what, vkResultName(result),
                     baseName(file), line);
}

// Evaluates a Vulkan call once and returns an Error from the enclosing function (returning Status
// or Result<T>) unless the call gave VK_SUCCESS. Positive codes such as VK_INCOMPLETE fail as well:
// no call made here can return one when it did what this file expects.
#define SR_VK_CHECK(expr)                                                                          \
    do {                                                                                           \
        VkResult sr_vk_result_ = (expr);                                                           \
        if (sr_vk_result_ != VK_SUCCESS) return vkError(sr_vk_result_, #expr, __FILE__, __LINE__); \
    } while (0)

// Validation errors of every device in the process, for vulkanValidationErrorCount().
std::atomic<size_t> gValidationErrors{0};

// What a device's debug messenger has seen; the layer may call back from any thread.
struct ValidationLog {
    std::mutex mutex;
    size_t errors = 0;
    std::string firstError;
};

VKAPI_ATTR VkBool32 VKAPI_CALL onDebugMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                              VkDebugUtilsMessageTypeFlagsEXT,
                                              const VkDebugUtilsMessengerCallbackDataEXT* data, void* user)
{
    std::string text = data && data->pMessage ? data->pMessage : "(no message text)";
    // The layer's messages span several lines at times; the project reports one line per problem.
    std::replace(text.begin(), text.end(), '\n', ' ');
    std::fprintf(stderr, "vulkan validation: %s\n", text.c_str());
    if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
        ++gValidationErrors;
        auto* log = static_cast<ValidationLog*>(user);
        std::lock_guard<std::mutex> lock(log->mutex);
        if (log->errors++ == 0) log->firstError = text;
    }
    return VK_FALSE;  // the call that triggered the message proceeds as it would without the layer
}

VkDebugUtilsMessengerCreateInfoEXT messengerCreateInfo(ValidationLog* log)
{
    VkDebugUtilsMessengerCreateInfoEXT info{};
    info.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    info.messageSeverity =
        VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    info.pfnUserCallback = onDebugMessage;
    info.pUserData = log;
    return info;
}

// Position of a device type in the selection order: real GPUs first, CPU implementations last.
int deviceTypeRank(VkPhysicalDeviceType type)
{
    switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 4;
    default: return 3;
    }
}

// A physical device that can run the pipeline, with what the backend needs to know about it.
struct Candidate {
    VkPhysicalDevice device = VK_NULL_HANDLE;
    VkPhysicalDeviceProperties properties{};
    std::string driver;
    VkDeviceSize maxAllocationSize = 0;
    uint32_t queueFamily = 0;
    uint32_t timestampValidBits = 0;
};

struct DeviceList {
    std::vector<Candidate> suitable;  // in selection order
    uint32_t physicalCount = 0;       // all physical devices, suitable or not
};

// Fills `candidate` and returns true when `device` meets every requirement of the pipeline.
bool inspectDevice(VkPhysicalDevice device, Candidate& candidate)
{
    VkPhysicalDeviceProperties basic{};
    vkGetPhysicalDeviceProperties(device, &basic);
    // The *2 queries below are only valid on a device that knows their structures.
    if (basic.apiVersion < VK_API_VERSION_1_2 || !(basic.limits.timestampPeriod > 0.0f)) return false;

    VkPhysicalDeviceDriverProperties driver{};
    driver.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES;
    VkPhysicalDeviceMaintenance3Properties maintenance3{};
    maintenance3.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES;
    maintenance3.pNext = &driver;
    VkPhysicalDeviceProperties2 properties{};
    properties.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    properties.pNext = &maintenance3;
    vkGetPhysicalDeviceProperties2(device, &properties);

    // The standalone struct, not VkPhysicalDeviceVulkan12Features: NVIDIA reports 64-bit buffer
    // atomics only there.
    VkPhysicalDeviceShaderAtomicInt64Features atomics{};
    atomics.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_INT64_FEATURES;
    VkPhysicalDeviceFeatures2 features{};
    features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    features.pNext = &atomics;
    vkGetPhysicalDeviceFeatures2(device, &features);
    if (!features.features.shaderInt64 || !atomics.shaderBufferInt64Atomics) return false;

    uint32_t familyCount = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(device, &familyCount, nullptr);
    std::vector<VkQueueFamilyProperties> families(familyCount);
    vkGetPhysicalDeviceQueueFamilyProperties(device, &familyCount, families.data());
    for (uint32_t i = 0; i < familyCount; ++i) {
        if ((families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) && families[i].timestampValidBits > 0) {
            candidate.device = device;
            candidate.properties = properties.properties;
            candidate.driver = driver.driverName;
            if (driver.driverInfo[0] != '\0') candidate.driver += std::string(" ") + driver.driverInfo;
            candidate.maxAllocationSize = maintenance3.maxMemoryAllocationSize;
            candidate.queueFamily = i;
            candidate.timestampValidBits = families[i].timestampValidBits;
            return true;
        }
    }
    return false;
}

Result<DeviceList> listDevices(VkInstance instance)
{
    DeviceList list;
    SR_VK_CHECK(vkEnumeratePhysicalDevices(instance, &list.physicalCount, nullptr));
    std::vector<VkPhysicalDevice> devices(list.physicalCount);
    SR_VK_CHECK(vkEnumeratePhysicalDevices(instance, &list.physicalCount, devices.data()));
    for (VkPhysicalDevice device : devices) {
        Candidate candidate;
        if (inspectDevice(device, candidate)) list.suitable.push_back(candidate);
    }
    std::stable_sort(list.suitable.begin(), list.suitable.end(), [](const Candidate& a, const Candidate& b) {
        return deviceTypeRank(a.properties.deviceType) < deviceTypeRank(b.properties.deviceType);
    });
    return list;
}

VkDeviceSize roundUp(VkDeviceSize value, VkDeviceSize multiple)
{
    return (value + multiple - 1) / multiple * multiple;
}

void memoryBarrier(VkCommandBuffer cmd, VkPipelineStageFlags srcStages, VkAccessFlags srcAccess,
                   VkPipelineStageFlags dstStages, VkAccessFlags dstAccess)
{
    VkMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    barrier.srcAccessMask = srcAccess;
    barrier.dstAccessMask = dstAccess;
    vkCmdPipelineBarrier(cmd, srcStages, dstStages, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

// A buffer with its own memory allocation.
struct GpuBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize capacity = 0;   // size the VkBuffer was created with; 0 until fully set up
    VkDeviceSize allocated = 0;  // size of `memory`, counted in allocatedBytes()
    void* mapped = nullptr;      // persistent mapping of host-visible memory
};

class VulkanDevice final : public ComputeDevice {
public:
    VulkanDevice() = default;
    VulkanDevice(const VulkanDevice&) = delete;
    VulkanDevice& operator=(const VulkanDevice&) = delete;
    ~VulkanDevice() override;

    // Creates everything; on failure the destructor releases whatever was created.
    Status init(int index);
    Status injectValidationError(const char* message);

    const DeviceInfo& info() const override { return info_; }
    Status resize(uint32_t buffer, size_t bytes) override
    {
        return checked([&] { return resizeBuffer(buffer, bytes); });
    }
    size_t size(uint32_t buffer) const override
    {
        return buffer > BUF_PARAMS && buffer < BUF_COUNT ? sizes_[buffer] : 0;
    }
    Status upload(uint32_t buffer, const void* data, size_t bytes) override
    {
        return checked([&] { return uploadBuffer(buffer, data, bytes); });
    }
    Status download(uint32_t buffer, void* data, size_t bytes) override
    {
        return checked([&] { return downloadBuffer(buffer, data, bytes); });
    }
    Status run(const RasterParams& params, const std::vector<Dispatch>& dispatches,
               std::vector<double>& gpuMs) override
    {
        return checked([&] { return runDispatches(params, dispatches, gpuMs); });
    }
    size_t allocatedBytes() const override { return allocatedBytes_; }
    size_t peakAllocatedBytes() const override { return peakAllocatedBytes_; }

private:
    // Runs `body` unless validation already failed, and fails it when validation complained during
    // it: a validation error names the real cause of whatever the body's own error would be.
    template <typename Body>
    Status checked(Body&& body)
    {
        SR_TRY(validationStatus());
        Status result = body();
        SR_TRY(validationStatus());
        return result;
    }

    Status validationStatus();
    Status createInstance();
    Status selectDevice(int index);
    Status createDevice();
    Status createLayouts();
    Status createPipelines();
    Status createCommandObjects();
    uint32_t findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags wanted) const;
    Status allocateBuffer(GpuBuffer& b, VkDeviceSize bytes, VkBufferUsageFlags usage,
                          std::initializer_list<VkMemoryPropertyFlags> preferredMemory);
    void destroyBuffer(GpuBuffer& b);
    Status ensureStaging(VkDeviceSize bytes);
    Status ensureBindings();
    Status ensureQueryPool(uint32_t queries);
    Status beginCommands();
    Status submitAndWait();
    Status checkTransfer(const char* what, uint32_t buffer, size_t bytes) const;
    Status resizeBuffer(uint32_t buffer, size_t bytes);
    Status uploadBuffer(uint32_t buffer, const void* data, size_t bytes);
    Status downloadBuffer(uint32_t buffer, void* data, size_t bytes);
    Status runDispatches(const RasterParams& params, const std::vector<Dispatch>& dispatches,
                         std::vector<double>& gpuMs);

    DeviceInfo info_;
    ValidationLog validationLog_;
    bool validation_ = false;

    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    PFN_vkDestroyDebugUtilsMessengerEXT destroyMessenger_ = nullptr;
    Candidate physical_;
    VkPhysicalDeviceMemoryProperties memoryProperties_{};
    VkDeviceSize maxStorageBytes_ = 0;  // largest buffer a descriptor can cover whole

    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
    VkPipelineLayout pipelineLayout_ = VK_NULL_HANDLE;
    VkPipeline pipelines_[STAGE_COUNT] = {};
    VkDescriptorPool descriptorPool_ = VK_NULL_HANDLE;
    VkDescriptorSet descriptorSet_ = VK_NULL_HANDLE;
    VkCommandPool commandPool_ = VK_NULL_HANDLE;
    VkCommandBuffer commandBuffer_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    VkQueryPool queryPool_ = VK_NULL_HANDLE;
    uint32_t queryCapacity_ = 0;

    GpuBuffer buffers_[BUF_COUNT];  // BUF_PARAMS is the uniform buffer, the rest storage buffers
    size_t sizes_[BUF_COUNT] = {};  // logical sizes, as resize() was last asked
    GpuBuffer staging_;
    bool descriptorsDirty_ = true;  // a buffer was replaced since the descriptor set was written
    size_t allocatedBytes_ = 0;
    size_t peakAllocatedBytes_ = 0;
};

VulkanDevice::~VulkanDevice()
{
    if (device_ != VK_NULL_HANDLE) {
        // Every call waits for its own work, so this only matters after a failed wait; a destructor
        // cannot return the error, only report it.
        VkResult result = vkDeviceWaitIdle(device_);
        if (result != VK_SUCCESS)
            std::fprintf(stderr, "vulkan: vkDeviceWaitIdle failed: %s\n", vkResultName(result).c_str());
        for (GpuBuffer& b : buffers_) destroyBuffer(b);
        destroyBuffer(staging_);
        for (VkPipeline pipeline : pipelines_) vkDestroyPipeline(device_, pipeline, nullptr);
        vkDestroyQueryPool(device_, queryPool_, nullptr);
        vkDestroyFence(device_, fence_, nullptr);
        vkDestroyCommandPool(device_, commandPool_, nullptr);        // frees commandBuffer_
        vkDestroyDescriptorPool(device_, descriptorPool_, nullptr);  // frees descriptorSet_
        vkDestroyPipelineLayout(device_, pipelineLayout_, nullptr);
        vkDestroyDescriptorSetLayout(device_, setLayout_, nullptr);
        vkDestroyDevice(device_, nullptr);
    }
    if (messenger_ != VK_NULL_HANDLE) destroyMessenger_(instance_, messenger_, nullptr);
    // The messenger chained into the instance create info still reports leaks found here.
    if (instance_ != VK_NULL_HANDLE) vkDestroyInstance(instance_, nullptr);
}

Status VulkanDevice::init(int index)
{
    SR_TRY(createInstance());
    SR_TRY(selectDevice(index));
    SR_TRY(createDevice());
    SR_TRY(createLayouts());
    SR_TRY(createPipelines());
    SR_TRY(createCommandObjects());
    // Host-visible so that run() writes the parameters directly; device-local where the device
    // offers such memory (resizable BAR), which makes the reads from every stage cheaper.
    SR_TRY(allocateBuffer(buffers_[BUF_PARAMS], roundUp(sizeof(RasterParams), kMinBufferBytes),
                          VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                          {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                               VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                           VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT}));

    const VkPhysicalDeviceProperties& p = physical_.properties;
    info_.backend = "vulkan";
    info_.name = p.deviceName;
    info_.driver = physical_.driver;
    info_.isCpu = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    info_.rasterGroups = info_.isCpu ? kCpuRasterGroups : kGpuRasterGroups;
    return validationStatus();
}

Status VulkanDevice::validationStatus()
{
    std::lock_guard<std::mutex> lock(validationLog_.mutex);
    if (validationLog_.errors == 0) return okStatus();
    return makeError(ExitCode::Runtime, "vulkan validation reported {} error(s); first: {}",
                     validationLog_.errors, validationLog_.firstError);
}

Status VulkanDevice::createInstance()
{
    const char* env = std::getenv("SR_VULKAN_VALIDATION");
    validation_ = env != nullptr && std::strcmp(env, "1") == 0;

    std::vector<const char*> layers;
    std::vector<const char*> extensions;
    if (validation_) {
        uint32_t count = 0;
        SR_VK_CHECK(vkEnumerateInstanceLayerProperties(&count, nullptr));
        std::vector<VkLayerProperties> available(count);
        SR_VK_CHECK(vkEnumerateInstanceLayerProperties(&count, available.data()));
        bool found = std::any_of(available.begin(), available.end(), [](const VkLayerProperties& l) {
            return std::strcmp(l.layerName, kValidationLayer) == 0;
        });
        if (!found)
            return makeError(ExitCode::Usage,
                             "vulkan: SR_VULKAN_VALIDATION=1 but {} is not installed "
                             "(Debian package vulkan-validationlayers)",
                             kValidationLayer);
        layers.push_back(kValidationLayer);
        extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    }

    VkApplicationInfo app{};
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "raster";
    app.apiVersion = VK_API_VERSION_1_2;
    // Chained into the create info, the messenger also covers vkCreateInstance and
    // vkDestroyInstance, which the messenger object created below cannot see.
    VkDebugUtilsMessengerCreateInfoEXT messengerInfo = messengerCreateInfo(&validationLog_);
    VkInstanceCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    info.pNext = validation_ ? &messengerInfo : nullptr;
    info.pApplicationInfo = &app;
    info.enabledLayerCount = static_cast<uint32_t>(layers.size());
    info.ppEnabledLayerNames = layers.data();
    info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();
    VkResult result = vkCreateInstance(&info, nullptr, &instance_);
    // The loader's answer when no driver is installed: a missing backend, not a run-time failure.
    if (result == VK_ERROR_INCOMPATIBLE_DRIVER)
        return makeError(ExitCode::Usage, "vulkan: no Vulkan driver found (vkCreateInstance: {})",
                         vkResultName(result));
    SR_VK_CHECK(result);

    if (validation_) {
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
        destroyMessenger_ = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
        if (create == nullptr || destroyMessenger_ == nullptr)
            return makeError(ExitCode::Runtime, "vulkan: {} functions not found",
                             VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        SR_VK_CHECK(create(instance_, &messengerInfo, nullptr, &messenger_));
    }
    return okStatus();
}

Status VulkanDevice::selectDevice(int index)
{
    Result<DeviceList> list = listDevices(instance_);
    if (!list.ok()) return list.error();
    const std::vector<Candidate>& suitable = list->suitable;
    if (suitable.empty())
        return makeError(ExitCode::Usage,
                         "vulkan: none of the {} physical device(s) is suitable (needs Vulkan 1.2, a "
                         "compute queue with timestamps, shaderInt64 and 64-bit buffer atomics)",
                         list->physicalCount);
    if (index < -1 || index >= static_cast<int>(suitable.size())) {
        std::string names;
        for (size_t i = 0; i < suitable.size(); ++i)
            names += fmt::format("{}{}: {}", i > 0 ? ", " : "", i, suitable[i].properties.deviceName);
        return makeError(ExitCode::Usage, "vulkan: device index {} out of range; {} suitable device(s): {}",
                         index, suitable.size(), names);
    }
    physical_ = suitable[index < 0 ? 0 : static_cast<size_t>(index)];
    vkGetPhysicalDeviceMemoryProperties(physical_.device, &memoryProperties_);
    maxStorageBytes_ = std::min<VkDeviceSize>(physical_.properties.limits.maxStorageBufferRange,
                                              physical_.maxAllocationSize);
    return okStatus();
}

Status VulkanDevice::createDevice()
{
    float priority = 1.0f;
    VkDeviceQueueCreateInfo queueInfo{};
    queueInfo.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    queueInfo.queueFamilyIndex = physical_.queueFamily;
    queueInfo.queueCount = 1;
    queueInfo.pQueuePriorities = &priority;

    // Exactly the features the shaders use: 64-bit integers for the edge functions and the
    // visibility key, and 64-bit buffer atomics for the depth test.
    VkPhysicalDeviceShaderAtomicInt64Features atomics{};
    atomics.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_INT64_FEATURES;
    atomics.shaderBufferInt64Atomics = VK_TRUE;
    VkPhysicalDeviceFeatures2 features{};
    features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    features.pNext = &atomics;
    features.features.shaderInt64 = VK_TRUE;

    VkDeviceCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    info.pNext = &features;
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &queueInfo;
    SR_VK_CHECK(vkCreateDevice(physical_.device, &info, nullptr, &device_));
    vkGetDeviceQueue(device_, physical_.queueFamily, 0, &queue_);
    return okStatus();
}

Status VulkanDevice::createLayouts()
{
    // Every stage declares every binding (compute_glsl/buffers.glsl), so one layout serves them
    // all.
    VkDescriptorSetLayoutBinding bindings[BUF_COUNT];
    for (uint32_t i = 0; i < BUF_COUNT; ++i) {
        bindings[i] = VkDescriptorSetLayoutBinding{};
        bindings[i].binding = i;
        bindings[i].descriptorType =
            i == BUF_PARAMS ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        bindings[i].descriptorCount = 1;
        bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    VkDescriptorSetLayoutCreateInfo setInfo{};
    setInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    setInfo.bindingCount = BUF_COUNT;
    setInfo.pBindings = bindings;
    SR_VK_CHECK(vkCreateDescriptorSetLayout(device_, &setInfo, nullptr, &setLayout_));

    VkPipelineLayoutCreateInfo layoutInfo{};
    layoutInfo.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    layoutInfo.setLayoutCount = 1;
    layoutInfo.pSetLayouts = &setLayout_;
    SR_VK_CHECK(vkCreatePipelineLayout(device_, &layoutInfo, nullptr, &pipelineLayout_));

    VkDescriptorPoolSize poolSizes[2] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1},
                                         {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, BUF_COUNT - 1}};
    VkDescriptorPoolCreateInfo poolInfo{};
    poolInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    poolInfo.maxSets = 1;
    poolInfo.poolSizeCount = 2;
    poolInfo.pPoolSizes = poolSizes;
    SR_VK_CHECK(vkCreateDescriptorPool(device_, &poolInfo, nullptr, &descriptorPool_));

    VkDescriptorSetAllocateInfo setAlloc{};
    setAlloc.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    setAlloc.descriptorPool = descriptorPool_;
    setAlloc.descriptorSetCount = 1;
    setAlloc.pSetLayouts = &setLayout_;
    SR_VK_CHECK(vkAllocateDescriptorSets(device_, &setAlloc, &descriptorSet_));
    return okStatus();
}

Status VulkanDevice::createPipelines()
{
    // All at construction: a shader the driver rejects is reported before any work is done, and
    // lazy creation would only move the compile time into the first frame's timings.
    for (uint32_t stage = 0; stage < STAGE_COUNT; ++stage) {
        VkShaderModuleCreateInfo moduleInfo{};
        moduleInfo.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
        moduleInfo.codeSize = kStageSpirv[stage].bytes;
        moduleInfo.pCode = kStageSpirv[stage].code;
        VkShaderModule module = VK_NULL_HANDLE;
        SR_VK_CHECK(vkCreateShaderModule(device_, &moduleInfo, nullptr, &module));

        VkComputePipelineCreateInfo info{};
        info.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
        info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
        info.stage.module = module;
        info.stage.pName = "main";
        info.layout = pipelineLayout_;
        VkResult result =
            vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &info, nullptr, &pipelines_[stage]);
        // The pipeline keeps what it needs of the module.
        vkDestroyShaderModule(device_, module, nullptr);
        if (result != VK_SUCCESS)
            return vkError(result, fmt::format("vkCreateComputePipelines (stage {})", stageName(stage)),
                           __FILE__, __LINE__);
    }
    return okStatus();
}

Status VulkanDevice::createCommandObjects()
{
    VkCommandPoolCreateInfo poolInfo{};
    poolInfo.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    // One command buffer is re-recorded for every call; beginning it again resets it.
    poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    poolInfo.queueFamilyIndex = physical_.queueFamily;
    SR_VK_CHECK(vkCreateCommandPool(device_, &poolInfo, nullptr, &commandPool_));

    VkCommandBufferAllocateInfo allocInfo{};
    allocInfo.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    allocInfo.commandPool = commandPool_;
    allocInfo.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    allocInfo.commandBufferCount = 1;
    SR_VK_CHECK(vkAllocateCommandBuffers(device_, &allocInfo, &commandBuffer_));

    VkFenceCreateInfo fenceInfo{};
    fenceInfo.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    SR_VK_CHECK(vkCreateFence(device_, &fenceInfo, nullptr, &fence_));
    return okStatus();
}

// Index of the first memory type allowed by `typeBits` with all of `wanted`, or UINT32_MAX.
uint32_t VulkanDevice::findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags wanted) const
{
    for (uint32_t i = 0; i < memoryProperties_.memoryTypeCount; ++i)
        if ((typeBits & (1u << i)) && (memoryProperties_.memoryTypes[i].propertyFlags & wanted) == wanted)
            return i;
    return UINT32_MAX;
}

// Creates `b`, which must be empty, with memory of the first of `preferredMemory` the device has.
// On failure `b` may hold part of what was created; destroyBuffer() releases it.
Status VulkanDevice::allocateBuffer(GpuBuffer& b, VkDeviceSize bytes, VkBufferUsageFlags usage,
                                    std::initializer_list<VkMemoryPropertyFlags> preferredMemory)
{
    VkBufferCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    info.size = bytes;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    SR_VK_CHECK(vkCreateBuffer(device_, &info, nullptr, &b.buffer));

    VkMemoryRequirements requirements{};
    vkGetBufferMemoryRequirements(device_, b.buffer, &requirements);
    uint32_t type = UINT32_MAX;
    VkMemoryPropertyFlags flags = 0;
    for (VkMemoryPropertyFlags wanted : preferredMemory) {
        type = findMemoryType(requirements.memoryTypeBits, wanted);
        if (type != UINT32_MAX) {
            flags = wanted;
            break;
        }
    }
    if (type == UINT32_MAX)
        return makeError(ExitCode::Runtime, "vulkan: no suitable memory type for a buffer of {} bytes",
                         bytes);

    VkMemoryAllocateInfo allocInfo{};
    allocInfo.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    allocInfo.allocationSize = requirements.size;
    allocInfo.memoryTypeIndex = type;
    SR_VK_CHECK(vkAllocateMemory(device_, &allocInfo, nullptr, &b.memory));
    b.allocated = requirements.size;
    allocatedBytes_ += b.allocated;
    peakAllocatedBytes_ = std::max(peakAllocatedBytes_, allocatedBytes_);

    SR_VK_CHECK(vkBindBufferMemory(device_, b.buffer, b.memory, 0));
    if (flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)
        SR_VK_CHECK(vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped));
    b.capacity = bytes;
    return okStatus();
}

void VulkanDevice::destroyBuffer(GpuBuffer& b)
{
    vkDestroyBuffer(device_, b.buffer, nullptr);
    vkFreeMemory(device_, b.memory, nullptr);  // also unmaps
    allocatedBytes_ -= b.allocated;
    b = GpuBuffer{};
}

Status VulkanDevice::ensureStaging(VkDeviceSize bytes)
{
    if (staging_.capacity >= bytes) return okStatus();
    destroyBuffer(staging_);
    // Cached memory makes the host's reads of downloads fast; coherent memory needs no flushes.
    return allocateBuffer(staging_, roundUp(bytes, kMinBufferBytes),
                          VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                          {VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT |
                               VK_MEMORY_PROPERTY_HOST_CACHED_BIT,
                           VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT});
}

Status VulkanDevice::ensureBindings()
{
    for (uint32_t i = BUF_PARAMS + 1; i < BUF_COUNT; ++i) {
        GpuBuffer& b = buffers_[i];
        if (b.capacity > 0) continue;
        // The descriptor set names every binding, and each must be a valid buffer, whether or not
        // the stages of this run touch it.
        destroyBuffer(b);
        descriptorsDirty_ = true;
        SR_TRY(allocateBuffer(b, kMinBufferBytes, kStorageUsage, {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT}));
    }
    if (!descriptorsDirty_) return okStatus();

    VkDescriptorBufferInfo infos[BUF_COUNT];
    VkWriteDescriptorSet writes[BUF_COUNT];
    for (uint32_t i = 0; i < BUF_COUNT; ++i) {
        infos[i] = VkDescriptorBufferInfo{buffers_[i].buffer, 0, VK_WHOLE_SIZE};
        writes[i] = VkWriteDescriptorSet{};
        writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        writes[i].dstSet = descriptorSet_;
        writes[i].dstBinding = i;
        writes[i].descriptorCount = 1;
        writes[i].descriptorType =
            i == BUF_PARAMS ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[i].pBufferInfo = &infos[i];
    }
    // No submitted work uses the set any more (every call waits), so it can be updated in place.
    vkUpdateDescriptorSets(device_, BUF_COUNT, writes, 0, nullptr);
    descriptorsDirty_ = false;
    return okStatus();
}

Status VulkanDevice::ensureQueryPool(uint32_t queries)
{
    if (queryCapacity_ >= queries) return okStatus();
    vkDestroyQueryPool(device_, queryPool_, nullptr);
    queryPool_ = VK_NULL_HANDLE;
    queryCapacity_ = 0;
    VkQueryPoolCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
    info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    info.queryCount = queries;
    SR_VK_CHECK(vkCreateQueryPool(device_, &info, nullptr, &queryPool_));
    queryCapacity_ = queries;
    return okStatus();
}

Status VulkanDevice::beginCommands()
{
    VkCommandBufferBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    SR_VK_CHECK(vkBeginCommandBuffer(commandBuffer_, &begin));
    return okStatus();
}

Status VulkanDevice::submitAndWait()
{
    SR_VK_CHECK(vkEndCommandBuffer(commandBuffer_));
    // Reset here rather than after the wait, so that a failed wait cannot leave it signalled.
    SR_VK_CHECK(vkResetFences(device_, 1, &fence_));
    VkSubmitInfo submit{};
    submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &commandBuffer_;
    SR_VK_CHECK(vkQueueSubmit(queue_, 1, &submit, fence_));
    SR_VK_CHECK(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX));
    return okStatus();
}

Status VulkanDevice::checkTransfer(const char* what, uint32_t buffer, size_t bytes) const
{
    if (buffer <= BUF_PARAMS || buffer >= BUF_COUNT)
        return makeError(ExitCode::Runtime, "vulkan: {} of invalid buffer index {}", what, buffer);
    if (bytes > sizes_[buffer])
        return makeError(ExitCode::Runtime, "vulkan: {} of {} bytes but buffer {} holds {} bytes", what,
                         bytes, buffer, sizes_[buffer]);
    return okStatus();
}

Status VulkanDevice::resizeBuffer(uint32_t buffer, size_t bytes)
{
    if (buffer <= BUF_PARAMS || buffer >= BUF_COUNT)
        return makeError(ExitCode::Runtime, "vulkan: resize of invalid buffer index {}", buffer);
    // A storage descriptor covers the whole buffer, so the buffer may not exceed the device's
    // range.
    if (bytes > maxStorageBytes_ ||
        roundUp(std::max<VkDeviceSize>(bytes, kMinBufferBytes), kMinBufferBytes) > maxStorageBytes_)
        return makeError(ExitCode::Runtime,
                         "vulkan: buffer {} needs {} bytes, more than the device allows per storage "
                         "buffer ({} bytes)",
                         buffer, bytes, maxStorageBytes_);
    const VkDeviceSize capacity = roundUp(std::max<VkDeviceSize>(bytes, kMinBufferBytes), kMinBufferBytes);
    GpuBuffer& b = buffers_[buffer];
    if (b.capacity >= capacity) {
        sizes_[buffer] = bytes;
        return okStatus();
    }
    // Free first so that the old and new allocations never coexist; the contents are undefined
    // anyway.
    destroyBuffer(b);
    sizes_[buffer] = 0;
    descriptorsDirty_ = true;
    SR_TRY(allocateBuffer(b, capacity, kStorageUsage, {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT}));
    sizes_[buffer] = bytes;
    return okStatus();
}

Status VulkanDevice::uploadBuffer(uint32_t buffer, const void* data, size_t bytes)
{
    SR_TRY(checkTransfer("upload", buffer, bytes));
    if (bytes == 0) return okStatus();
    SR_TRY(ensureStaging(bytes));
    std::memcpy(staging_.mapped, data, bytes);  // coherent: the submission makes it visible

    SR_TRY(beginCommands());
    VkBufferCopy region{0, 0, bytes};
    vkCmdCopyBuffer(commandBuffer_, staging_.buffer, buffers_[buffer].buffer, 1, &region);
    // Barriers order against later submissions too: the next run's stages and transfers see the
    // data.
    memoryBarrier(commandBuffer_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                  VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                      VK_ACCESS_TRANSFER_WRITE_BIT);
    return submitAndWait();
}

Status VulkanDevice::downloadBuffer(uint32_t buffer, void* data, size_t bytes)
{
    SR_TRY(checkTransfer("download", buffer, bytes));
    if (bytes == 0) return okStatus();
    SR_TRY(ensureStaging(bytes));

    SR_TRY(beginCommands());
    VkBufferCopy region{0, 0, bytes};
    vkCmdCopyBuffer(commandBuffer_, buffers_[buffer].buffer, staging_.buffer, 1, &region);
    memoryBarrier(commandBuffer_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    SR_TRY(submitAndWait());
    std::memcpy(data, staging_.mapped, bytes);
    return okStatus();
}

Status VulkanDevice::runDispatches(const RasterParams& params, const std::vector<Dispatch>& dispatches,
                                   std::vector<double>& gpuMs)
{
    gpuMs.clear();
    const uint32_t maxGroups = physical_.properties.limits.maxComputeWorkGroupCount[0];
    for (const Dispatch& d : dispatches) {
        if (d.stage >= STAGE_COUNT)
            return makeError(ExitCode::Runtime, "vulkan: dispatch of unknown stage {}", d.stage);
        if (d.groups > maxGroups)
            return makeError(ExitCode::Runtime,
                             "vulkan: stage {} needs {} groups, more than the device's limit of {}",
                             stageName(d.stage), d.groups, maxGroups);
    }
    if (dispatches.empty()) return okStatus();

    const uint32_t queries = static_cast<uint32_t>(2 * dispatches.size());
    SR_TRY(ensureQueryPool(queries));
    SR_TRY(ensureBindings());
    // Nothing submitted earlier still reads the uniform buffer, so it is overwritten in place.
    std::memcpy(buffers_[BUF_PARAMS].mapped, &params, sizeof params);

    SR_TRY(beginCommands());
    VkCommandBuffer cmd = commandBuffer_;
    vkCmdResetQueryPool(cmd, queryPool_, 0, queries);
    // All pipelines share one layout, so the set stays bound across the pipeline switches below.
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout_, 0, 1, &descriptorSet_, 0,
                            nullptr);
    for (size_t i = 0; i < dispatches.size(); ++i) {
        const Dispatch& d = dispatches[i];
        const uint32_t first = static_cast<uint32_t>(2 * i);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelines_[d.stage]);
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queryPool_, first);
        // An empty stage still gets its two timestamps, so gpuMs keeps one entry per dispatch.
        if (d.groups > 0) vkCmdDispatch(cmd, d.groups, 1, 1);
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queryPool_, first + 1);
        // Each stage reads what the previous ones wrote. The transfer bits reach past this
        // submission (barriers follow submission order) and cover the downloads and uploads that
        // come after it.
        memoryBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                      VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                          VK_ACCESS_TRANSFER_WRITE_BIT);
    }
    SR_TRY(submitAndWait());

    std::vector<uint64_t> ticks(queries);
    SR_VK_CHECK(vkGetQueryPoolResults(device_, queryPool_, 0, queries, ticks.size() * sizeof(uint64_t),
                                      ticks.data(), sizeof(uint64_t),
                                      VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    const uint32_t validBits = physical_.timestampValidBits;
    const uint64_t mask = validBits >= 64 ? ~uint64_t(0) : (uint64_t(1) << validBits) - 1;
    const double msPerTick = double(physical_.properties.limits.timestampPeriod) * 1e-6;
    gpuMs.reserve(dispatches.size());
    for (size_t i = 0; i < dispatches.size(); ++i) {
        // Subtracting modulo the counter width stays right when the counter wrapped in between.
        const uint64_t ticksTaken = (ticks[2 * i + 1] - ticks[2 * i]) & mask;
        gpuMs.push_back(double(ticksTaken) * msPerTick);
    }
    return okStatus();
}

Status VulkanDevice::injectValidationError(const char* message)
{
    if (!validation_)
        return makeError(ExitCode::Usage, "vulkan: validation is off (set SR_VULKAN_VALIDATION=1)");
    auto submit = reinterpret_cast<PFN_vkSubmitDebugUtilsMessageEXT>(
        vkGetInstanceProcAddr(instance_, "vkSubmitDebugUtilsMessageEXT"));
    if (submit == nullptr)
        return makeError(ExitCode::Runtime, "vulkan: vkSubmitDebugUtilsMessageEXT not found");
    VkDebugUtilsMessengerCallbackDataEXT data{};
    data.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CALLBACK_DATA_EXT;
    data.pMessageIdName = "sr-injected";
    data.pMessage = message;
    submit(instance_, VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT,
           VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT, &data);
    return okStatus();
}

}  // namespace

Result<std::unique_ptr<ComputeDevice>> makeVulkanDevice(int index)
{
    auto device = std::make_unique<VulkanDevice>();
    SR_TRY(device->init(index));
    return std::unique_ptr<ComputeDevice>(std::move(device));
}

size_t vulkanValidationErrorCount()
{
    return gValidationErrors.load();
}

Status injectVulkanValidationError(ComputeDevice& device, const char* message)
{
    auto* vulkan = dynamic_cast<VulkanDevice*>(&device);
    if (vulkan == nullptr) return makeError(ExitCode::Usage, "vulkan: not a Vulkan device");
    return vulkan->injectValidationError(message);
}

}  // namespace sr
