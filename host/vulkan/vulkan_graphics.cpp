// vulkan_graphics.cpp - see vulkan_graphics.h.
//
// Everything lives for one call: a VulkanContext on a graphics queue, the scene's input buffers
// (BUF_INDICES doubles as the index buffer), the scene's textures as sampled images with their mip
// chains and samplers (descriptor set 1), the three attachments, a classic render pass with one
// subpass, one framebuffer and one pipeline. Each frame is one submission holding the render pass
// between two timestamps; after the last frame the attachments are copied into the context's staging
// buffer and read on the host.
//
// Anti-aliasing (RenderSettings::msaa and ssaa) draws the raster grid of the params (the output
// resolution times the SSAA factor per side) with params.sampleCount rasterization samples at the
// standard sample locations and no sample shading, so the fragment shader runs once per pixel and
// triangle at the pixel centre and its outputs go to every covered sample that passes the depth test.
// The attachments are then floats (reference_aa.frag says why); multisampled ones cannot be copied to a
// buffer, so a compute pass (reference_samples.comp) reads every sample. The host averages the linear
// colours of each output pixel's samples and takes the ids and depths per sample.
//
// Line segments (Scene::lines) and points (Scene::points) are further draws in the same render pass,
// in id order (triangles, segments, points), each through a pipeline of its own (LINE_LIST with
// reference_line.vert and reference_line*.frag, POINT_LIST with reference_point.vert and
// reference_point*.frag) with the same attachments, depth test and descriptor sets: the depth test
// sees every primitive in one buffer, and a primitive at an earlier one's depth loses to it, as the
// lower id wins in the compute visibility key. A scene without triangles, segments or points skips
// that draw.
#include "vulkan/vulkan_graphics.h"

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

#include "ao/ao_host.h"
#include "ao/ao_image.h"
#include "ao/ao_reference.h"
#include "render/aov.h"
#include "render/materials.h"
#include "vulkan/vulkan_context.h"

