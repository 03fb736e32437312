// graphics_render.h - the vulkan-graphics reference's one render (GraphicsRender) and what its files
// share: the attachment formats, the specialization constant ids, the checks. Private to host/vulkan/:
// vulkan_graphics.cpp (a render from start to end), graphics_checks.cpp (what the device and the scene
// must offer), graphics_targets.cpp (uploads, textures and attachments), graphics_pipelines.cpp (render
// pass pipelines) and graphics_readback.cpp (the attachments back to the host).
#ifndef RASTER_GRAPHICS_RENDER_H
#define RASTER_GRAPHICS_RENDER_H

#include <vulkan/vulkan.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

#include "render/aov.h"
#include "render/materials.h"
#include "vulkan/vulkan_context.h"
#include "vulkan/vulkan_graphics.h"

namespace sr::graphics {

constexpr VkFormat kWordFormat = VK_FORMAT_R32_UINT;  // colour and id attachments without anti-aliasing
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
// With anti-aliasing: 32-bit float colour keeps the shading's linear value unrounded until the host
// averages it, as the compute pipeline averages it; ids are exact floats below 2^24, and the id
// attachment's clear value decodes to EMPTY_ID.
constexpr VkFormat kLinearColorFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kFloatIdFormat = VK_FORMAT_R32_SFLOAT;
constexpr uint64_t kMaxFloatIds = uint64_t(1) << 24;
constexpr float kEmptyFloatId = -1.0f;

// Invocations per side of one reference_samples.comp group (its local_size_x and local_size_y).
constexpr uint32_t kReadGroupSide = 8;

// Texture formats: the hardware decodes sRGB texels to linear before filtering, as the compute path's
// decode table does.
constexpr VkFormat kSrgbTextureFormat = VK_FORMAT_R8G8B8A8_SRGB;
constexpr VkFormat kLinearTextureFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormatFeatureFlags kTextureFeatures = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT |
                                                  VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT |
                                                  VK_FORMAT_FEATURE_TRANSFER_DST_BIT;

// Specialization constant ids: the visibility shader's background word, the vertex shader's
// texcoords switch, the fragment shader's texture array size, the anti-aliased visibility shader's
// linear background (three ids from this one) and the point and line fragment shaders' visibility
// switch.
constexpr uint32_t kBackgroundConstant = 0;
constexpr uint32_t kHasTexcoordsConstant = 1;
constexpr uint32_t kTextureSlotsConstant = 2;
constexpr uint32_t kBackgroundRgbConstant = 3;
constexpr uint32_t kUnlitVisibilityConstant = 6;

// Attachment indices of the render pass and the framebuffer.
constexpr uint32_t kColorAttachment = 0;
constexpr uint32_t kIdAttachment = 1;
constexpr uint32_t kDepthAttachment = 2;
constexpr uint32_t kAttachmentCount = 3;

// Who reads the scene buffers after their upload: the index fetch and both shader stages.
constexpr VkPipelineStageFlags kSceneReaderStages = VK_PIPELINE_STAGE_VERTEX_INPUT_BIT |
                                                    VK_PIPELINE_STAGE_VERTEX_SHADER_BIT |
                                                    VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT;
constexpr VkAccessFlags kSceneReaderAccess = VK_ACCESS_INDEX_READ_BIT | VK_ACCESS_SHADER_READ_BIT;

// Where a frame touches the attachments: clears and colour writes, depth tests and writes.
constexpr VkPipelineStageFlags kAttachmentStages = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
                                                   VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                                                   VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
constexpr VkAccessFlags kAttachmentWrites =
    VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;

// A sample count as the flag bit Vulkan takes: VK_SAMPLE_COUNT_n_BIT has the value n.
inline VkSampleCountFlagBits sampleCountBit(uint32_t samples)
{
    return static_cast<VkSampleCountFlagBits>(samples);
}

// An id read back from a float id attachment.
inline uint32_t decodeFloatId(float value)
{
    return value < 0.0f ? EMPTY_ID : static_cast<uint32_t>(value);
}

// Texels a full level chain of `levels` levels from width x height holds.
inline uint64_t chainTexels(uint32_t width, uint32_t height, uint32_t levels)
{
    uint64_t texels = 0;
    for (uint32_t k = 0; k < levels; ++k)
        texels += uint64_t(std::max(width >> k, 1u)) * std::max(height >> k, 1u);
    return texels;
}

// The checks of every backend, plus those this backend adds: the shaders read the material buffers
// and fetch texcoords per vertex without bounds checks, and each texture becomes an image.
Status checkInputs(const Scene& scene, const RenderSettings& settings);

// Optimal-tiling features of the attachments that are copied to the host.
constexpr VkFormatFeatureFlags kCopyableColor =
    VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT;
constexpr VkFormatFeatureFlags kCopyableDepth =
    VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT;

// A format, the optimal-tiling features an attachment of it needs, and how an error names that use.
struct FormatNeed {
    VkFormat format;
    VkFormatFeatureFlags features;
    const char* name;
};

// A one-line Usage error for the first need the context's device does not meet.
Status checkFormats(const VulkanContext& ctx, std::initializer_list<FormatNeed> needs);

// The objects of one render on top of a context; the destructor releases them.
class GraphicsRender {
public:
    explicit GraphicsRender(VulkanContext& context) : ctx_(context) {}
    GraphicsRender(const GraphicsRender&) = delete;
    GraphicsRender& operator=(const GraphicsRender&) = delete;
    ~GraphicsRender();

