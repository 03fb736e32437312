// reference_samples.comp - reads the `vulkan-graphics` reference's multisampled attachments back
// (host/vulkan/vulkan_graphics.cpp). vkCmdCopyImageToBuffer takes single-sample images only, and
// vkCmdResolveImage would average the ids, so every sample is fetched here instead. One invocation per
// pixel of a band of rows (the bands keep each buffer within the device's storage buffer range) writes
// the mean linear colour of the pixel's samples, and each sample's id (as the float the attachment holds)
// and depth, sample-major within the band: sample s of band pixel p at s * (width * rows) + p.
#version 460
#extension GL_EXT_samplerless_texture_functions : require

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform texture2DMS colorSamples;
layout(set = 0, binding = 1) uniform texture2DMS idSamples;
layout(set = 0, binding = 2) uniform texture2DMS depthSamples;
layout(std430, set = 0, binding = 3) writeonly buffer PixelColorBlock { vec4 pixelColor[]; };
layout(std430, set = 0, binding = 4) writeonly buffer SampleIdBlock { float sampleId[]; };
layout(std430, set = 0, binding = 5) writeonly buffer SampleDepthBlock { float sampleDepth[]; };

layout(push_constant) uniform BandBlock {
    uint firstRow;  // the band's first row of the image
    uint rows;      // rows in the band
} band;

void main()
{
    uint width = uint(textureSize(colorSamples).x);
    uvec2 local = gl_GlobalInvocationID.xy;
    if (local.x >= width || local.y >= band.rows) return;
    ivec2 pixel = ivec2(local.x, band.firstRow + local.y);
    uint bandPixels = width * band.rows;
    uint p = local.y * width + local.x;
    int samples = textureSamples(colorSamples);
    vec4 sum = vec4(0.0f);
    for (int s = 0; s < samples; ++s) {
        sum += texelFetch(colorSamples, pixel, s);
        sampleId[uint(s) * bandPixels + p] = texelFetch(idSamples, pixel, s).x;
        sampleDepth[uint(s) * bandPixels + p] = texelFetch(depthSamples, pixel, s).x;
    }
    pixelColor[p] = sum / float(samples);  // a power of two: the division is exact
}
