// graphics_readback.cpp - the vulkan-graphics reference's attachments back on the host: copied words
// without anti-aliasing; every sample through reference_samples.comp with it, resolved on the host.
#include "vulkan/graphics_render.h"

namespace sr::graphics {

// The generated headers define one `const uint32_t kSpv_<shader>[]` each.
#include "reference_samples_comp.spv.h"

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

}  // namespace sr::graphics
