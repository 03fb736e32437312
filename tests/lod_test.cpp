// lod_test.cpp - level of detail (host/scene/lod.h, common/shared/cluster.h's clusterLodDrawn).
//
// The hierarchy, checked against the scene: level 0 holds every scene triangle once; every simplified
// triangle is in one cluster; a group's members carry its bound as their parent's and the clusters made
// from it as their own, bit for bit; bounds are monotonic (a parent's sphere holds its members', its
// error is at least theirs) and hold their clusters' vertices; a group's border (borderEdges) is the
// border of what it was simplified to. Then cuts, for cameras near and far and
// errors from a quarter pixel to 64 pixels: every scene triangle is drawn exactly once through the
// hierarchy (a level-0 cluster, or every cluster that replaced its group, recursively), no drawn
// cluster overlaps the clusters it was made from, and a block that lod_cut skips whole holds none of it. On
// the devices: a closed sphere drawn with its back faces has an even number of hits on every sample (a crack
// makes it odd) at every error and distance, far views draw fewer triangles, --lod off after --lod on draws
// today's frame, the two backends draw the same cut, and lavapipe's graphics pipeline, drawing the cut the
// host takes with the same test, agrees with the compute pipeline.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "api/backend.h"
#include "render/renderer.h"
#include "camera/camera.h"
#include "scene/lod.h"
#include "scene/scene.h"
#include "test_util.h"
#include "vulkan/vulkan_device_internal.h"

