// points_test.cpp - points on each backend against analytic coverage: the square of the point size
// centred on the snapped vertex covers the samples inside it (left and top sides inside, right and
// bottom outside), at the vertex's depth, with ids after the triangles'; culled whole when the vertex
// leaves the view volume; unlit colour. The conformant rasterizer's points are compared in
// points_graphics_test.cpp and the oracle tests.
#include <cmath>

#include <gtest/gtest.h>

#include "scene/primitive_mode.h"
#include "test_util.h"

namespace sr::test {
namespace {

constexpr uint32_t kSize = 32;  // power of two: window <-> NDC conversions are exact

// Points (and triangles) in a kSize x kSize viewport.
Scene pointScene(const std::vector<WindowPoint>& points, const std::vector<glm::vec4>& triangles = {})
{
    return windowPointScene(points, kSize, kSize, triangles);
}

class PointsTest : public BackendTest {};

// The expected owner of every sample: the nearest point whose square contains it (ties to the lowest
// id), by the rule in double precision.
std::vector<uint32_t> expectedSamples(const std::vector<WindowPoint>& points, uint32_t triangles, float size,
                                      uint32_t msaa)
{
    std::vector<uint32_t> ids(size_t(kSize) * kSize * msaa, EMPTY_ID);
    std::vector<float> depth(ids.size(), 2.0f);
    for (uint32_t k = 0; k < points.size(); ++k) {
        const WindowPoint& p = points[k];
        for (uint32_t s = 0; s < msaa; ++s)
            for (uint32_t y = 0; y < kSize; ++y)
                for (uint32_t x = 0; x < kSize; ++x) {
                    ivec2 o = standardSample(msaa, s);
                    double sx = x + o.x / 16.0, sy = y + o.y / 16.0;
                    bool inside = sx >= p.x - size / 2 && sx < p.x + size / 2 && sy >= p.y - size / 2 &&
                                  sy < p.y + size / 2;
                    size_t i = size_t(s) * kSize * kSize + size_t(y) * kSize + x;
                    if (inside && p.z < depth[i]) {
                        depth[i] = p.z;
                        ids[i] = triangles + k;
                    }
                }
    }
    return ids;
}

// Points at pixel centres, on pixel corners and on edges, of sizes 1 to 5, overlapping at different
// depths: every sample matches the rule, at 1 and 4 samples per pixel.
TEST_P(PointsTest, SquaresCoverTheSamplesInsideWithTheTopLeftRule)
{
    const std::vector<WindowPoint> points = {
        {4.5, 4.5, 0.5f},     // centre
        {10.0, 4.0, 0.5f},    // corner
        {16.0, 4.5, 0.5f},    // vertical edge
        {22.5, 4.0, 0.5f},    // horizontal edge
        {5.25, 12.75, 0.3f},  // off-grid
        {6.0, 13.0, 0.2f},    // overlapping, nearer
        {20.5, 20.5, 0.6f},   // a big one, partly under...
        {21.0, 21.0, 0.4f},   // ...a nearer one
    };
    for (float size : {1.0f, 2.0f, 3.0f, 5.0f})
        for (uint32_t msaa : {1u, 4u}) {
            RenderSettings s = testSettings(kSize, kSize);
            s.pointSize = size;
            s.msaa = msaa;
            s.aovSamples = true;
            RenderOutput out = render(pointScene(points), s);
            ASSERT_EQ(out.samples.id.size(), size_t(kSize) * kSize * msaa);
            std::vector<uint32_t> expected = expectedSamples(points, 0, size, msaa);
            for (size_t i = 0; i < expected.size(); ++i) {
                ASSERT_EQ(out.samples.id[i], expected[i])
                    << "size " << size << ", " << msaa << "x, sample " << i / (kSize * kSize) << " of pixel "
                    << i % kSize << "," << (i / kSize) % kSize;
                if (expected[i] != EMPTY_ID) {
                    ASSERT_EQ(out.samples.depth[i], points[expected[i]].z);
                }
            }
            EXPECT_EQ(out.stats.points, points.size());
        }
}

// A point's vertex outside the view volume removes the whole point, even where its square would
// reach into the viewport; a point inside the viewport whose square crosses its border is cut there.
TEST_P(PointsTest, PointsOutsideTheViewVolumeAreCulledWhole)
{
    RenderSettings s = testSettings(kSize, kSize);
    s.pointSize = 8.0f;
    RenderOutput out =
        render(pointScene({{kSize + 0.25, 10.5, 0.5f}, {-0.25, 20.5, 0.5f}, {8.5, 8.5, 1.5f}}), s);
    EXPECT_EQ(countId(out.aov, 0), 0u);
    EXPECT_EQ(countId(out.aov, 1), 0u);
    EXPECT_EQ(countId(out.aov, 2), 0u);  // beyond the far plane
    EXPECT_EQ(out.stats.culled, 3u);
    out = render(pointScene({{1.5, 1.5, 0.5f}}), s);
    EXPECT_EQ(countId(out.aov, 0), 5u * 5u);  // x and y from -2.5 to 5.5: pixels 0..4
}

// Points and triangles share the depth test and one id space: triangles first, then points.
TEST_P(PointsTest, PointsAndTrianglesShareDepthAndIds)
{
    std::vector<glm::vec4> quad = clipQuad(-1, -1, 0, 1, 0.5f);  // covers the left half at depth 0.5
    Scene scene = pointScene({{8.5, 8.5, 0.7f}, {8.5, 20.5, 0.3f}, {24.5, 8.5, 0.7f}}, quad);
    RenderSettings s = testSettings(kSize, kSize);
    s.pointSize = 3.0f;
    RenderOutput out = render(scene, s);
    EXPECT_EQ(countId(out.aov, 2), 0u);  // behind the quad
    EXPECT_EQ(countId(out.aov, 3), 9u);  // in front of it
    EXPECT_EQ(countId(out.aov, 4), 9u);  // beside it
    EXPECT_EQ(out.aov.id[20 * kSize + 8], 3u);
    EXPECT_EQ(out.aov.depth[20 * kSize + 8], 0.3f);
}

// Points are drawn unlit: vertex colour x material factor, whatever the light.
TEST_P(PointsTest, PointsAreUnlit)
{
    Scene scene = pointScene({{8.5, 8.5, 0.5f}, {20.5, 20.5, 0.5f}});
    scene.colors = {glm::vec4(0.25f, 0.5f, 1.0f, 1.0f), glm::vec4(1.0f)};
    SceneMaterial red;
    red.baseColorFactor = glm::vec4(1.0f, 0.2f, 0.2f, 1.0f);
    scene.materials = {SceneMaterial{}, red};
    scene.pointMaterials = {0, 1};
    RenderSettings s = testSettings(kSize, kSize);
    s.lightColor = glm::vec3(3.0f);
    RenderOutput out = render(scene, s);
    EXPECT_EQ(out.color.pixels[8 * kSize + 8], packRgba8(vec3(0.25f, 0.5f, 1.0f)));
    EXPECT_EQ(out.color.pixels[20 * kSize + 20], packRgba8(vec3(1.0f, 0.2f, 0.2f)));
}

// A scene of points alone renders; a point with a non-finite position is dropped and counted.
TEST_P(PointsTest, PointCloudsRenderAndBadPointsAreDropped)
{
    Scene scene = pointScene({{3.5, 3.5, 0.5f}, {7.5, 3.5, 0.5f}, {11.5, 3.5, 0.5f}});
    scene.positions[1].x = std::nanf("");
    RenderOutput out = render(scene, testSettings(kSize, kSize));
    EXPECT_EQ(countId(out.aov, 0), 1u);
    EXPECT_EQ(countId(out.aov, 1), 0u);
    EXPECT_EQ(countId(out.aov, 2), 1u);
    EXPECT_EQ(out.stats.invalid, 1u);
    EXPECT_EQ(out.stats.points, 2u);
}

TEST_P(PointsTest, PointSizesOutsideTheRangeAreUsageErrors)
{
    for (float size : {0.5f, 64.125f, 1.1f, NAN}) {
        RenderSettings s = testSettings(kSize, kSize);
        s.pointSize = size;
        auto out = renderScene(*device_, pointScene({{3.5, 3.5, 0.5f}}), identityCamera(), s);
        ASSERT_FALSE(out.ok()) << size;
        EXPECT_EQ(out.error().code, ExitCode::Usage);
    }
}

// --primitive-mode points: every vertex a triangle uses, once, in vertex order, with the material of
// the first triangle that uses it; unused vertices are not drawn; the file's own points follow.
TEST(PrimitiveMode, MeshAsPointsKeepsEachUsedVertexOnce)
{
    Scene scene;
    for (int i = 0; i < 6; ++i) {
        scene.positions.push_back(glm::vec4(float(i), 0.0f, 0.0f, 1.0f));
        scene.normals.push_back(glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
    }
    scene.indices = {4, 1, 2, 2, 1, 0};  // vertices 3 and 5 unused
    scene.triFlags = {0, 0};
    scene.materials = {SceneMaterial{}, SceneMaterial{}, SceneMaterial{}};
    scene.triMaterials = {2, 1};
    scene.points = {5};
    scene.pointMaterials = {0};
    Scene points = meshAsPoints(scene);
    EXPECT_EQ(points.triangleCount(), 0u);
    EXPECT_TRUE(points.triMaterials.empty());
    EXPECT_EQ(points.points, (std::vector<uint32_t>{0, 1, 2, 4, 5}));
    EXPECT_EQ(points.pointMaterials, (std::vector<uint32_t>{1, 2, 2, 2, 0}));
    EXPECT_EQ(points.positions.size(), scene.positions.size());
}

// The built-in scene drawn as its vertices on each backend: as many points rasterized as its mesh
// uses vertices inside the view, and every covered pixel shows a point id.
TEST_P(PointsTest, TheBuiltInSceneAsPoints)
{
    FramedScene f = framedBuiltin(96, 72);
    Scene points = meshAsPoints(f.scene);
    f.settings.pointSize = 2.0f;
    RenderOutput out = render(points, f.settings, f.camera);
    EXPECT_GT(out.stats.points, points.pointCount() / 2);
    EXPECT_EQ(out.stats.points + out.stats.culled, points.pointCount());
    size_t covered = 0;
    for (uint32_t id : out.aov.id) {
        if (id == EMPTY_ID) continue;
        ++covered;
        ASSERT_LT(id, points.pointCount());
    }
    EXPECT_GT(covered, 200u);
}

INSTANTIATE_TEST_SUITE_P(Backends, PointsTest, ::testing::Values("vulkan", "cuda"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace sr::test
