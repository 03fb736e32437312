// reference.frag - fragment stage of the `vulkan-graphics` reference backend without anti-aliasing
// (host/vulkan/vulkan_graphics.cpp): reference_shade.glsl's colour as the packed sRGB RGBA8 word the
// compute `shade` stage writes, and the triangle id, into R32_UINT attachments.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"
#include "reference_shade.glsl"

layout(location = 0) out uint outColor;
layout(location = 1) out uint outId;

void main()
{
    uint id = uint(gl_PrimitiveID);
    outColor = packRgba8(referenceShade(id));
    outId = id;
}
