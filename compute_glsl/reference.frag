// reference.frag - fragment stage of the `vulkan-graphics` reference backend
// (host/vulkan/vulkan_graphics.cpp).
// gl_PrimitiveID of the single indexed draw is the triangle id of the compute backends. Facing culling
// happens here, per triangle flag, because one draw has one pipeline cull mode and glTF doubleSided
// triangles must never be culled. The colour is computed as compute_glsl/shade.comp computes it, by
// shadeTriangleAt at the pixel centre.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(location = 0) out uint outColor;
layout(location = 1) out uint outId;

void main()
{
    uint id = uint(gl_PrimitiveID);
    bool doubleSided = (triFlags[id] & TRI_FLAG_DOUBLE_SIDED) != 0u;
    bool culled = (params.cullMode == CULL_BACK && !gl_FrontFacing) ||
                  (params.cullMode == CULL_FRONT && gl_FrontFacing);
    if (culled && !doubleSided) discard;
    uint i0 = indices[3u * id];
    uint i1 = indices[3u * id + 1u];
    uint i2 = indices[3u * id + 2u];
    vec4 white = vec4(1.0f);
    bool hasColors = params.hasColors != 0u;
    vec3 color = shadeTriangleAt(params, id, int(gl_FragCoord.x), int(gl_FragCoord.y), positions[i0],
                                 positions[i1], positions[i2], normals[i0], normals[i1], normals[i2],
                                 hasColors ? colors[i0] : white, hasColors ? colors[i1] : white,
                                 hasColors ? colors[i2] : white);
    outColor = packRgba8(color);
    outId = id;
}
