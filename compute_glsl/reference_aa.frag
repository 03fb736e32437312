// reference_aa.frag - fragment stage of the `vulkan-graphics` reference backend with anti-aliasing
// (MSAA and/or SSAA; host/vulkan/vulkan_graphics.cpp). Without sample shading the hardware runs it once
// per pixel and triangle, at the pixel centre, and writes its outputs to every sample of the pixel the
// triangle covers and wins the depth test: MSAA as the compute pipeline defines it. The outputs are
// floats because devices need not offer multisampled integer attachments (lavapipe offers none):
// reference_shade.glsl's linear colour, clamped to [0, 1] as the image shows it (so that a highlight far
// above 1 does not bleed over the other samples of the mean, as in the compute shade stage) and resolved
// on the host, and the triangle id as an exact float (the host refuses scenes of more than 2^24
// triangles in this mode).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"
#include "reference_shade.glsl"

layout(location = 0) out vec4 outColor;
layout(location = 1) out float outId;

void main()
{
    uint id = uint(gl_PrimitiveID);
    outColor = vec4(clamp(referenceShade(id), vec3(0.0f), vec3(1.0f)), 1.0f);
    outId = float(id);
}
