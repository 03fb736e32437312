// reference_point_aa.frag - fragment stage of the `vulkan-graphics` point draw with anti-aliasing (MSAA
// and/or SSAA; host/vulkan/vulkan_graphics.cpp): reference_point.frag with reference_aa.frag's float
// outputs. The unlit colour is clamped to [0, 1] as the compute shade stage clamps every sample before
// the mean, and the primitive id is an exact float (the host refuses more than 2^24 primitives in this
// mode). In the visibility pass (kVisibilityOnly) the colour is the linear background, as
// reference_visibility_aa.frag writes it. The fragment runs once per pixel and point; the hardware
// writes its outputs to every sample of the pixel inside the point's square that passes the depth test.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(early_fragment_tests) in;
layout(constant_id = 3) const float kBackgroundR = 0.0f;
layout(constant_id = 4) const float kBackgroundG = 0.0f;
layout(constant_id = 5) const float kBackgroundB = 0.0f;
layout(constant_id = 6) const bool kVisibilityOnly = false;

layout(location = 0) out vec4 outColor;
layout(location = 1) out float outId;

void main()
{
    uint id = params.triangleCount + params.lineCount + uint(gl_PrimitiveID);
    vec3 color = kVisibilityOnly ? vec3(kBackgroundR, kBackgroundG, kBackgroundB)
                                 : clamp(shadeUnlit(params, id, pointBaseColor(id)), vec3(0.0f), vec3(1.0f));
    outColor = vec4(color, 1.0f);
    outId = float(id);
}
