// shade.comp - stage `shade`: per pixel, resolve the visibility key to its triangle, interpolate that
// triangle's vertex outputs perspective-correctly at the pixel centre, shade, and store RGBA8 (sRGB).
// One thread per pixel; groups = ceil(width * height / GROUP_SIZE).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(local_size_x = GROUP_SIZE) in;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= params.width * params.height) return;
    uint id = visibilityId(visibility[i]);
    vec3 color = vec3(params.background.x, params.background.y, params.background.z);
    if (params.shadingMode == SHADING_HIT_COUNT) {
        color = hitCountColor(hitCount[i], color);
    } else if (id != EMPTY_ID) {
        uint i0 = indices[3u * id];
        uint i1 = indices[3u * id + 1u];
        uint i2 = indices[3u * id + 2u];
        vec4 white = vec4(1.0f);
        bool hasColors = params.hasColors != 0u;
        color = shadeTriangleAt(params, id, int(i % params.width), int(i / params.width), clipPos[i0],
                                clipPos[i1], clipPos[i2], viewPos[i0], viewPos[i1], viewPos[i2],
                                viewNormal[i0], viewNormal[i1], viewNormal[i2], hasColors ? colors[i0] : white,
                                hasColors ? colors[i1] : white, hasColors ? colors[i2] : white);
    }
    framebuffer[i] = packRgba8(color);
}
