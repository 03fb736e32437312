// lines_oracle_test.cpp - the compute pipeline's line segments against the conformant rasterizer
// (`vulkan-graphics` drawing VK_PRIMITIVE_TOPOLOGY_LINE_LIST with rectangular lines; lavapipe in CI),
// sample by sample.
//
// Criteria: with endpoints on the 1/256-pixel grid, identical ids at every sample at 1x, for segments of
// every octant, of slopes 0, 1/3, 1, 3 and vertical, of lengths 0, 1 and 1000 pixels, with endpoints
// on pixel centres, edges and corners and anywhere on the grid, widths 1 to 3, crossing each other and
// triangles. Depth where the ids agree: within the depth change over one subpixel (1/256 px) along the
// segment plus 1e-6 (depthBound): lavapipe interpolates depth from the unsnapped segment, we across
// the snapped rectangle's two triangles, whose corners are rounded to the subpixel grid. With MSAA,
// coverage (covered or not, every sample) must be identical, but ids and depth are not compared:
// lavapipe (Mesa 22.3) evaluates a multisampled line's depth half a pixel off (lines_graphics_test.cpp
// pins it), which changes which of two crossing lines wins. The glTF-Asset-Generator's line models
// from Debian's assimp-testmodels, through a perspective camera, may differ in at most
// kProjectedBound samples, as projected points and triangles may (points_oracle_test.cpp), depth by
// depthBound of the projected segments. Wider lines with MSAA may differ in coverage in at most
// kRoundingBound samples, the freedom the rectangle's rounded corners leave (its half-width offset is
// rounded to the subpixel grid once, from the snapped segment here and from the unsnapped one in
// lavapipe); at 1x no sample of these scenes comes that close to a side. These are the criteria
// against lavapipe (CI). A GPU's line rasterizer rounds with its own precision (on the H100 up to 2
// differing ids at 1x and 0.3% of the samples' coverage with MSAA), so on a GPU every id and coverage
// count may be up to gpuBound: 0.5% of the covered samples.
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <random>

#include <gtest/gtest.h>

#include "test_util.h"

namespace sr::test {
namespace {

constexpr long kProjectedBound = 64;
constexpr long kRoundingBound = 4;

// The depth criterion for window-space segments: 1e-6 plus the largest depth change over 1/256 px.
float depthBound(const std::vector<WindowLine>& lines)
{
    double gradient = 0.0;
    for (const WindowLine& l : lines) {
        double length = std::hypot(l.x1 - l.x0, l.y1 - l.y0);
        if (length > 0.0) gradient = std::max(gradient, std::abs(double(l.z1) - l.z0) / length);
    }
    return float(1e-6 + gradient / 256.0);
}

class LinesOracleTest : public ComputeOracleTest {
protected:
    // `strict` against the conformant CPU rasterizer, else gpuBound of the covered samples.
    long bound(long strict, size_t covered) const
    {
        return compute_->info().isCpu ? strict : std::max<long>(strict, long(covered / 200));
    }
};

Scene linesWithTriangles(const std::vector<WindowLine>& lines, uint32_t w, uint32_t h)
{
    return windowLineScene(lines, w, h,
                           {windowVertex(3, 30, w, h, 0.5f), windowVertex(40, 28, w, h, 0.5f),
                            windowVertex(20, 45, w, h, 0.5f)});
}

// The scene's segments in window coordinates of a width x height viewport under `camera`.
std::vector<WindowLine> projectedLines(const Scene& scene, const CameraMatrices& camera, uint32_t w,
                                       uint32_t h)
{
    auto window = [&](uint32_t v, double& x, double& y, float& z) {
        glm::vec4 c = camera.clipFromWorld * scene.positions[v];
        x = (c.x / c.w + 1.0) * 0.5 * w;
        y = (c.y / c.w + 1.0) * 0.5 * h;
        z = c.z / c.w;
    };
    std::vector<WindowLine> lines(scene.lineCount());
    for (size_t k = 0; k < lines.size(); ++k) {
        window(scene.lines[2 * k], lines[k].x0, lines[k].y0, lines[k].z0);
        window(scene.lines[2 * k + 1], lines[k].x1, lines[k].y1, lines[k].z1);
    }
    return lines;
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
        SampleAgreement r = compareSamples(scene, s, identityCamera());
        EXPECT_LE(r.differingIds, bound(0, r.covered)) << "width " << width;
        EXPECT_LE(r.maxDepthDifference, depthBound(lines)) << "width " << width;
        EXPECT_GT(r.covered, 300u);
        std::cout << "[ measured ] width " << width << " 1x: " << r.differingIds << " of " << r.covered
                  << " samples differ, depth within " << r.maxDepthDifference << " (bound "
                  << depthBound(lines) << ")\n";
        int offered = 0;
        for (uint32_t msaa : {2u, 4u, 8u, 16u}) {
            s.msaa = msaa;
            r = compareSamples(scene, s, identityCamera());
            if (!r.offered) continue;
            ++offered;
            EXPECT_LE(r.differingCoverage, bound(width == 1.0f ? 0 : kRoundingBound, r.covered))
                << "width " << width << " at " << msaa << "x";
            std::cout << "[ measured ] width " << width << " " << msaa << "x: coverage differs in "
                      << r.differingCoverage << " of " << r.covered << " samples\n";
        }
        EXPECT_GT(offered, 0);
    }
}

// 1000-pixel segments, shallow and steep, through the binned path on both sides.
TEST_F(LinesOracleTest, ThousandPixelSegmentsAgree)
{
    const std::vector<WindowLine> shallow = {{10.5, 4.5, 0.2f, 1010.5, 4.5, 0.8f},
                                             {1012.0, 10.0, 0.5f, 12.0, 20.0, 0.5f},
                                             {5.25, 30.5, 0.7f, 1005.25, 2.5, 0.1f}};
    const std::vector<WindowLine> steep = {{4.5, 10.5, 0.2f, 4.5, 1010.5, 0.8f},
                                           {20.0, 1012.0, 0.5f, 10.0, 12.0, 0.5f}};
    for (const auto& [lines, w, h] : {std::tuple{&shallow, 1024u, 32u}, std::tuple{&steep, 32u, 1024u}}) {
        SampleAgreement r =
            compareSamples(windowLineScene(*lines, w, h), testSettings(w, h), identityCamera());
        EXPECT_LE(r.differingIds, bound(0, r.covered)) << w << "x" << h;
        EXPECT_LE(r.maxDepthDifference, depthBound(*lines)) << w << "x" << h;
        EXPECT_GE(r.covered, 950u * lines->size());  // crossing segments share a few pixels
        std::cout << "[ measured ] 1000 px, " << w << "x" << h << ": " << r.differingIds << " of "
                  << r.covered << " samples differ, depth within " << r.maxDepthDifference << "\n";
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
    for (int k = 1; k <= 15; ++k) {
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
            SampleAgreement r = compareSamples(*scene, s, *camera);
            EXPECT_LE(r.differingIds, kProjectedBound) << file << " width " << width;
            EXPECT_LE(r.maxDepthDifference, depthBound(projectedLines(*scene, *camera, 96, 96)))
                << file << " width " << width;
            EXPECT_GT(r.covered, 100u) << file;
            std::cout << "[ measured ] " << file.substr(root.size()) << " width " << width << ": "
                      << r.differingIds << " of " << r.covered << " samples differ, depth within "
                      << r.maxDepthDifference << "\n";
        }
    }
    EXPECT_GE(models, 6);
}

}  // namespace
}  // namespace sr::test
