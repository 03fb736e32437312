// vulkan_context.cpp - see vulkan_context.h.
#include "vulkan/vulkan_context.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "vulkan/vulkan_device_internal.h"

namespace sr {
namespace {

const char* const kValidationLayer = "VK_LAYER_KHRONOS_validation";

// Every binding is visible to every stage that either backend runs: the compute stages and the
// graphics backend's vertex and fragment shaders declare the same set (compute_glsl/buffers.glsl).
constexpr VkShaderStageFlags kBindingStages =
    VK_SHADER_STAGE_COMPUTE_BIT | VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;

// Last component of a __FILE__ path: CMake passes absolute paths, which would bury the line number.
const char* baseName(const char* path)
{
    const char* slash = std::strrchr(path, '/');
    return slash ? slash + 1 : path;
}

// Validation errors of every context in the process, for vulkanValidationErrorCount().
std::atomic<size_t> gValidationErrors{0};

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

// The KHR promotion of VK_EXT_line_rasterization keeps the EXT's structure types and enum values, so the
// EXT declarations serve both; the Vulkan headers this builds with may predate the KHR name.
const char* const kKhrLineRasterization = "VK_KHR_line_rasterization";

// The extension that gives `device` Vulkan's rectangular line rasterization (VK_LINE_RASTERIZATION_MODE_
// RECTANGULAR_EXT): VK_KHR_line_rasterization where offered, else VK_EXT_line_rasterization, provided that
// the device reports the rectangularLines feature; nullptr when it has neither or lacks the feature. The
// instance asks for Vulkan 1.2, so a Vulkan 1.4 device's core line rasterization is reached through the
// extension too.
Result<const char*> rectangularLineExtension(VkPhysicalDevice device)
{
    uint32_t count = 0;
    SR_VK_CHECK(vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr));
    std::vector<VkExtensionProperties> offered(count);
    SR_VK_CHECK(vkEnumerateDeviceExtensionProperties(device, nullptr, &count, offered.data()));
    const char* chosen = nullptr;
    for (const char* name : {kKhrLineRasterization, VK_EXT_LINE_RASTERIZATION_EXTENSION_NAME})
        if (chosen == nullptr &&
            std::any_of(offered.begin(), offered.end(), [&](const VkExtensionProperties& e) {
                return std::strcmp(e.extensionName, name) == 0;
            }))
            chosen = name;
    if (chosen == nullptr) return static_cast<const char*>(nullptr);
    VkPhysicalDeviceLineRasterizationFeaturesEXT line{};
    line.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_LINE_RASTERIZATION_FEATURES_EXT;
    VkPhysicalDeviceFeatures2 features{};
    features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    features.pNext = &line;
    vkGetPhysicalDeviceFeatures2(device, &features);
    return line.rectangularLines ? chosen : nullptr;
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

// A physical device that can run the compute pipeline, with what the backends need to know about
// it. Graphics support does not make a device suitable or unsuitable, so that device indices are
// the same for every backend.
struct Candidate {
    VkPhysicalDevice device = VK_NULL_HANDLE;
    VkPhysicalDeviceProperties properties{};
    std::string driver;
    VkDeviceSize maxAllocationSize = 0;
    uint32_t computeFamily = 0;
    uint32_t computeTimestampBits = 0;
    uint32_t graphicsFamily = UINT32_MAX;  // UINT32_MAX: no graphics queue with timestamps
    uint32_t graphicsTimestampBits = 0;
    bool geometryShader = false;
    std::array<uint8_t, 16> uuid{};  // VkPhysicalDeviceIDProperties::deviceUUID
};

struct DeviceList {
    std::vector<Candidate> suitable;  // in selection order
    uint32_t physicalCount = 0;       // all physical devices, suitable or not
};

// Fills `candidate` and returns true when `device` meets every requirement of the compute pipeline.
bool inspectDevice(VkPhysicalDevice device, Candidate& candidate)
{
    VkPhysicalDeviceProperties basic{};
    vkGetPhysicalDeviceProperties(device, &basic);
    // The *2 queries below are only valid on a device that knows their structures.
    if (basic.apiVersion < VK_API_VERSION_1_2 || !(basic.limits.timestampPeriod > 0.0f)) return false;

    VkPhysicalDeviceIDProperties id{};
    id.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ID_PROPERTIES;
    VkPhysicalDeviceDriverProperties driver{};
    driver.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES;
    driver.pNext = &id;
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
    bool hasCompute = false;
    for (uint32_t i = 0; i < familyCount; ++i) {
        if (families[i].timestampValidBits == 0) continue;
        if (!hasCompute && (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT)) {
            hasCompute = true;
            candidate.computeFamily = i;
            candidate.computeTimestampBits = families[i].timestampValidBits;
        }
        if (candidate.graphicsFamily == UINT32_MAX && (families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT)) {
            candidate.graphicsFamily = i;
            candidate.graphicsTimestampBits = families[i].timestampValidBits;
        }
    }
    if (!hasCompute) return false;
    candidate.device = device;
    candidate.properties = properties.properties;
    candidate.driver = driver.driverName;
    if (driver.driverInfo[0] != '\0') candidate.driver += std::string(" ") + driver.driverInfo;
    candidate.maxAllocationSize = maintenance3.maxMemoryAllocationSize;
    candidate.geometryShader = features.features.geometryShader == VK_TRUE;
    std::copy(id.deviceUUID, id.deviceUUID + VK_UUID_SIZE, candidate.uuid.begin());
    return true;
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

std::string uuidText(const std::array<uint8_t, 16>& uuid)
{
    std::string text;
    for (size_t i = 0; i < uuid.size(); ++i)
        text += fmt::format("{}{:02x}", i == 4 || i == 6 || i == 8 || i == 10 ? "-" : "", uuid[i]);
    return text;
}

Result<bool> offersExtension(VkPhysicalDevice device, const char* name)
{
    uint32_t count = 0;
    SR_VK_CHECK(vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr));
    std::vector<VkExtensionProperties> all(count);
    SR_VK_CHECK(vkEnumerateDeviceExtensionProperties(device, nullptr, &count, all.data()));
    return std::any_of(all.begin(), all.end(), [&](const VkExtensionProperties& e) {
        return std::strcmp(e.extensionName, name) == 0;
    });
}

}  // namespace

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

Error vkError(VkResult result, std::string_view what, const char* file, int line)
{
    return makeError(ExitCode::Runtime, "vulkan: {} failed: {} ({}:{})", what, vkResultName(result),
                     baseName(file), line);
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

Status createSingleSet(VkDevice device, const VkDescriptorPoolSize* sizes, uint32_t sizeCount,
                       VkDescriptorSetLayout layout, VkDescriptorPool& pool, VkDescriptorSet& set)
{
    VkDescriptorPoolCreateInfo poolInfo{};
    poolInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    poolInfo.maxSets = 1;
    poolInfo.poolSizeCount = sizeCount;
    poolInfo.pPoolSizes = sizes;
    SR_VK_CHECK(vkCreateDescriptorPool(device, &poolInfo, nullptr, &pool));
    VkDescriptorSetAllocateInfo alloc{};
    alloc.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    alloc.descriptorPool = pool;
    alloc.descriptorSetCount = 1;
    alloc.pSetLayouts = &layout;
    SR_VK_CHECK(vkAllocateDescriptorSets(device, &alloc, &set));
    return okStatus();
}

Status validationStatus(ValidationLog& log)
{
    std::lock_guard<std::mutex> lock(log.mutex);
    if (log.errors == 0) return okStatus();
    return makeError(ExitCode::Runtime, "vulkan validation reported {} error(s); first: {}", log.errors,
                     log.firstError);
}

size_t vulkanValidationErrorCount()
{
    return gValidationErrors.load();
}

VulkanContext::VulkanContext() : validationLog_(std::make_shared<ValidationLog>()) {}

VulkanContext::~VulkanContext()
{
    if (device_ != VK_NULL_HANDLE) {
        waitIdle();
        destroyBuffer(staging_);
        vkDestroyQueryPool(device_, queryPool_, nullptr);
        vkDestroyFence(device_, fence_, nullptr);
        vkDestroyCommandPool(device_, commandPool_, nullptr);        // frees commandBuffer_
        vkDestroyDescriptorPool(device_, descriptorPool_, nullptr);  // frees descriptorSet_
        vkDestroyPipelineLayout(device_, pipelineLayout_, nullptr);
        vkDestroyDescriptorSetLayout(device_, setLayout_, nullptr);
        vkDestroyDevice(device_, nullptr);
    }
    if (surface_ != VK_NULL_HANDLE) vkDestroySurfaceKHR(instance_, surface_, nullptr);
    if (messenger_ != VK_NULL_HANDLE) destroyMessenger_(instance_, messenger_, nullptr);
    // The messenger chained into the instance create info still reports leaks found here.
    if (instance_ != VK_NULL_HANDLE) vkDestroyInstance(instance_, nullptr);
}

Status VulkanContext::init(int index, QueueKind kind, const PresentTarget* present,
                           const ExternalSharing* sharing)
{
    SR_TRY(createInstance(present));
    if (present != nullptr) SR_VK_CHECK(present->createSurface(instance_, &surface_));
    SR_TRY(selectDevice(index, kind, sharing));
    SR_TRY(createDevice(kind, sharing));
    SR_TRY(createDescriptorObjects());
    SR_TRY(createCommandObjects());
    return validationStatus();
}

void VulkanContext::waitIdle()
{
    if (device_ == VK_NULL_HANDLE) return;
    // Every submission waits for its own work, so this only matters after a failed wait.
    VkResult result = vkDeviceWaitIdle(device_);
    if (result != VK_SUCCESS)
        std::fprintf(stderr, "vulkan: vkDeviceWaitIdle failed: %s\n", vkResultName(result).c_str());
}

Status VulkanContext::createInstance(const PresentTarget* present)
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
    if (present != nullptr)
        for (const std::string& e : present->instanceExtensions) extensions.push_back(e.c_str());

    VkApplicationInfo app{};
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "raster";
    app.apiVersion = VK_API_VERSION_1_2;
    // Chained into the create info, the messenger also covers vkCreateInstance and
    // vkDestroyInstance, which the messenger object created below cannot see.
    VkDebugUtilsMessengerCreateInfoEXT messengerInfo = messengerCreateInfo(validationLog_.get());
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

Status VulkanContext::selectDevice(int index, QueueKind kind, const ExternalSharing* sharing)
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
    size_t pick = index < 0 ? 0 : static_cast<size_t>(index);
    if (sharing != nullptr) {
        // The GPU of the API that imports: by index -1 wherever it is, else device `index` must be it.
        auto same = [&](const Candidate& c) { return c.uuid == sharing->deviceUuid; };
        if (index < 0) {
            auto found = std::find_if(suitable.begin(), suitable.end(), same);
            if (found == suitable.end()) {
                std::string names;
                for (size_t i = 0; i < suitable.size(); ++i)
                    names += fmt::format("{}{}", i > 0 ? ", " : "", suitable[i].properties.deviceName);
                return makeError(ExitCode::Usage,
                                 "vulkan: no Vulkan device is the GPU of UUID {} (devices: {})",
                                 uuidText(sharing->deviceUuid), names);
            }
            pick = static_cast<size_t>(found - suitable.begin());
        } else if (!same(suitable[pick])) {
            return makeError(ExitCode::Usage, "vulkan: device {} ({}) is not the GPU of UUID {}", index,
                             suitable[pick].properties.deviceName, uuidText(sharing->deviceUuid));
        }
    }
    const Candidate& chosen = suitable[pick];
    if (kind == QueueKind::Graphics) {
        if (chosen.graphicsFamily == UINT32_MAX)
            return makeError(ExitCode::Usage, "vulkan: {} has no graphics queue with timestamps",
                             chosen.properties.deviceName);
        if (!chosen.geometryShader)
            return makeError(ExitCode::Usage,
                             "vulkan: {} lacks the geometryShader feature, which the graphics backend needs "
                             "for gl_PrimitiveID in its fragment shader",
                             chosen.properties.deviceName);
    }
    if (surface_ != VK_NULL_HANDLE) {
        // The viewer's queue runs the copy into the swapchain image and presents it.
        VkBool32 supported = VK_FALSE;
        uint32_t family = kind == QueueKind::Graphics ? chosen.graphicsFamily : chosen.computeFamily;
        SR_VK_CHECK(vkGetPhysicalDeviceSurfaceSupportKHR(chosen.device, family, surface_, &supported));
        if (!supported)
            return makeError(ExitCode::Usage, "vulkan: {} cannot present to this window from its {} queue",
                             chosen.properties.deviceName,
                             kind == QueueKind::Graphics ? "graphics" : "compute");
    }
    physical_ = chosen.device;
    properties_ = chosen.properties;
    driver_ = chosen.driver;
    deviceUuid_ = chosen.uuid;
    queueFamily_ = kind == QueueKind::Graphics ? chosen.graphicsFamily : chosen.computeFamily;
    timestampValidBits_ =
        kind == QueueKind::Graphics ? chosen.graphicsTimestampBits : chosen.computeTimestampBits;
    vkGetPhysicalDeviceMemoryProperties(physical_, &memoryProperties_);
    maxStorageBytes_ =
        std::min<VkDeviceSize>(properties_.limits.maxStorageBufferRange, chosen.maxAllocationSize);
    return okStatus();
}

Status VulkanContext::createDevice(QueueKind kind, const ExternalSharing* sharing)
{
    float priority = 1.0f;
    VkDeviceQueueCreateInfo queueInfo{};
    queueInfo.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    queueInfo.queueFamilyIndex = queueFamily_;
    queueInfo.queueCount = 1;
    queueInfo.pQueuePriorities = &priority;

    // Exactly the features the shaders use: 64-bit integers for the edge functions and the
    // visibility key, 64-bit buffer atomics for the depth test, and for graphics the Geometry
    // capability that gl_PrimitiveID in a fragment shader declares and, where offered, points larger
    // than one pixel, lines wider than one pixel and rectangular line rasterization with its
    // extension (vulkan-graphics refuses what a device lacks when a scene needs it).
    const bool graphics = kind == QueueKind::Graphics;
    VkPhysicalDeviceShaderAtomicInt64Features atomics{};
    atomics.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_INT64_FEATURES;
    atomics.shaderBufferInt64Atomics = VK_TRUE;
    VkPhysicalDeviceFeatures2 features{};
    features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    features.pNext = &atomics;
    features.features.shaderInt64 = VK_TRUE;
    features.features.geometryShader = graphics ? VK_TRUE : VK_FALSE;
    VkPhysicalDeviceFeatures offered{};
    vkGetPhysicalDeviceFeatures(physical_, &offered);
    features.features.largePoints = graphics ? offered.largePoints : VK_FALSE;
    features.features.wideLines = graphics ? offered.wideLines : VK_FALSE;

    const char* lineExtension = nullptr;
    if (graphics) {
        Result<const char*> found = rectangularLineExtension(physical_);
        if (!found.ok()) return found.error();
        lineExtension = *found;
    }
    VkPhysicalDeviceLineRasterizationFeaturesEXT lineFeatures{};
    lineFeatures.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_LINE_RASTERIZATION_FEATURES_EXT;
    lineFeatures.rectangularLines = VK_TRUE;
    if (lineExtension != nullptr) atomics.pNext = &lineFeatures;
    rectangularLines_ = lineExtension != nullptr;

    VkDeviceCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    info.pNext = &features;
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &queueInfo;
    std::vector<const char*> extensions;
    if (lineExtension != nullptr) extensions.push_back(lineExtension);
    if (surface_ != VK_NULL_HANDLE) extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    if (sharing != nullptr) {
        // Each where offered: lavapipe, for one, exports memory but not semaphores.
        Result<bool> memory = offersExtension(physical_, VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME);
        if (!memory.ok()) return memory.error();
        Result<bool> semaphore = offersExtension(physical_, VK_KHR_EXTERNAL_SEMAPHORE_FD_EXTENSION_NAME);
        if (!semaphore.ok()) return semaphore.error();
        externalMemoryFd_ = *memory;
        externalSemaphoreFd_ = *semaphore;
        if (externalMemoryFd_) extensions.push_back(VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME);
        if (externalSemaphoreFd_) extensions.push_back(VK_KHR_EXTERNAL_SEMAPHORE_FD_EXTENSION_NAME);
    }
    info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();
    SR_VK_CHECK(vkCreateDevice(physical_, &info, nullptr, &device_));
    vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);
    return okStatus();
}

