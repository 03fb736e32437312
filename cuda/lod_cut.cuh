// lod_cut.cuh - stage `lod_cut` (RasterParams.lodScale > 0): the level-of-detail cut, a thread per
// cluster. Each thread reads its cluster's CLUSTER_LOD_WORDS at the head of BUF_CLUSTER_DATA (three
// 16-byte loads, no dependent load), decides with clusterLodDrawn (common/shared/cluster.h) and appends
// the clusters the cut draws to BUF_LOD_CUT, counting their triangles; stage clusters then takes those
// alone, so a frame's cluster work grows with the cut, not with every level of the hierarchy.
// blocks = ceil(clusterCount / GROUP_SIZE).
namespace sr {

__device__ inline void lodCutStage(const RasterParams& params, const Buffers& b)
{
    uint k = blockIdx.x * uint(GROUP_SIZE) + threadIdx.x;
    if (k >= params.clusterCount) return;
    const uint4* words = reinterpret_cast<const uint4*>(b.clusterData) + k * (CLUSTER_LOD_WORDS / 4u);
    uint4 own = words[0], parent = words[1], extra = words[2];
    vec4 ownSphere(uintBitsToFloat(own.x), uintBitsToFloat(own.y), uintBitsToFloat(own.z),
                   uintBitsToFloat(own.w));
    vec4 parentSphere(uintBitsToFloat(parent.y), uintBitsToFloat(parent.z), uintBitsToFloat(parent.w),
                      uintBitsToFloat(extra.x));
    if (!clusterLodDrawn(params, ownSphere, uintBitsToFloat(parent.x), parentSphere,
                         uintBitsToFloat(extra.y)))
        return;
    b.lodCut[atomicAdd(&b.counters[COUNTER_LOD_CLUSTERS], 1u)] = k;
    atomicAdd(&b.counters[COUNTER_LOD_TRIANGLES], extra.z);
}

}  // namespace sr