namespace sr::test {
namespace {

bool sameBound(const LodBound& a, const LodBound& b)
{
    return std::memcmp(&a.sphere, &b.sphere, sizeof a.sphere) == 0 &&
           std::memcmp(&a.error, &b.error, sizeof a.error) == 0;
}

// The border of a set of triangles (corner positions, 3 per triangle): the edges (vertex pairs by
// position bits, unordered) that an odd number of them use, the boundary of the surface as a chain mod 2.
// On a manifold that is the edges of one triangle only; where three triangles meet at an edge (the bunny
// has such edges) simplification may turn three uses into one, which is the same boundary.
std::set<std::pair<std::array<uint32_t, 3>, std::array<uint32_t, 3>>> borderEdges(
    const std::vector<glm::vec4>& corners)
{
    auto bits = [](const glm::vec4& p) {
        std::array<uint32_t, 3> b;
        std::memcpy(b.data(), &p.x, sizeof b);
        return b;
    };
    std::map<std::pair<std::array<uint32_t, 3>, std::array<uint32_t, 3>>, int> uses;
    for (size_t t = 0; t + 2 < corners.size(); t += 3)
        for (int k = 0; k < 3; ++k) {
            auto a = bits(corners[t + k]), b = bits(corners[t + (k + 1) % 3]);
            ++uses[{std::min(a, b), std::max(a, b)}];
        }
    std::set<std::pair<std::array<uint32_t, 3>, std::array<uint32_t, 3>>> border;
    for (const auto& [edge, n] : uses)
        if (n % 2 == 1) border.insert(edge);
    return border;
}

std::vector<glm::vec4> clusterCorners(const Scene& full, const LodHierarchy& h, size_t k)
{
    const Cluster& c = h.clusters.clusters[k];
    std::vector<glm::vec4> corners;
    for (uint32_t t = 0; t < c.triangleCount; ++t)
        for (int i = 0; i < 3; ++i)
            corners.push_back(
                full.positions[h.clusters
                                   .vertices[c.vertexOffset +
                                             h.clusters.localIndices[3 * size_t(c.triangleOffset + t) + i]]]);
    return corners;
}

void checkHierarchy(const Scene& scene, const LodHierarchy& h, const std::string& name)
{
    const size_t triangles = scene.triangleCount();
    const size_t simplified = h.sourceIds.size();
    const size_t clusters = h.clusters.clusters.size();
    ASSERT_GT(clusters, 0u) << name;
    ASSERT_EQ(h.bounds.size(), clusters);
    ASSERT_EQ(h.indices.size(), 3 * simplified);
    ASSERT_EQ(h.triFlags.size(), simplified);
    std::vector<int> seen(triangles + simplified, 0);
    std::map<uint32_t, std::vector<size_t>> members, made;  // group -> its members, the clusters made from it
    const Scene full = lodScene(scene, h);
    ASSERT_EQ(full.triangleCount(), triangles + simplified);
    std::vector<size_t> perLevel(h.levels, 0);
    for (size_t k = 0; k < clusters; ++k) {
        const Cluster& c = h.clusters.clusters[k];
        ASSERT_LT(h.level[k], h.levels);
        perLevel[h.level[k]] += c.triangleCount;
        ASSERT_LE(c.triangleCount, kClusterMaxTriangles);
        ASSERT_LE(c.vertexCount, kClusterMaxVertices);
        for (uint32_t t = 0; t < c.triangleCount; ++t) {
            const uint32_t id = h.clusters.triangleIds[c.triangleOffset + t];
            ASSERT_LT(id, triangles + simplified);
            // Level 0 holds the scene's triangles, the others simplified ones.
            EXPECT_EQ(h.level[k] == 0, id < triangles) << name << " cluster " << k;
            ++seen[id];
            for (int i = 0; i < 3; ++i) {
                const glm::vec4 corner =
                    full.positions
                        [h.clusters.vertices[c.vertexOffset +
                                             h.clusters.localIndices[3 * size_t(c.triangleOffset + t) + i]]];
                EXPECT_EQ(
                    std::memcmp(&corner, &full.positions[full.indices[3 * size_t(id) + i]], sizeof corner), 0)
                    << name << " triangle " << id << " corner " << i;
            }
        }
        const ClusterLod& b = h.bounds[k];
        if (h.level[k] == 0) {
            EXPECT_EQ(b.own.error, 0.0f);
            EXPECT_EQ(h.ownGroup[k], kLodNoGroup);
        } else {
            ASSERT_LT(h.ownGroup[k], h.groups.size());
            EXPECT_TRUE(sameBound(b.own, h.groups[h.ownGroup[k]])) << name << " cluster " << k;
            made[h.ownGroup[k]].push_back(k);
        }
        if (h.parentGroup[k] == kLodNoGroup) {
            EXPECT_TRUE(std::isinf(b.parent.error));
        } else {
            ASSERT_LT(h.parentGroup[k], h.groups.size());
            EXPECT_TRUE(sameBound(b.parent, h.groups[h.parentGroup[k]])) << name << " cluster " << k;
            members[h.parentGroup[k]].push_back(k);
            // Monotonic: the parent's error is at least the cluster's own, its sphere holds the own one.
            EXPECT_GE(b.parent.error, b.own.error) << name << " cluster " << k;
            if (std::isfinite(b.own.sphere.w)) {
                const double reach = glm::length(glm::dvec3(glm::vec3(b.parent.sphere)) -
                                                 glm::dvec3(glm::vec3(b.own.sphere))) +
                                     double(b.own.sphere.w);
                EXPECT_LE(reach, double(b.parent.sphere.w)) << name << " cluster " << k;
            }
        }
        // The own bound's sphere holds the cluster's vertices (the cut projects its error from there).
        if (std::isfinite(b.own.sphere.w))
            for (uint32_t v = 0; v < c.vertexCount; ++v) {
                const glm::dvec3 p(glm::vec3(full.positions[h.clusters.vertices[c.vertexOffset + v]]));
                EXPECT_LE(glm::length(p - glm::dvec3(glm::vec3(b.own.sphere))),
                          double(b.own.sphere.w) * (1 + 1e-6))
                    << name << " cluster " << k;
            }
    }
    for (size_t id = 0; id < seen.size(); ++id) ASSERT_EQ(seen[id], 1) << name << " triangle " << id;
    // Every group has members and was simplified into clusters; its border is locked.
    EXPECT_EQ(members.size(), h.groups.size());
    EXPECT_EQ(made.size(), h.groups.size());
    for (const auto& [g, list] : members) {
        std::vector<glm::vec4> before, after;
        for (size_t k : list) {
            auto c = clusterCorners(full, h, k);
            before.insert(before.end(), c.begin(), c.end());
        }
        for (size_t k : made[g]) {
            auto c = clusterCorners(full, h, k);
            after.insert(after.end(), c.begin(), c.end());
        }
        EXPECT_LT(after.size(), before.size()) << name << " group " << g;
        const auto b0 = borderEdges(before), b1 = borderEdges(after);
        EXPECT_EQ(b0, b1) << name << " group " << g;
    }
    std::string levels;
    for (size_t n : perLevel) levels += " " + std::to_string(n);
    std::printf(
        "%s: %zu triangles, %u levels (triangles per level:%s), %zu clusters, %zu groups, "
        "hierarchy %.2f MB over the mesh's %.2f MB\n",
        name.c_str(), triangles, h.levels, levels.c_str(), clusters, h.groups.size(),
        double(h.deviceBytes()) / 1e6,
        double(scene.positions.size() * 16 + scene.indices.size() * 4 + triangles * 4) / 1e6);
    EXPECT_GE(h.levels, 3u) << name;
}

TEST(LodHierarchy, InvariantsOnASphereTheBunnyAndTheBuiltinScene)
{
    for (const std::string name : {"builtin:dense:48", "bunny.obj", "builtin"}) {
        const Scene scene = namedScene(name);
        checkHierarchy(scene, buildLodHierarchy(scene), name);
    }
}

// The hierarchy of meshes that many triangles share a vertex or a centroid of builds in a time near
// linear too (its clusters come from the same builder; the campaign's --lod on took as long as
// --clusters on: 70 s for 100,000 copies of one degenerate triangle), with every scene triangle in one
// cluster of level 0.
TEST(LodHierarchy, BusyVerticesAndCoincidentTrianglesBuildInNearLinearTime)
{
    constexpr uint32_t n = 100000;
    for (const char* kind : {"degenerate copies", "copies", "fan", "collapsed"}) {
        const Scene scene = pathologicalScene(kind, n);
        const auto start = std::chrono::steady_clock::now();
        const LodHierarchy h = buildLodHierarchy(scene);
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::printf("%s, %u triangles: hierarchy of %u levels in %.2f s\n", kind, n, h.levels, s);
        EXPECT_LT(s, 30.0) << kind;  // generous: only a quadratic build misses it
        std::vector<int> seen(scene.triangleCount(), 0);
        for (size_t k = 0; k < h.clusters.clusters.size(); ++k) {
            if (h.level[k] != 0) continue;
            const Cluster& c = h.clusters.clusters[k];
            for (uint32_t t = 0; t < c.triangleCount; ++t) {
                const uint32_t id = h.clusters.triangleIds[c.triangleOffset + t];
                ASSERT_LT(id, seen.size()) << kind;
                ++seen[id];
            }
        }
        EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), std::ptrdiff_t(seen.size())) << kind;
    }
}

