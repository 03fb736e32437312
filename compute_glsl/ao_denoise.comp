// ao_denoise.comp - stage `ao_denoise` (RasterParams.aoMode == AO_GTAO, aoPlane == AO_PLANE_DENOISED): per raster pixel,
// the 5 x 5 tent-weighted mean of plane AO_PLANE_RAW of BUF_AO over the neighbours on the pixel's own surface
// (aoDenoiseWeight, common/shared/ao.h), into plane AO_PLANE_DENOISED; it averages the 4 x 4 slice pattern out and keeps
// edges. groups = ceil(samplePlane / GROUP_SIZE). AO_CPU (with SR_CPU_BUILD): the build for CPU devices,
// which reads through the texel views (compute_glsl/buffers.glsl).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(local_size_x = GROUP_SIZE) in;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    uint plane = params.samplePlane;
    if (i >= plane) return;
    float dist = LOAD_AO(AO_PLANE_DISTANCE * plane + i);
    if (dist == 0.0f) {
        ao[AO_PLANE_DENOISED * plane + i] = 1.0f;
        return;
    }
    int x = int(i % params.width);
    int y = int(i / params.width);
    AoPixel a = aoPixelAt(params, x, y, dist,
                          vec3(LOAD_AO(AO_PLANE_NORMAL * plane + i), LOAD_AO((AO_PLANE_NORMAL + 1u) * plane + i), LOAD_AO((AO_PLANE_NORMAL + 2u) * plane + i)));
    precise float sum = 0.0f;
    precise float weights = 0.0f;
    for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
            int qx = aoDenoiseNeighbour(x + dx, params.width);
            int qy = aoDenoiseNeighbour(y + dy, params.height);
            if (qx < 0 || qy < 0) continue;
            uint q = uint(qy) * params.width + uint(qx);
            float d = LOAD_AO(AO_PLANE_DISTANCE * plane + q);
            if (d == 0.0f) continue;
            float w = aoDenoiseWeight(a, dist, aoViewPoint(params, qx, qy, d), dx, dy);
            sum = sum + w * LOAD_AO(AO_PLANE_RAW * plane + q);
            weights = weights + w;
        }
    }
    ao[AO_PLANE_DENOISED * plane + i] = aoDenoiseResolve(sum, weights);
}
