// clusters.cpp - building a scene's clusters with meshoptimizer (clusters.h).
#include "scene/clusters.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <thread>

#include <meshoptimizer.h>

#include "scene/lod.h"
#include "scene/scene.h"

namespace sr {

namespace {

// meshoptimizer's balance between a cluster's spatial compactness and the spread of its normals (0:
// spatial only; its documentation suggests 0.25 where cone culling is used).
constexpr float kConeWeight = 0.25f;

uint32_t floatBits(float f)
{
    uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
}

bool isFinite(const glm::vec4& p)
{
    return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

// The scene triangles sorted by their corner triple (by id among equal ones), to find the id of a
// triangle a cluster holds. Each entry holds its corners, so a search reads the sorted array alone.
class TriangleLookup {
public:
    explicit TriangleLookup(const std::vector<uint32_t>& indices)
    {
        const uint32_t count = uint32_t(indices.size() / 3);
        entries_.resize(count);
        for (uint32_t t = 0; t < count; ++t)
            entries_[t] = {
                {indices[3 * size_t(t)], indices[3 * size_t(t) + 1], indices[3 * size_t(t) + 2]}, t, 0u};
        std::sort(entries_.begin(), entries_.end(), [](const Entry& x, const Entry& y) {
            return x.corners < y.corners || (x.corners == y.corners && x.id < y.id);
        });
    }

    // The lowest untaken scene triangle with corners (a, b, c) in this order, marked taken; or
    // UINT32_MAX when there is none left. Triangles of one corner triple are taken in id order, so the
    // taken ones are the head of their run: its first entry counts them, and n copies of one triangle
    // cost O(n log n) in all, not O(n^2).
    uint32_t take(uint32_t a, uint32_t b, uint32_t c)
    {
        const std::array<uint32_t, 3> want{a, b, c};
        auto it =
            std::lower_bound(entries_.begin(), entries_.end(), want,
                             [](const Entry& e, const std::array<uint32_t, 3>& k) { return e.corners < k; });
        if (it == entries_.end() || it->corners != want) return UINT32_MAX;
        const auto next = it + it->taken;
        if (next == entries_.end() || next->corners != want) return UINT32_MAX;
        ++it->taken;
        return next->id;
    }

private:
    struct Entry {
        std::array<uint32_t, 3> corners;
        uint32_t id;
        uint32_t taken;  // at a run's first entry: how many of the run are taken
    };
    std::vector<Entry> entries_;
};

// Triangles around one vertex that meshoptimizer's clusterizer is given at most. It grows a cluster by
// scanning the triangles around each of the cluster's vertices and removes each triangle it places from
// its corners' lists by a linear search, so a vertex shared by n triangles (a fan's centre, or n copies
// of one degenerate triangle) costs it O(n) per triangle and O(n^2) in all: the campaign's 100,000 such
// triangles took 70 s. A vertex of more than kSplitVertexTriangles triangles is handed to it as copies,
// each shared by at most kMaxVertexTriangles; a cluster that receives several copies of one vertex names
// it once. Vertices up to the threshold (a UV sphere's poles, a cone's apex) are left as they are, so
// that the clusters of such meshes, and the level-of-detail cuts made from them, stay as they were; the
// work is then at most that threshold per triangle.
constexpr uint32_t kSplitVertexTriangles = 1024;
constexpr uint32_t kMaxVertexTriangles = 32;

// Triangles that may share one centroid before they are packed apart (below).
constexpr size_t kMaxCoincidentTriangles = 16;

// Coordinates beyond this make a cluster never cull: their clip positions could overflow to infinity,
// which setup counts invalid, not culled.
constexpr double kLargestCoordinate = 1e18;

// The bounding radius and facing bounds of cluster `c` (its sphere centre already set) from its
// triangles, in double and rounded outwards (cluster.h's tests are only as safe as these bounds).
void facingBounds(const std::vector<glm::vec4>& positions, const std::vector<uint32_t>& triFlags,
                  const ClusterSet& set, bool allFinite, Cluster& c)
{
    const glm::dvec3 centre(glm::vec3(c.sphere));
    double radius = 0.0;
    bool small = true;
    for (uint32_t v = 0; v < c.vertexCount; ++v) {
        const glm::dvec3 p(glm::vec3(positions[set.vertices[c.vertexOffset + v]]));
        radius = std::max(radius, glm::length(p - centre));
        small = small && std::abs(p.x) < kLargestCoordinate && std::abs(p.y) < kLargestCoordinate &&
                std::abs(p.z) < kLargestCoordinate;
    }
    if (!allFinite || !small) {
        c.sphere.w = INFINITY;
        c.coneBounds = glm::vec4(0.0f);
        return;
    }
    c.sphere.w = float(radius * (1.0 + 1e-6)) + 1e-30f;
    // Unit normals by winding, and each triangle's inradius (2 area / perimeter).
    std::vector<glm::dvec3> normals(c.triangleCount);
    std::vector<glm::dvec3> corners(3 * size_t(c.triangleCount));
    glm::dvec3 sum(0.0);
    double rho = INFINITY;
    for (uint32_t t = 0; t < c.triangleCount; ++t) {
        const size_t slot = c.triangleOffset + t;
        glm::dvec3 q[3];
        for (int k = 0; k < 3; ++k)
            q[k] = corners[3 * size_t(t) + k] = glm::dvec3(
                glm::vec3(positions[set.vertices[c.vertexOffset + set.localIndices[3 * slot + k]]]));
        const glm::dvec3 n = glm::cross(q[1] - q[0], q[2] - q[0]);
        const double twiceArea = glm::length(n);
        const double perimeter =
            glm::length(q[1] - q[0]) + glm::length(q[2] - q[1]) + glm::length(q[0] - q[2]);
        const bool doubleSided = (triFlags[set.triangleIds[slot]] & TRI_FLAG_DOUBLE_SIDED) != 0u;
        if (!(twiceArea > 0.0) || doubleSided) {
            rho = 0.0;
            normals[t] = glm::dvec3(0.0);
            continue;
        }
        normals[t] = n / twiceArea;
        sum += normals[t];
        rho = std::min(rho, twiceArea / perimeter);
    }
    const double sumLength = glm::length(sum);
    if (!(rho > 0.0) || !(sumLength > 1e-6 * c.triangleCount)) {
        c.coneBounds = glm::vec4(0.0f);
        return;
    }
    // The bounds hold for the axis as stored (any vector a: n . d >= a . d - |n - a| |d|).
    const glm::vec3 axis = glm::vec3(sum / sumLength);
    const glm::dvec3 a(axis);
    double spread = 0.0, low = INFINITY, high = -INFINITY;
    for (uint32_t t = 0; t < c.triangleCount; ++t) {
        spread = std::max(spread, glm::length(normals[t] - a));
        for (int k = 0; k < 3; ++k) {
            const double d = glm::dot(normals[t], corners[3 * size_t(t) + k] - centre);
            low = std::min(low, d);
            high = std::max(high, d);
        }
    }
    // Rounded outwards: a relative 1e-6 of the cluster's size covers double's rounding many times over.
    const double margin = 1e-6 * (radius + 1e-30);
    c.cone = glm::vec4(axis, float(spread * (1.0 + 1e-6) + 1e-7));
    c.coneBounds = glm::vec4(float(low - margin), float(-(high + margin)), float(rho * (1.0 - 1e-6)), 0.0f);
}

}  // namespace

namespace {

// Triangles per chunk: the mesh is clustered in chunks of consecutive triangles, on every core. A chunk
// holds thousands of clusters, so the seams between chunks (clusters never span two) cost little, and
// meshoptimizer's work per chunk is linear in the chunk alone.
constexpr size_t kChunkTriangles = size_t(1) << 20;

// The clusters of scene triangles [first, first + count), or of entries [first, first + count) of
// `list` where it is not empty, with scene triangle ids and scene vertices; offsets count from the
// chunk's own arrays.
ClusterSet buildChunk(const Scene& scene, const std::vector<uint32_t>& list, size_t first, size_t count)
{
    ClusterSet set;
    const size_t indexCount = 3 * count;
    std::vector<uint32_t> listed;  // the chunk's corners, when it is a list of triangles
    if (!list.empty()) {
        listed.resize(indexCount);
        for (size_t t = 0; t < count; ++t)
            for (size_t k = 0; k < 3; ++k) listed[3 * t + k] = scene.indices[3 * size_t(list[first + t]) + k];
    }
    const uint32_t* indices = list.empty() ? scene.indices.data() + 3 * first : listed.data();
    // The chunk's vertices, in scene order, and its corners as indices into them.
    std::vector<uint32_t> global(indices, indices + indexCount);
    std::sort(global.begin(), global.end());
    global.erase(std::unique(global.begin(), global.end()), global.end());
    std::vector<uint32_t> local(indexCount);
    const size_t span = size_t(global.back()) - global.front() + 1;
    if (span <= 4 * global.size()) {  // a coherent mesh: a table over the chunk's range of vertices
        std::vector<uint32_t> table(span);
        for (size_t v = 0; v < global.size(); ++v) table[global[v] - global.front()] = uint32_t(v);
        for (size_t i = 0; i < indexCount; ++i) local[i] = table[indices[i] - global.front()];
    } else {
        for (size_t i = 0; i < indexCount; ++i)
            local[i] = uint32_t(std::lower_bound(global.begin(), global.end(), indices[i]) - global.begin());
    }
    const size_t vertexCount = global.size();

    // meshoptimizer reads positions for locality and bounds only; a vertex that is not finite (the GPU
    // drops its triangles) takes the origin here, and the clusters holding one never cull.
    std::vector<glm::vec4> exact(vertexCount);
    std::vector<glm::vec3> positions(vertexCount);
    std::vector<bool> finite(vertexCount);
    for (size_t v = 0; v < vertexCount; ++v) {
        exact[v] = scene.positions[global[v]];
        finite[v] = isFinite(exact[v]);
        positions[v] = finite[v] ? glm::vec3(exact[v]) : glm::vec3(0.0f);
    }

    // Vertices at one position (bitwise) are one vertex to the clusters, named by the first of them: the
    // clusters feed visibility, which reads positions alone, and those transform and snap to the same
    // bits. (OBJ gives every face corner its own vertex; shading reads the scene's own vertices by
    // triangle id.) So 64 vertices of a closed mesh hold about twice their count in triangles.
    std::vector<uint32_t> welded(indexCount);
    const meshopt_Stream stream = {exact.data(), sizeof(glm::vec4), sizeof(glm::vec4)};
    meshopt_generateShadowIndexBufferMulti(welded.data(), local.data(), indexCount, vertexCount, &stream, 1);

    // What the clusterizer is given: the welded corners with every busy vertex split into copies
    // (kMaxVertexTriangles), and for each of its vertices the welded vertex it stands for.
    std::vector<uint32_t> uses(vertexCount, 0u);
    for (uint32_t v : welded) ++uses[v];
    std::vector<uint32_t> split = welded;
    std::vector<uint32_t> origin(vertexCount);
    for (size_t v = 0; v < vertexCount; ++v) origin[v] = uint32_t(v);
    {
        std::vector<uint32_t> seen(vertexCount, 0u), copy(vertexCount, 0u);
        for (uint32_t& v : split) {
            const uint32_t w = v;
            if (uses[w] <= kSplitVertexTriangles) continue;
            const uint32_t n = seen[w]++;           // this corner is use n of w
            if (n < kMaxVertexTriangles) continue;  // the first ones keep w itself
            if (n % kMaxVertexTriangles == 0) {     // each further kMaxVertexTriangles get a copy
                copy[w] = uint32_t(origin.size());
                origin.push_back(w);
                const glm::vec3 p = positions[w];
                positions.push_back(p);
            }
            v = copy[w];
        }
    }

    // Triangles whose centroid many others share (copies of one triangle, a mesh collapsed to a point)
    // are kept from the clusterizer: it finds each new cluster's first triangle in a k-d tree over the
    // centroids, which cannot split coincident points and scans them all for every cluster, O(n^2) in
    // all (the campaign's million copies of one triangle did not finish in 180 s). They are packed in
    // centroid order by meshoptimizer's scan instead, in linear time: they lie on one point, so no order
    // of them is more compact than another.
    //
    // Triangles are counted first in hash buckets (about one per triangle): a run of equal centroids lies in
    // one bucket, so only the triangles of buckets holding more than kMaxCoincidentTriangles are sorted by
    // centroid to find the runs; an ordinary mesh has none, and costs one linear pass.
    std::vector<std::array<uint32_t, 3>> centroid(count);
    size_t bucketCount = 1;
    while (bucketCount < count) bucketCount *= 2;
    std::vector<uint32_t> bucketOf(count), inBucket(bucketCount, 0u);
    for (size_t t = 0; t < count; ++t) {
        const glm::vec3 c =
            positions[welded[3 * t]] + positions[welded[3 * t + 1]] + positions[welded[3 * t + 2]];
        centroid[t] = {floatBits(c.x), floatBits(c.y), floatBits(c.z)};
        const uint64_t h = (uint64_t(centroid[t][0]) * 0x9E3779B97F4A7C15ull) ^
                           (uint64_t(centroid[t][1]) * 0xC2B2AE3D27D4EB4Full) ^
                           (uint64_t(centroid[t][2]) * 0x165667B19E3779F9ull);
        bucketOf[t] = uint32_t((h ^ (h >> 29)) & (bucketCount - 1));
        ++inBucket[bucketOf[t]];
    }
    std::vector<std::pair<std::array<uint32_t, 3>, uint32_t>> byCentroid;
    for (size_t t = 0; t < count; ++t)
        if (inBucket[bucketOf[t]] > kMaxCoincidentTriangles) byCentroid.push_back({centroid[t], uint32_t(t)});
    std::sort(byCentroid.begin(), byCentroid.end());
    std::vector<bool> crowdedTriangle(count, false);
    std::vector<uint32_t> crowded;  // the scan's corners, in centroid order
    for (size_t run = 0; run < byCentroid.size();) {
        size_t end = run + 1;
        while (end < byCentroid.size() && byCentroid[end].first == byCentroid[run].first) ++end;
        if (end - run > kMaxCoincidentTriangles)
            for (size_t i = run; i < end; ++i) {
                const uint32_t t = byCentroid[i].second;
                crowdedTriangle[t] = true;
                crowded.insert(crowded.end(), split.begin() + 3 * t, split.begin() + 3 * t + 3);
            }
        run = end;
    }
    std::vector<uint32_t> spread;  // the clusterizer's corners, in chunk order (its result depends on it)
    spread.reserve(indexCount - crowded.size());
    for (size_t t = 0; t < count; ++t)
        if (!crowdedTriangle[t])
            spread.insert(spread.end(), split.begin() + 3 * t, split.begin() + 3 * t + 3);

    struct Meshlets {
        std::vector<meshopt_Meshlet> meshlets;
        std::vector<unsigned int> vertices;
        std::vector<unsigned char> triangles;
        explicit Meshlets(size_t corners)
        {
            const size_t bound =
                meshopt_buildMeshletsBound(corners, kClusterMaxVertices, kClusterMaxTriangles);
            meshlets.resize(bound);
            vertices.resize(bound * kClusterMaxVertices);
            triangles.resize(bound * kClusterMaxTriangles * 3);
        }
    };
    Meshlets built(spread.size()), scanned(crowded.size());
    if (!spread.empty())
        built.meshlets.resize(meshopt_buildMeshlets(built.meshlets.data(), built.vertices.data(),
                                                    built.triangles.data(), spread.data(), spread.size(),
                                                    &positions[0].x, positions.size(), sizeof(glm::vec3),
                                                    kClusterMaxVertices, kClusterMaxTriangles, kConeWeight));
    else
        built.meshlets.clear();
    if (!crowded.empty())
        scanned.meshlets.resize(meshopt_buildMeshletsScan(
            scanned.meshlets.data(), scanned.vertices.data(), scanned.triangles.data(), crowded.data(),
            crowded.size(), positions.size(), kClusterMaxVertices, kClusterMaxTriangles));
    else
        scanned.meshlets.clear();

    TriangleLookup lookup(welded);
    set.clusters.reserve(built.meshlets.size() + scanned.meshlets.size());
    set.triangleIds.reserve(count);
    set.localIndices.reserve(indexCount);
    std::vector<bool> clusterFinite;  // per cluster: every vertex finite
    bool placed = true;               // every triangle found in the scene once
    std::vector<uint32_t> stamp(vertexCount, 0u);
    std::vector<uint8_t> slotIn(vertexCount);
    uint32_t clusterStamp = 0;
    for (const Meshlets* from : {&built, &scanned})
        for (const meshopt_Meshlet& m : from->meshlets) {
            Cluster c;
            c.vertexOffset = uint32_t(set.vertices.size());
            c.triangleOffset = uint32_t(set.triangleIds.size());
            c.triangleCount = m.triangle_count;
            const unsigned int* mv = &from->vertices[m.vertex_offset];
            // The cluster's welded vertices, each once (copies of a split vertex become one), and the
            // clusterizer's local vertices as indices into them; slotIn[w] is w's place in the cluster
            // that stamp[w] names, so each vertex costs O(1).
            uint32_t welds[kClusterMaxVertices];
            uint32_t weldCount = 0;
            uint8_t localOf[kClusterMaxVertices];
            bool allFinite = true;
            ++clusterStamp;
            for (uint32_t i = 0; i < m.vertex_count; ++i) {
                const uint32_t w = origin[mv[i]];
                if (stamp[w] == clusterStamp) {
                    localOf[i] = slotIn[w];
                    continue;
                }
                stamp[w] = clusterStamp;
                slotIn[w] = uint8_t(weldCount);
                localOf[i] = uint8_t(weldCount);
                welds[weldCount++] = w;
                set.vertices.push_back(global[w]);
                allFinite = allFinite && finite[w];
            }
            c.vertexCount = weldCount;
            const unsigned char* localTriangles = &from->triangles[m.triangle_offset];
            for (uint32_t t = 0; t < m.triangle_count; ++t) {
                const unsigned char* raw = localTriangles + 3 * size_t(t);
                const uint8_t tri[3] = {localOf[raw[0]], localOf[raw[1]], localOf[raw[2]]};
                // The triangle as the scene winds it: meshoptimizer keeps the corner order, but any
                // rotation of it is the same triangle, so look for each and store the local corners in
                // scene order.
                uint32_t id = UINT32_MAX;
                uint8_t corner[3] = {tri[0], tri[1], tri[2]};
                for (int r = 0; r < 3 && id == UINT32_MAX; ++r) {
                    uint8_t a = tri[r], b = tri[(r + 1) % 3], cc = tri[(r + 2) % 3];
                    id = lookup.take(welds[a], welds[b], welds[cc]);
                    if (id != UINT32_MAX) {
                        corner[0] = a;
                        corner[1] = b;
                        corner[2] = cc;
                    }
                }
                placed = placed && id != UINT32_MAX;
                set.triangleIds.push_back(id == UINT32_MAX ? id
                                          : list.empty()   ? uint32_t(first + id)
                                                           : list[first + id]);
                set.localIndices.insert(set.localIndices.end(), corner, corner + 3);
            }
            const meshopt_Bounds b = meshopt_computeMeshletBounds(
                mv, localTriangles, m.triangle_count, &positions[0].x, positions.size(), sizeof(glm::vec3));
            c.sphere = glm::vec4(b.center[0], b.center[1], b.center[2], 0.0f);
            set.clusters.push_back(c);
            clusterFinite.push_back(allFinite);
        }
    // meshoptimizer's clusters hold every triangle once with its corners rotated at most; should a
    // version not, the chunk has no clusters and buildClusters returns none (setup draws the scene).
    if (!placed || set.triangleIds.size() != count) return ClusterSet{};
    for (size_t k = 0; k < set.clusters.size(); ++k)
        facingBounds(scene.positions, scene.triFlags, set, clusterFinite[k], set.clusters[k]);
    return set;
}

}  // namespace

ClusterSet buildClusters(const Scene& scene)
{
    return buildClusters(scene, {});
}

ClusterSet buildClusters(const Scene& scene, const std::vector<uint32_t>& list)
{
    ClusterSet set;
    const size_t triangles = list.empty() ? scene.indices.size() / 3 : list.size();
    const size_t vertexCount = scene.positions.size();
    if (triangles == 0 || vertexCount == 0) return set;
    if (std::any_of(scene.indices.begin(), scene.indices.end(), [&](uint32_t i) { return i >= vertexCount; }))
        return set;

    const size_t chunks = (triangles + kChunkTriangles - 1) / kChunkTriangles;
    std::vector<ClusterSet> parts(chunks);
    std::atomic<size_t> next{0};
    auto work = [&] {
        for (size_t k = next++; k < chunks; k = next++)
            parts[k] = buildChunk(scene, list, k * kChunkTriangles,
                                  std::min(kChunkTriangles, triangles - k * kChunkTriangles));
    };
    const size_t threads = std::min<size_t>(chunks, std::max(1u, std::thread::hardware_concurrency()));
    std::vector<std::thread> pool;
    for (size_t t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();

    // The chunks' clusters in chunk order, their offsets moved past the chunks before them.
    for (const ClusterSet& part : parts)
        if (part.clusters.empty()) return set;
    for (ClusterSet& part : parts) {
        const auto vertexBase = uint32_t(set.vertices.size());
        const auto triangleBase = uint32_t(set.triangleIds.size());
        for (Cluster c : part.clusters) {
            c.vertexOffset += vertexBase;
            c.triangleOffset += triangleBase;
            set.clusters.push_back(c);
        }
        set.vertices.insert(set.vertices.end(), part.vertices.begin(), part.vertices.end());
        set.triangleIds.insert(set.triangleIds.end(), part.triangleIds.begin(), part.triangleIds.end());
        set.localIndices.insert(set.localIndices.end(), part.localIndices.begin(), part.localIndices.end());
        part = ClusterSet{};
    }
    return set;
}

void clusterBounds(const std::vector<glm::vec4>& positions, const std::vector<uint32_t>& triFlags,
                   const ClusterSet& set, Cluster& c)
{
    bool allFinite = true;
    for (uint32_t v = 0; v < c.vertexCount; ++v)
        allFinite = allFinite && isFinite(positions[set.vertices[c.vertexOffset + v]]);
    facingBounds(positions, triFlags, set, allFinite, c);
}

bool clusterConeBackFacing(const Cluster& c, const glm::vec3& eye)
{
    if (!(c.coneBounds.z > 0.0f)) return false;
    const glm::dvec3 toCentre = glm::dvec3(glm::vec3(c.sphere)) - glm::dvec3(eye);
    const double s = double(c.coneBounds.x) + glm::dot(glm::dvec3(glm::vec3(c.cone)), toCentre) -
                     double(c.cone.w) * glm::length(toCentre);
    return s > 0.0;
}

void gpuClusters(const ClusterSet& set, const std::vector<uint32_t>& triFlags,
                 std::vector<GpuCluster>& clusters, std::vector<uint32_t>& data,
                 const std::vector<ClusterLod>* lod)
{
    clusters.clear();
    data.clear();
    clusters.reserve(set.clusters.size());
    data.reserve(set.vertices.size() + 2 * set.triangleIds.size() +
                 (lod ? CLUSTER_LOD_WORDS * (set.clusters.size() * 2 + 1) : 0));
    // With level of detail, every cluster's words first (stage lod_cut reads them by cluster index).
    if (lod)
        for (size_t k = 0; k < set.clusters.size(); ++k) {
            const ClusterLod& l = (*lod)[k];
            const float words[10] = {
                l.own.sphere.x,    l.own.sphere.y,    l.own.sphere.z,    l.own.sphere.w,    l.own.error,
                l.parent.sphere.x, l.parent.sphere.y, l.parent.sphere.z, l.parent.sphere.w, l.parent.error};
            for (float w : words) data.push_back(floatBits(w));
            data.push_back(set.clusters[k].triangleCount);
            data.push_back(0u);
        }
    // Then every block's bounds of its clusters' bounds (lodBlock).
    if (lod)
        for (size_t first = 0; first < set.clusters.size(); first += CLUSTER_LOD_BLOCK) {
            const LodBlock b = lodBlock(lod->data() + first,
                                        std::min<size_t>(CLUSTER_LOD_BLOCK, set.clusters.size() - first));
            const float words[10] = {
                b.parent.sphere.x, b.parent.sphere.y, b.parent.sphere.z, b.parent.sphere.w, b.parent.error,
                b.own.sphere.x,    b.own.sphere.y,    b.own.sphere.z,    b.own.sphere.w,    b.own.error};
            for (float w : words) data.push_back(floatBits(w));
            data.push_back(b.skippable ? 0u : 1u);
            data.push_back(0u);
        }
    for (size_t k = 0; k < set.clusters.size(); ++k) {
        const Cluster& c = set.clusters[k];
        GpuCluster g{};
        g.sphere = c.sphere;
        g.cone = c.cone;
        g.coneBounds = c.coneBounds;
        g.vertexCount = c.vertexCount;
        g.triangleCount = c.triangleCount;
        g.vertexOffset = uint32_t(data.size());
        data.insert(data.end(), set.vertices.begin() + c.vertexOffset,
                    set.vertices.begin() + c.vertexOffset + c.vertexCount);
        g.triangleOffset = uint32_t(data.size());
        for (uint32_t t = 0; t < c.triangleCount; ++t) {
            const size_t slot = c.triangleOffset + t;
            const uint32_t id = set.triangleIds[slot];
            const bool doubleSided = id < triFlags.size() && (triFlags[id] & TRI_FLAG_DOUBLE_SIDED) != 0u;
            data.push_back(id);
            data.push_back(uint32_t(set.localIndices[3 * slot]) |
                           uint32_t(set.localIndices[3 * slot + 1]) << 8 |
                           uint32_t(set.localIndices[3 * slot + 2]) << 16 |
                           (doubleSided ? CLUSTER_TRI_DOUBLE_SIDED : 0u));
        }
        clusters.push_back(g);
    }
}

void setClusterParams(RasterParams& p, uint32_t clusterCount, uint32_t rasterMethod)
{
    p.clusterCount = clusterCount;
    p.setupFirstPrimitive = clusterCount > 0 ? p.triangleCount : 0u;
    const glm::mat4& m = p.clipFromWorld;
    // Row i of the clip transform (glm is column-major), in double: clip component i = row . (p, 1).
    auto row = [&](int i) { return glm::dvec4(m[0][i], m[1][i], m[2][i], m[3][i]); };
    const glm::dvec4 rx = row(0), ry = row(1), rz = row(2), rw = row(3);
    auto absSum = [](const glm::dvec4& r) {
        return std::abs(r.x) + std::abs(r.y) + std::abs(r.z) + std::abs(r.w);
    };
    auto lin = [](const glm::dvec4& r) { return glm::dvec3(r); };
    constexpr double u = 1.0 / 16777216.0;  // float's unit roundoff, 2^-24
    // Planes in frustumOutcode's order, then the sides at twice the viewport; each with the two rows it
    // combines, for its float error.
    const glm::dvec4 planes[CLUSTER_PLANE_COUNT] = {
        rw + rx, rw - rx,       rw + ry,       rw - ry,       rz,
        rw - rz, 2.0 * rw + rx, 2.0 * rw - rx, 2.0 * rw + ry, 2.0 * rw - ry};
    const double rowError[CLUSTER_PLANE_COUNT] = {absSum(rw) + absSum(rx),
                                                  absSum(rw) + absSum(rx),
                                                  absSum(rw) + absSum(ry),
                                                  absSum(rw) + absSum(ry),
                                                  absSum(rz),
                                                  absSum(rw) + absSum(rz),
                                                  2 * absSum(rw) + absSum(rx),
                                                  2 * absSum(rw) + absSum(rx),
                                                  2 * absSum(rw) + absSum(ry),
                                                  2 * absSum(rw) + absSum(ry)};
    double slack = 0.0;
    for (int k = 0; k < CLUSTER_PLANE_COUNT; ++k) {
        const double n = glm::length(lin(planes[k]));
        // A plane without a normal is a constant: neither culls nor admits anything.
        if (!(n > 0.0) || !std::isfinite(n)) {
            p.clusterPlanes[k] = glm::vec4(0.0f);
            continue;
        }
        p.clusterPlanes[k] = glm::vec4(planes[k] / n);
        // Each clip component is three products and three sums of float terms, each rounded: a plane's
        // value is off by at most 4u x (its rows' absolute sums) x the largest coordinate (>= 1), twice
        // that here for the normalised plane's own rounding.
        slack = std::max(slack, 8.0 * u * rowError[k] / n);
    }
    p.clusterPlanes[CLUSTER_PLANE_W] = glm::vec4(rw);
    // The camera centre e: clip x, y and w vanish there (L e = -t for L the linear part of those rows).
    const glm::dmat3 lt(lin(rx), lin(ry), lin(rw));  // columns: the transpose of L
    const double det = glm::determinant(lt);
    const double scale = glm::length(lin(rx)) * glm::length(lin(ry)) * glm::length(lin(rw));
    const bool perspective = scale > 0.0 && std::abs(det) > 1e-9 * scale;
    const bool exactFacing = rasterMethod == RASTER_FIXED8 || rasterMethod == RASTER_FIXED4;
    float sign = 0.0f;
    glm::dvec3 eye(0.0);
    if (perspective && exactFacing && p.cullMode != CULL_NONE) {
        eye = glm::inverse(glm::transpose(lt)) * -glm::dvec3(rx.w, ry.w, rw.w);
        // setup culls back faces where the snapped area is positive: det(L) x n . (p - e) > 0.
        sign = float((det > 0.0) == (p.cullMode == CULL_BACK) ? 1 : -1);
    }
    p.clusterEye = glm::vec4(glm::vec3(eye), sign);
    const double width = p.width, height = p.height;
    const double nx = glm::length(lin(rx)), ny = glm::length(lin(ry)), nw = glm::length(lin(rw));
    // The window transform's largest stretch at clip w, with |x|, |y| <= 2w: K1 / w.
    const double k1 = std::hypot(0.5 * width * (nx + 2.0 * nw), 0.5 * height * (ny + 2.0 * nw));
    const double k = perspective ? 0.25 * width * height * std::abs(det) / (k1 * nw * nw) : 0.0;
    // Half a snapping step per axis: 1/512 pixel (fixed8), 1/32 (fixed4).
    const double snap = rasterMethod == RASTER_FIXED4 ? 0.5 / 16.0 : 0.5 / double(SUBPIXEL_SCALE);
    const double extent = std::max(width, height);
    // Twice the corner displacement (sqrt 2 per axis): snapping and the window transform's rounding (the
    // reciprocal's ulp and three float operations) in z, the clip positions' rounding in y (per unit of
    // vertex magnitude over w: 4u per component, 3x through x/w with |x/w| <= 2, half the extent).
    const double twoRoot2 = 2.0 * std::sqrt(2.0);
    const double rowsError = std::max({absSum(rx), absSum(ry), absSum(rw)});
    p.clusterCone =
        glm::vec4(float(k), float(twoRoot2 * 0.5 * extent * 12.0 * u * rowsError),
                  float(twoRoot2 * (snap + extent * (std::ldexp(1.0, -23) + 4.0 * u))), float(2.0 * slack));
}

}  // namespace sr
