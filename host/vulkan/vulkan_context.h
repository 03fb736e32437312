// vulkan_context.h - the Vulkan plumbing shared by the two Vulkan backends: the compute ComputeDevice
// (host/vulkan/vulkan_device.cpp) and the `vulkan-graphics` reference renderer
// (host/vulkan/vulkan_graphics.cpp).
//
// A VulkanContext is one instance (with the validation layer and its messenger when
// SR_VULKAN_VALIDATION=1), one physical device picked from the project's device list, one logical
// device with one queue, the descriptor set of the BUF_* bindings with its pipeline layout, one
// re-recorded command buffer with a fence, a timestamp query pool, a host-visible staging buffer, and
// the memory accounting behind allocatedBytes(). Every submission waits on the fence: both backends
// run short chains of dependent work with nothing to overlap, and waiting keeps a failure attached to
// the call that caused it.
//
// Objects a backend creates through the context (buffers, images, pipelines) belong to the backend,
// which must destroy them, after waitIdle(), before the context is destroyed.
#ifndef RASTER_VULKAN_CONTEXT_H
#define RASTER_VULKAN_CONTEXT_H

#include <vulkan/vulkan.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "render/compute_device.h"
#include "raster_shared.h"
#include "base/result.h"

namespace sr {

std::string vkResultName(VkResult result);

// The one-line Runtime error of a failed Vulkan call `what`, located at file:line.
Error vkError(VkResult result, std::string_view what, const char* file, int line);

// Evaluates a Vulkan call once and returns an Error from the enclosing function (returning Status
// or Result<T>) unless the call gave VK_SUCCESS. Positive codes such as VK_INCOMPLETE fail as well:
// no call made by the backends can return one when it did what they expect.
#define SR_VK_CHECK(expr)                                                                                \
    do {                                                                                                 \
        VkResult sr_vk_result_ = (expr);                                                                 \
        if (sr_vk_result_ != VK_SUCCESS) return ::sr::vkError(sr_vk_result_, #expr, __FILE__, __LINE__); \
    } while (0)

// Smallest allocation and allocation granularity. 16 bytes hold one vec4, the largest element of
// any buffer, so a shader indexing element 0 of a placeholder buffer stays in bounds.
constexpr VkDeviceSize kMinBufferBytes = 16;

// The bindings of set 0 that are uniform buffers (BUF_PARAMS, and BUF_SRGB_TABLE, which as a uniform
// buffer keeps the storage buffers within lavapipe's maxPerStageDescriptorStorageBuffers of 32); the
// others below BUF_COUNT are storage buffers.
constexpr bool uniformBinding(uint32_t binding)
{
    return binding == BUF_PARAMS || binding == BUF_SRGB_TABLE;
}
constexpr uint32_t kUniformBindings = 2;
// The table of one uniform buffer is read as vec4[64] (std140): its buffer holds at least that.
constexpr VkDeviceSize kSrgbTableBytes = 256 * sizeof(float);

VkDeviceSize roundUp(VkDeviceSize value, VkDeviceSize multiple);

// A descriptor pool sized for exactly one set of `layout` (its bindings' counts in `sizes`) and that set.
Status createSingleSet(VkDevice device, const VkDescriptorPoolSize* sizes, uint32_t sizeCount,
                       VkDescriptorSetLayout layout, VkDescriptorPool& pool, VkDescriptorSet& set);

// A global memory barrier: everything the backends synchronize is a whole buffer or a whole image
// outside of layout transitions.
void memoryBarrier(VkCommandBuffer cmd, VkPipelineStageFlags srcStages, VkAccessFlags srcAccess,
                   VkPipelineStageFlags dstStages, VkAccessFlags dstAccess);

// A buffer with its own memory allocation.
struct GpuBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize capacity = 0;   // size the VkBuffer was created with; 0 until fully set up
    VkDeviceSize allocated = 0;  // bytes of `memory` counted in allocatedBytes() (0 for host memory)
    void* mapped = nullptr;      // persistent mapping of host-visible memory
};

// A 2D single-sample image with its own memory and one view of the whole image.
struct GpuImage {
    VkImage image = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize allocated = 0;  // bytes of `memory` counted in allocatedBytes() (0 for host memory)
};

// What a context's debug messenger has seen; the layer may call back from any thread. Shared with
// the caller so that problems reported while the device and instance are destroyed (leaks) can still
// be looked at after the context is gone.
struct ValidationLog {
    std::mutex mutex;
    size_t errors = 0;
    std::string firstError;
};

// OK, or a one-line Runtime error giving the number of validation errors and the first one.
Status validationStatus(ValidationLog& log);

// The queue a context runs its work on. Graphics also needs the geometryShader feature: a fragment
// shader reading gl_PrimitiveID declares the Geometry capability.
enum class QueueKind { Compute, Graphics };

// A window a context presents to (`raster view`): the instance extensions its surface needs and the
// function that creates the surface once the instance exists. A context given one creates the surface,
// picks a queue that can present to it, and enables VK_KHR_swapchain.
struct PresentTarget {
    std::vector<std::string> instanceExtensions;
    std::function<VkResult(VkInstance, VkSurfaceKHR*)> createSurface;
};

// A context whose memory and semaphores another API imports (the viewer's CUDA path,
// render/frame_share.h): it must be on that API's GPU, which both name by the same UUID
// (VkPhysicalDeviceIDProperties::deviceUUID, cudaDeviceProp::uuid). Its device enables
// VK_KHR_external_memory_fd and VK_KHR_external_semaphore_fd where offered (the non-fd halves are core in
// Vulkan 1.1); the export calls below fail in one line where they are not.
struct ExternalSharing {
    std::array<uint8_t, 16> deviceUuid{};
};

class VulkanContext {
public:
    VulkanContext();
    VulkanContext(const VulkanContext&) = delete;
    VulkanContext& operator=(const VulkanContext&) = delete;
    ~VulkanContext();

