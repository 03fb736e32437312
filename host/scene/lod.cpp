// lod.cpp - building a scene's cluster hierarchy with meshoptimizer, and the host's side of the cut
// (lod.h).
#include "scene/lod.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <numeric>
#include <thread>
#include <utility>

#include <meshoptimizer.h>

#include "raster_shared.h"
#include "scene/scene.h"

namespace sr {

namespace {

// meshoptimizer's balance of compactness and normal spread, as for the scene's own clusters.
constexpr float kConeWeight = 0.25f;
// Levels at most (a level halves the triangles: 2^32 triangles need 32).
constexpr uint32_t kMaxLevels = 32;

// Runs body(i) for i in [0, count) on every core.
void parallelFor(size_t count, const std::function<void(size_t)>& body)
{
    std::atomic<size_t> next{0};
    auto work = [&] {
        for (size_t i = next++; i < count; i = next++) body(i);
    };
    const size_t threads = std::min<size_t>(count, std::max(1u, std::thread::hardware_concurrency()));
    std::vector<std::thread> pool;
    for (size_t t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
}

std::array<uint32_t, 3> positionBits(const glm::vec4& p)
{
    std::array<uint32_t, 3> bits;
    std::memcpy(bits.data(), &p.x, sizeof bits);
    return bits;
}

// weld[v]: the lowest vertex whose position has v's bits.
std::vector<uint32_t> weldVertices(const std::vector<glm::vec4>& positions)
{
    std::vector<uint32_t> order(positions.size());
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        const auto ka = positionBits(positions[a]), kb = positionBits(positions[b]);
        return ka != kb ? ka < kb : a < b;
    });
    std::vector<uint32_t> weld(positions.size());
    for (size_t i = 0; i < order.size();) {
        size_t j = i;
        const auto key = positionBits(positions[order[i]]);
        for (; j < order.size() && positionBits(positions[order[j]]) == key; ++j) weld[order[j]] = order[i];
        i = j;
    }
    return weld;
}

// The smallest sphere about the centre of their bounding box that holds every sphere, widened by
// kLodSphereWidening and rounded outwards to float.
glm::vec4 enclosingSphere(const std::vector<glm::vec4>& spheres)
{
    glm::dvec3 lo(INFINITY), hi(-INFINITY);
    for (const glm::vec4& s : spheres) {
        lo = glm::min(lo, glm::dvec3(glm::vec3(s)) - double(s.w));
        hi = glm::max(hi, glm::dvec3(glm::vec3(s)) + double(s.w));
    }
    const glm::vec3 centre = glm::vec3(0.5 * (lo + hi));
    double radius = 0.0;
    for (const glm::vec4& s : spheres)
        radius = std::max(radius, glm::length(glm::dvec3(glm::vec3(s)) - glm::dvec3(centre)) + double(s.w));
    radius *= 1.0 + kLodSphereWidening;
    float r = float(radius);
    if (double(r) < radius) r = std::nextafter(r, INFINITY);
    return glm::vec4(centre, r);
}

// A cluster while the hierarchy is built: its triangles' corners (welded scene vertices), the part it
// belongs to, its own bound, its bounding sphere and its index in the hierarchy's clusters.
struct WorkCluster {
    std::vector<uint32_t> corners;
    uint32_t part = 0;
    LodBound own;
    glm::vec4 sphere{0.0f};
    uint32_t index = 0;
};

// A group's simplified triangles in clusters: each cluster's vertices (scene vertices) and corners.
struct NewCluster {
    std::vector<uint32_t> vertices;
    std::vector<uint8_t> corners;
    Cluster bounds;  // sphere, cone, coneBounds (offsets unset)
};
struct GroupResult {
    bool simplified = false;
    double error = 0.0;  // meshoptimizer's error in world units
    std::vector<NewCluster> clusters;
};

// The boundary edges of each cluster (edges of one of its triangles only), and from them each
// cluster's neighbours in the same part with the number of edges they share.
std::vector<std::vector<std::pair<uint32_t, uint32_t>>> clusterNeighbours(
    const std::vector<WorkCluster>& work, const std::vector<uint32_t>& active)
{
    std::vector<std::vector<uint64_t>> perCluster(active.size());
    parallelFor(active.size(), [&](size_t i) {
        const std::vector<uint32_t>& c = work[active[i]].corners;
        std::vector<uint64_t> edges;
        edges.reserve(c.size());
        for (size_t t = 0; t + 2 < c.size(); t += 3)
            for (int k = 0; k < 3; ++k) {
                const uint32_t a = c[t + k], b = c[t + (k + 1) % 3];
                edges.push_back(uint64_t(std::min(a, b)) << 32 | std::max(a, b));
            }
        std::sort(edges.begin(), edges.end());
        std::vector<uint64_t>& border = perCluster[i];
        for (size_t e = 0; e < edges.size();) {
            size_t f = e;
            while (f < edges.size() && edges[f] == edges[e]) ++f;
            if (f - e == 1) border.push_back(edges[e]);
            e = f;
        }
    });
    std::vector<std::pair<uint64_t, uint32_t>> edges;
    for (size_t i = 0; i < active.size(); ++i)
        for (uint64_t e : perCluster[i]) edges.emplace_back(e, uint32_t(i));
    perCluster.clear();
    std::sort(edges.begin(), edges.end());
    std::vector<std::pair<uint32_t, uint32_t>> pairs;
    for (size_t e = 0; e < edges.size();) {
        size_t f = e;
        while (f < edges.size() && edges[f].first == edges[e].first) ++f;
        for (size_t a = e; a < f; ++a)
            for (size_t b = e; b < f; ++b)
                if (edges[a].second != edges[b].second &&
                    work[active[edges[a].second]].part == work[active[edges[b].second]].part)
                    pairs.emplace_back(edges[a].second, edges[b].second);
        e = f;
    }
    edges.clear();
    std::sort(pairs.begin(), pairs.end());
    std::vector<std::vector<std::pair<uint32_t, uint32_t>>> neighbours(active.size());
    for (size_t p = 0; p < pairs.size();) {
        size_t q = p;
        while (q < pairs.size() && pairs[q] == pairs[p]) ++q;
        neighbours[pairs[p].first].emplace_back(pairs[p].second, uint32_t(q - p));
        p = q;
    }
    return neighbours;
}

// Morton code of a point in the box [lo, hi], 10 bits per axis.
uint32_t morton(const glm::vec3& p, const glm::vec3& lo, const glm::vec3& hi)
{
    auto spread = [](uint32_t v) {
        v = (v | (v << 16)) & 0x030000FFu;
        v = (v | (v << 8)) & 0x0300F00Fu;
        v = (v | (v << 4)) & 0x030C30C3u;
        return (v | (v << 2)) & 0x09249249u;
    };
    uint32_t q[3];
    for (int k = 0; k < 3; ++k) {
        const float extent = hi[k] - lo[k];
        const float t = extent > 0.0f ? (p[k] - lo[k]) / extent : 0.0f;
        q[k] = uint32_t(std::clamp(t, 0.0f, 1.0f) * 1023.0f);
    }
    return spread(q[0]) | spread(q[1]) << 1 | spread(q[2]) << 2;
}

// Groups of up to kLodGroupClusters neighbouring clusters (indices into `active`): seeds taken along a
// Morton curve of the clusters' centres within each part, each grown by the neighbour that shares the
// most edges with it (the first in curve order on a tie).
std::vector<std::vector<uint32_t>> groupClusters(const std::vector<WorkCluster>& work,
                                                 const std::vector<uint32_t>& active)
{
    const auto neighbours = clusterNeighbours(work, active);
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (uint32_t k : active) {
        lo = glm::min(lo, glm::vec3(work[k].sphere));
        hi = glm::max(hi, glm::vec3(work[k].sphere));
    }
    std::vector<std::pair<uint64_t, uint32_t>> order(active.size());
    for (size_t i = 0; i < active.size(); ++i)
        order[i] = {uint64_t(work[active[i]].part) << 32 | morton(glm::vec3(work[active[i]].sphere), lo, hi),
                    uint32_t(i)};
    std::sort(order.begin(), order.end());
    std::vector<uint32_t> rank(active.size());
    for (size_t r = 0; r < order.size(); ++r) rank[order[r].second] = uint32_t(r);

    std::vector<bool> grouped(active.size(), false);
    std::vector<std::vector<uint32_t>> groups;
    std::map<uint32_t, uint32_t> score;  // candidate -> shared edges with the group
    for (const auto& seed : order) {
        if (grouped[seed.second]) continue;
        std::vector<uint32_t> group{seed.second};
        grouped[seed.second] = true;
        while (group.size() < kLodGroupClusters) {
            score.clear();
            for (uint32_t m : group)
                for (const auto& [n, shared] : neighbours[m])
                    if (!grouped[n]) score[n] += shared;
            uint32_t best = UINT32_MAX, bestScore = 0;
            for (const auto& [n, s] : score)
                if (s > bestScore || (s == bestScore && best != UINT32_MAX && rank[n] < rank[best])) {
                    best = n;
                    bestScore = s;
                }
            if (best == UINT32_MAX) break;
            group.push_back(best);
            grouped[best] = true;
        }
        groups.push_back(std::move(group));
    }
    return groups;
}

// Simplifies a group (its members' corners) to half its triangles with its border locked and splits
// the result into clusters.
GroupResult simplifyGroup(const Scene& scene, const std::vector<WorkCluster>& work,
                          const std::vector<uint32_t>& members, uint32_t partFlags)
{
    GroupResult result;
    std::vector<uint32_t> corners;
    for (uint32_t m : members) corners.insert(corners.end(), work[m].corners.begin(), work[m].corners.end());
    std::vector<uint32_t> vertices = corners;
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    std::vector<uint32_t> local(corners.size());
    for (size_t i = 0; i < corners.size(); ++i)
        local[i] =
            uint32_t(std::lower_bound(vertices.begin(), vertices.end(), corners[i]) - vertices.begin());
    std::vector<glm::vec3> positions(vertices.size());
    for (size_t v = 0; v < vertices.size(); ++v) positions[v] = glm::vec3(scene.positions[vertices[v]]);

    const size_t triangles = corners.size() / 3;
    const size_t target = 3 * (triangles / 2);
    std::vector<uint32_t> simplified(corners.size());
    float relativeError = 0.0f;
    const size_t count =
        meshopt_simplify(simplified.data(), local.data(), local.size(), &positions[0].x, positions.size(),
                         sizeof(glm::vec3), target, 1.0f, meshopt_SimplifyLockBorder, &relativeError);
    if (count == 0 || double(count) > kLodMinReduction * double(local.size())) return result;
    simplified.resize(count);
    result.simplified = true;
    result.error = double(relativeError) *
                   double(meshopt_simplifyScale(&positions[0].x, positions.size(), sizeof(glm::vec3)));

    const size_t bound = meshopt_buildMeshletsBound(count, kClusterMaxVertices, kClusterMaxTriangles);
    std::vector<meshopt_Meshlet> meshlets(bound);
    std::vector<unsigned int> meshletVertices(bound * kClusterMaxVertices);
    std::vector<unsigned char> meshletTriangles(bound * kClusterMaxTriangles * 3);
    const size_t made =
        meshopt_buildMeshlets(meshlets.data(), meshletVertices.data(), meshletTriangles.data(),
                              simplified.data(), count, &positions[0].x, positions.size(), sizeof(glm::vec3),
                              kClusterMaxVertices, kClusterMaxTriangles, kConeWeight);
    const std::vector<uint32_t> flags{partFlags};
    for (size_t k = 0; k < made; ++k) {
        const meshopt_Meshlet& m = meshlets[k];
        NewCluster c;
        glm::vec3 lo(INFINITY), hi(-INFINITY);
        for (uint32_t v = 0; v < m.vertex_count; ++v) {
            const uint32_t lv = meshletVertices[m.vertex_offset + v];
            c.vertices.push_back(vertices[lv]);
            lo = glm::min(lo, positions[lv]);
            hi = glm::max(hi, positions[lv]);
        }
        c.corners.assign(&meshletTriangles[m.triangle_offset],
                         &meshletTriangles[m.triangle_offset] + 3 * size_t(m.triangle_count));
        // The cone and facing bounds as for the scene's clusters, every triangle with the part's flags.
        ClusterSet one;
        one.vertices = c.vertices;
        one.localIndices = c.corners;
        one.triangleIds.assign(m.triangle_count, 0u);
        c.bounds.vertexCount = m.vertex_count;
        c.bounds.triangleCount = m.triangle_count;
        c.bounds.sphere = glm::vec4(0.5f * (lo + hi), 0.0f);
        clusterBounds(scene.positions, flags, one, c.bounds);
        result.clusters.push_back(std::move(c));
    }
    return result;
}

}  // namespace

