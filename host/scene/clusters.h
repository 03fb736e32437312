// clusters.h - a scene's triangles split into clusters (meshlets) at load time: the geometry unit of the
// cluster path (issue 28) and, later, of level of detail.
//
// A cluster holds at most kClusterMaxVertices vertices and kClusterMaxTriangles triangles (the sizes
// hardware mesh shaders use: 64 vertices fit a warp's two passes, 124 triangles keep the 8-bit local
// index list a multiple of 4 bytes). Debian's meshoptimizer 0.18 builds them (meshopt_buildMeshlets,
// which grows each cluster from its neighbours and weighs the normal spread) in chunks of consecutive
// triangles on every core; the bounding sphere's centre is meshopt_computeMeshletBounds', and the radius
// and facing bounds of stage clusters (common/shared/cluster.h) are computed here, in double. Clusters
// reorder the triangles, so each keeps the scene id of every triangle it holds: the id AOV goes on naming
// the scene's triangles. Clusters serve visibility, which reads vertex positions alone: a cluster's
// vertices are scene vertices, and vertices at the same position (bitwise; OBJ gives every face corner
// its own vertex) are one to the clusters, named by the first of them in the chunk, as they transform and
// snap to the same bits. Shading goes on reading the scene's own vertices by triangle id.
#ifndef RASTER_CLUSTERS_H
#define RASTER_CLUSTERS_H

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "raster_shared.h"

namespace sr {

struct Scene;

constexpr uint32_t kClusterMaxVertices = CLUSTER_MAX_VERTICES;
constexpr uint32_t kClusterMaxTriangles = CLUSTER_MAX_TRIANGLES;

struct Cluster {
    uint32_t vertexOffset = 0;    // first of its vertices in ClusterSet::vertices
    uint32_t triangleOffset = 0;  // first of its triangles in ClusterSet::triangleIds (x3 in localIndices)
    uint32_t vertexCount = 0;     // 1 .. kClusterMaxVertices
    uint32_t triangleCount = 0;   // 1 .. kClusterMaxTriangles
    // Bounding sphere in world space: centre xyz, radius w; every vertex of the cluster lies inside. An
    // infinite radius (a vertex that is not finite, or beyond 1e18) never culls.
    glm::vec4 sphere{0.0f};
    // The facing bounds of GpuCluster (common/raster_shared.h, common/shared/cluster.h): cone = axis a
    // xyz, spread beta >= |n - a| over the unit normals n of its triangles (by their winding);
    // coneBounds = h <= n . (p - c), -H with H >= n . (p - c) (p any corner, c the centre), and rho <= the
    // smallest inradius, 0 when a triangle is degenerate or double-sided (never culled by facing).
    glm::vec4 cone{0.0f, 0.0f, 1.0f, 2.0f};
    glm::vec4 coneBounds{0.0f};
};

struct ClusterSet {
    std::vector<Cluster> clusters;
    std::vector<uint32_t> vertices;  // the scene vertex of each cluster-local vertex (first at its position)
    std::vector<uint8_t> localIndices;  // three per cluster triangle, indices into its cluster's vertices
    std::vector<uint32_t> triangleIds;  // the scene triangle of each cluster triangle, wound as in the scene
};

// The clusters of every triangle of the scene (lines and points are not clustered). Each scene triangle
// lands in exactly one cluster with its three corners in the scene's order (each corner the scene's
// vertex or the first vertex at its position). A scene with an index out of range has no clusters (its
// triangles go through setup, which counts them invalid).
ClusterSet buildClusters(const Scene& scene);
// The same for the scene triangles `triangles` alone (empty: every triangle), in clusters of their own.
ClusterSet buildClusters(const Scene& scene, const std::vector<uint32_t>& triangles);

// A cluster's bounding radius and facing bounds from its vertices and triangles, the sphere's centre
// already set (`triFlags` indexed by the set's triangle ids): what buildClusters computes for its own.
void clusterBounds(const std::vector<glm::vec4>& positions, const std::vector<uint32_t>& triFlags,
                   const ClusterSet& set, Cluster& c);

// Whether every triangle of `c` faces away from a viewer at world position `eye` (n . (p - eye) > 0 for
// every triangle, n its unit normal by its winding, p a corner) by the cluster's facing bounds. World
// space only: the pipeline's facing rule is the sign of the snapped window-space area, which
// clusterCull adds its margins for.
bool clusterConeBackFacing(const Cluster& c, const glm::vec3& eye);

// The GPU form of a cluster set: a GpuCluster per cluster (BUF_CLUSTERS) and BUF_CLUSTER_DATA (every
// cluster's vertex list, then two words per triangle: its scene id, its corners 8 bits each with
// CLUSTER_TRI_DOUBLE_SIDED from the scene's triangle flags `triFlags`).
// With `lod` (one per cluster, host/scene/lod.h), BUF_CLUSTER_DATA begins with every cluster's
// CLUSTER_LOD_WORDS level-of-detail words, then every block's (common/shared/cluster.h).
struct ClusterLod;
void gpuClusters(const ClusterSet& set, const std::vector<uint32_t>& triFlags,
                 std::vector<GpuCluster>& clusters, std::vector<uint32_t>& data,
                 const std::vector<ClusterLod>* lod = nullptr);

// RasterParams' cluster fields for a frame of `p` (clipFromWorld, width, height, cullMode already set):
// clusterCount, setupFirstPrimitive (the triangles are the clusters' when clusterCount > 0), and the
// planes, camera centre and thresholds of clusterCull. rasterMethod: RASTER_*; the facing test is on for
// the fixed-point methods only, whose facing is the sign of an exact area.
void setClusterParams(RasterParams& p, uint32_t clusterCount, uint32_t rasterMethod);

}  // namespace sr

#endif  // RASTER_CLUSTERS_H
