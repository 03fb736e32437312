// ao.cuh - stage `ao` (RasterParams.aoMode == AO_GTAO): GTAO per raster pixel (common/shared/ao.h).
// Each of aoSlices screen directions searches aoSteps samples of BUF_AO's distance plane on
// either side for the highest horizon within the radius; the slices' closed-form visibilities are
// averaged into plane AO_PLANE_RAW of BUF_AO (1 where the pixel has no surface). blocks = ceil(samplePlane /
// GROUP_SIZE).
namespace sr {

__device__ inline void aoStage(const RasterParams& params, const Buffers& b)
{
    uint i = globalThreadId();
    uint plane = params.samplePlane;
    if (i >= plane) return;
    float dist = b.ao[AO_PLANE_DISTANCE * plane + i];
    int x = int(i % params.width);
    int y = int(i / params.width);
    AoPixel a = aoPixelAt(params, x, y, dist,
                          vec3(b.ao[AO_PLANE_NORMAL * plane + i], b.ao[(AO_PLANE_NORMAL + 1u) * plane + i],
                               b.ao[(AO_PLANE_NORMAL + 2u) * plane + i]));
    if (dist == 0.0f || !(a.radiusPx >= 1.0f)) {  // no surface, or no other pixel within the radius
        b.ao[AO_PLANE_RAW * plane + i] = 1.0f;
        return;
    }
    float sum = 0.0f;
    for (uint k = 0u; k < params.aoSlices; ++k) {
        AoSlice s = aoSliceBegin(params, a, k);
        for (uint j = 0u; j < params.aoSteps; ++j) {
            float offset = aoStepOffset(params, a, j);
            for (uint side = 0u; side < 2u; ++side) {
                vec2 position = aoSamplePosition(x, y, s.dir, offset, side == 1u);
                int qx = int(floor(position.x));
                int qy = int(floor(position.y));
                if (qx < 0 || qy < 0 || qx >= int(params.width) || qy >= int(params.height)) continue;
                uint q = uint(qy) * params.width + uint(qx);
                float d = b.ao[AO_PLANE_DISTANCE * plane + q];
                if (d == 0.0f) continue;
                vec3 qn = vec3(b.ao[AO_PLANE_NORMAL * plane + q], b.ao[(AO_PLANE_NORMAL + 1u) * plane + q],
                               b.ao[(AO_PLANE_NORMAL + 2u) * plane + q]);
                aoSample(params, a, s, aoSurfaceAt(params, position, qx, qy, d, qn), side == 1u);
            }
        }
        sum += aoSliceVisibility(s);
    }
    b.ao[AO_PLANE_RAW * plane + i] = aoResolve(params, sum);
}

}  // namespace sr
