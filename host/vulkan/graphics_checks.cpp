// graphics_checks.cpp - what the vulkan-graphics reference needs of the scene and the device, checked before
// anything is allocated: one-line errors naming what is missing.
#include "vulkan/graphics_render.h"

namespace sr::graphics {

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

}  // namespace sr::graphics