// What a cut does to cluster k: drawn, or replaced by finer clusters (its own bound too coarse), or by
// coarser ones (its parent's fine enough).
enum class Fate { Drawn, Finer, Coarser };

// For every scene triangle, how many times the cut draws it: through its level-0 cluster when that is
// drawn, else through the clusters made from the group it is simplified in, each of which must draw its
// share exactly once (recursively). 1 everywhere is a cut without holes or overlaps.
size_t skippedBlocks = 0, cuts = 0;  // over checkCut's calls: the block test must be at work

void checkCut(const LodHierarchy& h, const RasterParams& p, const std::string& what)
{
    const size_t clusters = h.clusters.clusters.size();
    std::vector<Fate> fate(clusters);
    for (size_t k = 0; k < clusters; ++k) {
        const ClusterLod& b = h.bounds[k];
        const bool ownCoarse = lodTooCoarse(p, b.own.sphere, b.own.error);
        const bool parentCoarse = lodTooCoarse(p, b.parent.sphere, b.parent.error);
        // Monotonic: a cluster whose own bound is too coarse has a parent that is too.
        ASSERT_FALSE(ownCoarse && !parentCoarse) << what << " cluster " << k;
        fate[k] = lodClusterDrawn(p, h, k) ? Fate::Drawn : ownCoarse ? Fate::Finer : Fate::Coarser;
    }
    std::map<uint32_t, std::vector<size_t>> made;
    for (size_t k = 0; k < clusters; ++k)
        if (h.ownGroup[k] != kLodNoGroup) made[h.ownGroup[k]].push_back(k);
    std::vector<int> cover(clusters, -1);
    std::function<int(size_t)> coverOf = [&](size_t k) -> int {
        if (cover[k] >= 0) return cover[k];
        int n = 0;
        if (fate[k] == Fate::Drawn) {
            n = 1;
        } else if (fate[k] == Fate::Coarser) {
            n = 1;
            for (size_t o : made[h.parentGroup[k]]) {
                const int m = coverOf(o);
                if (m != 1) n = m;
            }
        }
        return cover[k] = n;
    };
    size_t drawn = 0;
    for (size_t k = 0; k < clusters; ++k) {
        if (h.level[k] == 0) {
            ASSERT_EQ(coverOf(k), 1) << what << " level-0 cluster " << k;
        }
        // A drawn cluster does not overlap what it was made from: every member of its group went coarser.
        if (fate[k] == Fate::Drawn && h.ownGroup[k] != kLodNoGroup)
            for (size_t m = 0; m < clusters; ++m)
                if (h.parentGroup[m] == h.ownGroup[k]) {
                    ASSERT_EQ(fate[m], Fate::Coarser) << what << " cluster " << m;
                }
        drawn += fate[k] == Fate::Drawn ? h.clusters.clusters[k].triangleCount : 0;
    }
    EXPECT_GT(drawn, 0u) << what;
    // A block that lod_cut skips whole holds no cluster of the cut.
    for (size_t first = 0; first < clusters; first += CLUSTER_LOD_BLOCK) {
        const size_t count = std::min<size_t>(CLUSTER_LOD_BLOCK, clusters - first);
        const LodBlock b = lodBlock(h.bounds.data() + first, count);
        if (!b.skippable || !lodBlockSkipped(p, b.parent.sphere, b.parent.error, b.own.sphere, b.own.error))
            continue;
        ++skippedBlocks;
        for (size_t k = first; k < first + count; ++k) {
            ASSERT_NE(fate[k], Fate::Drawn) << what << " cluster " << k << " in a skipped block";
        }
    }
    ++cuts;
}

