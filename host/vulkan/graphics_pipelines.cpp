// graphics_pipelines.cpp - the vulkan-graphics reference's set-up (GraphicsRender::init) and its pipelines:
// triangles (full or visibility-only, anti-aliased or not), segments and points.
#include "vulkan/graphics_render.h"

namespace sr::graphics {

// The generated headers define one `const uint32_t kSpv_<shader>[]` each.
#include "reference_aa_frag.spv.h"
#include "reference_frag.spv.h"
#include "reference_line_aa_frag.spv.h"
#include "reference_line_frag.spv.h"
#include "reference_line_vert.spv.h"
#include "reference_point_aa_frag.spv.h"
#include "reference_point_frag.spv.h"
#include "reference_point_vert.spv.h"
#include "reference_visibility_aa_frag.spv.h"
#include "reference_visibility_frag.spv.h"
#include "reference_vert.spv.h"

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

}  // namespace sr::graphics