Status VulkanContext::createDescriptorObjects()
{
    // Every shader declares every binding (compute_glsl/buffers.glsl), so one layout serves all; the
    // CPU builds of the stages also read the VIEW_* texel views.
    const uint32_t count = BUF_COUNT + (texelViews() ? VIEW_COUNT : 0);
    VkDescriptorSetLayoutBinding bindings[BUF_COUNT + VIEW_COUNT];
    for (uint32_t i = 0; i < count; ++i) {
        bindings[i] = VkDescriptorSetLayoutBinding{};
        bindings[i].binding = i;
        bindings[i].descriptorType = i >= BUF_COUNT      ? VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER
                                     : uniformBinding(i) ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER
                                                         : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        bindings[i].descriptorCount = 1;
        bindings[i].stageFlags = kBindingStages;
    }
    VkDescriptorSetLayoutCreateInfo setInfo{};
    setInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    setInfo.bindingCount = count;
    setInfo.pBindings = bindings;
    SR_VK_CHECK(vkCreateDescriptorSetLayout(device_, &setInfo, nullptr, &setLayout_));

    VkPipelineLayoutCreateInfo layoutInfo{};
    layoutInfo.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    layoutInfo.setLayoutCount = 1;
    layoutInfo.pSetLayouts = &setLayout_;
    SR_VK_CHECK(vkCreatePipelineLayout(device_, &layoutInfo, nullptr, &pipelineLayout_));

    VkDescriptorPoolSize poolSizes[3] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, kUniformBindings},
                                         {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, BUF_COUNT - kUniformBindings},
                                         {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, VIEW_COUNT}};
    return createSingleSet(device_, poolSizes, texelViews() ? 3 : 2, setLayout_, descriptorPool_,
                           descriptorSet_);
}