namespace sr {
namespace {

// The generated headers define one `const uint32_t kSpv_<shader>[]` each, e.g. kSpv_reference_vert.
#include "reference_aa_frag.spv.h"
#include "reference_frag.spv.h"
#include "reference_line_aa_frag.spv.h"
#include "reference_line_frag.spv.h"
#include "reference_line_vert.spv.h"
#include "reference_point_aa_frag.spv.h"
#include "reference_point_frag.spv.h"
#include "reference_point_vert.spv.h"
#include "reference_samples_comp.spv.h"
#include "reference_visibility_aa_frag.spv.h"
#include "reference_visibility_frag.spv.h"
#include "reference_vert.spv.h"

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
VkSampleCountFlagBits sampleCountBit(uint32_t samples)
{
    return static_cast<VkSampleCountFlagBits>(samples);
}

// An id read back from a float id attachment.
uint32_t decodeFloatId(float value)
{
    return value < 0.0f ? EMPTY_ID : static_cast<uint32_t>(value);
}

// Texels a full level chain of `levels` levels from width x height holds.
uint64_t chainTexels(uint32_t width, uint32_t height, uint32_t levels)
{
    uint64_t texels = 0;
    for (uint32_t k = 0; k < levels; ++k)
        texels += uint64_t(std::max(width >> k, 1u)) * std::max(height >> k, 1u);
    return texels;
}

// The checks of every backend, plus those this backend adds: the shaders read the material buffers
// and fetch texcoords per vertex without bounds checks, and each texture becomes an image.
Status checkInputs(const Scene& scene, const RenderSettings& settings)
{
    SR_TRY(checkRenderInputs(scene, settings));
    // The hardware has its own rule, the one fixed8 implements.
    if (settings.rasterMethod != RASTER_FIXED8)
        return makeError(ExitCode::Usage,
                         "vulkan-graphics: --raster-method exists only in the compute pipeline (the device "
                         "rasterizes by its own rule)");
    // The hit count is a debug view of the compute pipeline's own counter buffer.
    if (settings.shadingMode == SHADING_HIT_COUNT)
        return makeError(ExitCode::Usage,
                         "vulkan-graphics: shading mode {} exists only in the compute pipeline",
                         settings.shadingMode);
    if (!scene.materials.empty() && scene.triMaterials.size() != scene.triangleCount())
        return makeError(ExitCode::Usage, "the scene has {} triangle materials for {} triangles",
                         scene.triMaterials.size(), scene.triangleCount());
    if (scene.lines.size() % 2 != 0)
        return makeError(ExitCode::Usage, "the scene has {} line indices, not two per segment",
                         scene.lines.size());
    if (!scene.materials.empty() && scene.lineMaterials.size() != scene.lineCount())
        return makeError(ExitCode::Usage, "the scene has {} line materials for {} segments",
                         scene.lineMaterials.size(), scene.lineCount());
    if (!scene.materials.empty() && scene.pointMaterials.size() != scene.pointCount())
        return makeError(ExitCode::Usage, "the scene has {} point materials for {} points",
                         scene.pointMaterials.size(), scene.pointCount());
    // The line and point vertex shaders fetch through their lists, skipping kDroppedVertex alone.
    for (size_t k = 0; k < scene.lines.size(); ++k)
        if (scene.lines[k] >= scene.vertexCount() && scene.lines[k] != kDroppedVertex)
            return makeError(ExitCode::Usage, "segment {} names vertex {} of {}", k / 2, scene.lines[k],
                             scene.vertexCount());
    for (size_t k = 0; k < scene.points.size(); ++k)
        if (scene.points[k] >= scene.vertexCount() && scene.points[k] != kDroppedVertex)
            return makeError(ExitCode::Usage, "point {} names vertex {} of {}", k, scene.points[k],
                             scene.vertexCount());
    // The line settings as RenderSettings defines them: widths are multiples of 1/8 pixel, and the bias
    // enters the depth arithmetic.
    if (scene.lineCount() > 0) {
        if (!(settings.lineWidth >= 1.0f && settings.lineWidth <= MAX_LINE_WIDTH) ||
            settings.lineWidth * 8.0f != std::floor(settings.lineWidth * 8.0f))
            return makeError(ExitCode::Usage, "line width {} is not a multiple of 1/8 between 1 and {}",
                             settings.lineWidth, MAX_LINE_WIDTH);
        if (!std::isfinite(settings.lineDepthBias))
            return makeError(ExitCode::Usage, "line depth bias {} is not a finite number",
                             settings.lineDepthBias);
    }
    const bool textured =
        std::any_of(scene.materials.begin(), scene.materials.end(), [&](const SceneMaterial& m) {
            return (m.baseColorTexture >= 0 && size_t(m.baseColorTexture) < scene.textures.size()) ||
                   (m.emissiveTexture >= 0 && size_t(m.emissiveTexture) < scene.textures.size());
        });
    if ((textured || !scene.texcoords.empty()) && scene.texcoords.size() != scene.vertexCount())
        return makeError(ExitCode::Usage, "the scene has {} texture coordinates for {} vertices",
                         scene.texcoords.size(), scene.vertexCount());
    for (const SceneTexture& t : scene.textures) {
        uint32_t fullChain = 1;  // 1 + floor(log2(max(width, height)))
        while ((std::max(t.width, t.height) >> fullChain) != 0) ++fullChain;
        if (t.width < 1 || t.height < 1 || t.width > MAX_TEXTURE_DIM || t.height > MAX_TEXTURE_DIM ||
            t.levels < 1 || t.levels > fullChain ||
            t.texels.size() != chainTexels(t.width, t.height, t.levels))
            return makeError(ExitCode::Usage, "texture '{}' is malformed ({}x{}, {} levels, {} texels)",
                             t.name, t.width, t.height, t.levels, t.texels.size());
    }
    return okStatus();
}

VkFilter vkFilter(uint32_t filter)
{
    return filter == FILTER_NEAREST ? VK_FILTER_NEAREST : VK_FILTER_LINEAR;
}

VkSamplerAddressMode vkAddressMode(uint32_t wrap)
{
    return wrap == WRAP_CLAMP_TO_EDGE     ? VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE
           : wrap == WRAP_MIRRORED_REPEAT ? VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT
                                          : VK_SAMPLER_ADDRESS_MODE_REPEAT;
}

// The VkSampler description of `sampler` for a texture of `levels` levels, with the --texture-filter
// override (TEXTURE_FILTER_*) applied as texture.h's textureSelect applies it.
VkSamplerCreateInfo samplerInfo(const TextureSampler& sampler, uint32_t levels, uint32_t filterOverride)
{
    uint32_t magFilter = sampler.magFilter, minFilter = sampler.minFilter, mipmapMode = sampler.mipmapMode;
    if (filterOverride == TEXTURE_FILTER_NEAREST) {
        magFilter = minFilter = FILTER_NEAREST;
        mipmapMode = MIPMAP_NONE;
    } else if (filterOverride == TEXTURE_FILTER_BILINEAR) {
        magFilter = minFilter = FILTER_LINEAR;
        mipmapMode = MIPMAP_NONE;
    } else if (filterOverride == TEXTURE_FILTER_TRILINEAR) {
        magFilter = minFilter = FILTER_LINEAR;
        mipmapMode = MIPMAP_LINEAR;
    }
    VkSamplerCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
    info.magFilter = vkFilter(magFilter);
    info.minFilter = vkFilter(minFilter);
    info.mipmapMode =
        mipmapMode == MIPMAP_LINEAR ? VK_SAMPLER_MIPMAP_MODE_LINEAR : VK_SAMPLER_MIPMAP_MODE_NEAREST;
    info.addressModeU = vkAddressMode(sampler.wrapS);
    info.addressModeV = vkAddressMode(sampler.wrapT);
    info.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    info.anisotropyEnable = VK_FALSE;
    info.compareEnable = VK_FALSE;
    info.minLod = 0.0f;
    // No mipmapping is level 0 only: maxLod 0.25 keeps lambda's sign, and so the choice between the
    // min and mag filters, while nearest level selection can only give level 0 (the spec's advice for
    // OpenGL's non-mipmapped min filters).
    info.maxLod = mipmapMode == MIPMAP_NONE ? 0.25f : float(levels);
    info.borderColor = VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK;
    info.unnormalizedCoordinates = VK_FALSE;
    return info;
}

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
Status checkFormats(const VulkanContext& ctx, std::initializer_list<FormatNeed> needs)
{
    for (const FormatNeed& need : needs) {
        VkFormatProperties properties{};
        vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice(), need.format, &properties);
        if ((properties.optimalTilingFeatures & need.features) != need.features)
            return makeError(ExitCode::Usage, "vulkan-graphics: {} does not support {}",
                             ctx.properties().deviceName, need.name);
    }
    return okStatus();
}

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

GraphicsRender::~GraphicsRender()
{
    VkDevice device = ctx_.device();
    if (device == VK_NULL_HANDLE) return;
    ctx_.waitIdle();
    vkDestroyPipeline(device, readPipeline_, nullptr);
    vkDestroyPipelineLayout(device, readLayout_, nullptr);
    vkDestroyDescriptorPool(device, readPool_, nullptr);
    vkDestroyDescriptorSetLayout(device, readSetLayout_, nullptr);
    for (GpuBuffer* b : {&readColors_, &readIds_, &readDepths_}) ctx_.destroyBuffer(*b);
    vkDestroyPipeline(device, pointPipeline_, nullptr);
    vkDestroyPipeline(device, linePipeline_, nullptr);
    vkDestroyPipeline(device, pipeline_, nullptr);
    vkDestroyFramebuffer(device, framebuffer_, nullptr);
    vkDestroyRenderPass(device, renderPass_, nullptr);
    vkDestroyPipelineLayout(device, pipelineLayout_, nullptr);
    vkDestroyDescriptorPool(device, texturePool_, nullptr);
    vkDestroyDescriptorSetLayout(device, textureSetLayout_, nullptr);
    for (VkSampler sampler : samplers_) vkDestroySampler(device, sampler, nullptr);
    for (GpuImage& image : textures_) ctx_.destroyImage(image);
    for (GpuImage* image : {&color_, &id_, &depth_}) ctx_.destroyImage(*image);
    for (GpuBuffer& b : buffers_) ctx_.destroyBuffer(b);
    ctx_.destroyBuffer(placeholder_);
}

Status GraphicsRender::init(const Scene& scene, const RasterParams& params, bool visibilityOnly)
{
    bool anyDoubleSided = std::any_of(scene.triFlags.begin(), scene.triFlags.end(),
                                      [](uint32_t f) { return (f & TRI_FLAG_DOUBLE_SIDED) != 0u; });
    // Alpha-masked triangles cover a pixel only where their texture says so, which only the full
    // fragment shader knows (the compute pipeline tests the flag only when there are materials).
    bool anyMasked =
        params.materialCount > 0 && std::any_of(scene.triFlags.begin(), scene.triFlags.end(),
                                                [](uint32_t f) { return (f & TRI_FLAG_ALPHA_MASK) != 0u; });
    visibilityOnly_ = visibilityOnly && (!anyDoubleSided || params.cullMode == CULL_NONE) && !anyMasked;
    params_ = params;
    backgroundWord_ = packRgba8(glm::vec3(params.background));
    linearBackground_ = glm::clamp(glm::vec3(params.background), glm::vec3(0.0f), glm::vec3(1.0f));
    samples_ = params.sampleCount;
    antialiased_ = params.sampleCount > 1 || params.ssaa > 1;
    indexCount_ = static_cast<uint32_t>(scene.indices.size());
    lineCount_ = static_cast<uint32_t>(scene.lineCount());
    pointCount_ = static_cast<uint32_t>(scene.pointCount());
    SR_TRY(checkDevice(scene));
    SR_TRY(uploadScene(scene));
    SR_TRY(createTextures(scene));
    SR_TRY(createTargets());
    SR_TRY(createRenderPass());
    SR_TRY(createFramebuffer());
    if (indexCount_ > 0) SR_TRY(createPipeline());
    if (lineCount_ > 0)
        SR_TRY(createUnlitPipeline(
            kSpv_reference_line_vert, sizeof kSpv_reference_line_vert,
            antialiased_ ? kSpv_reference_line_aa_frag : kSpv_reference_line_frag,
            antialiased_ ? sizeof kSpv_reference_line_aa_frag : sizeof kSpv_reference_line_frag,
            VK_PRIMITIVE_TOPOLOGY_LINE_LIST, linePipeline_));
    if (pointCount_ > 0)
        SR_TRY(createUnlitPipeline(
            kSpv_reference_point_vert, sizeof kSpv_reference_point_vert,
            antialiased_ ? kSpv_reference_point_aa_frag : kSpv_reference_point_frag,
            antialiased_ ? sizeof kSpv_reference_point_aa_frag : sizeof kSpv_reference_point_frag,
            VK_PRIMITIVE_TOPOLOGY_POINT_LIST, pointPipeline_));
    if (samples_ > 1) SR_TRY(createSampleReadback());
    SR_TRY(ctx_.ensureQueryPool(2));
    return ctx_.validationStatus();
}

// What the device must offer beyond what the context already checked; each miss is a one-line
// Usage error, as for a device that lacks a feature.
Status GraphicsRender::checkDevice(const Scene& scene) const
{
    const VkPhysicalDeviceLimits& limits = ctx_.properties().limits;
    const uint32_t maxWidth =
        std::min({limits.maxFramebufferWidth, limits.maxImageDimension2D, limits.maxViewportDimensions[0]});
    const uint32_t maxHeight =
        std::min({limits.maxFramebufferHeight, limits.maxImageDimension2D, limits.maxViewportDimensions[1]});
    if (params_.width > maxWidth || params_.height > maxHeight)
        return makeError(ExitCode::Usage,
                         "vulkan-graphics: {}x{} exceeds the device's framebuffer limit of {}x{}",
                         params_.width, params_.height, maxWidth, maxHeight);
    if (scene.vertexCount() - 1 > limits.maxDrawIndexedIndexValue)
        return makeError(ExitCode::Usage,
                         "vulkan-graphics: {} vertices exceed the device's index limit of {}",
                         scene.vertexCount(), uint64_t(limits.maxDrawIndexedIndexValue) + 1);
    if (scene.lineCount() > 0) SR_TRY(checkLines());
    if (scene.pointCount() > 0) SR_TRY(checkPoints());

    if (antialiased_)
        SR_TRY(checkAntialiasing(scene));
    else
        SR_TRY(checkFormats(
            ctx_, {{kWordFormat, kCopyableColor, "copyable VK_FORMAT_R32_UINT colour attachments"},
                   {kDepthFormat, kCopyableDepth, "copyable VK_FORMAT_D32_SFLOAT depth attachments"}}));

    // Textures: sampled, linearly filtered, uploaded images of both formats, and as many samplers and
    // sampled images in the fragment stage as there are textures (next to the set 0 buffers and the
    // two colour outputs).
    for (VkFormat format : {kSrgbTextureFormat, kLinearTextureFormat}) {
        VkFormatProperties properties{};
        vkGetPhysicalDeviceFormatProperties(ctx_.physicalDevice(), format, &properties);
        if ((properties.optimalTilingFeatures & kTextureFeatures) != kTextureFeatures)
            return makeError(ExitCode::Usage,
                             "vulkan-graphics: {} cannot sample and filter RGBA8 {} textures",
                             ctx_.properties().deviceName, format == kSrgbTextureFormat ? "sRGB" : "UNORM");
    }
    const uint64_t slots = std::max<uint64_t>(scene.textures.size(), 1);
    const uint64_t maxSlots =
        std::min({limits.maxPerStageDescriptorSamplers, limits.maxPerStageDescriptorSampledImages,
                  limits.maxDescriptorSetSamplers, limits.maxDescriptorSetSampledImages,
                  limits.maxSamplerAllocationCount, limits.maxPerStageResources - BUF_COUNT - 2});
    if (slots > maxSlots)
        return makeError(ExitCode::Usage, "vulkan-graphics: {} textures exceed the device's limit of {}",
                         scene.textures.size(), maxSlots);
    for (const SceneTexture& t : scene.textures)
        if (std::max(t.width, t.height) > limits.maxImageDimension2D)
            return makeError(ExitCode::Usage,
                             "vulkan-graphics: texture '{}' ({}x{}) exceeds the device's image limit of {}",
                             t.name, t.width, t.height, limits.maxImageDimension2D);
    return okStatus();
}

// What anti-aliasing adds: ids exact as floats, the float attachments at the requested sample count,
// and for the multisampled readback a queue that runs compute work.
Status GraphicsRender::checkAntialiasing(const Scene& scene) const
{
    const char* name = ctx_.properties().deviceName;
    if (scene.primitiveCount() > kMaxFloatIds)
        return makeError(
            ExitCode::Usage,
            "vulkan-graphics: anti-aliasing stores primitive ids as floats, exact for at most {} "
            "primitives; the scene has {}",
            kMaxFloatIds, scene.primitiveCount());
    if (samples_ == 1)
        return checkFormats(
            ctx_, {{kLinearColorFormat, kCopyableColor,
                    "copyable VK_FORMAT_R32G32B32A32_SFLOAT colour attachments"},
                   {kFloatIdFormat, kCopyableColor, "copyable VK_FORMAT_R32_SFLOAT colour attachments"},
                   {kDepthFormat, kCopyableDepth, "copyable VK_FORMAT_D32_SFLOAT depth attachments"}});
    if (!offersSamples(samples_)) {
        std::string offered = "1x";
        for (uint32_t count = 2; count <= MAX_SAMPLES; count *= 2)
            if (offersSamples(count)) offered += fmt::format(", {}x", count);
        return makeError(ExitCode::Usage,
                         "vulkan-graphics: {} does not offer {}x MSAA for float colour and depth attachments "
                         "read by a shader at {}x{}; it offers {}",
                         name, samples_, params_.width, params_.height, offered);
    }
    // The readback runs on the context's queue, which the context picked for graphics: refuse a device
    // where that kind of queue need not run compute work.
    uint32_t familyCount = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(ctx_.physicalDevice(), &familyCount, nullptr);
    std::vector<VkQueueFamilyProperties> families(familyCount);
    vkGetPhysicalDeviceQueueFamilyProperties(ctx_.physicalDevice(), &familyCount, families.data());
    for (const VkQueueFamilyProperties& family : families)
        if ((family.queueFlags & VK_QUEUE_GRAPHICS_BIT) && !(family.queueFlags & VK_QUEUE_COMPUTE_BIT))
            return makeError(ExitCode::Usage,
                             "vulkan-graphics: {} has a graphics queue without compute, which MSAA needs to "
                             "read its samples back",
                             name);
    return okStatus();
}

// What points need from the device: their side drawn exactly as asked. A side between two of the
// device's supported sizes would be drawn at the nearer one, and sizes above 1 need the largePoints
// feature: each is a one-line Usage error. (The view-volume cull needs nothing from the device:
// reference_point.vert applies it.)
Status GraphicsRender::checkPoints() const
{
    const VkPhysicalDeviceLimits& limits = ctx_.properties().limits;
    const char* name = ctx_.properties().deviceName;
    const float size = params_.pointSize;
    VkPhysicalDeviceFeatures features{};
    vkGetPhysicalDeviceFeatures(ctx_.physicalDevice(), &features);
    const float low = limits.pointSizeRange[0], high = limits.pointSizeRange[1];
    const float step = limits.pointSizeGranularity;
    // Granularities need not be binary fractions (the spec's example is 0.1): a size counts as a step
    // when it lies within a thousandth of a step of one.
    const double steps = step > 0.0f ? double(size - low) / step : 0.0;
    const bool onStep = step > 0.0f ? std::abs(steps - std::round(steps)) <= 1e-3 : size == low;
    if (!(size >= low && size <= high) || !onStep)
        return makeError(ExitCode::Usage,
                         "vulkan-graphics: {} cannot draw points of size {} exactly (it draws {} to {} in "
                         "steps of {})",
                         name, size, low, high, step);
    if (size > 1.0f && !features.largePoints)
        return makeError(ExitCode::Usage,
                         "vulkan-graphics: {} lacks the largePoints feature and draws points of size 1 only, "
                         "not {}",
                         name, size);
    return okStatus();
}

// What lines need from the device: Vulkan's rectangular lines (a rectangle of the line width centred on
// the segment, its ends cut square at the endpoints, covering the samples inside), which the compute
// pipeline draws, and their width drawn exactly. Rectangular mode comes from the line rasterization
// extension (VulkanContext::rectangularLines); without it, DEFAULT mode is rectangular only where
// limits.strictLines says so, and lines are refused elsewhere. Widths follow checkPoints' rules, with
// the wideLines feature for widths other than 1.
Status GraphicsRender::checkLines() const
{
    const VkPhysicalDeviceLimits& limits = ctx_.properties().limits;
    const char* name = ctx_.properties().deviceName;
    if (!ctx_.rectangularLines() && !limits.strictLines)
        return makeError(ExitCode::Usage,
                         "vulkan-graphics: {} draws no rectangular lines (no line rasterization extension "
                         "with rectangularLines, and strictLines is false)",
                         name);
    const float width = params_.lineWidth;
    VkPhysicalDeviceFeatures features{};
    vkGetPhysicalDeviceFeatures(ctx_.physicalDevice(), &features);
    const float low = limits.lineWidthRange[0], high = limits.lineWidthRange[1];
    const float step = limits.lineWidthGranularity;
    const double steps = step > 0.0f ? double(width - low) / step : 0.0;
    const bool onStep = step > 0.0f ? std::abs(steps - std::round(steps)) <= 1e-3 : width == low;
    if (!(width >= low && width <= high) || !onStep)
        return makeError(ExitCode::Usage,
                         "vulkan-graphics: {} cannot draw lines of width {} exactly (it draws {} to {} in "
                         "steps of {})",
                         name, width, low, high, step);
    if (width != 1.0f && !features.wideLines)
        return makeError(ExitCode::Usage,
                         "vulkan-graphics: {} lacks the wideLines feature and draws lines of width 1 only, "
                         "not {}",
                         name, width);
    return okStatus();
}

// Whether the device can rasterize `samples` samples per pixel into the anti-aliased attachments at
// this size and sample them in reference_samples.comp: the framebuffer and sampled-image limits, and
// each format's features and sample counts for that use.
bool GraphicsRender::offersSamples(uint32_t samples) const
{
    const VkPhysicalDeviceLimits& limits = ctx_.properties().limits;
    const VkSampleCountFlags bit = sampleCountBit(samples);
    const VkSampleCountFlags limited =
        limits.framebufferColorSampleCounts & limits.framebufferDepthSampleCounts &
        limits.sampledImageColorSampleCounts & limits.sampledImageDepthSampleCounts;
    if ((limited & bit) == 0) return false;
    struct Use {
        VkFormat format;
        VkImageUsageFlags usage;
        VkFormatFeatureFlags features;
    };
    const VkImageUsageFlags color = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    const VkFormatFeatureFlags colorFeatures =
        VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT;
    const Use uses[] = {
        {kLinearColorFormat, color, colorFeatures},
        {kFloatIdFormat, color, colorFeatures},
        {kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
         VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT},
    };
    for (const Use& use : uses) {
        VkFormatProperties features{};
        vkGetPhysicalDeviceFormatProperties(ctx_.physicalDevice(), use.format, &features);
        if ((features.optimalTilingFeatures & use.features) != use.features) return false;
        // Any result but VK_SUCCESS (VK_ERROR_FORMAT_NOT_SUPPORTED above all) means the combination
        // is not offered.
        VkImageFormatProperties properties{};
        if (vkGetPhysicalDeviceImageFormatProperties(ctx_.physicalDevice(), use.format, VK_IMAGE_TYPE_2D,
                                                     VK_IMAGE_TILING_OPTIMAL, use.usage, 0,
                                                     &properties) != VK_SUCCESS)
            return false;
        if ((properties.sampleCounts & bit) == 0 || properties.maxExtent.width < params_.width ||
            properties.maxExtent.height < params_.height)
            return false;
    }
    return true;
}

// Creates buffers_[binding] and fills it with `bytes` bytes of `data`.
Status GraphicsRender::uploadSceneBuffer(uint32_t binding, const void* data, VkDeviceSize bytes,
                                         VkBufferUsageFlags extraUsage)
{
    // A storage descriptor covers the whole buffer, so the buffer may not exceed the device's range.
    const VkDeviceSize capacity = roundUp(std::max(bytes, kMinBufferBytes), kMinBufferBytes);
    if (capacity > ctx_.maxStorageBytes())
        return makeError(ExitCode::Runtime,
                         "vulkan-graphics: buffer {} needs {} bytes, more than the device allows per storage "
                         "buffer ({} bytes)",
                         binding, bytes, ctx_.maxStorageBytes());
    SR_TRY(ctx_.allocateBuffer(
        buffers_[binding], capacity,
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | extraUsage,
        {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT}));
    return ctx_.upload(buffers_[binding].buffer, data, bytes, kSceneReaderStages, kSceneReaderAccess);
}

Status GraphicsRender::uploadScene(const Scene& scene)
{
    SR_TRY(uploadSceneBuffer(BUF_POSITIONS, scene.positions.data(),
                             scene.positions.size() * sizeof(glm::vec4), 0));
    SR_TRY(uploadSceneBuffer(BUF_NORMALS, scene.normals.data(), scene.normals.size() * sizeof(glm::vec4), 0));
    if (!scene.colors.empty())
        SR_TRY(
            uploadSceneBuffer(BUF_COLORS, scene.colors.data(), scene.colors.size() * sizeof(glm::vec4), 0));
    // The vertex stage fetches through the index buffer, the fragment stage reads the same indices
    // by triangle id. A scene of points alone draws no triangle and leaves both bindings placeholders.
    if (scene.triangleCount() > 0) {
        SR_TRY(uploadSceneBuffer(BUF_INDICES, scene.indices.data(), scene.indices.size() * sizeof(uint32_t),
                                 VK_BUFFER_USAGE_INDEX_BUFFER_BIT));
        SR_TRY(uploadSceneBuffer(BUF_TRI_FLAGS, scene.triFlags.data(),
                                 scene.triFlags.size() * sizeof(uint32_t), 0));
    }
    // The line and point vertex stages fetch each vertex through their lists, and the line fragment
    // stage reads the segment's two vertices to mix their colours.
    if (scene.lineCount() > 0)
        SR_TRY(uploadSceneBuffer(BUF_LINES, scene.lines.data(), scene.lines.size() * sizeof(uint32_t), 0));
    if (scene.pointCount() > 0)
        SR_TRY(uploadSceneBuffer(BUF_POINTS, scene.points.data(), scene.points.size() * sizeof(uint32_t), 0));
    // The fragment shaders read the material of their primitive, by primitive id: the triangles', the
    // segments', then the points' (as the compute pipeline lays BUF_TRI_MATERIALS out). The texels go to
    // images instead (createTextures), so BUF_TEXTURES and BUF_TEXELS stay placeholders.
    if (!scene.materials.empty()) {
        const std::vector<GpuMaterial> materials = gpuMaterials(scene);
        SR_TRY(uploadSceneBuffer(BUF_MATERIALS, materials.data(), materials.size() * sizeof(GpuMaterial), 0));
        std::vector<uint32_t> primitiveMaterials = scene.triMaterials;
        primitiveMaterials.insert(primitiveMaterials.end(), scene.lineMaterials.begin(),
                                  scene.lineMaterials.end());
        primitiveMaterials.insert(primitiveMaterials.end(), scene.pointMaterials.begin(),
                                  scene.pointMaterials.end());
        SR_TRY(uploadSceneBuffer(BUF_TRI_MATERIALS, primitiveMaterials.data(),
                                 primitiveMaterials.size() * sizeof(uint32_t), 0));
    }
    if (!scene.texcoords.empty()) {
        SR_TRY(uploadSceneBuffer(BUF_TEXCOORDS, scene.texcoords.data(),
                                 scene.texcoords.size() * sizeof(glm::vec4), 0));
        hasTexcoords_ = VK_TRUE;
    }

    // Ambient occlusion: BUF_AO's planes AO_PLANE_RAW and AO_PLANE_DENOISED (its first two) hold the
    // frame's AO once prepareAo has run (unoccluded until then), so the shading reads it whichever plane
    // aoPlane names.
    static_assert(AO_PLANE_RAW < 2 && AO_PLANE_DENOISED < 2, "the planes shade reads lead BUF_AO");
    if (params_.aoMode != AO_OFF) {
        const std::vector<float> unoccluded(2 * size_t(params_.samplePlane), 1.0f);
        SR_TRY(uploadSceneBuffer(BUF_AO, unoccluded.data(), unoccluded.size() * sizeof(float), 0));
    }

    // Written once by the host before the first submission, which makes the write visible.
    SR_TRY(ctx_.allocateBuffer(buffers_[BUF_PARAMS], roundUp(sizeof(RasterParams), kMinBufferBytes),
                               VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                               {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                    VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                                VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT}));
    std::memcpy(buffers_[BUF_PARAMS].mapped, &params_, sizeof params_);

    // The shaders declare every binding of the compute pipeline (buffers.glsl); the ones the draw
    // never reads share one small buffer so that the set is complete.
    // It also stands in for BUF_SRGB_TABLE, a uniform buffer the shaders read as 64 vec4s.
    SR_TRY(ctx_.allocateBuffer(placeholder_, kSrgbTableBytes,
                               VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
                               {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT}));
    VkBuffer handles[BUF_COUNT];
    for (uint32_t i = 0; i < BUF_COUNT; ++i)
        handles[i] = buffers_[i].buffer != VK_NULL_HANDLE ? buffers_[i].buffer : placeholder_.buffer;
    ctx_.writeDescriptorSet(handles);
    return okStatus();
}

// Creates `image` with every level of `texture` and uploads them, leaving it ready for sampling in
// the fragment shader.
Status GraphicsRender::uploadTexture(const SceneTexture& texture, GpuImage& image)
{
    const VkFormat format = texture.srgb ? kSrgbTextureFormat : kLinearTextureFormat;
    SR_TRY(ctx_.allocateImage(image, format, VK_IMAGE_ASPECT_COLOR_BIT, texture.width, texture.height,
                              texture.levels, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT));
    const VkDeviceSize bytes = texture.texels.size() * sizeof(uint32_t);
    SR_TRY(ctx_.ensureStaging(bytes));
    // RGBA8 with R in the low byte is the byte order R, G, B, A of the formats on a little-endian host.
    std::memcpy(ctx_.staging().mapped, texture.texels.data(), bytes);  // coherent: the submission shows it

    // The levels lie one after another in the staging buffer, each row-major from the top row, which
    // is the image's row 0 (t = 0, glTF's v = 0).
    std::vector<VkBufferImageCopy> regions(texture.levels);
    VkDeviceSize offset = 0;
    for (uint32_t k = 0; k < texture.levels; ++k) {
        const uint32_t w = std::max(texture.width >> k, 1u), h = std::max(texture.height >> k, 1u);
        regions[k] = VkBufferImageCopy{};
        regions[k].bufferOffset = offset;
        regions[k].imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, k, 0, 1};
        regions[k].imageExtent = {w, h, 1};
        offset += VkDeviceSize(w) * h * sizeof(uint32_t);
    }

    VkImageMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = image.image;
    barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, texture.levels, 0, 1};
    SR_TRY(ctx_.beginCommands());
    VkCommandBuffer cmd = ctx_.commandBuffer();
    // UNDEFINED -> TRANSFER_DST: nothing to keep, the copy waits for the transition.
    barrier.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    barrier.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    barrier.srcAccessMask = 0;
    barrier.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0,
                         nullptr, 0, nullptr, 1, &barrier);
    vkCmdCopyBufferToImage(cmd, ctx_.staging().buffer, image.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                           texture.levels, regions.data());
    // TRANSFER_DST -> SHADER_READ_ONLY, the copy made visible to the fragment shaders of every later
    // submission.
    barrier.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    barrier.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, 0, 0,
                         nullptr, 0, nullptr, 1, &barrier);
    return ctx_.submitAndWait();
}

Status GraphicsRender::createTextures(const Scene& scene)
{
    // A scene without textures still gets one (never sampled) entry: the array binding the fragment
    // shader declares must hold a valid descriptor.
    SceneTexture placeholder;
    placeholder.name = "placeholder";
    placeholder.width = placeholder.height = placeholder.levels = 1;
    placeholder.srgb = false;
    placeholder.texels = {0xFFFFFFFFu};
    std::vector<const SceneTexture*> sources;
    for (const SceneTexture& t : scene.textures) sources.push_back(&t);
    if (sources.empty()) sources.push_back(&placeholder);
    textureSlots_ = uint32_t(sources.size());

    textures_.resize(sources.size());
    samplers_.assign(sources.size(), VK_NULL_HANDLE);
    std::vector<VkDescriptorImageInfo> imageInfos(sources.size());
    for (size_t i = 0; i < sources.size(); ++i) {
        SR_TRY(uploadTexture(*sources[i], textures_[i]));
        const VkSamplerCreateInfo info =
            samplerInfo(sources[i]->sampler, sources[i]->levels, params_.textureFilter);
        SR_VK_CHECK(vkCreateSampler(ctx_.device(), &info, nullptr, &samplers_[i]));
        imageInfos[i] = {samplers_[i], textures_[i].view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    }

    VkDescriptorSetLayoutBinding binding{};
    binding.binding = 0;
    binding.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    binding.descriptorCount = textureSlots_;
    binding.stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT;
    VkDescriptorSetLayoutCreateInfo setInfo{};
    setInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    setInfo.bindingCount = 1;
    setInfo.pBindings = &binding;
    SR_VK_CHECK(vkCreateDescriptorSetLayout(ctx_.device(), &setInfo, nullptr, &textureSetLayout_));

    // Set 0 stays the context's, which the compute stages use unchanged; the texture array is set 1
    // (reference.frag's baseTextures).
    const VkDescriptorSetLayout setLayouts[2] = {ctx_.setLayout(), textureSetLayout_};
    VkPipelineLayoutCreateInfo layoutInfo{};
    layoutInfo.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    layoutInfo.setLayoutCount = 2;
    layoutInfo.pSetLayouts = setLayouts;
    SR_VK_CHECK(vkCreatePipelineLayout(ctx_.device(), &layoutInfo, nullptr, &pipelineLayout_));

    const VkDescriptorPoolSize poolSize{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, textureSlots_};
    SR_TRY(createSingleSet(ctx_.device(), &poolSize, 1, textureSetLayout_, texturePool_, textureSet_));

    VkWriteDescriptorSet write{};
    write.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    write.dstSet = textureSet_;
    write.dstBinding = 0;
    write.descriptorCount = textureSlots_;
    write.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    write.pImageInfo = imageInfos.data();
    vkUpdateDescriptorSets(ctx_.device(), 1, &write, 0, nullptr);
    return okStatus();
}

Status GraphicsRender::createTargets()
{
    const VkFormat colorFormat = antialiased_ ? kLinearColorFormat : kWordFormat;
    const VkFormat idFormat = antialiased_ ? kFloatIdFormat : kWordFormat;
    // Multisampled attachments are read by reference_samples.comp, single-sample ones copied.
    if (samples_ > 1) {
        const VkImageUsageFlags colorUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
        SR_TRY(allocateMultisampled(color_, colorFormat, VK_IMAGE_ASPECT_COLOR_BIT, colorUsage));
        SR_TRY(allocateMultisampled(id_, idFormat, VK_IMAGE_ASPECT_COLOR_BIT, colorUsage));
        return allocateMultisampled(depth_, kDepthFormat, VK_IMAGE_ASPECT_DEPTH_BIT,
                                    VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT);
    }
    const VkImageUsageFlags colorUsage =
        VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    SR_TRY(ctx_.allocateImage(color_, colorFormat, VK_IMAGE_ASPECT_COLOR_BIT, params_.width, params_.height,
                              colorUsage));
    SR_TRY(ctx_.allocateImage(id_, idFormat, VK_IMAGE_ASPECT_COLOR_BIT, params_.width, params_.height,
                              colorUsage));
    return ctx_.allocateImage(depth_, kDepthFormat, VK_IMAGE_ASPECT_DEPTH_BIT, params_.width, params_.height,
                              VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
}

// A params_.width x params_.height attachment of samples_ samples per pixel with its own device-local
// memory and a view of it: VulkanContext::allocateImage makes single-sample images only. The memory is
// counted in targetBytes_ (image.allocated stays 0), and ctx_.destroyImage releases it all.
Status GraphicsRender::allocateMultisampled(GpuImage& image, VkFormat format, VkImageAspectFlags aspect,
                                            VkImageUsageFlags usage)
{
    VkImageCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {params_.width, params_.height, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = sampleCountBit(samples_);
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    SR_VK_CHECK(vkCreateImage(ctx_.device(), &info, nullptr, &image.image));

    VkMemoryRequirements requirements{};
    vkGetImageMemoryRequirements(ctx_.device(), image.image, &requirements);
    VkPhysicalDeviceMemoryProperties memory{};
    vkGetPhysicalDeviceMemoryProperties(ctx_.physicalDevice(), &memory);
    uint32_t type = 0;
    while (type < memory.memoryTypeCount &&
           !((requirements.memoryTypeBits & (1u << type)) &&
             (memory.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT)))
        ++type;
    if (type == memory.memoryTypeCount)
        return makeError(
            ExitCode::Runtime,
            "vulkan-graphics: no device-local memory type for a multisampled attachment of {} bytes",
            requirements.size);
    VkMemoryAllocateInfo allocation{};
    allocation.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    allocation.allocationSize = requirements.size;
    allocation.memoryTypeIndex = type;
    SR_VK_CHECK(vkAllocateMemory(ctx_.device(), &allocation, nullptr, &image.memory));
    targetBytes_ += requirements.size;
    SR_VK_CHECK(vkBindImageMemory(ctx_.device(), image.image, image.memory, 0));

    VkImageViewCreateInfo viewInfo{};
    viewInfo.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    viewInfo.image = image.image;
    viewInfo.viewType = VK_IMAGE_VIEW_TYPE_2D;
    viewInfo.format = format;
    viewInfo.subresourceRange = {aspect, 0, 1, 0, 1};
    SR_VK_CHECK(vkCreateImageView(ctx_.device(), &viewInfo, nullptr, &image.view));
    return okStatus();
}

Status GraphicsRender::createRenderPass()
{
    // Every attachment is cleared, kept, and left ready for the copy to the host, or, multisampled,
    // for reference_samples.comp. Each frame starts from UNDEFINED: the previous frame's contents are
    // never needed.
    const bool sampled = samples_ > 1;
    const VkImageLayout readyLayout =
        sampled ? VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL : VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    const VkPipelineStageFlags readerStage =
        sampled ? VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT : VK_PIPELINE_STAGE_TRANSFER_BIT;
    const VkFormat formats[kAttachmentCount] = {antialiased_ ? kLinearColorFormat : kWordFormat,
                                                antialiased_ ? kFloatIdFormat : kWordFormat, kDepthFormat};
    VkAttachmentDescription attachments[kAttachmentCount]{};
    for (uint32_t i = 0; i < kAttachmentCount; ++i) {
        attachments[i].format = formats[i];
        attachments[i].samples = sampleCountBit(samples_);
        attachments[i].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
        attachments[i].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        attachments[i].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
        attachments[i].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
        attachments[i].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
        attachments[i].finalLayout = readyLayout;
    }
    const VkAttachmentReference colorRefs[2] = {{kColorAttachment, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL},
                                                {kIdAttachment, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL}};
    const VkAttachmentReference depthRef = {kDepthAttachment,
                                            VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    VkSubpassDescription subpass{};
    subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    subpass.colorAttachmentCount = 2;
    subpass.pColorAttachments = colorRefs;
    subpass.pDepthStencilAttachment = &depthRef;

    // In: the previous frame's attachment writes and its readback (a read, so only its execution is
    // waited for) complete before this frame's layout transitions and clears.
    // Out: this frame's writes are visible to the readback that may follow.
    VkSubpassDependency dependencies[2]{};
    dependencies[0].srcSubpass = VK_SUBPASS_EXTERNAL;
    dependencies[0].dstSubpass = 0;
    dependencies[0].srcStageMask = kAttachmentStages | readerStage;
    dependencies[0].srcAccessMask = kAttachmentWrites;
    dependencies[0].dstStageMask = kAttachmentStages;
    dependencies[0].dstAccessMask = kAttachmentWrites | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT;
    dependencies[1].srcSubpass = 0;
    dependencies[1].dstSubpass = VK_SUBPASS_EXTERNAL;
    dependencies[1].srcStageMask = kAttachmentStages;
    dependencies[1].srcAccessMask = kAttachmentWrites;
    dependencies[1].dstStageMask = readerStage;
    dependencies[1].dstAccessMask = sampled ? VK_ACCESS_SHADER_READ_BIT : VK_ACCESS_TRANSFER_READ_BIT;

    VkRenderPassCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO;
    info.attachmentCount = kAttachmentCount;
    info.pAttachments = attachments;
    info.subpassCount = 1;
    info.pSubpasses = &subpass;
    info.dependencyCount = 2;
    info.pDependencies = dependencies;
    SR_VK_CHECK(vkCreateRenderPass(ctx_.device(), &info, nullptr, &renderPass_));
    return okStatus();
}

Status GraphicsRender::createFramebuffer()
{
    VkImageView views[kAttachmentCount];
    views[kColorAttachment] = color_.view;
    views[kIdAttachment] = id_.view;
    views[kDepthAttachment] = depth_.view;
    VkFramebufferCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
    info.renderPass = renderPass_;
    info.attachmentCount = kAttachmentCount;
    info.pAttachments = views;
    info.width = params_.width;
    info.height = params_.height;
    info.layers = 1;
    SR_VK_CHECK(vkCreateFramebuffer(ctx_.device(), &info, nullptr, &framebuffer_));
    return okStatus();
}

Status GraphicsRender::createPipeline()
{
    Result<VkShaderModule> vertex = ctx_.createShaderModule(kSpv_reference_vert, sizeof kSpv_reference_vert);
    if (!vertex.ok()) return vertex.error();
    Result<VkShaderModule> fragment =
        visibilityOnly_ && antialiased_ ? ctx_.createShaderModule(kSpv_reference_visibility_aa_frag,
                                                                  sizeof kSpv_reference_visibility_aa_frag)
        : visibilityOnly_
            ? ctx_.createShaderModule(kSpv_reference_visibility_frag, sizeof kSpv_reference_visibility_frag)
        : antialiased_ ? ctx_.createShaderModule(kSpv_reference_aa_frag, sizeof kSpv_reference_aa_frag)
                       : ctx_.createShaderModule(kSpv_reference_frag, sizeof kSpv_reference_frag);
    if (!fragment.ok()) {
        vkDestroyShaderModule(ctx_.device(), *vertex, nullptr);
        return fragment.error();
    }
    // The visibility shader writes the background word (anti-aliased: the linear background); the
    // full one sizes its texture array; the vertex shader fetches texcoords only where the scene has
    // them.
    VkSpecializationMapEntry backgroundEntry{kBackgroundConstant, 0, sizeof(uint32_t)};
    VkSpecializationInfo background{1, &backgroundEntry, sizeof(uint32_t), &backgroundWord_};
    const float backgroundRgb[3] = {linearBackground_.x, linearBackground_.y, linearBackground_.z};
    const VkSpecializationMapEntry backgroundRgbEntries[3] = {
        {kBackgroundRgbConstant, 0, sizeof(float)},
        {kBackgroundRgbConstant + 1, sizeof(float), sizeof(float)},
        {kBackgroundRgbConstant + 2, 2 * sizeof(float), sizeof(float)}};
    VkSpecializationInfo linearBackground{3, backgroundRgbEntries, sizeof backgroundRgb, backgroundRgb};
    VkSpecializationMapEntry slotsEntry{kTextureSlotsConstant, 0, sizeof(uint32_t)};
    VkSpecializationInfo slots{1, &slotsEntry, sizeof(uint32_t), &textureSlots_};
    const VkSpecializationInfo* fragmentConstants = !visibilityOnly_ ? &slots
                                                    : antialiased_   ? &linearBackground
                                                                     : &background;
    VkSpecializationMapEntry texcoordsEntry{kHasTexcoordsConstant, 0, sizeof(VkBool32)};
    VkSpecializationInfo texcoords{1, &texcoordsEntry, sizeof(VkBool32), &hasTexcoords_};

    // No pipeline culling: the fragment shader culls per triangle, since doubleSided triangles must
    // survive within the same draw. The visibility pass has no per-triangle flags to honour, so the
    // pipeline culls.
    const VkCullModeFlags cullMode = !visibilityOnly_                 ? VK_CULL_MODE_NONE
                                     : params_.cullMode == CULL_BACK  ? VK_CULL_MODE_BACK_BIT
                                     : params_.cullMode == CULL_FRONT ? VK_CULL_MODE_FRONT_BIT
                                                                      : VK_CULL_MODE_NONE;
    Status status = buildPipeline(*vertex, &texcoords, *fragment, fragmentConstants,
                                  VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST, cullMode, pipeline_);
    // The pipeline keeps what it needs of the modules.
    vkDestroyShaderModule(ctx_.device(), *vertex, nullptr);
    vkDestroyShaderModule(ctx_.device(), *fragment, nullptr);
    return status;
}

// The pipeline of the unlit primitives of `topology`, points or segments: their vertex shader and the
// fragment shader of the attachments' kind (the caller picks it), in the visibility pass writing the
// background as the triangle pipeline's visibility shaders do.
Status GraphicsRender::createUnlitPipeline(const uint32_t* vertexCode, size_t vertexBytes,
                                           const uint32_t* fragmentCode, size_t fragmentBytes,
                                           VkPrimitiveTopology topology, VkPipeline& pipeline)
{
    Result<VkShaderModule> vertex = ctx_.createShaderModule(vertexCode, vertexBytes);
    if (!vertex.ok()) return vertex.error();
    Result<VkShaderModule> fragment = ctx_.createShaderModule(fragmentCode, fragmentBytes);
    if (!fragment.ok()) {
        vkDestroyShaderModule(ctx_.device(), *vertex, nullptr);
        return fragment.error();
    }
    // One block of every constant the fragment shaders may declare: the background word, the linear
    // background and the visibility switch.
    struct Constants {
        uint32_t backgroundWord;
        float backgroundRgb[3];
        VkBool32 visibilityOnly;
    };
    const Constants constants = {backgroundWord_,
                                 {linearBackground_.x, linearBackground_.y, linearBackground_.z},
                                 visibilityOnly_ ? VK_TRUE : VK_FALSE};
    const VkSpecializationMapEntry entries[5] = {
        {kBackgroundConstant, offsetof(Constants, backgroundWord), sizeof(uint32_t)},
        {kBackgroundRgbConstant, offsetof(Constants, backgroundRgb), sizeof(float)},
        {kBackgroundRgbConstant + 1, offsetof(Constants, backgroundRgb) + sizeof(float), sizeof(float)},
        {kBackgroundRgbConstant + 2, offsetof(Constants, backgroundRgb) + 2 * sizeof(float), sizeof(float)},
        {kUnlitVisibilityConstant, offsetof(Constants, visibilityOnly), sizeof(VkBool32)}};
    const VkSpecializationInfo fragmentConstants{5, entries, sizeof constants, &constants};
    // Facing culling applies to polygons only: points and segments have no facing.
    Status status =
        buildPipeline(*vertex, nullptr, *fragment, &fragmentConstants, topology, VK_CULL_MODE_NONE, pipeline);
    vkDestroyShaderModule(ctx_.device(), *vertex, nullptr);
    vkDestroyShaderModule(ctx_.device(), *fragment, nullptr);
    return status;
}

// A pipeline of the render pass's one subpass from the two modules with their constants, drawing
// `topology` with facing culling `cullMode`; every other state is common to the triangle, line and point
// pipelines, so that all draws rasterize, test depth and write the attachments alike. Lines get the
// line width and rectangular rasterization (checkLines).
Status GraphicsRender::buildPipeline(VkShaderModule vertex, const VkSpecializationInfo* vertexConstants,
                                     VkShaderModule fragment, const VkSpecializationInfo* fragmentConstants,
                                     VkPrimitiveTopology topology, VkCullModeFlags cullMode,
                                     VkPipeline& pipeline)
{
    VkPipelineShaderStageCreateInfo stages[2]{};
    for (VkPipelineShaderStageCreateInfo& stage : stages) {
        stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        stage.pName = "main";
    }
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = vertex;
    stages[0].pSpecializationInfo = vertexConstants;
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = fragment;
    stages[1].pSpecializationInfo = fragmentConstants;

    // Vertex pulling: the vertex shaders read BUF_POSITIONS themselves.
    VkPipelineVertexInputStateCreateInfo vertexInput{};
    vertexInput.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
    VkPipelineInputAssemblyStateCreateInfo assembly{};
    assembly.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
    assembly.topology = topology;

    // Depth range 0..1 and the whole framebuffer: the viewport transform of the compute pipeline.
    const VkViewport viewport = {0.0f, 0.0f, float(params_.width), float(params_.height), 0.0f, 1.0f};
    const VkRect2D scissor = {{0, 0}, {params_.width, params_.height}};
    VkPipelineViewportStateCreateInfo viewportState{};
    viewportState.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
    viewportState.viewportCount = 1;
    viewportState.pViewports = &viewport;
    viewportState.scissorCount = 1;
    viewportState.pScissors = &scissor;

    // Counter-clockwise on screen is front, as in setupTriangle (the projection flips y, so this is
    // glTF's front face). Depth clamping is off: triangles are clipped at the near and far planes, as
    // the compute pipeline clips them, and points outside them are discarded.
    VkPipelineRasterizationStateCreateInfo rasterization{};
    rasterization.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
    rasterization.depthClampEnable = VK_FALSE;
    rasterization.polygonMode = VK_POLYGON_MODE_FILL;
    rasterization.cullMode = cullMode;
    rasterization.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    // Lines: RECTANGULAR mode where the context enabled it; else checkLines has found strictLines, which
    // makes DEFAULT mode rectangular. The width is ignored by the other topologies.
    const bool lines = topology == VK_PRIMITIVE_TOPOLOGY_LINE_LIST;
    rasterization.lineWidth = lines ? params_.lineWidth : 1.0f;
    VkPipelineRasterizationLineStateCreateInfoEXT lineState{};
    lineState.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_LINE_STATE_CREATE_INFO_EXT;
    lineState.lineRasterizationMode = VK_LINE_RASTERIZATION_MODE_RECTANGULAR_EXT;
    lineState.stippledLineEnable = VK_FALSE;
    if (lines && ctx_.rectangularLines()) rasterization.pNext = &lineState;

    // The standard sample locations (RasterParams.sampleCount of them) and no sample shading: one
    // fragment shader invocation per pixel and primitive, its outputs written to every covered sample.
    VkPipelineMultisampleStateCreateInfo multisample{};
    multisample.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
    multisample.rasterizationSamples = sampleCountBit(samples_);
    multisample.sampleShadingEnable = VK_FALSE;

    // LESS keeps the first of equal depths, and primitives are drawn in id order (triangles, segments,
    // points), so a tie resolves to the lowest primitive id, as the compute pipeline's visibility key
    // does.
    VkPipelineDepthStencilStateCreateInfo depthStencil{};
    depthStencil.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
    depthStencil.depthTestEnable = VK_TRUE;
    depthStencil.depthWriteEnable = VK_TRUE;
    depthStencil.depthCompareOp = VK_COMPARE_OP_LESS;

    VkPipelineColorBlendAttachmentState blendAttachments[2]{};
    for (VkPipelineColorBlendAttachmentState& blend : blendAttachments)
        blend.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                               VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    VkPipelineColorBlendStateCreateInfo blendState{};
    blendState.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
    blendState.attachmentCount = 2;
    blendState.pAttachments = blendAttachments;

    VkGraphicsPipelineCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
    info.stageCount = 2;
    info.pStages = stages;
    info.pVertexInputState = &vertexInput;
    info.pInputAssemblyState = &assembly;
    info.pViewportState = &viewportState;
    info.pRasterizationState = &rasterization;
    info.pMultisampleState = &multisample;
    info.pDepthStencilState = &depthStencil;
    info.pColorBlendState = &blendState;
    info.layout = pipelineLayout_;
    info.renderPass = renderPass_;
    info.subpass = 0;
    SR_VK_CHECK(vkCreateGraphicsPipelines(ctx_.device(), VK_NULL_HANDLE, 1, &info, nullptr, &pipeline));
    return okStatus();
}

Status GraphicsRender::drawFrame(double& ms)
{
    SR_TRY(ctx_.beginCommands());
    VkCommandBuffer cmd = ctx_.commandBuffer();
    VkQueryPool queryPool = ctx_.queryPool();
    vkCmdResetQueryPool(cmd, queryPool, 0, 2);

    VkClearValue clears[kAttachmentCount]{};
    if (antialiased_) {
        clears[kColorAttachment].color.float32[0] = linearBackground_.x;
        clears[kColorAttachment].color.float32[1] = linearBackground_.y;
        clears[kColorAttachment].color.float32[2] = linearBackground_.z;
        clears[kColorAttachment].color.float32[3] = 1.0f;
        clears[kIdAttachment].color.float32[0] = kEmptyFloatId;
    } else {
        clears[kColorAttachment].color.uint32[0] = backgroundWord_;
        clears[kIdAttachment].color.uint32[0] = EMPTY_ID;
    }
    clears[kDepthAttachment].depthStencil.depth = 1.0f;
    VkRenderPassBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
    begin.renderPass = renderPass_;
    begin.framebuffer = framebuffer_;
    begin.renderArea = {{0, 0}, {params_.width, params_.height}};
    begin.clearValueCount = kAttachmentCount;
    begin.pClearValues = clears;

    // The clears are part of the timed pass, as the compute pipeline's clear stage is part of its frame.
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queryPool, 0);
    vkCmdBeginRenderPass(cmd, &begin, VK_SUBPASS_CONTENTS_INLINE);
    // The pipelines share the layout, so the sets stay bound across the draws.
    const VkDescriptorSet sets[2] = {ctx_.descriptorSet(), textureSet_};
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipelineLayout_, 0, 2, sets, 0, nullptr);
    if (indexCount_ > 0) {
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_);
        vkCmdBindIndexBuffer(cmd, buffers_[BUF_INDICES].buffer, 0, VK_INDEX_TYPE_UINT32);
        // One draw of the whole list: gl_PrimitiveID counts triangles from 0, the compute pipeline's ids.
        vkCmdDrawIndexed(cmd, indexCount_, 1, 0, 0, 0);
    }
    if (lineCount_ > 0) {
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, linePipeline_);
        // One draw of every segment after the triangles, two vertices each: gl_PrimitiveID counts
        // segments from 0, and the fragment shader adds the triangle count.
        vkCmdDraw(cmd, 2 * lineCount_, 1, 0, 0);
    }
    if (pointCount_ > 0) {
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pointPipeline_);
        // One draw of every point after the segments: gl_PrimitiveID counts points from 0, and the
        // fragment shader adds the triangle and segment counts.
        vkCmdDraw(cmd, pointCount_, 1, 0, 0);
    }
    vkCmdEndRenderPass(cmd);
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queryPool, 1);
    SR_TRY(ctx_.submitAndWait());

    std::vector<double> pairMs;
    SR_TRY(ctx_.readTimestampPairs(1, pairMs));
    ms = pairMs[0];
    return okStatus();
}

