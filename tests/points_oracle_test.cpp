// points_oracle_test.cpp - the compute pipeline's points against the conformant rasterizer
// (`vulkan-graphics` drawing VK_PRIMITIVE_TOPOLOGY_POINT_LIST; lavapipe in CI), sample by sample.
//
// Criteria, as for triangles: vertices on the 1/256-pixel grid give identical ids and depth at every
// sample, for points at pixel centres, on pixel corners and edges (where only the tie rule decides),
// off the grid of pixels, of every size from 1 to 9 pixels, mixed with triangles, at 1x and at every
// MSAA count the device offers. The glTF-Asset-Generator's POINTS models from Debian's assimp-testmodels,
// seen through a perspective camera (projected vertices, w != 1), may differ in at most
// kProjectedBound samples, where one pipeline's float projection rounds a vertex to the neighbouring
// subpixel, as triangles may (oracle_test.cpp), and depth by kProjectedDepthBound.
#include <cstdlib>
#include <random>

#include <gtest/gtest.h>

#include "test_util.h"
#include "vulkan/vulkan_graphics.h"

namespace sr::test {
namespace {

constexpr uint32_t kSize = 48;
constexpr long kProjectedBound = 64;
// lavapipe divides z by w of the unsnapped vertex with its own rounding: a few ulps at depth ~0.7.
constexpr float kProjectedDepthBound = 1e-6f;

using PointsOracleTest = ComputeOracleTest;

// Points on and off every kind of grid position, in front of and behind two triangles.
TEST_F(PointsOracleTest, PointsOfEverySizeAndPositionAgreeAtEverySample)
{
    std::mt19937 rng(17);
    std::uniform_int_distribution<int> cell(2, kSize - 3), sub(0, 255);
    std::uniform_real_distribution<float> depth(0.1f, 0.9f);
    Scene scene = clipSpaceScene(
        {windowVertex(3, 30, kSize, kSize, 0.5f), windowVertex(40, 28, kSize, kSize, 0.5f),
         windowVertex(20, 45, kSize, kSize, 0.5f), windowVertex(30, 2, kSize, kSize, 0.45f),
         windowVertex(46, 20, kSize, kSize, 0.45f), windowVertex(28, 22, kSize, kSize, 0.45f)});
    auto addPoint = [&](double x, double y) {
        scene.points.push_back(uint32_t(scene.positions.size()));
        scene.positions.push_back(windowVertex(x, y, kSize, kSize, depth(rng)));
        scene.normals.push_back(glm::vec4(0.0f));
    };
    for (int i = 0; i < 12; ++i) {
        double x = cell(rng), y = cell(rng);
        addPoint(x + 0.5, y + 0.5);                            // pixel centre
        addPoint(x, y);                                        // pixel corner
        addPoint(x + 0.5, y);                                  // horizontal edge
        addPoint(x, y + 0.5);                                  // vertical edge
        addPoint(x + sub(rng) / 256.0, y + sub(rng) / 256.0);  // anywhere on the 1/256 grid
    }
    for (float size : {1.0f, 2.0f, 3.0f, 4.5f, 9.0f}) {
        RenderSettings s = testSettings(kSize, kSize);
        s.pointSize = size;
        size_t covered = 0;
        EXPECT_EQ(differingSamples(scene, s, identityCamera(), covered), 0) << "size " << size << " at 1x";
        EXPECT_GT(covered, 100u);
        int offered = 0;
        for (uint32_t msaa : {2u, 4u, 8u, 16u}) {
            s.msaa = msaa;
            long differing = differingSamples(scene, s, identityCamera(), covered);
            if (differing < 0) continue;
            ++offered;
            EXPECT_EQ(differing, 0) << "size " << size << " at " << msaa << "x";
        }
        EXPECT_GT(offered, 0);
    }
}

// glTF-Asset-Generator's Mesh_PrimitiveMode_00 (POINTS, no indices) and _07 (POINTS, indices) under the
// auto camera, 1 and 3 px points.
TEST_F(PointsOracleTest, AssetGeneratorPointModelsAgree)
{
    const char* env = std::getenv("SR_ASSIMP_MODELS");
    const std::string root = std::string(env ? env : "/usr/share/assimp/models") +
                             "/glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/";
    for (const char* file : {"Mesh_PrimitiveMode_00.gltf", "Mesh_PrimitiveMode_07.gltf"}) {
        auto scene = loadScene(root + file);
        ASSERT_TRUE(scene.ok()) << scene.error().message;
        ASSERT_EQ(scene->pointCount(), 1024u) << file;
        auto camera = resolveCamera(CameraSpec{}, *scene, 96, 96);
        ASSERT_TRUE(camera.ok());
        for (float size : {1.0f, 3.0f}) {
            RenderSettings s = testSettings(96, 96);
            s.pointSize = size;
            size_t covered = 0;
            long differing = differingSamples(*scene, s, *camera, covered, kProjectedDepthBound);
            EXPECT_GE(differing, 0) << file;
            EXPECT_LE(differing, kProjectedBound) << file << " size " << size;
            EXPECT_GT(covered, 100u) << file;
        }
    }
}

}  // namespace
}  // namespace sr::test
