// reference.vert - vertex stage of the `vulkan-graphics` reference backend (host/vulkan/vulkan_graphics.cpp).
// Vertex pulling from BUF_POSITIONS, no vertex input bindings. The clip position comes from mulPoint,
// the function the compute `vertex` stage uses, so both backends start from bit-identical clip
// coordinates and any difference between them is the rasterizer's.
// The texture coordinates are the one attribute the fragment stage takes from the hardware's
// interpolators: the texture lookup needs the hardware's own derivatives of them. They go out twice,
// perspective-correct and screen-linear, and the fragment stage picks one per params.uvInterpolation.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

// Whether BUF_TEXCOORDS holds a (u0, v0, u1, v1) per vertex; without it the binding is a placeholder.
layout(constant_id = 1) const bool kHasTexcoords = false;

layout(location = 0) smooth out vec4 vTexcoords;
layout(location = 1) noperspective out vec4 vTexcoordsAffine;

void main()
{
    gl_Position = mulPoint(params.clipFromWorld, positions[gl_VertexIndex]);
    vec4 tc = kHasTexcoords ? texcoords[gl_VertexIndex] : vec4(0.0f);
    vTexcoords = tc;
    vTexcoordsAffine = tc;
}