// Copies the three single-sample attachments into the staging buffer at `offsets` (by attachment
// index) and waits until the host can read them.
Status GraphicsRender::copyAttachments(const VkDeviceSize offsets[kAttachmentCount])
{
    SR_TRY(ctx_.beginCommands());
    VkCommandBuffer cmd = ctx_.commandBuffer();
    const GpuImage* images[kAttachmentCount] = {&color_, &id_, &depth_};
    for (uint32_t i = 0; i < kAttachmentCount; ++i) {
        VkBufferImageCopy region{};
        region.bufferOffset = offsets[i];
        region.imageSubresource.aspectMask =
            i == kDepthAttachment ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
        region.imageSubresource.layerCount = 1;
        region.imageExtent = {params_.width, params_.height, 1};
        vkCmdCopyImageToBuffer(cmd, images[i]->image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                               ctx_.staging().buffer, 1, &region);
    }
    memoryBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    return ctx_.submitAndWait();
}

Status GraphicsRender::readBack(RenderOutput& out, bool allSamples)
{
    if (!antialiased_) return readWords(out, allSamples);
    SampleFrame frame;
    SR_TRY(samples_ > 1 ? readSamples(frame, allSamples) : readSingleSamples(frame));
    resolve(frame, out, allSamples);
    return okStatus();
}

