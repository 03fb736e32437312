// lod.h - continuous level of detail: a mesh's cluster hierarchy, built at load time in the manner of
// Nanite (issue 29), and the per-frame cut through it (common/shared/cluster.h's clusterLodDrawn).
//
// Level 0 is the scene's triangles in clusters (buildClusters), one set per part of the mesh that may be
// simplified as one: triangles of one material and the same TRI_FLAG_* bits. Each further level groups
// neighbouring clusters of the level below (up to kLodGroupClusters, grown greedily along the edges they
// share), simplifies each group to half its triangles with meshoptimizer (meshopt_simplify with
// meshopt_SimplifyLockBorder: the group's outer border stays where it is, so groups drawn at different
// levels still meet edge to edge) and splits the result into clusters again, until a part has one cluster
// or its groups no longer simplify. Vertices at one position (bitwise) are one vertex throughout: the
// simplified triangles' corners are scene vertices, the first at their position.
//
// Each group has a bound, a sphere and an error in world units: the error is the largest of its members'
// plus meshoptimizer's error for the group (the distance the simplified surface may lie from the
// original, bounded by the sum over the levels); the sphere contains its members' bounds' spheres (and
// their clusters), widened by a relative 2^-10. So a group's bound contains its members' (the choice is
// monotonic). A cluster keeps its own bound (the group it came from; error 0 at level 0) and its
// parent's (the group it is simplified in; an infinite error for a cluster that is never simplified).
//
// The simplified triangles are triangles sceneTriangles + k of lodScene(): ids past the scene's, whose
// materials and flags are their part's. The id AOV names them by a scene triangle at their first corner
// (lodAovId).
#ifndef RASTER_LOD_H
#define RASTER_LOD_H

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/clusters.h"

namespace sr {

struct Scene;
struct RasterParams;

constexpr uint32_t kLodGroupClusters = 8;  // clusters per group, at most
constexpr double kLodMinReduction = 0.85;  // a group simplified to more than this share stops there
constexpr double kLodSphereWidening = 1.0 / 1024.0;
constexpr uint32_t kLodNoGroup = UINT32_MAX;

// A sphere (xyz centre, w radius, world units) and a geometric error (world units).
struct LodBound {
    glm::vec4 sphere{0.0f};
    float error = 0.0f;
};

// A cluster's two bounds, as its CLUSTER_LOD_WORDS hold them.
struct ClusterLod {
    LodBound own;     // the group it was simplified from; error 0 for the scene's own clusters
    LodBound parent;  // the group it is simplified in; error infinite where there is none
};

struct LodHierarchy {
    ClusterSet clusters;                // every level; triangle ids index lodScene()'s triangles
    std::vector<ClusterLod> bounds;     // per cluster
    std::vector<uint32_t> level;        // per cluster: 0 for the scene's triangles
    std::vector<uint32_t> ownGroup;     // per cluster: the group it came from (kLodNoGroup at level 0)
    std::vector<uint32_t> parentGroup;  // per cluster: the group it is simplified in (kLodNoGroup: none)
    std::vector<LodBound> groups;       // per group
    uint32_t sceneTriangles = 0;     // the scene's triangles: simplified triangle k has id sceneTriangles + k
    std::vector<uint32_t> indices;   // 3 per simplified triangle: scene vertices
    std::vector<uint32_t> triFlags;  // per simplified triangle: its part's TRI_FLAG_* bits
    std::vector<uint32_t>
        triMaterials;                 // per simplified triangle: its part's material (when the scene has any)
    std::vector<uint32_t> sourceIds;  // per simplified triangle: a scene triangle at its first corner
    uint32_t levels = 0;              // levels built (1: nothing simplified)

    // Host memory of what the hierarchy adds to the scene, in bytes: the clusters and their data as the
    // GPU holds them and the simplified triangles' indices, flags and materials.
    uint64_t deviceBytes() const;
};

// The hierarchy of the scene's triangles. A scene with an index out of range, or with no triangles, has
// none (no clusters).
LodHierarchy buildLodHierarchy(const Scene& scene);

// `scene` with the hierarchy's simplified triangles appended to its triangles (its lines and points
// follow them, their ids moved up by as many).
Scene lodScene(const Scene& scene, const LodHierarchy& lod);

// The bounds of a block of clusters (common/shared/cluster.h's lodBlockSkipped): a sphere holding every
// parent sphere and the largest parent error, a sphere holding every own sphere and the smallest own
// error; `skippable` false where a bound is not finite (the block is never skipped).
struct LodBlock {
    LodBound parent;
    LodBound own;
    bool skippable = true;
};
LodBlock lodBlock(const ClusterLod* bounds, size_t count);

// RasterParams' level-of-detail fields (lodScale, lodWLength) for an error of `errorPx` output pixels;
// the clip transform, width, height, ssaa and clusterPlanes already set (setClusterParams).
void setLodParams(RasterParams& p, float errorPx);

// Whether the frame with `p` draws cluster k (clusterLodDrawn on the host).
bool lodClusterDrawn(const RasterParams& p, const LodHierarchy& lod, size_t k);

// The id AOV's value for primitive `id` of lodScene(): scene triangles keep theirs, a simplified triangle
// takes its sourceIds entry, lines and points move back to the scene's ids; EMPTY_ID stays.
uint32_t lodAovId(uint32_t id, const LodHierarchy& lod);

}  // namespace sr

#endif  // RASTER_LOD_H