    // Uploads the scene and `params` and creates the attachments and the pipeline, anti-aliased when
    // params asks for more than one sample per pixel or an SSAA factor above 1. `visibilityOnly` asks
    // for the depth + id pass with the cheapest fragment shader; it is honoured when the pipeline can
    // cull (no triangle is double-sided, or nothing is culled), else the full pass runs.
    Status init(const Scene& scene, const RasterParams& params, bool visibilityOnly);
    // Draws one frame and returns the GPU time of its render pass.
    Status drawFrame(double& ms);
    // Reads the attachments of the last frame into out.color and out.aov's id and depth (resolved to
    // the output resolution), and with `allSamples` every sample into out.samples.
    Status readBack(RenderOutput& out, bool allSamples);
    // Device memory this render allocated outside the context's accounting (multisampled attachments).
    size_t ownDeviceBytes() const { return size_t(targetBytes_); }
    // Ambient occlusion (params.aoMode != AO_OFF): draws a frame for its G-buffer, the ids and depths of
    // every sample the graphics pipeline rasterized; runs the AO stages' shared code on it on the host
    // (host/ao/ao_host.h; --ao reference: the rays of host/ao/ao_image.h) and uploads the result to
    // BUF_AO, which the fragment shader's shading reads from then on. Returns the AO per raster pixel.
    Result<std::vector<float>> prepareAo(const Scene& scene, const RenderSettings& settings);

private:
    // Every sample of an anti-aliased frame: per raster pixel the mean linear colour of its samples,
    // per sample the id and depth in planes of one sample per raster pixel, sample 0 first (as
    // SampleAovs); `planes` of them (1: sample 0 only).
    struct SampleFrame {
        std::vector<glm::vec4> pixelColor;
        std::vector<uint32_t> id;
        std::vector<float> depth;
        uint32_t planes = 0;
    };

