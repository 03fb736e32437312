// clusters.comp - stage `clusters`: the scene's triangles cluster by cluster (RasterParams.clusterCount >
// 0), in place of setup's invocation per triangle. CLUSTER_LANES invocations (a subgroup on NVIDIA) take
// one cluster: they cull it whole where every triangle would be culled anyway (clusterCull,
// common/shared/cluster.h), transform its vertices once into shared memory, and set up each triangle from
// there, so small triangles are rasterized and big ones binned exactly as setup would: with fixed8 each
// vertex is also classified and snapped once (clusterVertex) and each triangle set up from its snapped
// corners (clusterSetupTriangle), in one pass (CUDA's two passes ran 16-23% slower here on NVIDIA); a
// clipped triangle takes setup's setupClippedTriangle, and every triangle of the other raster methods
// setup's setupInputTriangle (setup_triangle.glsl), from the clip positions.
// Its triangles are counted in registers, each subgroup adding its sums of a round to its shard of the
// statistics (addThreadCounts, setup_triangle.glsl).
// SR_CPU_BUILD stores every big triangle as a record, as setup's CPU build does (raster_tiles' CPU build
// reads records alone).
// CLUSTERS_PER_GROUP clusters per group; groups = ceil(clusterCount / CLUSTERS_PER_GROUP), or with level
// of detail at most LOD_CLUSTER_GROUPS on a GPU, looping over the clusters stage lod_cut listed (on a CPU
// device every group takes its clusters once: a loop there may not run long, docs/benchmark.md).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "raster_shared.h"
#include "buffers.glsl"
#include "bin.glsl"

layout(local_size_x = CLUSTER_LANES * CLUSTERS_PER_GROUP) in;
#include "setup_triangle.glsl"

shared vec4 clusterClip[CLUSTERS_PER_GROUP][CLUSTER_MAX_VERTICES];
shared ivec4 clusterSnap[CLUSTERS_PER_GROUP][CLUSTER_MAX_VERTICES];  // x, y, depth bits, flags

// Where a subgroup is CLUSTER_LANES wide (NVIDIA's warp) each cluster's invocations are one subgroup, whose
// own barrier is enough between writing the cluster's vertices and reading them: the group's barrier()
// held each subgroup until the group's slowest cluster was transformed (ncu, sphere 10.2M, CUDA's
// clusters kernel on the H200: 20% of its stall samples). Elsewhere (a CPU's narrower subgroups) the
// group's barrier. `subgroupClusters` is the same for the whole dispatch, so both take uniform control flow.
void clusterBarrier(bool subgroupClusters)
{
    if (subgroupClusters) {
        subgroupMemoryBarrierShared();
        subgroupBarrier();
    } else {
        barrier();
    }
}