    // Creates everything on device `index` of the project's device list (GPUs first, CPU
    // implementations last; -1 picks the first), the same list for both kinds, so an index names
    // the same device for every backend. On failure the destructor releases whatever was created.
    // With `sharing`, only the device of that UUID is taken (index -1: wherever it is in the list; else
    // device `index` must be it), and the device enables what exporting needs.
    Status init(int index, QueueKind kind, const PresentTarget* present = nullptr,
                const ExternalSharing* sharing = nullptr);

    // Waits for all submitted work; a failure is printed, as there is no caller left to return it
    // to when this runs before destruction.
    void waitIdle();

    Status validationStatus() { return sr::validationStatus(*validationLog_); }
    std::shared_ptr<ValidationLog> validationLog() const { return validationLog_; }
    bool validationEnabled() const { return validation_; }
    // Sends `message` through the debug messenger as a validation error, exactly as the layer would.
    Status injectValidationError(const char* message);

    // backend, name, driver and isCpu of the selected device.
    DeviceInfo deviceInfo(const std::string& backend) const;
    VkDevice device() const { return device_; }
    VkQueue queue() const { return queue_; }
    // The window surface of a context made with a PresentTarget, else VK_NULL_HANDLE.
    VkSurfaceKHR surface() const { return surface_; }
    VkPhysicalDevice physicalDevice() const { return physical_; }
    uint32_t queueFamily() const { return queueFamily_; }
    // VkPhysicalDeviceIDProperties::deviceUUID of the selected device.
    const std::array<uint8_t, 16>& deviceUuid() const { return deviceUuid_; }
    const VkPhysicalDeviceProperties& properties() const { return properties_; }
    // Largest buffer a storage descriptor can cover whole.
    VkDeviceSize maxStorageBytes() const { return maxStorageBytes_; }
    // Whether pipelines may ask for VK_LINE_RASTERIZATION_MODE_RECTANGULAR_EXT (a
    // VkPipelineRasterizationLineStateCreateInfoEXT): a graphics context on a device that offers
    // VK_KHR_line_rasterization or VK_EXT_line_rasterization with the rectangularLines feature, which
    // are then enabled. The wideLines feature is enabled on graphics contexts wherever it is offered.
    bool rectangularLines() const { return rectangularLines_; }

