// reference.vert - vertex stage of the `vulkan-graphics` reference backend (host/vulkan/vulkan_graphics.cpp).
// Vertex pulling from BUF_POSITIONS, no vertex input bindings. The clip position comes from mulPoint,
// the function the compute `vertex` stage uses, so both backends start from bit-identical clip
// coordinates and any difference between them is the rasterizer's.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

void main()
{
    gl_Position = mulPoint(params.clipFromWorld, positions[gl_VertexIndex]);
}
