// lines_test.cpp - line segments on each backend against Vulkan's rectangular-line rule computed
// independently in double precision (lineCoversSample): the rectangle of the line width centred on the
// segment, ends cut square at the endpoints, the top-left rule where a sample lies on an end cap; depth
// linear along the segment; clipping against near and far; ids after the triangles and before the
// points; unlit colour interpolated perspective-correctly; the wireframe depth bias. The conformant
// rasterizer's lines are compared in lines_oracle_test.cpp.
#include <cmath>
#include <cstdlib>

#include <gtest/gtest.h>

#include "test_util.h"

namespace sr::test {
namespace {

constexpr uint32_t kSize = 32;  // power of two: window <-> NDC conversions are exact

class LinesTest : public BackendTest {};

// Every sample of `out` (kSize x kSize, `msaa` samples, `width` px lines) against the rule: the nearest
// segment covering it (ties to the lowest id), skipping samples the rule leaves to rounding. Returns how
// many samples were checked as covered.
size_t expectRule(const RenderOutput& out, const std::vector<WindowLine>& lines, double width, uint32_t msaa,
                  uint32_t firstId = 0)
{
    size_t covered = 0;
    for (uint32_t s = 0; s < msaa; ++s)
        for (uint32_t y = 0; y < kSize; ++y)
            for (uint32_t x = 0; x < kSize; ++x) {
                ivec2 o = standardSample(msaa, s);
                double sx = x + o.x / 16.0, sy = y + o.y / 16.0;
                uint32_t expected = EMPTY_ID;
                float depth = 2.0f;
                bool unsure = false;
                for (uint32_t k = 0; k < lines.size(); ++k) {
                    int c = lineCoversSample(lines[k], width, sx, sy);
                    unsure = unsure || c < 0;
                    // Flat lines (z0 == z1) only, so the depth of the winner is exact.
                    if (c == 1 && lines[k].z0 < depth) {
                        depth = lines[k].z0;
                        expected = firstId + k;
                    }
                }
                if (unsure) continue;
                size_t i = size_t(s) * kSize * kSize + size_t(y) * kSize + x;
                EXPECT_EQ(out.samples.id[i], expected)
                    << msaa << "x, sample " << s << " of pixel " << x << "," << y;
                if (expected != EMPTY_ID) {
                    EXPECT_EQ(out.samples.depth[i], depth);
                    ++covered;
                }
            }
    return covered;
}

RenderSettings lineSettings(double width, uint32_t msaa)
{
    RenderSettings s = testSettings(kSize, kSize);
    s.lineWidth = float(width);
    s.msaa = msaa;
    s.aovSamples = true;
    return s;
}

// Segments of every octant and of slopes 0, 1/3, 1, 3 and vertical, with ends on pixel centres, edges
// and corners and off the grid, at widths 1, 2, 3 and 2.5: every sample matches the rule at 1 and 4
// samples per pixel.
TEST_P(LinesTest, RectanglesCoverTheSamplesInside)
{
    std::vector<WindowLine> lines;
    const double ends[][4] = {
        {2.5, 2.5, 12.5, 2.5},    {12.5, 5.5, 2.5, 5.5},      // horizontal, both directions, centres
        {2.0, 8.0, 12.0, 8.0},    {14.5, 2.5, 14.5, 12.5},    // on a pixel edge / corners; vertical
        {17.5, 12.5, 17.5, 2.5},  {20.0, 2.0, 20.0, 12.0},    // vertical up; on corners
        {2.5, 16.5, 11.5, 19.5},  {11.5, 22.5, 2.5, 19.5},    // slope 1/3, both directions
        {14.5, 16.5, 17.5, 25.5}, {22.5, 28.5, 19.5, 19.5},   // slope 3
        {24.5, 2.5, 30.5, 8.5},   {30.0, 10.0, 24.0, 16.0},   // slope 1 and -1 (corners)
        {3.3, 26.1, 12.7, 29.9},  {25.2, 30.6, 29.8, 17.35},  // off the grid
    };
    for (const auto& e : ends) lines.push_back({e[0], e[1], 0.5f, e[2], e[3], 0.5f});
    for (double width : {1.0, 2.0, 3.0, 2.5})
        for (uint32_t msaa : {1u, 4u}) {
            // Each width on its own, so neighbours do not overlap: one segment per render at width > 1.
            for (size_t k = 0; k < lines.size(); ++k) {
                RenderOutput out =
                    render(windowLineScene({lines[k]}, kSize, kSize), lineSettings(width, msaa));
                ASSERT_EQ(out.samples.id.size(), size_t(kSize) * kSize * msaa);
                SCOPED_TRACE(testing::Message() << "segment " << k << ", width " << width);
                EXPECT_GT(expectRule(out, {lines[k]}, width, msaa), 0u);
                EXPECT_EQ(out.stats.lines, 1u);
            }
        }
}

// The end caps: a horizontal segment from pixel centre to pixel centre covers its length in pixels,
// the first endpoint's pixel but not the last one's, whichever way it runs; a strip of two such
// segments covers every pixel once.
TEST_P(LinesTest, EndCapsFollowTheTopLeftRule)
{
    RenderSettings s = testSettings(kSize, kSize);
    RenderOutput out = render(windowLineScene({{2.5, 3.5, 0.5f, 9.5, 3.5, 0.5f},
                                               {9.5, 6.5, 0.5f, 2.5, 6.5, 0.5f},
                                               {5.5, 10.5, 0.5f, 5.5, 20.5, 0.5f}},
                                              kSize, kSize),
                              s);
    for (uint32_t x = 0; x < kSize; ++x) {
        EXPECT_EQ(out.aov.id[3 * kSize + x], x >= 2 && x <= 8 ? 0u : EMPTY_ID) << x;
        EXPECT_EQ(out.aov.id[6 * kSize + x], x >= 2 && x <= 8 ? 1u : EMPTY_ID) << x;
    }
    for (uint32_t y = 7; y < kSize; ++y)  // below the two horizontal segments
        EXPECT_EQ(out.aov.id[y * kSize + 5], y >= 10 && y <= 19 ? 2u : EMPTY_ID) << y;

    s.countHits = true;
    s.shadingMode = SHADING_HIT_COUNT;
    out = render(
        windowLineScene({{2.5, 3.5, 0.5f, 9.5, 3.5, 0.5f}, {9.5, 3.5, 0.5f, 20.5, 3.5, 0.5f}}, kSize, kSize),
        s);
    ASSERT_EQ(out.hitCount.size(), size_t(kSize) * kSize);
    for (uint32_t x = 0; x < kSize; ++x)
        EXPECT_EQ(out.hitCount[3 * kSize + x], x >= 2 && x <= 19 ? 1u : 0u) << x;
}

// Depth is linear along the segment in window space (depth is affine in screen space).
TEST_P(LinesTest, DepthIsInterpolatedAlongTheSegment)
{
    RenderOutput out = render(windowLineScene({{2.5, 4.5, 0.2f, 26.5, 4.5, 0.8f}}, kSize, kSize),
                              testSettings(kSize, kSize));
    for (uint32_t x = 2; x <= 25; ++x) {
        double expected = 0.2 + (x - 2) / 24.0 * 0.6;
        EXPECT_NEAR(out.aov.depth[4 * kSize + x], expected, 1e-6) << x;
    }
}

// Ids: triangles, then segments, then points; all share the depth test.
TEST_P(LinesTest, LinesShareDepthAndIdsWithTrianglesAndPoints)
{
    std::vector<glm::vec4> quad = clipQuad(-1, -1, 0, 1, 0.5f);  // the left half at depth 0.5
    Scene scene = windowLineScene({{2.5, 8.5, 0.7f, 30.5, 8.5, 0.7f}, {2.5, 20.5, 0.3f, 30.5, 20.5, 0.3f}},
                                  kSize, kSize, quad, {{24.5, 26.5, 0.5f}});
    RenderOutput out = render(scene, testSettings(kSize, kSize));
    EXPECT_EQ(out.aov.id[8 * kSize + 4], 0u);    // behind the quad...
    EXPECT_EQ(out.aov.id[8 * kSize + 20], 2u);   // ...beside it
    EXPECT_EQ(out.aov.id[20 * kSize + 4], 3u);   // in front of the quad
    EXPECT_EQ(out.aov.id[26 * kSize + 24], 4u);  // the point after the two segments
    EXPECT_EQ(countId(out.aov, 2), 14u);
    EXPECT_EQ(countId(out.aov, 3), 28u);
    EXPECT_EQ(out.stats.linesIn, 2u);
    EXPECT_EQ(out.stats.lines, 2u);
}

// Near and far clip the segment (the drawn part starts where it crosses the plane, at depth 0 there);
// a segment outside one viewport plane draws nothing even where its width would reach in; a zero-length
// segment draws nothing.
TEST_P(LinesTest, ClippingAndCulling)
{
    // Window depth -0.5 at x = 2.5 to 0.5 at x = 22.5: z = 0 at x = 12.5.
    RenderOutput out = render(windowLineScene({{2.5, 4.5, -0.5f, 22.5, 4.5, 0.5f}}, kSize, kSize),
                              testSettings(kSize, kSize));
    for (uint32_t x = 0; x < kSize; ++x)
        EXPECT_EQ(out.aov.id[4 * kSize + x], x >= 12 && x <= 21 ? 0u : EMPTY_ID) << x;
    EXPECT_EQ(out.aov.depth[4 * kSize + 12], 0.0f);
    EXPECT_EQ(out.stats.clipped, 1u);
    // Beyond far from x = 12.5 on.
    out = render(windowLineScene({{2.5, 4.5, 0.5f, 22.5, 4.5, 1.5f}}, kSize, kSize),
                 testSettings(kSize, kSize));
    for (uint32_t x = 0; x < kSize; ++x)
        EXPECT_EQ(out.aov.id[4 * kSize + x], x >= 2 && x <= 11 ? 0u : EMPTY_ID) << x;

    RenderSettings wide = testSettings(kSize, kSize);
    wide.lineWidth = 8.0f;
    out = render(windowLineScene({{-1.0, 2.5, 0.5f, -1.0, 20.5, 0.5f}, {4.5, 8.5, 0.5f, 4.5, 8.5, 0.5f}},
                                 kSize, kSize),
                 wide);
    EXPECT_EQ(countId(out.aov, 0), 0u);
    EXPECT_EQ(countId(out.aov, 1), 0u);
    EXPECT_EQ(out.stats.culled, 2u);
    EXPECT_EQ(out.stats.lines, 0u);
}

// A line longer than the small-triangle span goes through the binned path (its rectangle's triangles
// are big, stored as records and cut into pieces) and still follows the rule exactly.
TEST_P(LinesTest, LongLinesAreBinned)
{
    const std::vector<WindowLine> lines = {{0.75, 1.25, 0.5f, 31.25, 29.5, 0.5f},
                                           {31.5, 2.5, 0.5f, 1.5, 6.5, 0.5f}};
    for (uint32_t msaa : {1u, 4u}) {
        RenderSettings s = lineSettings(3.0, msaa);
        s.initialListCapacity = 1;  // every list overflows once: grown and redrawn
        RenderOutput out = render(windowLineScene(lines, kSize, kSize), s);
        EXPECT_GT(expectRule(out, lines, 3.0, msaa), 150u);
        EXPECT_GT(out.stats.bigTris, 0u);
        EXPECT_GT(out.stats.records, 0u);
        EXPECT_GT(out.stats.redraws, 0u);
    }
}

// Lines are unlit: vertex colours mixed at the perspective-correct parameter of the point nearest the
// pixel centre, times the material factor.
TEST_P(LinesTest, ColourIsInterpolatedPerspectiveCorrectly)
{
    // A horizontal segment whose second end has w = 3 (clip coordinates scaled), so screen and
    // perspective parameters differ.
    Scene scene = windowLineScene({{2.5, 8.5, 0.5f, 26.5, 8.5, 0.5f}}, kSize, kSize);
    scene.positions[1] *= 3.0f;
    scene.colors = {glm::vec4(1.0f, 0.0f, 0.0f, 1.0f), glm::vec4(0.0f, 0.0f, 1.0f, 1.0f)};
    SceneMaterial half;
    half.baseColorFactor = glm::vec4(0.5f, 1.0f, 1.0f, 1.0f);
    scene.materials = {half};
    scene.lineMaterials = {0};
    RenderSettings s = testSettings(kSize, kSize);
    s.lightColor = glm::vec3(3.0f);
    RenderOutput out = render(scene, s);
    for (uint32_t x = 2; x <= 25; ++x) {
        double sFrac = (x - 2) / 24.0;
        double u = (sFrac / 3.0) / ((1.0 - sFrac) + sFrac / 3.0);
        uint32_t expected = packRgba8(vec3(float(0.5 * (1.0 - u)), 0.0f, float(u)));
        EXPECT_LE(channelDifference(out.color.pixels[8 * kSize + x], expected), 1) << x;
    }
}

// --wireframe's depth bias: an edge lying on its own surface loses the depth tie to it (the lower id
// wins) without the bias and wins with it; an edge behind a surface stays hidden.
TEST_P(LinesTest, WireframeBiasLiftsEdgesOffTheirSurface)
{
    std::vector<glm::vec4> quad = clipQuad(-1, -1, 1, 1, 0.5f);
    Scene scene = windowLineScene({{2.5, 8.5, 0.5f, 30.5, 8.5, 0.5f}, {2.5, 20.5, 0.6f, 30.5, 20.5, 0.6f}},
                                  kSize, kSize, quad);
    RenderSettings s = testSettings(kSize, kSize);
    EXPECT_EQ(countId(render(scene, s).aov, 2), 0u);
    s.lineDepthBias = kWireframeDepthBias;
    RenderOutput out = render(scene, s);
    EXPECT_EQ(countId(out.aov, 2), 28u);
    EXPECT_EQ(countId(out.aov, 3), 0u);
    EXPECT_NEAR(out.aov.depth[8 * kSize + 10], 0.5 - kWireframeDepthBias * 0.5, 1e-7);
}

// Bad input: a non-finite vertex or an out-of-range index drops the segment (counted invalid); widths
// outside 1..64 or off the 1/8 grid are usage errors.
TEST_P(LinesTest, BadLinesAreDroppedAndBadWidthsRefused)
{
    Scene scene = windowLineScene({{2.5, 3.5, 0.5f, 9.5, 3.5, 0.5f},
                                   {2.5, 6.5, 0.5f, 9.5, 6.5, 0.5f},
                                   {2.5, 9.5, 0.5f, 9.5, 9.5, 0.5f}},
                                  kSize, kSize);
    scene.positions[1].y = std::nanf("");
    scene.lines[3] = 1000;
    RenderOutput out = render(scene, testSettings(kSize, kSize));
    EXPECT_EQ(countId(out.aov, 0), 0u);
    EXPECT_EQ(countId(out.aov, 1), 0u);
    EXPECT_EQ(countId(out.aov, 2), 7u);
    EXPECT_EQ(out.stats.invalid, 2u);
    for (float width : {0.5f, 64.125f, 1.1f, NAN}) {
        RenderSettings s = testSettings(kSize, kSize);
        s.lineWidth = width;
        auto bad = renderScene(*device_, windowLineScene({{2.5, 3.5, 0.5f, 9.5, 3.5, 0.5f}}, kSize, kSize),
                               identityCamera(), s);
        ASSERT_FALSE(bad.ok()) << width;
        EXPECT_EQ(bad.error().code, ExitCode::Usage);
        EXPECT_TRUE(isOneLine(bad.error().message));
    }
}

// The acceptance models: every glTF-Asset-Generator Mesh_PrimitiveMode file (points, lines, loops,
// strips, triangles, with and without indices) and assimp-testmodels' OBJ files with `l` and `p`
// render, and every kind of primitive the file has shows in the ids.
TEST_P(LinesTest, PrimitiveModeModelsAndObjLinesAndPointsRender)
{
    const char* env = std::getenv("SR_ASSIMP_MODELS");
    const std::string root = std::string(env ? env : "/usr/share/assimp/models");
    std::vector<std::string> files = {root + "/OBJ/testline.obj", root + "/OBJ/testpoints.obj",
                                      root + "/OBJ/point_cloud.obj"};
    for (int k = 0; k <= 15; ++k)
        files.push_back(
            root +
            fmt::format("/glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_{:02d}.gltf", k));
    for (const std::string& file : files) {
        auto scene = loadScene(file);
        ASSERT_TRUE(scene.ok()) << scene.error().message;
        auto camera = resolveCamera(CameraSpec{}, *scene, 64, 64);
        ASSERT_TRUE(camera.ok()) << file;
        RenderSettings s = testSettings(64, 64);
        s.cullMode = CULL_NONE;
        RenderOutput out = render(*scene, s, *camera);
        const size_t tris = scene->triangleCount(), lineEnd = tris + scene->lineCount();
        size_t kinds[3] = {0, 0, 0};
        for (uint32_t id : out.aov.id)
            if (id != EMPTY_ID) ++kinds[id < tris ? 0 : id < lineEnd ? 1 : 2];
        EXPECT_EQ(kinds[0] > 0, tris > 0) << file;
        EXPECT_EQ(kinds[1] > 0, scene->lineCount() > 0) << file;
        EXPECT_EQ(kinds[2] > 0, scene->pointCount() > 0) << file;
        EXPECT_EQ(out.stats.lines, scene->lineCount()) << file;
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, LinesTest, ::testing::Values("vulkan", "cuda"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace sr::test