// Without anti-aliasing the attachments are the images: one sample per output pixel.
Status GraphicsRender::readWords(RenderOutput& out, bool allSamples)
{
    RgbaImage& color = out.color;
    AovImage& aov = out.aov;
    const size_t pixels = size_t(params_.width) * params_.height;
    const VkDeviceSize planeBytes = pixels * sizeof(uint32_t);  // every attachment has 4-byte texels
    SR_TRY(ctx_.ensureStaging(kAttachmentCount * planeBytes));

    const VkDeviceSize offsets[kAttachmentCount] = {kColorAttachment * planeBytes, kIdAttachment * planeBytes,
                                                    kDepthAttachment * planeBytes};
    SR_TRY(copyAttachments(offsets));

    const auto* planes = static_cast<const uint8_t*>(ctx_.staging().mapped);
    color.width = aov.width = params_.width;
    color.height = aov.height = params_.height;
    color.pixels.resize(pixels);
    aov.id.resize(pixels);
    aov.depth.resize(pixels);
    std::memcpy(color.pixels.data(), planes + kColorAttachment * planeBytes, planeBytes);
    std::memcpy(aov.id.data(), planes + kIdAttachment * planeBytes, planeBytes);
    std::memcpy(aov.depth.data(), planes + kDepthAttachment * planeBytes, planeBytes);
    if (allSamples) out.samples = SampleAovs{params_.width, params_.height, 1, aov.id, aov.depth};
    return okStatus();
}