Status VulkanContext::createCommandObjects()
{
    VkCommandPoolCreateInfo poolInfo{};
    poolInfo.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    // One command buffer is re-recorded for every submission; beginning it again resets it.
    poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    poolInfo.queueFamilyIndex = queueFamily_;
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

DeviceInfo VulkanContext::deviceInfo(const std::string& backend) const
{
    DeviceInfo info;
    info.backend = backend;
    info.name = properties_.deviceName;
    info.driver = driver_;
    info.isCpu = properties_.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    return info;
}

Status VulkanContext::injectValidationError(const char* message)
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

// Index of the first memory type allowed by `typeBits` with all of `wanted`, or UINT32_MAX.
uint32_t VulkanContext::findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags wanted) const
{
    for (uint32_t i = 0; i < memoryProperties_.memoryTypeCount; ++i)
        if ((typeBits & (1u << i)) && (memoryProperties_.memoryTypes[i].propertyFlags & wanted) == wanted)
            return i;
    return UINT32_MAX;
}

// Allocates `requirements.size` bytes of the first of `preferredMemory` the resource may use, counts
// them, and reports the flags that were chosen. `what` and `bytes` describe the resource in the error.
Status VulkanContext::allocateMemory(const char* what, VkDeviceSize bytes,
                                     const VkMemoryRequirements& requirements,
                                     std::initializer_list<VkMemoryPropertyFlags> preferredMemory,
                                     VkDeviceMemory& memory, VkDeviceSize& allocated,
                                     VkMemoryPropertyFlags& flags, const void* allocateNext)
{
    uint32_t type = UINT32_MAX;
    for (VkMemoryPropertyFlags wanted : preferredMemory) {
        type = findMemoryType(requirements.memoryTypeBits, wanted);
        if (type != UINT32_MAX) {
            flags = wanted;
            break;
        }
    }
    if (type == UINT32_MAX)
        return makeError(ExitCode::Runtime, "vulkan: no suitable memory type for {} of {} bytes", what,
                         bytes);

    VkMemoryAllocateInfo allocInfo{};
    allocInfo.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    allocInfo.pNext = allocateNext;
    allocInfo.allocationSize = requirements.size;
    allocInfo.memoryTypeIndex = type;
    SR_VK_CHECK(vkAllocateMemory(device_, &allocInfo, nullptr, &memory));
    // Device memory is what was asked for as device-local; the host-visible staging buffer is host
    // memory, as CUDA's pageable host copies are, and is left out of the accounting.
    allocated = (flags & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT) != 0 ? requirements.size : 0;
    allocatedBytes_ += allocated;
    peakAllocatedBytes_ = std::max(peakAllocatedBytes_, allocatedBytes_);
    return okStatus();
}