    Status checkDevice(const Scene& scene) const;
    Status checkAntialiasing(const Scene& scene) const;
    Status checkPoints() const;
    Status checkLines() const;
    bool offersSamples(uint32_t samples) const;
    Status uploadSceneBuffer(uint32_t binding, const void* data, VkDeviceSize bytes,
                             VkBufferUsageFlags extraUsage);
    Status uploadScene(const Scene& scene);
    Status uploadTexture(const SceneTexture& texture, GpuImage& image);
    Status createTextures(const Scene& scene);
    Status createTargets();
    Status allocateMultisampled(GpuImage& image, VkFormat format, VkImageAspectFlags aspect,
                                VkImageUsageFlags usage);
    Status createRenderPass();
    Status createFramebuffer();
    Status createPipeline();
    Status createUnlitPipeline(const uint32_t* vertexCode, size_t vertexBytes, const uint32_t* fragmentCode,
                               size_t fragmentBytes, VkPrimitiveTopology topology, VkPipeline& pipeline);
    Status buildPipeline(VkShaderModule vertex, const VkSpecializationInfo* vertexConstants,
                         VkShaderModule fragment, const VkSpecializationInfo* fragmentConstants,
                         VkPrimitiveTopology topology, VkCullModeFlags cullMode, VkPipeline& pipeline);
    Status createSampleReadback();
    Status readWords(RenderOutput& out, bool allSamples);
    Status readSingleSamples(SampleFrame& frame);
    Status copyAttachments(const VkDeviceSize offsets[kAttachmentCount]);
    Status readSamples(SampleFrame& frame, bool allSamples);
    void resolve(SampleFrame& frame, RenderOutput& out, bool allSamples) const;

    VulkanContext& ctx_;
    RasterParams params_{};
    uint32_t backgroundWord_ = 0;  // the colour attachment's clear value without anti-aliasing
    // With anti-aliasing: clamped to [0, 1] as reference_aa.frag clamps the shading, so that every
    // sample enters the mean as the image shows it.
    glm::vec3 linearBackground_{0.0f};
    uint32_t samples_ = 1;      // rasterization samples per pixel (params.sampleCount)
    bool antialiased_ = false;  // float attachments and the host resolve: MSAA, SSAA or both
    uint32_t indexCount_ = 0;
    uint32_t lineCount_ = 0;
    uint32_t pointCount_ = 0;
    bool visibilityOnly_ = false;
    VkBool32 hasTexcoords_ = VK_FALSE;  // BUF_TEXCOORDS holds the scene's texcoords
    GpuBuffer buffers_[BUF_COUNT];      // the parameters and the scene inputs; the other bindings stay empty
    GpuBuffer placeholder_;             // bound to every binding without a buffer of its own
    // One image and sampler per scene texture, or one white placeholder texel when there is none: the
    // fragment shader's texture array is never empty.
    std::vector<GpuImage> textures_;
    std::vector<VkSampler> samplers_;
    uint32_t textureSlots_ = 0;  // entries of the texture array binding
    VkDescriptorSetLayout textureSetLayout_ = VK_NULL_HANDLE;
    VkDescriptorPool texturePool_ = VK_NULL_HANDLE;
    VkDescriptorSet textureSet_ = VK_NULL_HANDLE;       // freed with texturePool_
    VkPipelineLayout pipelineLayout_ = VK_NULL_HANDLE;  // the context's set 0, then the texture set
    GpuImage color_, id_, depth_;
    VkDeviceSize targetBytes_ = 0;  // memory of the multisampled attachments
    VkRenderPass renderPass_ = VK_NULL_HANDLE;
    VkFramebuffer framebuffer_ = VK_NULL_HANDLE;
    VkPipeline pipeline_ = VK_NULL_HANDLE;       // triangles; none without triangles
    VkPipeline linePipeline_ = VK_NULL_HANDLE;   // segments; none without segments
    VkPipeline pointPipeline_ = VK_NULL_HANDLE;  // points; none without points
    // The readback of multisampled attachments (reference_samples.comp): its own set of the three
    // attachments and three output buffers, sized for bands of bandRows_ rows.
    VkDescriptorSetLayout readSetLayout_ = VK_NULL_HANDLE;
    VkDescriptorPool readPool_ = VK_NULL_HANDLE;
    VkDescriptorSet readSet_ = VK_NULL_HANDLE;  // freed with readPool_
    VkPipelineLayout readLayout_ = VK_NULL_HANDLE;
    VkPipeline readPipeline_ = VK_NULL_HANDLE;
    GpuBuffer readColors_, readIds_, readDepths_;
    uint32_t bandRows_ = 0;
};

}  // namespace sr::graphics

#endif  // RASTER_GRAPHICS_RENDER_H
