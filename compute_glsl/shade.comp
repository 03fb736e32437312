// shade.comp - stage `shade`: per pixel, resolve the visibility key to its triangle, interpolate that
// triangle's vertex attributes perspective-correctly at the pixel centre, apply its material (base
// colour factor, texture with analytic derivatives), shade, and store RGBA8 (sRGB).
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
        SurfacePoint s = surfaceAt(params, int(i % params.width), int(i / params.width), positions[i0],
                                   positions[i1], positions[i2], normals[i0], normals[i1], normals[i2]);
        vec2 uv;
        float lambda;
        vec4 base = materialBaseColor(id, i0, i1, i2, s, uv, lambda);
        color = shadeSurface(params, id, s, base, uv, lambda);
    }
    framebuffer[i] = packRgba8(color);
}