    // Creates `b`, which must be empty, with memory of the first of `preferredMemory` the device
    // has; host-visible memory stays mapped. On failure `b` may hold part of what was created, and
    // destroyBuffer() releases it.
    Status allocateBuffer(GpuBuffer& b, VkDeviceSize bytes, VkBufferUsageFlags usage,
                          std::initializer_list<VkMemoryPropertyFlags> preferredMemory);
    void destroyBuffer(GpuBuffer& b);
    // A device-local buffer whose memory can be exported as an OPAQUE_FD (a context made with
    // ExternalSharing): `memoryBytes` is the allocation's size and `dedicated` whether it is a dedicated
    // allocation (where the device requires or prefers one), both of which the importer must be told.
    Status allocateExportableBuffer(GpuBuffer& b, VkDeviceSize bytes, VkBufferUsageFlags usage,
                                    VkDeviceSize& memoryBytes, bool& dedicated);
    // A new file descriptor of `b`'s memory (vkGetMemoryFdKHR), which the caller then owns.
    Result<int> exportMemoryFd(const GpuBuffer& b);
    // A binary semaphore that can be exported as an OPAQUE_FD, and a new descriptor of it
    // (vkGetSemaphoreFdKHR). The caller destroys the semaphore (vkDestroySemaphore) and owns the fd.
    Status createExportableSemaphore(VkSemaphore& semaphore);
    Result<int> exportSemaphoreFd(VkSemaphore semaphore);
    // Same for a device-local optimal-tiling image in layout UNDEFINED.
    Status allocateImage(GpuImage& image, VkFormat format, VkImageAspectFlags aspect, uint32_t width,
                         uint32_t height, VkImageUsageFlags usage);
    // The same with `mipLevels` levels; the view covers all of them.
    Status allocateImage(GpuImage& image, VkFormat format, VkImageAspectFlags aspect, uint32_t width,
                         uint32_t height, uint32_t mipLevels, VkImageUsageFlags usage);
    void destroyImage(GpuImage& image);
    // Device memory allocated through this context now, and the most it ever held at once.
    size_t allocatedBytes() const { return allocatedBytes_; }
    size_t peakAllocatedBytes() const { return peakAllocatedBytes_; }

    // The host-visible staging buffer, grown to at least `bytes`; its contents are lost on growth.
    Status ensureStaging(VkDeviceSize bytes);
    const GpuBuffer& staging() const { return staging_; }
    // Copies host memory into the first `bytes` of `dst` through the staging buffer, made visible to
    // `readerStages`/`readerAccess` of every later submission.
    Status upload(VkBuffer dst, const void* data, VkDeviceSize bytes, VkPipelineStageFlags readerStages,
                  VkAccessFlags readerAccess);
    // Copies the first `bytes` of `src` to host memory through the staging buffer.
    Status download(VkBuffer src, void* data, VkDeviceSize bytes, VkDeviceSize offset = 0);

    // Descriptor set 0 as compute_glsl/buffers.glsl declares it (binding BUF_PARAMS a uniform
    // buffer, the others storage buffers; on a CPU device, texelViews(), also the VIEW_* uniform texel
    // buffers after them), visible to the compute, vertex and fragment stages, and the pipeline layout
    // of every pipeline of both backends.
    VkPipelineLayout pipelineLayout() const { return pipelineLayout_; }
    VkDescriptorSet descriptorSet() const { return descriptorSet_; }
    // The layout of that set, for a backend that builds a pipeline layout with further sets after it.
    VkDescriptorSetLayout setLayout() const { return setLayout_; }
    // Whether the set has the VIEW_* bindings: on CPU devices, whose stages' CPU builds read through them.
    bool texelViews() const { return properties_.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU; }
    // Points binding i at the whole of buffers[i] and, given `views` (VIEW_COUNT of them, texelViews()
    // only), binding VIEW_* at views[VIEW_* - BUF_COUNT]. No submitted work may still use the set.
    void writeDescriptorSet(const VkBuffer (&buffers)[BUF_COUNT], const VkBufferView* views = nullptr);

