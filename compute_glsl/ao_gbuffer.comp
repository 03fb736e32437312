// ao_gbuffer.comp - stage `ao_gbuffer` (RasterParams.aoMode == AO_GTAO): per raster pixel, the surface
// ambient occlusion is computed for, from the visibility buffer alone (no scene pass): its nearest
// sample's triangle at the pixel centre (surfaceAt, the surface shade lights), stored as its view
// distance and unit normal (aoGbufferOf, common/shared/ao.h) in planes AO_PLANE_DISTANCE and AO_PLANE_NORMAL of BUF_AO. A
// pixel without a triangle (empty, or a line or point) stores distance 0: it neither receives nor casts
// occlusion. groups = ceil(samplePlane / GROUP_SIZE). AO_CPU (with SR_CPU_BUILD): the build for CPU
// devices, which reads through the texel views (compute_glsl/buffers.glsl).
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
    // The nearest sample: the smallest key (depth first, then the lower id, as the depth test resolves).
    uint64_t key = LOAD_KEY(i);
    for (uint s = 1u; s < params.sampleCount; ++s) key = min(key, LOAD_KEY(s * plane + i));
    uint id = visibilityId(key);
    vec4 g = vec4(0.0f);
    if (id < params.triangleCount) {
        uint i0 = LOAD_INDEX(3u * id);
        uint i1 = LOAD_INDEX(3u * id + 1u);
        uint i2 = LOAD_INDEX(3u * id + 2u);
        vec4 pos0 = LOAD_POSITION(i0), pos1 = LOAD_POSITION(i1), pos2 = LOAD_POSITION(i2);
        vec4 nrm0 = LOAD_NORMAL(i0), nrm1 = LOAD_NORMAL(i1), nrm2 = LOAD_NORMAL(i2);
        SurfacePoint s =
            surfaceAt(params, int(i % params.width), int(i / params.width), pos0, pos1, pos2, nrm0, nrm1, nrm2);
        g = aoGbufferOf(params, s.bary, pos0, pos1, pos2, nrm0, nrm1, nrm2);
    }
    ao[AO_PLANE_DISTANCE * plane + i] = g.x;
    ao[AO_PLANE_NORMAL * plane + i] = g.y;
    ao[(AO_PLANE_NORMAL + 1u) * plane + i] = g.z;
    ao[(AO_PLANE_NORMAL + 2u) * plane + i] = g.w;
}