CameraMatrices orbitAt(const Scene& scene, float azimuth, float radii, uint32_t w, uint32_t h)
{
    const BoundingSphere sphere = boundingSphere(scene);
    OrbitPose pose;
    pose.azimuthDeg = azimuth;
    pose.elevationDeg = 20.0f;
    pose.distance = radii * sphere.radius;
    return orbitCameraMatrices(pose, sphere, w, h);
}

RasterParams lodParams(const Scene& full, const LodHierarchy& h, const CameraMatrices& camera,
                       const RenderSettings& s)
{
    RasterParams p = frameParams(full, camera, s, {}, {});
    setClusterParams(p, uint32_t(h.clusters.clusters.size()), s.rasterMethod);
    setLodParams(p, s.lodErrorPx);
    return p;
}

TEST(LodHierarchy, EveryCutDrawsEveryTriangleOnce)
{
    for (const std::string name : {"builtin:dense:48", "bunny.obj"}) {
        const Scene scene = namedScene(name);
        const LodHierarchy h = buildLodHierarchy(scene);
        const Scene full = lodScene(scene, h);
        RenderSettings s = testSettings(256, 192);
        for (float radii : {0.5f, 1.2f, 3.0f, 10.0f, 40.0f, 400.0f})
            for (float error : {0.25f, 1.0f, 4.0f, 64.0f}) {
                s.lodErrorPx = error;
                checkCut(h, lodParams(full, h, orbitAt(scene, 30.0f, radii, 256, 192), s),
                         name + " at " + std::to_string(radii) + " radii, " + std::to_string(error) + " px");
            }
    }
    std::printf("%zu blocks skipped whole over %zu cuts\n", skippedBlocks, cuts);
    EXPECT_GT(skippedBlocks, cuts);
}

class LodPipelineTest : public BackendTest {};

RenderSettings lodSettings(uint32_t w, uint32_t h, float errorPx)
{
    RenderSettings s = testSettings(w, h);
    s.lod = LOD_ON;
    s.lodErrorPx = errorPx;
    return s;
}

