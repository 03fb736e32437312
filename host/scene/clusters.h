// clusters.h - a scene's triangles split into clusters (meshlets) at load time: the geometry unit of the
// cluster path (issue 28) and, later, of level of detail.
//
// A cluster holds at most kClusterMaxVertices vertices and kClusterMaxTriangles triangles (the sizes
// hardware mesh shaders use: 64 vertices fit a warp's two passes, 124 triangles keep the 8-bit local
// index list a multiple of 4 bytes). Debian's meshoptimizer 0.18 builds them (meshopt_buildMeshlets,
// which grows each cluster from its neighbours and weighs the normal spread for a tight cone) and their
// bounds (meshopt_computeMeshletBounds). Clusters reorder the triangles, so each keeps the scene id of
// every triangle it holds: the id AOV goes on naming the scene's triangles. Clusters serve visibility,
// which reads vertex positions alone: a cluster's vertices are scene vertices, and vertices at the same
// position (bitwise; OBJ gives every face corner its own vertex) are one to the clusters, named by the
// first of them, as they transform and snap to the same bits. Shading goes on reading the scene's own
// vertices by triangle id.
#ifndef RASTER_CLUSTERS_H
#define RASTER_CLUSTERS_H

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace sr {

struct Scene;

constexpr uint32_t kClusterMaxVertices = 64;
constexpr uint32_t kClusterMaxTriangles = 124;

struct Cluster {
    uint32_t vertexOffset = 0;    // first of its vertices in ClusterSet::vertices
    uint32_t triangleOffset = 0;  // first of its triangles in ClusterSet::triangleIds (x3 in localIndices)
    uint32_t vertexCount = 0;     // 1 .. kClusterMaxVertices
    uint32_t triangleCount = 0;   // 1 .. kClusterMaxTriangles
    // Bounding sphere in world space: centre xyz, radius w; every vertex of the cluster lies inside.
    glm::vec4 sphere{0.0f};
    // Normal cone: apex xyz (w unused) and axis xyz, cutoff w. Every triangle of the cluster faces away
    // from a viewer at v where dot(normalize(apex - v), axis) >= cutoff (clusterConeBackFacing). A cutoff
    // above 1 never culls: clusters whose normals spread too far, or with a degenerate triangle.
    glm::vec4 coneApex{0.0f};
    glm::vec4 coneAxis{0.0f, 0.0f, 0.0f, 2.0f};
};

struct ClusterSet {
    std::vector<Cluster> clusters;
    std::vector<uint32_t> vertices;  // the scene vertex of each cluster-local vertex (first at its position)
    std::vector<uint8_t> localIndices;  // three per cluster triangle, indices into its cluster's vertices
    std::vector<uint32_t> triangleIds;  // the scene triangle of each cluster triangle, wound as in the scene
};

// The clusters of every triangle of the scene (lines and points are not clustered). Each scene triangle
// lands in exactly one cluster with its three corners in the scene's order (each corner the scene's
// vertex or the first vertex at its position).
ClusterSet buildClusters(const Scene& scene);

// Whether every triangle of `c` faces away from a viewer at world position `eye` by the cluster's cone
// (meshoptimizer's test on the apex). World-space facing only: the pipeline's facing rule is the sign of
// the snapped window-space area, which a cluster stage must respect on its own.
bool clusterConeBackFacing(const Cluster& c, const glm::vec3& eye);

}  // namespace sr

#endif  // RASTER_CLUSTERS_H
