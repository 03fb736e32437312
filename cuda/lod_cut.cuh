// lod_cut.cuh - stage `lod_cut` (RasterParams.lodScale > 0): the level-of-detail cut, a thread per
// cluster. Each thread reads its cluster's CLUSTER_LOD_WORDS at the head of BUF_CLUSTER_DATA (three
// 16-byte loads, no dependent load) unless its block's bounds rule the whole block out (lodBlockSkipped),
// decides with clusterLodDrawn (common/shared/cluster.h) and appends the clusters the cut draws to
// BUF_LOD_CUT, counting their triangles. Stage clusters then takes those alone, and the clusters of most
// of the hierarchy are never read: a frame's work grows with its cut more than with the mesh.
// blocks = ceil(clusterCount / GROUP_SIZE): block b is bounds block b (CLUSTER_LOD_BLOCK = GROUP_SIZE).
namespace sr {

__device__ inline void lodCutStage(const RasterParams& params, const Buffers& b)
{
    // The block's bounds first (the same address for the whole block): most blocks hold no cluster of
    // the cut, and their clusters' words are never read.
    const uint4* block = reinterpret_cast<const uint4*>(b.clusterData) +
                         (params.clusterCount + blockIdx.x) * (CLUSTER_LOD_WORDS / 4u);
    uint4 bp = block[0], bo = block[1], bx = block[2];
    if (bx.z == 0u &&
        lodBlockSkipped(
            params,
            vec4(uintBitsToFloat(bp.x), uintBitsToFloat(bp.y), uintBitsToFloat(bp.z), uintBitsToFloat(bp.w)),
            uintBitsToFloat(bo.x),
            vec4(uintBitsToFloat(bo.y), uintBitsToFloat(bo.z), uintBitsToFloat(bo.w), uintBitsToFloat(bx.x)),
            uintBitsToFloat(bx.y)))
        return;
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
