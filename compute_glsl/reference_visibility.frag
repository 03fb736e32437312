// reference_visibility.frag - fragment stage of the `vulkan-graphics` visibility pass: the hardware
// rasterizer's own cost with the cheapest possible fragment work, as `raster bench` measures it.
// The colour is the background word (a specialization constant), the id is gl_PrimitiveID; early
// fragment tests let the depth test run before the shader, and facing culling is done by the pipeline.
// Used only when no triangle needs per-triangle facing or an alpha test (host/vulkan/vulkan_graphics.cpp).
#version 460

layout(early_fragment_tests) in;
layout(constant_id = 0) const uint kBackgroundWord = 0u;

layout(location = 0) out uint outColor;
layout(location = 1) out uint outId;

void main()
{
    outColor = kBackgroundWord;
    outId = uint(gl_PrimitiveID);
}
