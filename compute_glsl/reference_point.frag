// reference_point.frag - fragment stage of the `vulkan-graphics` point draw without anti-aliasing
// (host/vulkan/vulkan_graphics.cpp): the point's unlit colour (shadeUnlit of pointBaseColor, the code the
// compute shade stage runs for a point) as the packed sRGB RGBA8 word, and its primitive id,
// params.triangleCount + params.lineCount + gl_PrimitiveID (point ids follow the segments'), into the
// R32_UINT attachments. In the visibility pass (kVisibilityOnly) the colour is the background word, as
// reference_visibility.frag writes it. Points have no facing and no alpha test, so the depth test may
// run before the shader.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(early_fragment_tests) in;
layout(constant_id = 0) const uint kBackgroundWord = 0u;
layout(constant_id = 6) const bool kVisibilityOnly = false;

layout(location = 0) out uint outColor;
layout(location = 1) out uint outId;

void main()
{
    uint id = params.triangleCount + params.lineCount + uint(gl_PrimitiveID);
    outColor = kVisibilityOnly ? kBackgroundWord : packRgba8(shadeUnlit(params, id, pointBaseColor(id)));
    outId = id;
}
