// reference.vert - vertex stage of the `vulkan-graphics` reference backend (host/vulkan/vulkan_graphics.cpp).
// Vertex pulling from BUF_POSITIONS, no vertex input bindings. The clip position comes from mulPoint,
// the function the compute `vertex` stage uses, so both backends start from bit-identical clip
// coordinates and any difference between them is the rasterizer's.
// The texture coordinates are the one attribute the fragment stage takes from the hardware's
// interpolators: the texture lookup needs the hardware's own derivatives of them. They go out twice,
// perspective-correct and screen-linear, and the fragment stage picks one per params.uvInterpolation.
// The screen-linear set is not a `noperspective` output: lavapipe (Mesa 22.3) returns wrong values for
// noperspective attributes of large triangles reaching far outside the viewport (builtin:checker at
// orbit:0,6,12, vertices at NDC x = +-11.7: fract(uv) = 0 over the whole lower half of the image while
// the exact screen-linear uv varies; tests/texture_oracle_test.cpp).
// Instead tc * w and w go out perspective-correct, and their quotient in the fragment stage is the
// screen-linear interpolation: perspective-correct weights are b_i = (e_i / w_i) / sum(e_k / w_k) with
// e_i the screen-space weights, so sum(b_i tc_i w_i) / sum(b_i w_i) = sum(e_i tc_i) / sum(e_i).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

// Whether BUF_TEXCOORDS holds a (u0, v0, u1, v1) per vertex; without it the binding is a placeholder.
layout(constant_id = 1) const bool kHasTexcoords = false;

layout(location = 0) smooth out vec4 vTexcoords;
layout(location = 1) smooth out vec4 vTexcoordsTimesW;
layout(location = 2) smooth out float vClipW;

void main()
{
    vec4 clip = mulPoint(params.clipFromWorld, positions[gl_VertexIndex]);
    gl_Position = clip;
    vec4 tc = kHasTexcoords ? texcoords[gl_VertexIndex] : vec4(0.0f);
    vTexcoords = tc;
    vTexcoordsTimesW = tc * clip.w;
    vClipW = clip.w;
}