LodHierarchy buildLodHierarchy(const Scene& scene)
{
    LodHierarchy h;
    const size_t sceneTriangles = scene.indices.size() / 3;
    h.sceneTriangles = uint32_t(sceneTriangles);
    if (sceneTriangles == 0) return h;

    // Level 0: the scene's clusters, part by part (a part: one material and one set of flags).
    const bool materials = !scene.materials.empty();
    std::map<std::pair<uint32_t, uint32_t>, std::vector<uint32_t>> partTriangles;
    for (uint32_t t = 0; t < sceneTriangles; ++t)
        partTriangles[{materials ? scene.triMaterials[t] : 0u, scene.triFlags[t]}].push_back(t);
    std::vector<std::pair<uint32_t, uint32_t>> parts;  // (material, flags) per part
    std::vector<WorkCluster> work;
    const std::vector<uint32_t> weld = weldVertices(scene.positions);
    for (auto& [key, triangles] : partTriangles) {
        ClusterSet set = partTriangles.size() == 1 ? buildClusters(scene) : buildClusters(scene, triangles);
        if (set.clusters.empty()) return LodHierarchy{};
        triangles.clear();
        const auto part = uint32_t(parts.size());
        parts.push_back(key);
        const auto base = uint32_t(h.clusters.clusters.size());
        const auto vertexBase = uint32_t(h.clusters.vertices.size());
        const auto triangleBase = uint32_t(h.clusters.triangleIds.size());
        for (size_t k = 0; k < set.clusters.size(); ++k) {
            Cluster c = set.clusters[k];
            WorkCluster w;
            w.part = part;
            w.sphere = c.sphere;
            w.own.sphere = c.sphere;
            w.index = base + uint32_t(k);
            for (uint32_t t = 0; t < c.triangleCount; ++t)
                for (uint32_t i = 0; i < 3; ++i)
                    w.corners.push_back(
                        weld[set.vertices[c.vertexOffset +
                                          set.localIndices[3 * size_t(c.triangleOffset + t) + i]]]);
            c.vertexOffset += vertexBase;
            c.triangleOffset += triangleBase;
            h.clusters.clusters.push_back(c);
            h.level.push_back(0);
            h.ownGroup.push_back(kLodNoGroup);
            h.parentGroup.push_back(kLodNoGroup);
            h.bounds.push_back(ClusterLod{w.own, LodBound{}});
            work.push_back(std::move(w));
        }
        h.clusters.vertices.insert(h.clusters.vertices.end(), set.vertices.begin(), set.vertices.end());
        h.clusters.triangleIds.insert(h.clusters.triangleIds.end(), set.triangleIds.begin(),
                                      set.triangleIds.end());
        h.clusters.localIndices.insert(h.clusters.localIndices.end(), set.localIndices.begin(),
                                       set.localIndices.end());
    }
    // A scene triangle at each vertex (for the id AOV of simplified triangles).
    std::vector<uint32_t> vertexTriangle(scene.positions.size(), 0u);
    for (size_t t = sceneTriangles; t-- > 0;)
        for (int k = 0; k < 3; ++k) vertexTriangle[weld[scene.indices[3 * t + k]]] = uint32_t(t);

    h.levels = 1;
    for (uint32_t level = 1; level < kMaxLevels; ++level) {
        // The clusters of the level below that may be simplified: finite, in a part of more than one.
        std::vector<uint32_t> active;
        std::vector<uint32_t> perPart(parts.size(), 0u);
        for (uint32_t k = 0; k < work.size(); ++k)
            if (std::isfinite(work[k].sphere.w)) ++perPart[work[k].part];
        for (uint32_t k = 0; k < work.size(); ++k)
            if (std::isfinite(work[k].sphere.w) && perPart[work[k].part] > 1) active.push_back(k);
        if (active.empty()) break;
        std::vector<std::vector<uint32_t>> groups = groupClusters(work, active);
        for (auto& g : groups)
            for (uint32_t& m : g) m = active[m];
        std::vector<GroupResult> results(groups.size());
        parallelFor(groups.size(), [&](size_t g) {
            results[g] = simplifyGroup(scene, work, groups[g], parts[work[groups[g][0]].part].second);
        });

        // A group that does not simplify (most of it on its locked border) leaves its clusters to the next
        // level, where they are grouped again with other neighbours; the clusters in no group go on too.
        std::vector<WorkCluster> next;
        std::vector<bool> grouped(work.size(), false);
        for (const auto& g : groups)
            for (uint32_t m : g) grouped[m] = true;
        bool simplified = false;
        for (size_t g = 0; g < groups.size(); ++g) {
            GroupResult& r = results[g];
            if (!r.simplified) {
                for (uint32_t m : groups[g]) next.push_back(std::move(work[m]));
                continue;
            }
            simplified = true;
            // The group's bound: its members' spheres and errors, plus its own simplification's error.
            std::vector<glm::vec4> spheres;
            double error = 0.0;
            for (uint32_t m : groups[g]) {
                spheres.push_back(work[m].own.sphere);
                spheres.push_back(work[m].sphere);
                error = std::max(error, double(work[m].own.error));
            }
            LodBound bound;
            bound.sphere = enclosingSphere(spheres);
            const double total = error + r.error;
            bound.error = float(total);
            if (double(bound.error) < total) bound.error = std::nextafter(bound.error, INFINITY);
            const auto group = uint32_t(h.groups.size());
            h.groups.push_back(bound);
            for (uint32_t m : groups[g]) {
                h.parentGroup[work[m].index] = group;
                h.bounds[work[m].index].parent = bound;
            }
            const uint32_t part = work[groups[g][0]].part;
            for (NewCluster& nc : r.clusters) {
                Cluster c = nc.bounds;
                c.vertexOffset = uint32_t(h.clusters.vertices.size());
                c.triangleOffset = uint32_t(h.clusters.triangleIds.size());
                h.clusters.vertices.insert(h.clusters.vertices.end(), nc.vertices.begin(), nc.vertices.end());
                WorkCluster w;
                w.part = part;
                w.own = bound;
                w.sphere = c.sphere;
                w.index = uint32_t(h.clusters.clusters.size());
                for (uint32_t t = 0; t < c.triangleCount; ++t) {
                    h.clusters.triangleIds.push_back(uint32_t(sceneTriangles + h.sourceIds.size()));
                    for (int k = 0; k < 3; ++k) {
                        const uint8_t corner = nc.corners[3 * size_t(t) + k];
                        h.clusters.localIndices.push_back(corner);
                        h.indices.push_back(nc.vertices[corner]);
                        w.corners.push_back(nc.vertices[corner]);
                    }
                    h.sourceIds.push_back(vertexTriangle[nc.vertices[nc.corners[3 * size_t(t)]]]);
                    h.triFlags.push_back(parts[part].second);
                    if (materials) h.triMaterials.push_back(parts[part].first);
                }
                h.clusters.clusters.push_back(c);
                h.level.push_back(level);
                h.ownGroup.push_back(group);
                h.parentGroup.push_back(kLodNoGroup);
                h.bounds.push_back(ClusterLod{bound, LodBound{}});
                next.push_back(std::move(w));
            }
            r = GroupResult{};
        }
        if (!simplified) break;
        for (uint32_t k = 0; k < work.size(); ++k)
            if (!grouped[k] && std::isfinite(work[k].sphere.w)) next.push_back(std::move(work[k]));
        work = std::move(next);
        h.levels = level + 1;
    }
    // Clusters never simplified are roots: their parent bound is always too coarse.
    for (size_t k = 0; k < h.bounds.size(); ++k)
        if (h.parentGroup[k] == kLodNoGroup) h.bounds[k].parent = LodBound{h.bounds[k].own.sphere, INFINITY};
    return h;
}