void VulkanContext::freeMemory(VkDeviceMemory& memory, VkDeviceSize& allocated)
{
    vkFreeMemory(device_, memory, nullptr);  // also unmaps
    allocatedBytes_ -= allocated;
    memory = VK_NULL_HANDLE;
    allocated = 0;
}

Status VulkanContext::allocateBuffer(GpuBuffer& b, VkDeviceSize bytes, VkBufferUsageFlags usage,
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
    VkMemoryPropertyFlags flags = 0;
    SR_TRY(allocateMemory("a buffer", bytes, requirements, preferredMemory, b.memory, b.allocated, flags));
    SR_VK_CHECK(vkBindBufferMemory(device_, b.buffer, b.memory, 0));
    if (flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)
        SR_VK_CHECK(vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped));
    b.capacity = bytes;
    return okStatus();
}

void VulkanContext::destroyBuffer(GpuBuffer& b)
{
    vkDestroyBuffer(device_, b.buffer, nullptr);
    freeMemory(b.memory, b.allocated);
    b = GpuBuffer{};
}

Status VulkanContext::allocateExportableBuffer(GpuBuffer& b, VkDeviceSize bytes, VkBufferUsageFlags usage,
                                               VkDeviceSize& memoryBytes, bool& dedicated)
{
    constexpr auto kHandle = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
    if (!externalMemoryFd_)
        return makeError(ExitCode::Runtime,
                         "vulkan: {} does not offer {} (or the context was not made for sharing)",
                         properties_.deviceName, VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME);
    VkPhysicalDeviceExternalBufferInfo query{};
    query.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_BUFFER_INFO;
    query.usage = usage;
    query.handleType = kHandle;
    VkExternalBufferProperties external{};
    external.sType = VK_STRUCTURE_TYPE_EXTERNAL_BUFFER_PROPERTIES;
    vkGetPhysicalDeviceExternalBufferProperties(physical_, &query, &external);
    const VkExternalMemoryProperties& memory = external.externalMemoryProperties;
    if ((memory.externalMemoryFeatures & VK_EXTERNAL_MEMORY_FEATURE_EXPORTABLE_BIT) == 0 ||
        (memory.compatibleHandleTypes & kHandle) == 0)
        return makeError(ExitCode::Runtime, "vulkan: {} cannot export buffer memory as an OPAQUE_FD",
                         properties_.deviceName);

    VkExternalMemoryBufferCreateInfo externalInfo{};
    externalInfo.sType = VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO;
    externalInfo.handleTypes = kHandle;
    VkBufferCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    info.pNext = &externalInfo;
    info.size = bytes;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    SR_VK_CHECK(vkCreateBuffer(device_, &info, nullptr, &b.buffer));

    VkMemoryDedicatedRequirements dedicatedNeeds{};
    dedicatedNeeds.sType = VK_STRUCTURE_TYPE_MEMORY_DEDICATED_REQUIREMENTS;
    VkMemoryRequirements2 requirements{};
    requirements.sType = VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2;
    requirements.pNext = &dedicatedNeeds;
    VkBufferMemoryRequirementsInfo2 requirementsInfo{};
    requirementsInfo.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_REQUIREMENTS_INFO_2;
    requirementsInfo.buffer = b.buffer;
    vkGetBufferMemoryRequirements2(device_, &requirementsInfo, &requirements);
    dedicated = (memory.externalMemoryFeatures & VK_EXTERNAL_MEMORY_FEATURE_DEDICATED_ONLY_BIT) != 0 ||
                dedicatedNeeds.requiresDedicatedAllocation || dedicatedNeeds.prefersDedicatedAllocation;

    VkMemoryDedicatedAllocateInfo dedicatedInfo{};
    dedicatedInfo.sType = VK_STRUCTURE_TYPE_MEMORY_DEDICATED_ALLOCATE_INFO;
    dedicatedInfo.buffer = b.buffer;
    VkExportMemoryAllocateInfo exportInfo{};
    exportInfo.sType = VK_STRUCTURE_TYPE_EXPORT_MEMORY_ALLOCATE_INFO;
    exportInfo.pNext = dedicated ? &dedicatedInfo : nullptr;
    exportInfo.handleTypes = kHandle;
    VkMemoryPropertyFlags flags = 0;
    SR_TRY(allocateMemory("an exportable buffer", bytes, requirements.memoryRequirements,
                          {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT}, b.memory, b.allocated, flags, &exportInfo));
    SR_VK_CHECK(vkBindBufferMemory(device_, b.buffer, b.memory, 0));
    b.capacity = bytes;
    memoryBytes = requirements.memoryRequirements.size;
    return okStatus();
}

