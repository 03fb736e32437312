// lines_oracle_test.cpp - the compute pipeline's line segments against the conformant rasterizer
// (`vulkan-graphics` drawing VK_PRIMITIVE_TOPOLOGY_LINE_LIST with rectangular lines; lavapipe in CI),
// sample by sample.
//
// Criteria: endpoints on the 1/256-pixel grid give identical ids at every sample and depth within
// kDepthBound (lavapipe interpolates depth along the line with its own plane, we across the rectangle's
// two triangles), for segments of every octant, of slopes 0, 1/3, 1, 3 and vertical, of lengths 0, 1
// and 1000 pixels, with endpoints on pixel centres, edges and corners and anywhere on the grid, widths 1
// to 3, mixed with triangles, at 1x and at every MSAA count the device offers. The rule leaves freedom
// in the rounding of a rectangle's corners (its half-width offset is rounded to the subpixel grid once,
// from the snapped segment here and from the unsnapped one in lavapipe), so samples within a subpixel
// of a side may differ: at most kRoundingBound per scene. The glTF-Asset-Generator's line models from
// Debian's assimp-testmodels, through a perspective camera, may differ in at most kProjectedBound
// samples, as projected points and triangles may (points_oracle_test.cpp).
#include <cstdlib>
#include <random>

#include <gtest/gtest.h>

#include "test_util.h"

namespace sr::test {
namespace {

constexpr float kDepthBound = 1e-6f;
constexpr long kRoundingBound = 4;
constexpr long kProjectedBound = 64;

using LinesOracleTest = ComputeOracleTest;

Scene linesWithTriangles(const std::vector<WindowLine>& lines, uint32_t w, uint32_t h)
{
    return windowLineScene(lines, w, h,
                           {windowVertex(3, 30, w, h, 0.5f), windowVertex(40, 28, w, h, 0.5f),
                            windowVertex(20, 45, w, h, 0.5f)});
}

// Every octant and the named slopes from pixel centres, edges and corners, and random grid positions.
TEST_F(LinesOracleTest, SegmentsOfEverySlopeAndEndpointAgree)
{
    constexpr uint32_t kSize = 48;
    std::mt19937 rng(23);
    std::uniform_int_distribution<int> cell(4, kSize - 5), sub(0, 255);
    std::uniform_real_distribution<float> depth(0.1f, 0.9f);
    std::vector<WindowLine> lines;
    // Direction vectors: slopes 0, 1/3, 1, 3 and vertical, in all eight octants (both signs of each).
    const int directions[][2] = {{6, 0}, {6, 2}, {4, 4}, {2, 6}, {0, 6}};
    const double offsets[][2] = {{0.5, 0.5}, {0.0, 0.0}, {0.5, 0.0}, {0.0, 0.5}};  // centre, corner, edges
    for (const auto& d : directions)
        for (int sx : {1, -1})
            for (int sy : {1, -1})
                for (const auto& o : offsets) {
                    double x = cell(rng) + o[0], y = cell(rng) + o[1];
                    float z = depth(rng);
                    lines.push_back({x, y, z, x + sx * d[0], y + sy * d[1], z});
                }
    for (int i = 0; i < 12; ++i) {  // anywhere on the grid, varying depth
        double x0 = cell(rng) + sub(rng) / 256.0, y0 = cell(rng) + sub(rng) / 256.0;
        double x1 = cell(rng) + sub(rng) / 256.0, y1 = cell(rng) + sub(rng) / 256.0;
        lines.push_back({x0, y0, depth(rng), x1, y1, depth(rng)});
    }
    lines.push_back({10.5, 10.5, 0.3f, 10.5, 10.5, 0.3f});  // length 0: nothing
    lines.push_back({12.5, 40.5, 0.3f, 13.5, 40.5, 0.3f});  // length 1
    lines.push_back({30.0, 40.0, 0.3f, 30.0, 41.0, 0.3f});  // length 1 on corners
    const Scene scene = linesWithTriangles(lines, kSize, kSize);
    for (float width : {1.0f, 2.0f, 3.0f}) {
        RenderSettings s = testSettings(kSize, kSize);
        s.lineWidth = width;
        size_t covered = 0;
        long differing = differingSamples(scene, s, identityCamera(), covered, kDepthBound);
        EXPECT_LE(differing, width == 1.0f ? 0 : kRoundingBound) << "width " << width << " at 1x";
        EXPECT_GT(covered, 300u);
        int offered = 0;
        for (uint32_t msaa : {2u, 4u, 8u, 16u}) {
            s.msaa = msaa;
            differing = differingSamples(scene, s, identityCamera(), covered, kDepthBound);
            if (differing < 0) continue;
            ++offered;
            EXPECT_LE(differing, width == 1.0f ? 0 : kRoundingBound)
                << "width " << width << " at " << msaa << "x";
        }
        EXPECT_GT(offered, 0);
    }
}

// 1000-pixel segments, shallow and steep, through the binned path on both sides.
TEST_F(LinesOracleTest, ThousandPixelSegmentsAgree)
{
    const Scene wide = windowLineScene({{10.5, 4.5, 0.2f, 1010.5, 4.5, 0.8f},
                                        {1012.0, 10.0, 0.5f, 12.0, 20.0, 0.5f},
                                        {5.25, 30.5, 0.7f, 1005.25, 2.5, 0.1f}},
                                       1024, 32);
    const Scene tall = windowLineScene(
        {{4.5, 10.5, 0.2f, 4.5, 1010.5, 0.8f}, {20.0, 1012.0, 0.5f, 10.0, 12.0, 0.5f}}, 32, 1024);
    for (const auto& [scene, w, h] : {std::tuple{&wide, 1024u, 32u}, std::tuple{&tall, 32u, 1024u}}) {
        RenderSettings s = testSettings(w, h);
        size_t covered = 0;
        EXPECT_EQ(differingSamples(*scene, s, identityCamera(), covered, kDepthBound), 0) << w << "x" << h;
        EXPECT_GT(covered, 2900u);
    }
}

// glTF-Asset-Generator's Mesh_PrimitiveMode_01 to _06 (LINES, LINE_LOOP, LINE_STRIP, with and without
// indices) under the auto camera, at widths 1 and 2.
TEST_F(LinesOracleTest, AssetGeneratorLineModelsAgree)
{
    const char* env = std::getenv("SR_ASSIMP_MODELS");
    const std::string root = std::string(env ? env : "/usr/share/assimp/models") +
                             "/glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/";
    int models = 0;
    for (int k = 1; k <= 13; ++k) {
        const std::string file = root + fmt::format("Mesh_PrimitiveMode_{:02d}.gltf", k);
        auto scene = loadScene(file);
        ASSERT_TRUE(scene.ok()) << scene.error().message;
        if (scene->lineCount() == 0) continue;
        ++models;
        auto camera = resolveCamera(CameraSpec{}, *scene, 96, 96);
        ASSERT_TRUE(camera.ok());
        for (float width : {1.0f, 2.0f}) {
            RenderSettings s = testSettings(96, 96);
            s.lineWidth = width;
            size_t covered = 0;
            long differing = differingSamples(*scene, s, *camera, covered, kDepthBound);
            EXPECT_GE(differing, 0) << file;
            EXPECT_LE(differing, kProjectedBound) << file << " width " << width;
            EXPECT_GT(covered, 100u) << file;
        }
    }
    EXPECT_GE(models, 6);
}

}  // namespace
}  // namespace sr::test