LodBlock lodBlock(const ClusterLod* bounds, size_t count)
{
    LodBlock block;
    std::vector<glm::vec4> parents, owns;
    block.parent.error = 0.0f;
    block.own.error = INFINITY;
    for (size_t k = 0; k < count; ++k) {
        const ClusterLod& b = bounds[k];
        for (const glm::vec4& sphere : {b.parent.sphere, b.own.sphere})
            block.skippable = block.skippable && std::isfinite(sphere.x) && std::isfinite(sphere.y) &&
                              std::isfinite(sphere.z) && std::isfinite(sphere.w);
        block.skippable = block.skippable && std::isfinite(b.parent.error);
        parents.push_back(b.parent.sphere);
        owns.push_back(b.own.sphere);
        block.parent.error = std::max(block.parent.error, b.parent.error);
        block.own.error = std::min(block.own.error, b.own.error);
    }
    if (!block.skippable) return block;
    block.parent.sphere = enclosingSphere(parents);
    block.own.sphere = enclosingSphere(owns);
    return block;
}

uint64_t LodHierarchy::deviceBytes() const
{
    const uint64_t words = clusters.vertices.size() + 2 * clusters.triangleIds.size() +
                           CLUSTER_LOD_WORDS * clusters.clusters.size();
    return clusters.clusters.size() * sizeof(GpuCluster) + words * sizeof(uint32_t) +
           (indices.size() + triFlags.size() + triMaterials.size()) * sizeof(uint32_t);
}

