// lod_cut.comp - stage `lod_cut` (RasterParams.lodScale > 0): the level-of-detail cut, an invocation per
// cluster. Each invocation reads its cluster's CLUSTER_LOD_WORDS at the head of BUF_CLUSTER_DATA (no
// dependent load) unless its group's bounds rule the whole group out (lodBlockSkipped), decides with
// clusterLodDrawn (common/shared/cluster.h) and appends the clusters the cut draws to BUF_LOD_CUT,
// counting their triangles. Stage clusters then takes those alone, and the clusters of most of the
// hierarchy are never read: a frame's work grows with its cut more than with the mesh.
// groups = ceil(clusterCount / GROUP_SIZE): group g is bounds block g (CLUSTER_LOD_BLOCK = GROUP_SIZE).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(local_size_x = GROUP_SIZE) in;

void main()
{
    // The group's bounds first (the same words for the whole group): most groups hold no cluster of the
    // cut, and their clusters' words are never read.
    uint bw = (params.clusterCount + gl_WorkGroupID.x) * CLUSTER_LOD_WORDS;
    if (clusterData[bw + 10u] == 0u &&
        lodBlockSkipped(params,
                        vec4(uintBitsToFloat(clusterData[bw]), uintBitsToFloat(clusterData[bw + 1u]),
                             uintBitsToFloat(clusterData[bw + 2u]), uintBitsToFloat(clusterData[bw + 3u])),
                        uintBitsToFloat(clusterData[bw + 4u]),
                        vec4(uintBitsToFloat(clusterData[bw + 5u]), uintBitsToFloat(clusterData[bw + 6u]),
                             uintBitsToFloat(clusterData[bw + 7u]), uintBitsToFloat(clusterData[bw + 8u])),
                        uintBitsToFloat(clusterData[bw + 9u])))
        return;
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
