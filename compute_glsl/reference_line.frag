// reference_line.frag - fragment stage of the `vulkan-graphics` line draw without anti-aliasing
// (host/vulkan/vulkan_graphics.cpp): the segment's unlit colour (shadeUnlit of lineBaseColor at the
// interpolated parameter vT, the code the compute shade stage runs for a segment) as the packed sRGB
// RGBA8 word, and its primitive id, params.triangleCount + gl_PrimitiveID, into the R32_UINT
// attachments. In the visibility pass (kVisibilityOnly) the colour is the background word, as
// reference_visibility.frag writes it. Lines have no facing and no alpha test, and the shader leaves
// the depth alone, so the depth test may run before it.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(early_fragment_tests) in;
layout(constant_id = 0) const uint kBackgroundWord = 0u;
layout(constant_id = 6) const bool kVisibilityOnly = false;

layout(location = 0) smooth in float vT;
layout(location = 0) out uint outColor;
layout(location = 1) out uint outId;

void main()
{
    uint id = params.triangleCount + uint(gl_PrimitiveID);
    outColor = kVisibilityOnly ? kBackgroundWord : packRgba8(shadeUnlit(params, id, lineBaseColor(id, vT)));
    outId = id;
}