// SSAA alone: single-sample float attachments, copied to the host. A pixel's colour is its one sample.
Status GraphicsRender::readSingleSamples(SampleFrame& frame)
{
    const size_t pixels = size_t(params_.width) * params_.height;
    const VkDeviceSize colorBytes = pixels * sizeof(glm::vec4), planeBytes = pixels * sizeof(float);
    const VkDeviceSize offsets[kAttachmentCount] = {0, colorBytes, colorBytes + planeBytes};
    SR_TRY(ctx_.ensureStaging(colorBytes + 2 * planeBytes));

    SR_TRY(copyAttachments(offsets));

    const auto* staged = static_cast<const uint8_t*>(ctx_.staging().mapped);
    frame.planes = 1;
    frame.pixelColor.resize(pixels);
    frame.id.resize(pixels);
    frame.depth.resize(pixels);
    std::memcpy(frame.pixelColor.data(), staged + offsets[kColorAttachment], colorBytes);
    std::vector<float> ids(pixels);
    std::memcpy(ids.data(), staged + offsets[kIdAttachment], planeBytes);
    std::transform(ids.begin(), ids.end(), frame.id.begin(), decodeFloatId);
    std::memcpy(frame.depth.data(), staged + offsets[kDepthAttachment], planeBytes);
    return okStatus();
}

