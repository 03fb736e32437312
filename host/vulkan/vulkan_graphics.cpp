// vulkan_graphics.cpp - see vulkan_graphics.h: one render from start to end (the checks, targets, pipelines
// and read-back it goes through are graphics_*.cpp, over graphics_render.h).
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

#include "ao/ao_host.h"
#include "ao/ao_image.h"
#include "ao/ao_reference.h"
#include "vulkan/graphics_render.h"

namespace sr {
namespace graphics {

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

}  // namespace graphics

namespace {

using graphics::GraphicsRender;

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
    SR_TRY(graphics::checkInputs(scene, settings));
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
