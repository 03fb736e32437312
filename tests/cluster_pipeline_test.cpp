// cluster_pipeline_test.cpp - stage clusters (cuda/clusters.cuh, compute_glsl/clusters.comp) against
// setup's thread per triangle on each backend: --clusters on must draw the same ids, depths and colours
// and count the same culled, clipped, invalid, small and big triangles as --clusters off, over scenes,
// cameras (inside the mesh, where clusters cross the near plane, to far away), cull modes, raster
// methods, MSAA, the alpha test, lines and points beside the triangles, lists that overflow and grow, and
// vertices that are not finite. The clusters must also be used and cull: a test that never reached stage
// clusters would pass by comparing setup with itself.
#include <gtest/gtest.h>

#include "camera/camera.h"
#include "scene/clusters.h"
#include "test_util.h"

namespace sr::test {
namespace {

class ClusterPathTest : public BackendTest {
protected:
    // Renders `scene` with clusters off and on and checks that everything the frame shows or counts is
    // the same; returns the clusters frame's statistics.
    RenderStats expectSameFrame(const Scene& scene, const CameraMatrices& camera, RenderSettings s,
                                const std::string& what)
    {
        s.clusters = CLUSTERS_OFF;
        RenderOutput off = render(scene, s, camera);
        s.clusters = CLUSTERS_ON;
        RenderOutput on = render(scene, s, camera);
        EXPECT_EQ(off.stats.clusters, 0u) << what;
        EXPECT_EQ(on.aov.id, off.aov.id) << what;
        EXPECT_EQ(on.aov.depth, off.aov.depth) << what;
        EXPECT_EQ(on.color.pixels, off.color.pixels) << what;
        EXPECT_EQ(on.samples.id, off.samples.id) << what;
        EXPECT_EQ(on.samples.depth, off.samples.depth) << what;
        EXPECT_EQ(on.stats.culled, off.stats.culled) << what;
        EXPECT_EQ(on.stats.clipped, off.stats.clipped) << what;
        EXPECT_EQ(on.stats.invalid, off.stats.invalid) << what;
        EXPECT_EQ(on.stats.smallTris, off.stats.smallTris) << what;
        EXPECT_EQ(on.stats.bigTris, off.stats.bigTris) << what;
        EXPECT_EQ(on.stats.lines, off.stats.lines) << what;
        EXPECT_EQ(on.stats.points, off.stats.points) << what;
        return on.stats;
    }
};

CameraMatrices orbit(const Scene& scene, float azimuth, float elevation, float radii, uint32_t w, uint32_t h)
{
    const BoundingSphere sphere = boundingSphere(scene);
    OrbitPose pose;
    pose.azimuthDeg = azimuth;
    pose.elevationDeg = elevation;
    pose.distance = radii * sphere.radius;
    return orbitCameraMatrices(pose, sphere, w, h);
}

// testSettings with back faces culled, as a render does by default: the facing test must be at work.
RenderSettings backSettings(uint32_t width, uint32_t height)
{
    RenderSettings s = testSettings(width, height);
    s.cullMode = CULL_BACK;
    return s;
}

Scene loaded(const std::string& name)
{
    auto scene = name.rfind("builtin", 0) == 0 ? builtinSceneNamed(name) : loadScene(glmark2Model(name));
    EXPECT_TRUE(scene.ok()) << name << ": " << (scene.ok() ? "" : scene.error().message);
    return scene.ok() ? std::move(*scene) : Scene{};
}

TEST_P(ClusterPathTest, ClustersDrawAndCountWhatSetupDoes)
{
    uint64_t clustersCulled = 0;
    for (const char* name : {"builtin", "builtin:dense", "bunny.obj"}) {
        const Scene scene = loaded(name);
        for (float radii : {0.5f, 1.5f, 3.0f, 12.0f}) {
            for (float azimuth : {20.0f, 160.0f}) {
                const CameraMatrices camera = orbit(scene, azimuth, 30.0f, radii, 96, 64);
                RenderSettings s = backSettings(96, 64);
                const std::string what = std::string(name) + " at " + std::to_string(radii) +
                                         " radii, azimuth " + std::to_string(azimuth);
                RenderStats st = expectSameFrame(scene, camera, s, what);
                EXPECT_GT(st.clusters, 0u) << what;
                clustersCulled += st.clustersCulled;
            }
        }
        // Every cull mode and fixed-point method, MSAA (every sample compared), and lists of one entry
        // that overflow, grow and redraw.
        const CameraMatrices camera = orbit(scene, 40.0f, 20.0f, 2.0f, 96, 64);
        for (uint32_t cull : {uint32_t(CULL_FRONT), uint32_t(CULL_NONE)}) {
            RenderSettings s = backSettings(96, 64);
            s.cullMode = cull;
            expectSameFrame(scene, camera, s, std::string(name) + " cull " + std::to_string(cull));
        }
        for (uint32_t method : {uint32_t(RASTER_FIXED4), uint32_t(RASTER_FLOAT)}) {
            RenderSettings s = backSettings(96, 64);
            s.rasterMethod = method;
            expectSameFrame(scene, camera, s, std::string(name) + " method " + std::to_string(method));
        }
        RenderSettings s = backSettings(96, 64);
        s.msaa = 4;
        s.aovSamples = true;
        s.initialListCapacity = 1;
        expectSameFrame(scene, camera, s, std::string(name) + " msaa 4, one-entry lists");
    }
    EXPECT_GT(clustersCulled, 0u) << "no cluster was ever culled whole";
}

// The alpha test of MASK materials (stage clusters' materials build), and lines and points beside the
// triangles (setup then sets up the lines and points alone, from primitive triangleCount on).
TEST_P(ClusterPathTest, AlphaTestAndLinesAndPointsBesideClusters)
{
    Scene scene = loaded("builtin:checker");
    ASSERT_FALSE(scene.materials.empty());
    SceneMaterial cut = scene.materials[0];
    cut.alphaMode = ALPHA_MASK;
    cut.alphaCutoff = 0.7f;
    cut.baseColorFactor.w = 0.6f;  // below the cutoff: every masked triangle vanishes, where it covers
    scene.materials.push_back(cut);
    for (size_t t = 0; t < scene.triFlags.size(); t += 3) {
        scene.triFlags[t] |= TRI_FLAG_ALPHA_MASK;
        scene.triMaterials[t] = uint32_t(scene.materials.size() - 1);
    }
    const CameraMatrices camera = orbit(scene, 10.0f, 35.0f, 2.0f, 96, 64);
    RenderStats masked = expectSameFrame(scene, camera, backSettings(96, 64), "checker with MASK triangles");
    EXPECT_GT(masked.clusters, 0u);

    Scene mixed = loaded("builtin");
    for (uint32_t v = 0; v + 1 < 40; v += 2) {
        mixed.lines.push_back(v);
        mixed.lines.push_back(v + 1);
        mixed.lineMaterials.push_back(mixed.triMaterials.empty() ? 0u : mixed.triMaterials[0]);
        mixed.points.push_back(v);
        mixed.pointMaterials.push_back(mixed.triMaterials.empty() ? 0u : mixed.triMaterials[0]);
    }
    if (mixed.materials.empty()) {
        mixed.lineMaterials.clear();
        mixed.pointMaterials.clear();
    }
    RenderSettings s = backSettings(96, 64);
    s.pointSize = 3.0f;
    s.lineWidth = 2.0f;
    RenderStats st = expectSameFrame(mixed, orbit(mixed, 30.0f, 20.0f, 2.0f, 96, 64), s, "lines and points");
    EXPECT_GT(st.clusters, 0u);
    EXPECT_GT(st.lines, 0u);
    EXPECT_GT(st.points, 0u);
}

// A vertex that is not finite (its triangles are counted invalid, its cluster never culled), double-sided
// triangles (never culled by facing), and a scene with an index out of range, which has no clusters: its
// triangles go through setup, which counts the bad one invalid.
TEST_P(ClusterPathTest, BadVerticesDoubleSidedTrianglesAndBadIndices)
{
    Scene scene = loaded("builtin:dense");
    scene.positions[scene.indices[300]] = glm::vec4(NAN, 0.0f, 0.0f, 1.0f);
    scene.positions[scene.indices[900]] = glm::vec4(INFINITY, 1.0f, 0.0f, 1.0f);
    for (size_t t = 0; t < scene.triFlags.size(); t += 7) scene.triFlags[t] |= TRI_FLAG_DOUBLE_SIDED;
    const CameraMatrices camera = orbit(scene, 60.0f, 10.0f, 2.0f, 96, 64);
    RenderStats st =
        expectSameFrame(scene, camera, backSettings(96, 64), "non-finite vertices, double-sided");
    EXPECT_GT(st.invalid, 0u);
    EXPECT_GT(st.clusters, 0u);

    // A scene that never went through finalizeScene (no triangle flags) is refused in one line.
    Scene unflagged = scene;
    unflagged.triFlags.clear();
    auto refused = renderScene(*device_, unflagged, camera, backSettings(96, 64));
    ASSERT_FALSE(refused.ok());
    EXPECT_NE(refused.error().message.find("triangle flags"), std::string::npos) << refused.error().message;

    scene.indices[5] = uint32_t(scene.positions.size()) + 10;
    RenderStats bad = expectSameFrame(scene, camera, backSettings(96, 64), "an index out of range");
    EXPECT_EQ(bad.clusters, 0u);
    EXPECT_GT(bad.invalid, st.invalid);
}

// A session switching between the two paths and sizes draws what a fresh device draws without clusters.
TEST_P(ClusterPathTest, ASessionSwitchingPathsDrawsWhatAFreshDeviceDraws)
{
    const Scene scene = loaded("bunny.obj");
    auto session = RenderSession::create(*device_, scene);
    ASSERT_TRUE(session.ok()) << session.error().message;
    bool skip = false;
    auto fresh = openBackend(GetParam(), skip);
    ASSERT_TRUE(fresh);
    for (uint32_t clusters : {CLUSTERS_ON, CLUSTERS_OFF, CLUSTERS_ON}) {
        for (uint32_t w : {64u, 120u}) {
            RenderSettings s = backSettings(w, 48);
            s.clusters = clusters;
            const CameraMatrices camera = orbit(scene, float(w), 20.0f, 1.8f, w, 48);
            auto inSession = session->render(camera, s);
            ASSERT_TRUE(inSession.ok()) << inSession.error().message;
            s.clusters = CLUSTERS_OFF;
            auto alone = renderScene(*fresh, scene, camera, s);
            ASSERT_TRUE(alone.ok()) << alone.error().message;
            EXPECT_EQ(inSession->aov.id, alone->aov.id) << clusters << " " << w;
            EXPECT_EQ(inSession->color.pixels, alone->color.pixels) << clusters << " " << w;
            EXPECT_EQ(inSession->stats.clusters > 0u, clusters == CLUSTERS_ON) << clusters << " " << w;
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, ClusterPathTest, ::testing::Values("vulkan", "cuda"));

}  // namespace
}  // namespace sr::test
