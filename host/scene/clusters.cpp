// clusters.cpp - building a scene's clusters with meshoptimizer (clusters.h).
#include "scene/clusters.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <meshoptimizer.h>

#include "scene/scene.h"

namespace sr {
namespace {

// meshoptimizer's balance between a cluster's spatial compactness and the spread of its normals (0:
// spatial only; its documentation suggests 0.25 where cone culling is used).
constexpr float kConeWeight = 0.25f;

bool isFinite(const glm::vec4& p)
{
    return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

// The scene triangles sorted by their corner triple, to find the id of a triangle a cluster holds.
class TriangleLookup {
public:
    explicit TriangleLookup(const std::vector<uint32_t>& indices) : indices_(indices)
    {
        const uint32_t count = uint32_t(indices.size() / 3);
        order_.resize(count);
        for (uint32_t t = 0; t < count; ++t) order_[t] = t;
        std::sort(order_.begin(), order_.end(), [&](uint32_t a, uint32_t b) { return key(a) < key(b); });
        taken_.assign(count, false);
    }

    // The lowest untaken scene triangle with corners (a, b, c) in this order, marked taken; or
    // UINT32_MAX when there is none left.
    uint32_t take(uint32_t a, uint32_t b, uint32_t c)
    {
        const std::array<uint32_t, 3> want{a, b, c};
        auto it = std::lower_bound(order_.begin(), order_.end(), want,
                                   [&](uint32_t t, const std::array<uint32_t, 3>& k) { return key(t) < k; });
        for (; it != order_.end() && key(*it) == want; ++it) {
            if (taken_[*it]) continue;
            taken_[*it] = true;
            return *it;
        }
        return UINT32_MAX;
    }

private:
    std::array<uint32_t, 3> key(uint32_t t) const
    {
        return {indices_[3 * size_t(t)], indices_[3 * size_t(t) + 1], indices_[3 * size_t(t) + 2]};
    }

    const std::vector<uint32_t>& indices_;
    std::vector<uint32_t> order_;
    std::vector<bool> taken_;
};

}  // namespace

ClusterSet buildClusters(const Scene& scene)
{
    ClusterSet set;
    const size_t indexCount = scene.indices.size();
    const size_t vertexCount = scene.positions.size();
    if (indexCount == 0 || vertexCount == 0) return set;

    // meshoptimizer reads positions for locality and bounds only; a vertex that is not finite (the GPU
    // drops its triangles) takes the origin here, and the clusters holding one never cull.
    std::vector<glm::vec3> positions(vertexCount);
    std::vector<bool> finite(vertexCount);
    for (size_t v = 0; v < vertexCount; ++v) {
        finite[v] = isFinite(scene.positions[v]);
        positions[v] = finite[v] ? glm::vec3(scene.positions[v]) : glm::vec3(0.0f);
    }

    // Vertices at one position (bitwise) are one vertex to the clusters, named by the first of them: the
    // clusters feed visibility, which reads positions alone, and those transform and snap to the same
    // bits. (OBJ gives every face corner its own vertex; shading reads the scene's own vertices by
    // triangle id.) So 64 vertices of a closed mesh hold about twice their count in triangles.
    std::vector<uint32_t> welded(indexCount);
    const meshopt_Stream stream = {scene.positions.data(), sizeof(glm::vec4), sizeof(glm::vec4)};
    meshopt_generateShadowIndexBufferMulti(welded.data(), scene.indices.data(), indexCount, vertexCount,
                                           &stream, 1);

    const size_t bound = meshopt_buildMeshletsBound(indexCount, kClusterMaxVertices, kClusterMaxTriangles);
    std::vector<meshopt_Meshlet> meshlets(bound);
    std::vector<unsigned int> vertices(bound * kClusterMaxVertices);
    std::vector<unsigned char> triangles(bound * kClusterMaxTriangles * 3);
    const size_t count = meshopt_buildMeshlets(
        meshlets.data(), vertices.data(), triangles.data(), welded.data(), indexCount, &positions[0].x,
        vertexCount, sizeof(glm::vec3), kClusterMaxVertices, kClusterMaxTriangles, kConeWeight);

    TriangleLookup lookup(welded);
    set.clusters.reserve(count);
    for (size_t k = 0; k < count; ++k) {
        const meshopt_Meshlet& m = meshlets[k];
        Cluster c;
        c.vertexOffset = uint32_t(set.vertices.size());
        c.triangleOffset = uint32_t(set.triangleIds.size());
        c.vertexCount = m.vertex_count;
        c.triangleCount = m.triangle_count;
        const unsigned int* local = &vertices[m.vertex_offset];
        set.vertices.insert(set.vertices.end(), local, local + m.vertex_count);
        bool allFinite = true;
        for (uint32_t i = 0; i < m.vertex_count; ++i) allFinite = allFinite && finite[local[i]];
        for (uint32_t t = 0; t < m.triangle_count; ++t) {
            const unsigned char* tri = &triangles[m.triangle_offset + 3 * size_t(t)];
            // The triangle as the scene winds it: meshoptimizer keeps the corner order, but any rotation
            // of it is the same triangle, so look for each and store the local corners in scene order.
            uint32_t id = UINT32_MAX;
            uint8_t corner[3] = {tri[0], tri[1], tri[2]};
            for (int r = 0; r < 3 && id == UINT32_MAX; ++r) {
                uint8_t a = tri[r], b = tri[(r + 1) % 3], cc = tri[(r + 2) % 3];
                id = lookup.take(local[a], local[b], local[cc]);
                if (id != UINT32_MAX) {
                    corner[0] = a;
                    corner[1] = b;
                    corner[2] = cc;
                }
            }
            set.triangleIds.push_back(id);
            set.localIndices.insert(set.localIndices.end(), corner, corner + 3);
        }
        const meshopt_Bounds b =
            meshopt_computeMeshletBounds(local, &triangles[m.triangle_offset], m.triangle_count,
                                         &positions[0].x, vertexCount, sizeof(glm::vec3));
        c.sphere = glm::vec4(b.center[0], b.center[1], b.center[2], b.radius);
        c.coneApex = glm::vec4(b.cone_apex[0], b.cone_apex[1], b.cone_apex[2], 0.0f);
        c.coneAxis = glm::vec4(b.cone_axis[0], b.cone_axis[1], b.cone_axis[2], b.cone_cutoff);
        if (!allFinite) {
            c.sphere.w = INFINITY;
            c.coneAxis.w = 2.0f;
        }
        set.clusters.push_back(c);
    }
    return set;
}

bool clusterConeBackFacing(const Cluster& c, const glm::vec3& eye)
{
    const glm::vec3 toApex = glm::vec3(c.coneApex) - eye;
    const float length = glm::length(toApex);
    if (!(length > 0.0f) || !(c.coneAxis.w <= 1.0f)) return false;
    return glm::dot(toApex / length, glm::vec3(c.coneAxis)) >= c.coneAxis.w;
}

}  // namespace sr
