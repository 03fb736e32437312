// lod_cut.comp - stage `lod_cut` (RasterParams.lodScale > 0): the level-of-detail cut, an invocation per
// cluster. Each invocation reads its cluster's CLUSTER_LOD_WORDS at the head of BUF_CLUSTER_DATA (no
// dependent load), decides with clusterLodDrawn (common/shared/cluster.h) and appends the clusters the
// cut draws to BUF_LOD_CUT, counting their triangles; stage clusters then takes those alone, so a
// frame's cluster work grows with the cut, not with every level of the hierarchy.
// groups = ceil(clusterCount / GROUP_SIZE).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(local_size_x = GROUP_SIZE) in;

void main()
{
    uint k = gl_GlobalInvocationID.x;
    if (k >= params.clusterCount) return;
    uint w = k * CLUSTER_LOD_WORDS;
    vec4 ownSphere = vec4(uintBitsToFloat(clusterData[w]), uintBitsToFloat(clusterData[w + 1u]),
                          uintBitsToFloat(clusterData[w + 2u]), uintBitsToFloat(clusterData[w + 3u]));
    vec4 parentSphere = vec4(uintBitsToFloat(clusterData[w + 5u]), uintBitsToFloat(clusterData[w + 6u]),
                             uintBitsToFloat(clusterData[w + 7u]), uintBitsToFloat(clusterData[w + 8u]));
    if (!clusterLodDrawn(params, ownSphere, uintBitsToFloat(clusterData[w + 4u]), parentSphere,
                         uintBitsToFloat(clusterData[w + 9u])))
        return;
    lodCut[atomicAdd(counters[COUNTER_LOD_CLUSTERS], 1u)] = k;
    atomicAdd(counters[COUNTER_LOD_TRIANGLES], clusterData[w + 10u]);
}