Result<int> VulkanContext::exportMemoryFd(const GpuBuffer& b)
{
    auto getFd = reinterpret_cast<PFN_vkGetMemoryFdKHR>(vkGetDeviceProcAddr(device_, "vkGetMemoryFdKHR"));
    if (!externalMemoryFd_ || getFd == nullptr)
        return makeError(ExitCode::Runtime, "vulkan: vkGetMemoryFdKHR is not available on {}",
                         properties_.deviceName);
    VkMemoryGetFdInfoKHR info{};
    info.sType = VK_STRUCTURE_TYPE_MEMORY_GET_FD_INFO_KHR;
    info.memory = b.memory;
    info.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
    int fd = -1;
    SR_VK_CHECK(getFd(device_, &info, &fd));
    return fd;
}

Status VulkanContext::createExportableSemaphore(VkSemaphore& semaphore)
{
    constexpr auto kHandle = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
    if (!externalSemaphoreFd_)
        return makeError(ExitCode::Runtime,
                         "vulkan: {} does not offer {} (or the context was not made for sharing)",
                         properties_.deviceName, VK_KHR_EXTERNAL_SEMAPHORE_FD_EXTENSION_NAME);
    VkPhysicalDeviceExternalSemaphoreInfo query{};
    query.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_SEMAPHORE_INFO;
    query.handleType = kHandle;
    VkExternalSemaphoreProperties external{};
    external.sType = VK_STRUCTURE_TYPE_EXTERNAL_SEMAPHORE_PROPERTIES;
    vkGetPhysicalDeviceExternalSemaphoreProperties(physical_, &query, &external);
    if ((external.externalSemaphoreFeatures & VK_EXTERNAL_SEMAPHORE_FEATURE_EXPORTABLE_BIT) == 0 ||
        (external.compatibleHandleTypes & kHandle) == 0)
        return makeError(ExitCode::Runtime, "vulkan: {} cannot export a semaphore as an OPAQUE_FD",
                         properties_.deviceName);
    VkExportSemaphoreCreateInfo exportInfo{};
    exportInfo.sType = VK_STRUCTURE_TYPE_EXPORT_SEMAPHORE_CREATE_INFO;
    exportInfo.handleTypes = kHandle;
    VkSemaphoreCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
    info.pNext = &exportInfo;
    SR_VK_CHECK(vkCreateSemaphore(device_, &info, nullptr, &semaphore));
    return okStatus();
}