// A closed sphere with its back faces: every sample is covered an even number of times, at every error
// and at distances that cross the levels, and far views draw fewer triangles than near ones.
TEST_P(LodPipelineTest, AClosedSphereStaysWatertightAtEveryErrorAndDistance)
{
    const Scene scene = namedScene("builtin:dense:48");
    const uint32_t w = 160, hgt = 120;
    auto session = RenderSession::create(*device_, scene);
    ASSERT_TRUE(session.ok()) << session.error().message;
    for (float error : {0.25f, 1.0f, 4.0f}) {
        uint64_t previous = UINT64_MAX;
        for (float radii : {1.6f, 3.0f, 6.0f, 12.0f, 24.0f}) {
            RenderSettings s = lodSettings(w, hgt, error);
            s.cullMode = CULL_NONE;
            s.countHits = true;
            auto out = session->render(orbitAt(scene, 15.0f, radii, w, hgt), s);
            ASSERT_TRUE(out.ok()) << out.error().message;
            size_t covered = 0, odd = 0;
            for (uint32_t hits : out->hitCount) {
                covered += hits > 0;
                odd += hits % 2;
            }
            const std::string what = std::to_string(error) + " px at " + std::to_string(radii) + " radii";
            EXPECT_GT(covered, 20u) << what;
            EXPECT_EQ(odd, 0u) << what << ": samples covered an odd number of times (a crack)";
            EXPECT_EQ(out->stats.lodSceneTriangles, scene.triangleCount());
            EXPECT_LE(out->stats.lodTriangles, previous) << what;
            previous = out->stats.lodTriangles;
            for (uint32_t id : out->aov.id) ASSERT_TRUE(id == EMPTY_ID || id < scene.triangleCount()) << what;
        }
        EXPECT_LT(previous, scene.triangleCount() / 4) << error << " px: the far view draws a coarse level";
    }
}

// --lod off in a session that drew with --lod on is today's frame, and --lod on again its own frame.
TEST_P(LodPipelineTest, LodOffAfterLodOnIsTheFrameWithoutIt)
{
    const Scene scene = namedScene("bunny.obj");
    const uint32_t w = 128, hgt = 96;
    const CameraMatrices camera = orbitAt(scene, 40.0f, 6.0f, w, hgt);
    RenderSettings off = testSettings(w, hgt);
    const RenderOutput today = render(scene, off, camera);
    auto session = RenderSession::create(*device_, scene);
    ASSERT_TRUE(session.ok()) << session.error().message;
    auto on = session->render(camera, lodSettings(w, hgt, 2.0f));
    ASSERT_TRUE(on.ok()) << on.error().message;
    EXPECT_LT(on->stats.lodTriangles, scene.triangleCount());
    auto again = session->render(camera, off);
    ASSERT_TRUE(again.ok()) << again.error().message;
    EXPECT_EQ(again->aov.id, today.aov.id);
    EXPECT_EQ(again->aov.depth, today.aov.depth);
    EXPECT_EQ(again->color.pixels, today.color.pixels);
    auto onAgain = session->render(camera, lodSettings(w, hgt, 2.0f));
    ASSERT_TRUE(onAgain.ok()) << onAgain.error().message;
    EXPECT_EQ(onAgain->aov.id, on->aov.id);
    EXPECT_EQ(onAgain->aov.depth, on->aov.depth);
    EXPECT_EQ(onAgain->color.pixels, on->color.pixels);
}

// The device draws the cut the host takes with the same test: as many triangles as the host's cut.
TEST_P(LodPipelineTest, TheDeviceDrawsTheHostsCut)
{
    const Scene scene = namedScene("bunny.obj");
    const LodHierarchy h = buildLodHierarchy(scene);
    const Scene full = lodScene(scene, h);
    for (float radii : {1.5f, 5.0f, 30.0f}) {
        const CameraMatrices camera = orbitAt(scene, 70.0f, radii, 128, 96);
        const RenderSettings s = lodSettings(128, 96, 1.0f);
        const RasterParams p = lodParams(full, h, camera, s);
        uint64_t cut = 0;
        for (size_t k = 0; k < h.clusters.clusters.size(); ++k)
            cut += lodClusterDrawn(p, h, k) ? h.clusters.clusters[k].triangleCount : 0;
        RenderOutput out = render(scene, s, camera);
        EXPECT_EQ(out.stats.lodTriangles, cut) << radii << " radii";
    }
}

