// ao_gbuffer.cuh - stage `ao_gbuffer` (RasterParams.aoMode == AO_GTAO): per raster pixel, the surface
// ambient occlusion is computed for, from the visibility buffer alone (no scene pass): its nearest
// sample's triangle at the pixel centre (surfaceAt, the surface shade lights), stored as its view
// distance and unit normal (aoGbufferOf, common/shared/ao.h) in planes AO_PLANE_DISTANCE and AO_PLANE_NORMAL
// of BUF_AO. A pixel without a triangle (empty, or a line or point) stores distance 0: it neither receives
// nor casts occlusion. blocks = ceil(samplePlane / GROUP_SIZE).
namespace sr {

__device__ inline void aoGbufferStage(const RasterParams& params, const Buffers& b)
{
    uint i = globalThreadId();
    uint plane = params.samplePlane;
    if (i >= plane) return;
    // The nearest sample: the smallest key (depth first, then the lower id, as the depth test resolves).
    unsigned long long key = b.visibility[i];
    for (uint s = 1u; s < params.sampleCount; ++s) key = min(key, b.visibility[s * plane + i]);
    uint id = visibilityId(key);
    vec4 g = vec4(0.0f);
    if (id < params.triangleCount) {
        uint i0 = b.indices[3u * id];
        uint i1 = b.indices[3u * id + 1u];
        uint i2 = b.indices[3u * id + 2u];
        vec4 pos0 = b.positions[i0], pos1 = b.positions[i1], pos2 = b.positions[i2];
        vec4 nrm0 = b.normals[i0], nrm1 = b.normals[i1], nrm2 = b.normals[i2];
        SurfacePoint s = surfaceAt(params, int(i % params.width), int(i / params.width), pos0, pos1, pos2,
                                   nrm0, nrm1, nrm2);
        g = aoGbufferOf(params, s.bary, pos0, pos1, pos2, nrm0, nrm1, nrm2);
    }
    b.ao[AO_PLANE_DISTANCE * plane + i] = g.x;
    b.ao[AO_PLANE_NORMAL * plane + i] = g.y;
    b.ao[(AO_PLANE_NORMAL + 1u) * plane + i] = g.z;
    b.ao[(AO_PLANE_NORMAL + 2u) * plane + i] = g.w;
}

}  // namespace sr