Result<int> VulkanContext::exportSemaphoreFd(VkSemaphore semaphore)
{
    auto getFd =
        reinterpret_cast<PFN_vkGetSemaphoreFdKHR>(vkGetDeviceProcAddr(device_, "vkGetSemaphoreFdKHR"));
    if (!externalSemaphoreFd_ || getFd == nullptr)
        return makeError(ExitCode::Runtime, "vulkan: vkGetSemaphoreFdKHR is not available on {}",
                         properties_.deviceName);
    VkSemaphoreGetFdInfoKHR info{};
    info.sType = VK_STRUCTURE_TYPE_SEMAPHORE_GET_FD_INFO_KHR;
    info.semaphore = semaphore;
    info.handleType = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
    int fd = -1;
    SR_VK_CHECK(getFd(device_, &info, &fd));
    return fd;
}

Status VulkanContext::allocateImage(GpuImage& image, VkFormat format, VkImageAspectFlags aspect,
                                    uint32_t width, uint32_t height, VkImageUsageFlags usage)
{
    return allocateImage(image, format, aspect, width, height, 1, usage);
}

Status VulkanContext::allocateImage(GpuImage& image, VkFormat format, VkImageAspectFlags aspect,
                                    uint32_t width, uint32_t height, uint32_t mipLevels,
                                    VkImageUsageFlags usage)
{
    VkImageCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {width, height, 1};
    info.mipLevels = mipLevels;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    SR_VK_CHECK(vkCreateImage(device_, &info, nullptr, &image.image));

    VkMemoryRequirements requirements{};
    vkGetImageMemoryRequirements(device_, image.image, &requirements);
    VkMemoryPropertyFlags flags = 0;
    SR_TRY(allocateMemory("an image", requirements.size, requirements, {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT},
                          image.memory, image.allocated, flags));
    SR_VK_CHECK(vkBindImageMemory(device_, image.image, image.memory, 0));

    VkImageViewCreateInfo viewInfo{};
    viewInfo.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    viewInfo.image = image.image;
    viewInfo.viewType = VK_IMAGE_VIEW_TYPE_2D;
    viewInfo.format = format;
    viewInfo.subresourceRange = {aspect, 0, mipLevels, 0, 1};
    SR_VK_CHECK(vkCreateImageView(device_, &viewInfo, nullptr, &image.view));
    return okStatus();
}