    // A module to build one pipeline from, destroyed by the caller once the pipeline exists.
    Result<VkShaderModule> createShaderModule(const uint32_t* code, size_t bytes);

    // Recording and submission of the context's one command buffer.
    VkCommandBuffer commandBuffer() const { return commandBuffer_; }
    Status beginCommands();
    // Submits the command buffer and waits for its fence. With `wait`, the submission first waits on
    // that binary semaphore at `waitStages` (which must have a signal pending, e.g. from another API).
    Status submitAndWait(VkSemaphore wait = VK_NULL_HANDLE, VkPipelineStageFlags waitStages = 0);

    // A timestamp query pool of at least `queries` entries.
    Status ensureQueryPool(uint32_t queries);
    VkQueryPool queryPool() const { return queryPool_; }
    // After a submission wrote timestamps 0 .. 2 * pairs - 1: ms[i] = GPU milliseconds between
    // timestamps 2i and 2i + 1.
    Status readTimestampPairs(uint32_t pairs, std::vector<double>& ms);

private:
    Status createInstance(const PresentTarget* present);
    Status selectDevice(int index, QueueKind kind, const ExternalSharing* sharing);
    Status createDevice(QueueKind kind, const ExternalSharing* sharing);
    Status createDescriptorObjects();
    Status createCommandObjects();
    uint32_t findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags wanted) const;
    Status allocateMemory(const char* what, VkDeviceSize bytes, const VkMemoryRequirements& requirements,
                          std::initializer_list<VkMemoryPropertyFlags> preferredMemory,
                          VkDeviceMemory& memory, VkDeviceSize& allocated, VkMemoryPropertyFlags& flags,
                          const void* allocateNext = nullptr);
    void freeMemory(VkDeviceMemory& memory, VkDeviceSize& allocated);

    std::shared_ptr<ValidationLog> validationLog_;
    bool validation_ = false;

    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkSurfaceKHR surface_ = VK_NULL_HANDLE;
    PFN_vkDestroyDebugUtilsMessengerEXT destroyMessenger_ = nullptr;
    VkPhysicalDevice physical_ = VK_NULL_HANDLE;
    VkPhysicalDeviceProperties properties_{};
    std::string driver_;
    VkPhysicalDeviceMemoryProperties memoryProperties_{};
    VkDeviceSize maxStorageBytes_ = 0;
    uint32_t queueFamily_ = 0;
    uint32_t timestampValidBits_ = 0;
    bool rectangularLines_ = false;
    std::array<uint8_t, 16> deviceUuid_{};
    bool externalMemoryFd_ = false;     // VK_KHR_external_memory_fd enabled
    bool externalSemaphoreFd_ = false;  // VK_KHR_external_semaphore_fd enabled

    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
    VkPipelineLayout pipelineLayout_ = VK_NULL_HANDLE;
    VkDescriptorPool descriptorPool_ = VK_NULL_HANDLE;
    VkDescriptorSet descriptorSet_ = VK_NULL_HANDLE;
    VkCommandPool commandPool_ = VK_NULL_HANDLE;
    VkCommandBuffer commandBuffer_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    VkQueryPool queryPool_ = VK_NULL_HANDLE;
    uint32_t queryCapacity_ = 0;
    GpuBuffer staging_;
    size_t allocatedBytes_ = 0;
    size_t peakAllocatedBytes_ = 0;
};

}  // namespace sr

#endif  // RASTER_VULKAN_CONTEXT_H