Scene lodScene(const Scene& scene, const LodHierarchy& lod)
{
    Scene out = scene;
    out.indices.insert(out.indices.end(), lod.indices.begin(), lod.indices.end());
    out.triFlags.insert(out.triFlags.end(), lod.triFlags.begin(), lod.triFlags.end());
    if (!out.materials.empty())
        out.triMaterials.insert(out.triMaterials.end(), lod.triMaterials.begin(), lod.triMaterials.end());
    return out;
}

void setLodParams(RasterParams& p, float errorPx)
{
    const glm::mat4& m = p.clipFromWorld;
    auto rowLength = [&](int i) { return glm::length(glm::dvec3(m[0][i], m[1][i], m[2][i])); };
    // Pixels of the output per world unit at clip w = 1, in the direction that projects largest.
    const double ssaa = std::max(1u, p.ssaa);
    const double k = std::max(0.5 * p.width * rowLength(0), 0.5 * p.height * rowLength(1)) / ssaa;
    p.lodScale = float(k / double(errorPx));
    p.lodWLength = float(rowLength(3));
}

bool lodClusterDrawn(const RasterParams& p, const LodHierarchy& lod, size_t k)
{
    const ClusterLod& b = lod.bounds[k];
    return clusterLodDrawn(p, b.own.sphere, b.own.error, b.parent.sphere, b.parent.error);
}

uint32_t lodAovId(uint32_t id, const LodHierarchy& lod)
{
    if (id == EMPTY_ID || id < lod.sceneTriangles) return id;
    const auto simplified = uint32_t(lod.sourceIds.size());
    if (id - lod.sceneTriangles < simplified) return lod.sourceIds[id - lod.sceneTriangles];
    return id - simplified;
}

}  // namespace sr