void main()
{
    ThreadCounts counts;
    counts.bits = 0u;
    const bool subgroupClusters =
        gl_SubgroupSize == uint(CLUSTER_LANES) && gl_NumSubgroups == uint(CLUSTERS_PER_GROUP);
    uint slot = subgroupClusters ? gl_SubgroupID : gl_LocalInvocationID.x / uint(CLUSTER_LANES);
    uint lane = subgroupClusters ? gl_SubgroupInvocationID : gl_LocalInvocationID.x % uint(CLUSTER_LANES);
    // With level of detail (lodScale > 0) stage lod_cut listed the clusters to draw in BUF_LOD_CUT, and
    // the groups (LOD_CLUSTER_GROUPS) loop over that list; without, each group takes its clusters once.
    // The loop's bounds are the group's own: every invocation reaches each barrier() alike.
    const bool lod = params.lodScale > 0.0f;
    const uint total = lod ? counters[COUNTER_LOD_CLUSTERS] : params.clusterCount;
    const uint stride = lod ? gl_NumWorkGroups.x * uint(CLUSTERS_PER_GROUP) : total;
    for (uint first = gl_WorkGroupID.x * uint(CLUSTERS_PER_GROUP); first < total; first += stride) {
        uint entry = first + slot;
        GpuCluster c;
        uint verdict = CLUSTER_FRUSTUM_CULLED;  // past the last cluster: nothing to do
        // The lane's first triangle (its input index and corners) and the scene indices of its vertices,
        // requested as soon as the cluster's record is here: their loads overlap the cull's arithmetic (a
        // culled cluster wastes them). Each round of the triangle loop then fetches the lane's next
        // triangle. With the vertices' loads below, the 10.2M sphere -5% and the 100M sphere -11% on the
        // H200 (CUDA's clusters keep these loads after the cull, where they measured 3% faster).
        uint index[CLUSTER_VERTEX_ROUNDS];
        uint t = lane, tri = 0u, corners = 0u;
        if (entry < total) {
            c = clusters[lod ? lodCut[entry] : entry];
            if (t < c.triangleCount) {
                tri = clusterData[c.triangleOffset + 2u * t];
                corners = clusterData[c.triangleOffset + 2u * t + 1u];
            }
            for (uint r = 0u; r < CLUSTER_VERTEX_ROUNDS; ++r) {
                uint v = lane + r * uint(CLUSTER_LANES);
                index[r] = v < c.vertexCount ? clusterData[c.vertexOffset + v] : 0u;
            }
            verdict = clusterCull(params, c);
            if (verdict != CLUSTER_DRAWN && lane == 0u) {
                addStat(COUNTER_CULLED, c.triangleCount);
                addStat(COUNTER_CLUSTERS_CULLED, 1u);
            }
        }
        if (verdict == CLUSTER_DRAWN) {
            // A lane's vertices all requested before any is transformed (cuda/clusters.cuh says why).
            vec4 world[CLUSTER_VERTEX_ROUNDS];
            for (uint r = 0u; r < CLUSTER_VERTEX_ROUNDS; ++r) {
                uint v = lane + r * uint(CLUSTER_LANES);
                world[r] = v < c.vertexCount ? positions[index[r]] : vec4(0.0f);
            }
            for (uint r = 0u; r < CLUSTER_VERTEX_ROUNDS; ++r) {
                uint v = lane + r * uint(CLUSTER_LANES);
                if (v >= c.vertexCount) break;
                vec4 clip = mulPoint(params.clipFromWorld, world[r]);
                clusterClip[slot][v] = clip;
#if RASTER_METHOD == RASTER_FIXED8
                ivec2 xy;
                float z;
                uint flags = clusterVertex(clip, params.guardBand, params.width, params.height, xy, z);
                clusterSnap[slot][v] = ivec4(xy.x, xy.y, int(floatBitsToUint(z)), int(flags));
#endif
            }
        }
        clusterBarrier(subgroupClusters);  // every invocation of the group reaches it: no return above
        if (verdict == CLUSTER_DRAWN) {
            for (; t < c.triangleCount; t += uint(CLUSTER_LANES)) {
                uint nextTri = 0u, nextCorners = 0u;
                if (t + uint(CLUSTER_LANES) < c.triangleCount) {
                    nextTri = clusterData[c.triangleOffset + 2u * (t + uint(CLUSTER_LANES))];
                    nextCorners = clusterData[c.triangleOffset + 2u * (t + uint(CLUSTER_LANES)) + 1u];
                }
                uint k0 = clusterCorner(corners, 0u), k1 = clusterCorner(corners, 1u),
                     k2 = clusterCorner(corners, 2u);
#if RASTER_METHOD == RASTER_FIXED8
                ivec4 s0 = clusterSnap[slot][k0], s1 = clusterSnap[slot][k1], s2 = clusterSnap[slot][k2];
                TriSetup setup;
                uint kind = clusterSetupTriangle(
                    uint(s0.w), uint(s1.w), uint(s2.w), ivec2(s0.x, s0.y), ivec2(s1.x, s1.y),
                    ivec2(s2.x, s2.y), uintBitsToFloat(uint(s0.z)), uintBitsToFloat(uint(s1.z)),
                    uintBitsToFloat(uint(s2.z)), tri, (corners & CLUSTER_TRI_DOUBLE_SIDED) != 0u,
                    params.cullMode, params.width, params.height, params.sampleBounds, setup);
                if (kind == PREPARE_DIRECT)
                    emitTriangle(setup, STORED_AS_RECORD(false), counts);
                else if (kind == PREPARE_CLIPPED)
                    setupClippedTriangle(tri, clusterClip[slot][k0], clusterClip[slot][k1],
                                         clusterClip[slot][k2], counts);
                else if (kind == PREPARE_CULLED)
                    countPrimitive(counts, COUNTER_CULLED);
                else
                    countPrimitive(counts, COUNTER_INVALID);
#else
                setupInputTriangle(tri, clusterClip[slot][k0], clusterClip[slot][k1], clusterClip[slot][k2],
                                   counts);
#endif
                tri = nextTri;
                corners = nextCorners;
            }
        }
        // The subgroups' counts of this round (every invocation is here).
        addThreadCounts(counts);
        // The next round writes the vertices again.
        if (lod) clusterBarrier(subgroupClusters);
    }
}
