// aovs.comp - stage `aovs`: per output pixel, the id and depth of the sample it reports (aovSampleOf) into
// BUF_FRAMEBUFFER after the colour, and with AOV_OUT_SURFACE or AOV_OUT_RAST the surface of its triangle there: barycentrics,
// texture coordinates of the base colour texture and the shading normal, or rasterize's (u, v, z/w,
// id + 1) (layout: shared/aovs.h). The host then copies out only the arrays it was asked for, already
// unpacked, instead of every sample's 64-bit key. Lines and points get their id and depth, and zero
// surfaces. One invocation per output pixel; groups = ceil(outputPixels / GROUP_SIZE).
// AOVS_CPU: the build for CPU devices, which a frame without the surface AOVs and rasterize's output runs:
// ids and depth alone, each key read through the texel view (a vector gather, where llvmpipe loads a
// storage buffer lane by lane). A CPU device runs the code behind a branch under a mask whether or not
// any lane takes it, so the surface part, compiled in, would cost every pixel of every frame.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(local_size_x = GROUP_SIZE) in;

void main()
{
    RasterParams pixelParams = outputParams(params);
    uint n = pixelParams.width * pixelParams.height;
    uint i = gl_GlobalInvocationID.x;
    if (i >= n) return;
    uint x = i % pixelParams.width;
    uint y = i / pixelParams.width;
    uint64_t key = LOAD_KEY(aovSampleOf(params, x, y));
    uint id = visibilityId(key);
    float depth = visibilityDepth(key);
    AovsLayout l = aovsLayout(n, params.aovOutputs);
    framebuffer[l.ids + i] = id;
    framebuffer[l.depths + i] = floatBitsToUint(depth);
#if !defined(AOVS_CPU)
    if ((params.aovOutputs & (AOV_OUT_SURFACE | AOV_OUT_RAST)) == 0u) return;

    vec2 bary = vec2(0.0f);
    vec2 uv = vec2(0.0f);
    vec3 normal = vec3(0.0f);
    if (id < params.triangleCount) {
        uint i0 = indices[3u * id];
        uint i1 = indices[3u * id + 1u];
        uint i2 = indices[3u * id + 2u];
        SurfacePoint s = surfaceAtNdc(pixelParams, aovSampleNdc(params, x, y), false, positions[i0], positions[i1],
                                      positions[i2], normals[i0], normals[i1], normals[i2]);
        bary = vec2(s.bary.y, s.bary.z);
        if (params.materialCount > 0u) {
            // The base colour texture's coordinates, looked up as materialBaseColor does.
            GpuMaterial m = materials[min(triMaterials[id], params.materialCount - 1u)];
            if (m.baseColorTexture < params.textureCount) {
                vec2 dx, dy;
                uv = surfaceUvOfSet(s, texcoords[i0], texcoords[i1], texcoords[i2], m.texCoord, dx, dy);
                uv = materialTransformUv(m, uv);
            }
        }
        normal = aovNormal(params, s.bary, positions[i0], positions[i1], positions[i2], normals[i0], normals[i1],
                           normals[i2]);
    }
    if ((params.aovOutputs & AOV_OUT_SURFACE) != 0u) {
        framebuffer[l.surface + i] = floatBitsToUint(bary.x);
        framebuffer[l.surface + n + i] = floatBitsToUint(bary.y);
        framebuffer[l.surface + 2u * n + i] = floatBitsToUint(uv.x);
        framebuffer[l.surface + 3u * n + i] = floatBitsToUint(uv.y);
        framebuffer[l.surface + 4u * n + i] = floatBitsToUint(normal.x);
        framebuffer[l.surface + 5u * n + i] = floatBitsToUint(normal.y);
        framebuffer[l.surface + 6u * n + i] = floatBitsToUint(normal.z);
    }
    if ((params.aovOutputs & AOV_OUT_RAST) != 0u) {
        vec4 r = rastOutput(id, depth, bary.x, bary.y);
        framebuffer[l.rast + 4u * i] = floatBitsToUint(r.x);
        framebuffer[l.rast + 4u * i + 1u] = floatBitsToUint(r.y);
        framebuffer[l.rast + 4u * i + 2u] = floatBitsToUint(r.z);
        framebuffer[l.rast + 4u * i + 3u] = floatBitsToUint(r.w);
    }
#endif
}