// The compute pipeline of reference_samples.comp with its set (the three attachments and three
// storage buffers), and the buffers sized for bands of as many rows as the device's storage buffer
// range allows.
Status GraphicsRender::createSampleReadback()
{
    const VkDeviceSize maxBytes = ctx_.maxStorageBytes() / kMinBufferBytes * kMinBufferBytes;
    const VkDeviceSize rowBytes =
        VkDeviceSize(params_.width) * std::max<VkDeviceSize>(sizeof(glm::vec4), samples_ * sizeof(float));
    bandRows_ = uint32_t(std::clamp<VkDeviceSize>(maxBytes / rowBytes, 1, params_.height));
    const VkDeviceSize bandPixels = VkDeviceSize(params_.width) * bandRows_;
    const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    SR_TRY(ctx_.allocateBuffer(readColors_, roundUp(bandPixels * sizeof(glm::vec4), kMinBufferBytes), usage,
                               {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT}));
    for (GpuBuffer* b : {&readIds_, &readDepths_})
        SR_TRY(ctx_.allocateBuffer(*b, roundUp(bandPixels * samples_ * sizeof(float), kMinBufferBytes), usage,
                                   {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT}));

    VkDescriptorSetLayoutBinding bindings[6]{};
    for (uint32_t i = 0; i < 6; ++i) {
        bindings[i].binding = i;
        bindings[i].descriptorType =
            i < 3 ? VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        bindings[i].descriptorCount = 1;
        bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    VkDescriptorSetLayoutCreateInfo setInfo{};
    setInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    setInfo.bindingCount = 6;
    setInfo.pBindings = bindings;
    SR_VK_CHECK(vkCreateDescriptorSetLayout(ctx_.device(), &setInfo, nullptr, &readSetLayout_));
    // The band: its first row and its number of rows.
    const VkPushConstantRange band{VK_SHADER_STAGE_COMPUTE_BIT, 0, 2 * sizeof(uint32_t)};
    VkPipelineLayoutCreateInfo layoutInfo{};
    layoutInfo.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    layoutInfo.setLayoutCount = 1;
    layoutInfo.pSetLayouts = &readSetLayout_;
    layoutInfo.pushConstantRangeCount = 1;
    layoutInfo.pPushConstantRanges = &band;
    SR_VK_CHECK(vkCreatePipelineLayout(ctx_.device(), &layoutInfo, nullptr, &readLayout_));

    const VkDescriptorPoolSize poolSizes[2] = {{VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, 3},
                                               {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 3}};
    SR_TRY(createSingleSet(ctx_.device(), poolSizes, 2, readSetLayout_, readPool_, readSet_));
    const VkDescriptorImageInfo images[3] = {
        {VK_NULL_HANDLE, color_.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL},
        {VK_NULL_HANDLE, id_.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL},
        {VK_NULL_HANDLE, depth_.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL}};
    const VkDescriptorBufferInfo buffers[3] = {{readColors_.buffer, 0, VK_WHOLE_SIZE},
                                               {readIds_.buffer, 0, VK_WHOLE_SIZE},
                                               {readDepths_.buffer, 0, VK_WHOLE_SIZE}};
    VkWriteDescriptorSet writes[2]{};
    for (VkWriteDescriptorSet& write : writes) {
        write.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        write.dstSet = readSet_;
        write.descriptorCount = 3;
    }
    writes[0].dstBinding = 0;
    writes[0].descriptorType = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
    writes[0].pImageInfo = images;
    writes[1].dstBinding = 3;
    writes[1].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[1].pBufferInfo = buffers;
    vkUpdateDescriptorSets(ctx_.device(), 2, writes, 0, nullptr);

    Result<VkShaderModule> module =
        ctx_.createShaderModule(kSpv_reference_samples_comp, sizeof kSpv_reference_samples_comp);
    if (!module.ok()) return module.error();
    VkComputePipelineCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = *module;
    info.stage.pName = "main";
    info.layout = readLayout_;
    VkResult result =
        vkCreateComputePipelines(ctx_.device(), VK_NULL_HANDLE, 1, &info, nullptr, &readPipeline_);
    vkDestroyShaderModule(ctx_.device(), *module, nullptr);  // the pipeline keeps what it needs
    SR_VK_CHECK(result);
    return okStatus();
}

// MSAA: reference_samples.comp reads every sample, one band of rows per submission, and each band's
// buffers are downloaded into the frame (only sample 0's ids and depths without `allSamples`).
Status GraphicsRender::readSamples(SampleFrame& frame, bool allSamples)
{
    const size_t pixels = size_t(params_.width) * params_.height;
    frame.planes = allSamples ? samples_ : 1;
    frame.pixelColor.resize(pixels);
    frame.id.resize(pixels * frame.planes);
    frame.depth.resize(pixels * frame.planes);
    std::vector<float> bandIds, bandDepths;
    for (uint32_t firstRow = 0; firstRow < params_.height; firstRow += bandRows_) {
        const uint32_t band[2] = {firstRow, std::min(bandRows_, params_.height - firstRow)};
        SR_TRY(ctx_.beginCommands());
        VkCommandBuffer cmd = ctx_.commandBuffer();
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, readPipeline_);
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, readLayout_, 0, 1, &readSet_, 0,
                                nullptr);
        vkCmdPushConstants(cmd, readLayout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof band, band);
        vkCmdDispatch(cmd, (params_.width + kReadGroupSide - 1) / kReadGroupSide,
                      (band[1] + kReadGroupSide - 1) / kReadGroupSide, 1);
        // Barriers order against later submissions too: the downloads' copies see the writes.
        memoryBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
        SR_TRY(ctx_.submitAndWait());

        // Sample-major within the band: the first `planes` planes are the buffers' first bytes.
        const size_t bandPixels = size_t(params_.width) * band[1];
        const size_t rowOffset = size_t(firstRow) * params_.width;
        SR_TRY(ctx_.download(readColors_.buffer, frame.pixelColor.data() + rowOffset,
                             bandPixels * sizeof(glm::vec4)));
        bandIds.resize(bandPixels * frame.planes);
        bandDepths.resize(bandPixels * frame.planes);
        SR_TRY(ctx_.download(readIds_.buffer, bandIds.data(), bandIds.size() * sizeof(float)));
        SR_TRY(ctx_.download(readDepths_.buffer, bandDepths.data(), bandDepths.size() * sizeof(float)));
        for (uint32_t s = 0; s < frame.planes; ++s) {
            const auto ids = bandIds.begin() + std::ptrdiff_t(s * bandPixels);
            const auto depths = bandDepths.begin() + std::ptrdiff_t(s * bandPixels);
            std::transform(ids, ids + std::ptrdiff_t(bandPixels),
                           frame.id.begin() + std::ptrdiff_t(s * pixels + rowOffset), decodeFloatId);
            std::copy(depths, depths + std::ptrdiff_t(bandPixels),
                      frame.depth.begin() + std::ptrdiff_t(s * pixels + rowOffset));
        }
    }
    return okStatus();
}

