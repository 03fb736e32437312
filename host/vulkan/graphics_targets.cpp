// graphics_targets.cpp - the vulkan-graphics reference's inputs and outputs on the device: the scene's
// buffers, its textures with their mip chains and samplers, the attachments, the render pass and the
// framebuffer.
#include "vulkan/graphics_render.h"

namespace sr::graphics {

namespace {

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

}  // namespace

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

}  // namespace sr::graphics