void VulkanContext::destroyImage(GpuImage& image)
{
    vkDestroyImageView(device_, image.view, nullptr);
    vkDestroyImage(device_, image.image, nullptr);
    freeMemory(image.memory, image.allocated);
    image = GpuImage{};
}

Status VulkanContext::ensureStaging(VkDeviceSize bytes)
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

Status VulkanContext::upload(VkBuffer dst, const void* data, VkDeviceSize bytes,
                             VkPipelineStageFlags readerStages, VkAccessFlags readerAccess)
{
    SR_TRY(ensureStaging(bytes));
    std::memcpy(staging_.mapped, data, bytes);  // coherent: the submission makes it visible

    SR_TRY(beginCommands());
    VkBufferCopy region{0, 0, bytes};
    vkCmdCopyBuffer(commandBuffer_, staging_.buffer, dst, 1, &region);
    // Barriers order against later submissions too: the readers of every later one see the data.
    memoryBarrier(commandBuffer_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, readerStages,
                  readerAccess);
    return submitAndWait();
}

Status VulkanContext::download(VkBuffer src, void* data, VkDeviceSize bytes, VkDeviceSize offset)
{
    SR_TRY(ensureStaging(bytes));
    SR_TRY(beginCommands());
    VkBufferCopy region{offset, 0, bytes};
    vkCmdCopyBuffer(commandBuffer_, src, staging_.buffer, 1, &region);
    memoryBarrier(commandBuffer_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    SR_TRY(submitAndWait());
    std::memcpy(data, staging_.mapped, bytes);
    return okStatus();
}

void VulkanContext::writeDescriptorSet(const VkBuffer (&buffers)[BUF_COUNT], const VkBufferView* views)
{
    VkDescriptorBufferInfo infos[BUF_COUNT];
    VkWriteDescriptorSet writes[BUF_COUNT + VIEW_COUNT];
    const uint32_t count = BUF_COUNT + (views != nullptr ? VIEW_COUNT : 0);
    for (uint32_t i = 0; i < count; ++i) {
        writes[i] = VkWriteDescriptorSet{};
        writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        writes[i].dstSet = descriptorSet_;
        writes[i].dstBinding = i;
        writes[i].descriptorCount = 1;
        if (i >= BUF_COUNT) {
            writes[i].descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
            writes[i].pTexelBufferView = &views[i - BUF_COUNT];
            continue;
        }
        infos[i] = VkDescriptorBufferInfo{buffers[i], 0, VK_WHOLE_SIZE};
        writes[i].descriptorType =
            uniformBinding(i) ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[i].pBufferInfo = &infos[i];
    }
    vkUpdateDescriptorSets(device_, count, writes, 0, nullptr);
}

Result<VkShaderModule> VulkanContext::createShaderModule(const uint32_t* code, size_t bytes)
{
    VkShaderModuleCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    info.codeSize = bytes;
    info.pCode = code;
    VkShaderModule module = VK_NULL_HANDLE;
    SR_VK_CHECK(vkCreateShaderModule(device_, &info, nullptr, &module));
    return module;
}

Status VulkanContext::beginCommands()
{
    VkCommandBufferBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    SR_VK_CHECK(vkBeginCommandBuffer(commandBuffer_, &begin));
    return okStatus();
}

Status VulkanContext::submitAndWait(VkSemaphore wait, VkPipelineStageFlags waitStages)
{
    SR_VK_CHECK(vkEndCommandBuffer(commandBuffer_));
    // Reset here rather than after the wait, so that a failed wait cannot leave it signalled.
    SR_VK_CHECK(vkResetFences(device_, 1, &fence_));
    VkSubmitInfo submit{};
    submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &commandBuffer_;
    if (wait != VK_NULL_HANDLE) {
        submit.waitSemaphoreCount = 1;
        submit.pWaitSemaphores = &wait;
        submit.pWaitDstStageMask = &waitStages;
    }
    SR_VK_CHECK(vkQueueSubmit(queue_, 1, &submit, fence_));
    SR_VK_CHECK(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX));
    return okStatus();
}

Status VulkanContext::ensureQueryPool(uint32_t queries)
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

Status VulkanContext::readTimestampPairs(uint32_t pairs, std::vector<double>& ms)
{
    const uint32_t queries = 2 * pairs;
    std::vector<uint64_t> ticks(queries);
    SR_VK_CHECK(vkGetQueryPoolResults(device_, queryPool_, 0, queries, ticks.size() * sizeof(uint64_t),
                                      ticks.data(), sizeof(uint64_t),
                                      VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    const uint64_t mask = timestampValidBits_ >= 64 ? ~uint64_t(0) : (uint64_t(1) << timestampValidBits_) - 1;
    const double msPerTick = double(properties_.limits.timestampPeriod) * 1e-6;
    ms.clear();
    ms.reserve(pairs);
    for (uint32_t i = 0; i < pairs; ++i) {
        // Subtracting modulo the counter width stays right when the counter wrapped in between.
        const uint64_t ticksTaken = (ticks[2 * i + 1] - ticks[2 * i]) & mask;
        ms.push_back(double(ticksTaken) * msPerTick);
    }
    return okStatus();
}

}  // namespace sr