// The output images from the raster grid's samples: each output pixel's colour is the mean linear colour
// of the samples of its ssaa x ssaa raster pixels (each pixelColor already the mean of its pixel's
// samples, all of equal count), sRGB-encoded as the compute shade stage encodes it; its id and depth are
// those of aovSampleIndex's sample.
void GraphicsRender::resolve(SampleFrame& frame, RenderOutput& out, bool allSamples) const
{
    const uint32_t n = params_.ssaa, width = params_.width / n, height = params_.height / n;
    const float blockPixels = float(n * n);
    out.color.width = out.aov.width = width;
    out.color.height = out.aov.height = height;
    out.color.pixels.resize(size_t(width) * height);
    out.aov.id.resize(size_t(width) * height);
    out.aov.depth.resize(size_t(width) * height);
    for (uint32_t y = 0; y < height; ++y)
        for (uint32_t x = 0; x < width; ++x) {
            glm::vec3 sum(0.0f);
            for (uint32_t dy = 0; dy < n; ++dy)
                for (uint32_t dx = 0; dx < n; ++dx)
                    sum += glm::vec3(frame.pixelColor[size_t(y * n + dy) * params_.width + x * n + dx]);
            const size_t i = size_t(y) * width + x;
            out.color.pixels[i] = packRgba8(sum / blockPixels);
            const uint64_t sample = aovSampleIndex(x, y, params_.width, n);
            out.aov.id[i] = frame.id[sample];
            out.aov.depth[i] = frame.depth[sample];
        }
    if (allSamples)
        out.samples =
            SampleAovs{params_.width, params_.height, samples_, std::move(frame.id), std::move(frame.depth)};
}

Result<std::vector<float>> GraphicsRender::prepareAo(const Scene& scene, const RenderSettings& settings)
{
    double ms = 0.0;
    SR_TRY(drawFrame(ms));
    RenderOutput gbuffer;
    SR_TRY(readBack(gbuffer, true));
    // The graphics pipeline's samples as the compute pipeline's visibility keys (sample-major planes).
    const SampleAovs& samples = gbuffer.samples;
    std::vector<uint64_t> visibility(samples.id.size(), ~uint64_t(0));
    for (size_t i = 0; i < visibility.size(); ++i)
        if (samples.id[i] != EMPTY_ID) visibility[i] = packVisibility(samples.depth[i], samples.id[i]);
    std::vector<float> ao;
    if (params_.aoMode == AO_REFERENCE) {
        const AoBvh bvh(scene);
        ao = referenceAoImage(scene, bvh, params_, visibility, aoWorldRadius(scene, settings),
                              settings.aoReferenceRays);
    } else {
        const AoGbufferPlanes planes = aoGbufferOnHost(scene, params_, visibility);
        ao = gtaoOnHost(params_, planes);
        if (params_.aoPlane == AO_PLANE_DENOISED) ao = aoDenoiseOnHost(params_, planes, ao);
    }
    std::vector<float> planes(2 * size_t(params_.samplePlane));
    for (uint32_t plane : {AO_PLANE_RAW, AO_PLANE_DENOISED})
        std::copy(ao.begin(), ao.end(), planes.begin() + std::ptrdiff_t(plane * size_t(params_.samplePlane)));
    SR_TRY(ctx_.upload(buffers_[BUF_AO].buffer, planes.data(), planes.size() * sizeof(float),
                       kSceneReaderStages, kSceneReaderAccess));
    return ao;
}

Result<RenderOutput> renderWithContext(VulkanContext& context, const Scene& scene,
                                       const CameraMatrices& camera, const RenderSettings& settings,
                                       int deviceIndex)
{
    SR_TRY(context.init(deviceIndex, QueueKind::Graphics));
    RenderOutput out;
    out.params = frameParams(scene, camera, settings, ListCapacities{}, GroupCounts{});
    // The line fields as this backend's shaders and checks read them (the segment count also places
    // the point ids), whatever frameParams has filled in.
    out.params.lineCount = uint32_t(scene.lineCount());
    out.params.lineWidth = settings.lineWidth;
    out.params.lineDepthBias = settings.lineDepthBias;
    out.device = context.deviceInfo("vulkan-graphics");

    GraphicsRender render(context);
    SR_TRY(render.init(scene, out.params, settings.visibilityOnly));
    std::vector<float> ao;
    if (settings.ao != AO_OFF) {
        auto prepared = render.prepareAo(scene, settings);
        if (!prepared) return prepared.error();
        ao = std::move(*prepared);
    }
    std::vector<double> drawMs;
    for (uint32_t frame = 0; frame < settings.warmup + settings.repeat; ++frame) {
        double ms = 0.0;
        SR_TRY(render.drawFrame(ms));
        if (frame >= settings.warmup) drawMs.push_back(ms);
    }
    SR_TRY(render.readBack(out, settings.aovSamples));
    if (!ao.empty()) {
        for (float& v : ao) v = aoShaded(v);
        out.aov.ao = resolveAo(ao, settings.width, settings.height, settings.ssaa);
    }
    // The surface channels describe the sample the id and depth AOVs come from (aovSampleIndex).
    if (settings.surfaceAovs) fillSurfaceAovs(scene, out.params, out.aov);

    StageTiming draw;
    draw.name = "draw";
    draw.minMs = *std::min_element(drawMs.begin(), drawMs.end());
    draw.maxMs = *std::max_element(drawMs.begin(), drawMs.end());
    draw.medianMs = median(drawMs);
    out.stages = {draw};
    out.total = draw;
    out.total.name = "total";
    out.stats.trianglesIn = scene.triangleCount();
    out.stats.linesIn = scene.lineCount();
    out.stats.pointsIn = scene.pointCount();
    out.stats.pipelineCounts = false;
    out.camera = camera;
    // No device memory is freed before the render ends, so the render's own adds to the context's peak.
    out.peakDeviceBytes = context.peakAllocatedBytes() + render.ownDeviceBytes();
    return out;
}

}  // namespace

Result<RenderOutput> renderVulkanGraphics(const Scene& scene, const CameraMatrices& camera,
                                          const RenderSettings& settings, int deviceIndex)
{
    SR_TRY(checkInputs(scene, settings));
    auto context = std::make_unique<VulkanContext>();
    std::shared_ptr<ValidationLog> log = context->validationLog();
    Result<RenderOutput> out = renderWithContext(*context, scene, camera, settings, deviceIndex);
    // Leaked objects are reported while the device and the instance are destroyed, after the last
    // call that could fail; a validation error also names the real cause of any other failure.
    context.reset();
    SR_TRY(validationStatus(*log));
    return out;
}

}  // namespace sr
