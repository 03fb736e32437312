// clusters.cuh - stage `clusters`: the scene's triangles cluster by cluster (RasterParams.clusterCount > 0),
// in place of setup's thread per triangle. A warp (CLUSTER_LANES threads) takes one cluster: it culls the
// cluster whole where every triangle would be culled anyway (clusterCull, common/shared/cluster.h), then
// transforms its vertices once into shared memory and sets up each triangle from there, so small
// triangles are rasterized and big ones binned exactly as setup would.
// What the warp saves is setup's per-corner work: with fixed8 each vertex is also classified and snapped
// once (clusterVertex) where setup snaps every corner of every triangle (about six times per vertex of a
// closed mesh), and a triangle's three indices and 48 bytes of clip positions become two words. With
// fixed8 the triangles go in two passes: the first ends those that the corners' flags or an empty sample
// box decide (on a dense mesh most: clusterTriangleKind) and queues the others in shared memory; the
// second sets those up and rasterizes or bins them, a lane each, so that those with a sample no longer
// hold the warp's other lanes idle in every round. The triangles that setup would count culled or invalid
// are counted per thread, then per warp.
// A clipped triangle takes setup's setupClippedTriangle, and every triangle of the other raster methods
// setup's setupInputTriangle, from the clip positions. A culled cluster costs one 64-byte record for up to
// 124 triangles. CLUSTERS_PER_GROUP clusters per block; blocks = ceil(clusterCount / CLUSTERS_PER_GROUP),
// or with level of detail at most LOD_CLUSTER_GROUPS, looping over the clusters stage lod_cut listed.
namespace sr {

template <bool kMaterials, bool kMultisample, uint kMethod>
__device__ inline void clustersStage(const RasterParams& params, const Buffers& b)
{
    // A cluster's vertices: clip positions, and snapped (x, y, depth bits, flags). 16-byte aligned, so
    // that a vertex is one 16-byte access (loadVec4, loadIvec4).
    __shared__ __align__(16) vec4 clusterClip[CLUSTERS_PER_GROUP][CLUSTER_MAX_VERTICES];
    __shared__ __align__(16) ivec4 clusterSnap[CLUSTERS_PER_GROUP][CLUSTER_MAX_VERTICES];
    // fixed8: the triangles (input index, corners) that pass 1 leaves to pass 2, and their number.
    __shared__ uvec2 clusterQueue[CLUSTERS_PER_GROUP][CLUSTER_MAX_TRIANGLES];
    __shared__ uint clusterQueued[CLUSTERS_PER_GROUP];
    uint slot = threadIdx.x / uint(CLUSTER_LANES);
    uint lane = threadIdx.x % uint(CLUSTER_LANES);
    // With level of detail (lodScale > 0) stage lod_cut listed the clusters to draw in BUF_LOD_CUT, and
    // the blocks (LOD_CLUSTER_GROUPS) loop over that list; without, each block takes its clusters once.
    const bool lod = params.lodScale > 0.0f;
    const uint total = lod ? b.counters[COUNTER_LOD_CLUSTERS] : params.clusterCount;
    const uint stride = lod ? gridDim.x * uint(CLUSTERS_PER_GROUP) : total;
    for (uint first = blockIdx.x * uint(CLUSTERS_PER_GROUP); first < total; first += stride) {
        uint entry = first + slot;
        GpuCluster c;
        uint verdict = CLUSTER_FRUSTUM_CULLED;  // past the last cluster: nothing to do
        if (entry < total) {
            c = b.clusters[lod ? b.lodCut[entry] : entry];
            verdict = clusterCull(params, c);
            if (verdict != CLUSTER_DRAWN && lane == 0u) {
                addStat(b, COUNTER_CULLED, c.triangleCount);
                addStat(b, COUNTER_CLUSTERS_CULLED, 1u);
            }
        }
        // The lane's first triangle (its input index and corners), fetched before the vertices so that its
        // load overlaps theirs; each round of the triangle loop then fetches the lane's next one.
        uint t = lane, tri = 0u, corners = 0u;
        if (verdict == CLUSTER_DRAWN && t < c.triangleCount) {
            tri = b.clusterData[c.triangleOffset + 2u * t];
            corners = b.clusterData[c.triangleOffset + 2u * t + 1u];
        }
        if (lane == 0u) clusterQueued[slot] = 0u;
        if (verdict == CLUSTER_DRAWN) {
            // A vertex is two dependent loads (its scene index, then its position); a lane's vertices
            // (CLUSTER_MAX_VERTICES = 2 x CLUSTER_LANES) are all requested before any is transformed, so
            // that the lane waits for two loads in a row and not for four (the 100M sphere -9%, H200).
            // compute_glsl requests the indices before the cull; here that ran the 10.2M sphere 3% slower.
            uint index[CLUSTER_VERTEX_ROUNDS];
            vec4 world[CLUSTER_VERTEX_ROUNDS];
#pragma unroll
            for (uint r = 0u; r < uint(CLUSTER_VERTEX_ROUNDS); ++r) {
                uint v = lane + r * uint(CLUSTER_LANES);
                index[r] = v < c.vertexCount ? b.clusterData[c.vertexOffset + v] : 0u;
            }
#pragma unroll
            for (uint r = 0u; r < uint(CLUSTER_VERTEX_ROUNDS); ++r) {
                uint v = lane + r * uint(CLUSTER_LANES);
                world[r] = v < c.vertexCount ? loadVec4(b.positions, index[r]) : vec4(0.0f);
            }
#pragma unroll
            for (uint r = 0u; r < uint(CLUSTER_VERTEX_ROUNDS); ++r) {
                uint v = lane + r * uint(CLUSTER_LANES);
                if (v >= c.vertexCount) break;
                vec4 clip = mulPoint(params.clipFromWorld, world[r]);
                storeVec4(clusterClip[slot], v, clip);
                if constexpr (kMethod == RASTER_FIXED8) {
                    ivec2 xy;
                    float z;
                    uint flags = clusterVertex(clip, params.guardBand, params.width, params.height, xy, z);
                    storeIvec4(clusterSnap[slot], v, ivec4(xy.x, xy.y, int(floatBitsToUint(z)), int(flags)));
                }
            }
        }
        // A warp reads only its own cluster's vertices: the warp's barrier is enough (compute_glsl's
        // clusterBarrier: a subgroup's where subgroups are CLUSTER_LANES wide, the group's elsewhere). The
        // block's barrier held each warp until the block's slowest cluster was transformed (ncu, sphere
        // 10.2M on the H200: 20% of the kernel's stall samples).
        __syncwarp();
        uint invalid = 0u, culled = 0u;
        if (verdict == CLUSTER_DRAWN) {
            for (; t < c.triangleCount; t += uint(CLUSTER_LANES)) {
                uint nextTri = 0u, nextCorners = 0u;
                if (t + uint(CLUSTER_LANES) < c.triangleCount) {
                    nextTri = b.clusterData[c.triangleOffset + 2u * (t + uint(CLUSTER_LANES))];
                    nextCorners = b.clusterData[c.triangleOffset + 2u * (t + uint(CLUSTER_LANES)) + 1u];
                }
                uint k0 = clusterCorner(corners, 0u), k1 = clusterCorner(corners, 1u),
                     k2 = clusterCorner(corners, 2u);
                if constexpr (kMethod == RASTER_FIXED8) {
                    // Pass 1: the triangles that end at their corners' flags or an empty sample box are
                    // counted here; the others wait in the cluster's queue for pass 2.
                    ivec4 s0 = loadIvec4(clusterSnap[slot], k0), s1 = loadIvec4(clusterSnap[slot], k1),
                          s2 = loadIvec4(clusterSnap[slot], k2);
                    uint kind = clusterTriangleKind(uint(s0.w), uint(s1.w), uint(s2.w), ivec2(s0.x, s0.y),
                                                    ivec2(s1.x, s1.y), ivec2(s2.x, s2.y), params.width,
                                                    params.height, params.sampleBounds);
                    if (kind == PREPARE_DIRECT || kind == PREPARE_CLIPPED)
                        clusterQueue[slot][atomicAdd(&clusterQueued[slot], 1u)] = uvec2(tri, corners);
                    invalid += kind == PREPARE_INVALID ? 1u : 0u;
                    culled += kind == PREPARE_CULLED ? 1u : 0u;
                } else {
                    setupInputTriangle<kMaterials, kMultisample, kMethod>(
                        params, b, tri, loadVec4(clusterClip[slot], k0), loadVec4(clusterClip[slot], k1),
                        loadVec4(clusterClip[slot], k2));
                }
                tri = nextTri;
                corners = nextCorners;
            }
        }
        if constexpr (kMethod == RASTER_FIXED8) {
            // Pass 2: the queued triangles set up, rasterized or binned, clipped where they need it, with
            // every lane busy. In one pass their lanes ran this part in nearly every round, beside lanes
            // whose triangles were done: on the 10.2M sphere one drawn triangle in eight has a sample in
            // its box. Alone the split measured -1.5% (10.2M sphere) and +2% (100M) on the H200; it is what
            // lets the 64-register build (kernels.cuh) pay, its loop keeping less alive than the whole
            // setup inside the triangle loop did (docs/benchmark.md, "Seventh pass"). compute_glsl keeps
            // one pass: there NVIDIA's Vulkan compiler ran the split 16-23% slower.
            __syncwarp();
            uint queued = verdict == CLUSTER_DRAWN ? clusterQueued[slot] : 0u;
            for (uint q = lane; q < queued; q += uint(CLUSTER_LANES)) {
                uvec2 entry = clusterQueue[slot][q];
                uint qTri = entry.x, qCorners = entry.y;
                uint k0 = clusterCorner(qCorners, 0u), k1 = clusterCorner(qCorners, 1u),
                     k2 = clusterCorner(qCorners, 2u);
                ivec4 s0 = loadIvec4(clusterSnap[slot], k0), s1 = loadIvec4(clusterSnap[slot], k1),
                      s2 = loadIvec4(clusterSnap[slot], k2);
                TriSetup setup;
                uint kind = clusterSetupTriangle(
                    uint(s0.w), uint(s1.w), uint(s2.w), ivec2(s0.x, s0.y), ivec2(s1.x, s1.y),
                    ivec2(s2.x, s2.y), uintBitsToFloat(uint(s0.z)), uintBitsToFloat(uint(s1.z)),
                    uintBitsToFloat(uint(s2.z)), qTri, (qCorners & CLUSTER_TRI_DOUBLE_SIDED) != 0u,
                    params.cullMode, params.width, params.height, params.sampleBounds, setup);
                if (kind == PREPARE_DIRECT)
                    emitTriangle<kMaterials, kMultisample, false, kMethod>(params, b, setup, false);
                else if (kind == PREPARE_CLIPPED)
                    setupClippedTriangle<kMaterials, kMultisample, kMethod>(
                        params, b, qTri, loadVec4(clusterClip[slot], k0), loadVec4(clusterClip[slot], k1),
                        loadVec4(clusterClip[slot], k2));
                culled += kind == PREPARE_CULLED ? 1u : 0u;
            }
        }
        // The warp's counts of this round, one atomic each where it has any (every thread is here).
        invalid = warpSum(invalid);
        culled = warpSum(culled);
        if (lane == 0u) {
            if (invalid != 0u) addStat(b, COUNTER_INVALID, invalid);
            if (culled != 0u) addStat(b, COUNTER_CULLED, culled);
        }
        // The next round writes the vertices again.
        if (lod) __syncwarp();
    }
}

}  // namespace sr