// Level of detail with tessellation or a display form is refused with one line.
TEST_P(LodPipelineTest, LodWithTessellationIsRefused)
{
    const Scene scene = namedScene("builtin:dense:16");
    RenderSettings s = lodSettings(64, 64, 1.0f);
    s.tessellate = TESS_FLAT;
    auto out = renderScene(*device_, scene, orbitAt(scene, 0.0f, 3.0f, 64, 64), s);
    ASSERT_FALSE(out.ok());
    EXPECT_TRUE(isOneLine(out.error().message)) << out.error().message;
    EXPECT_NE(out.error().message.find("--lod"), std::string::npos) << out.error().message;
}

// A vertex that is not finite: its clusters never simplify (they are roots, always drawn), so its
// triangles are dropped and counted invalid as without level of detail, and the rest is drawn.
TEST_P(LodPipelineTest, NonFiniteVerticesAreCountedInvalidAsWithoutIt)
{
    Scene scene = namedScene("builtin:dense:24");
    scene.positions[scene.indices[300]].x = NAN;
    scene.positions[scene.indices[900]].y = INFINITY;
    const CameraMatrices camera = orbitAt(scene, 10.0f, 6.0f, 96, 96);
    RenderSettings off = testSettings(96, 96);
    off.clusters = CLUSTERS_ON;
    const RenderOutput without = render(scene, off, camera);
    for (float error : {0.25f, 4.0f}) {
        RenderSettings s = lodSettings(96, 96, error);
        const RenderOutput with = render(scene, s, camera);
        EXPECT_GT(with.stats.invalid, 0u) << error;
        EXPECT_EQ(with.stats.invalid, without.stats.invalid) << error;
        EXPECT_LT(with.stats.lodTriangles, scene.triangleCount()) << error;
        size_t covered = 0;
        for (uint32_t id : with.aov.id) covered += id != EMPTY_ID;
        EXPECT_GT(covered, 200u) << error;
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, LodPipelineTest, ::testing::Values("vulkan", "cuda"));

// lavapipe's graphics pipeline drawing the host's cut against the compute pipeline drawing its own: the
// same triangles, so the tolerance of the built-in scene's comparison (vulkan_graphics_test.cpp).
TEST(LodGraphics, TheGraphicsPipelineDrawsTheSameCut)
{
    setenv("SR_VULKAN_VALIDATION", "1", 1);
    const size_t errorsBefore = vulkanValidationErrorCount();
    const Scene scene = namedScene("bunny.obj");
    const uint32_t w = 128, hgt = 96;
    for (float radii : {2.0f, 5.0f}) {
        const CameraMatrices camera = orbitAt(scene, 200.0f, radii, w, hgt);
        const RenderSettings s = lodSettings(w, hgt, 1.0f);
        auto graphics = renderGraphics(scene, camera, s, -1);
        ASSERT_TRUE(graphics.ok()) << graphics.error().message;
        auto device = makeVulkanDevice(-1);
        ASSERT_TRUE(device.ok()) << device.error().message;
        auto compute = renderScene(**device, scene, camera, s);
        ASSERT_TRUE(compute.ok()) << compute.error().message;
        EXPECT_EQ(graphics->stats.lodTriangles, compute->stats.lodTriangles);
        EXPECT_LT(compute->stats.lodTriangles, scene.triangleCount());
        const size_t pixels = size_t(w) * hgt;
        size_t agree = 0, covered = 0;
        float worstDepth = 0.0f;
        for (size_t i = 0; i < pixels; ++i) {
            covered += compute->aov.id[i] != EMPTY_ID;
            if (graphics->aov.id[i] != compute->aov.id[i]) continue;
            ++agree;
            if (compute->aov.id[i] != EMPTY_ID)
                worstDepth = std::max(worstDepth, std::abs(graphics->aov.depth[i] - compute->aov.depth[i]));
        }
        std::printf(
            "bunny at %g radii, 1 px: %llu of %zu triangles; ids agree at %zu of %zu pixels (%zu covered), "
            "depths within %g\n",
            double(radii), (unsigned long long)compute->stats.lodTriangles, scene.triangleCount(), agree,
            pixels, covered, double(worstDepth));
        EXPECT_GT(covered, pixels / 50);
        EXPECT_GE(double(agree), 0.999 * double(pixels));
        EXPECT_LT(worstDepth, 1e-3f);
    }
    EXPECT_EQ(vulkanValidationErrorCount(), errorsBefore);
}

}  // namespace
}  // namespace sr::test
