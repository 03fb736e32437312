// points_graphics_test.cpp - points in the `vulkan-graphics` reference backend on the machine's first
// suitable Vulkan device (lavapipe in CI) with validation on, against expectations that owe nothing to
// the backend: Vulkan's basic point rasterization (a sample is covered when it lies inside the square of
// side pointSize centred on the point's framebuffer position), the spec's table of standard sample
// locations, the view-volume cull of points (VK_POINT_CLIPPING_BEHAVIOR_ALL_CLIP_PLANES), the depth
// test against triangles, and the unlit colour (vertex colour x material factor). Positions put no
// sample on a side of a square, except in the test of those ties, which the spec leaves open: there
// every device must give each tied sample to exactly one side, and lavapipe to the left and top sides.
// No Vulkan device is a failure unless SR_ALLOW_MISSING_BACKENDS lists vulkan.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "test_util.h"
#include "vulkan/vulkan_device_internal.h"
#include "vulkan/vulkan_graphics.h"

namespace sr::test {
namespace {

constexpr uint32_t kSize = 16;  // power of two: every window position below converts to NDC exactly

// The spec's standard sample locations at 4 samples per pixel ("Standard sample locations"), in pixels
// from the pixel's top-left corner, sample 0 first.
const glm::dvec2 kStandard4x[4] = {{0.375, 0.125}, {0.875, 0.375}, {0.125, 0.625}, {0.625, 0.875}};
const glm::dvec2 kCentre(0.5, 0.5);

// Whether the point's vertex lies in the view volume (0 <= x, y <= kSize, 0 <= z <= 1 in window
// terms, the planes themselves inside): a point outside is discarded whole.
bool inView(const WindowPoint& p)
{
    return p.x >= 0.0 && p.x <= kSize && p.y >= 0.0 && p.y <= kSize && p.z >= 0.0f && p.z <= 1.0f;
}

// Whether the square of side `size` centred on p (scaled by `scale`: SSAA raster coordinates) covers
// the sample at s by the spec's rule. The position must put no sample on a side: a tie fails the test.
bool covers(const WindowPoint& p, double size, glm::dvec2 s, double scale = 1.0)
{
    const double h = size / 2, dx = std::abs(s.x - p.x * scale), dy = std::abs(s.y - p.y * scale);
    EXPECT_FALSE((dx == h && dy <= h) || (dy == h && dx <= h))
        << "sample " << s.x << "," << s.y << " on a side of the square at " << p.x << "," << p.y;
    return dx < h && dy < h;
}

// The rule with ties to the left and top sides (inside) and the right and bottom ones (outside): the
// top-left rule of a square drawn as two triangles.
bool coversTopLeft(const WindowPoint& p, double size, glm::dvec2 s)
{
    const double h = size / 2;
    return s.x >= p.x - h && s.x < p.x + h && s.y >= p.y - h && s.y < p.y + h;
}

// Points (and triangles) in a kSize x kSize viewport.
Scene pointScene(const std::vector<WindowPoint>& points, const std::vector<glm::vec4>& triangles = {})
{
    return windowPointScene(points, kSize, kSize, triangles);
}

class PointsGraphicsTest : public GraphicsTest {
protected:
    // Renders the points alone at 1x and point size `size` and checks every pixel: the first point in
    // the view volume whose square covers the pixel centre (all points share one depth or are apart),
    // with that point's depth, else empty.
    void expectPixels(const std::vector<WindowPoint>& points, float size)
    {
        RenderSettings s = unlitSettings(kSize, kSize);
        s.pointSize = size;
        RenderOutput out = render(pointScene(points), s);
        ASSERT_EQ(out.aov.id.size(), size_t(kSize) * kSize);
        for (uint32_t y = 0; y < kSize; ++y)
            for (uint32_t x = 0; x < kSize; ++x) {
                uint32_t id = EMPTY_ID;
                float depth = 1.0f;
                for (uint32_t k = 0; k < points.size() && id == EMPTY_ID; ++k)
                    if (inView(points[k]) && covers(points[k], size, glm::dvec2(x, y) + kCentre)) {
                        id = k;
                        depth = points[k].z;
                    }
                const size_t i = size_t(y) * kSize + x;
                EXPECT_EQ(out.aov.id[i], id) << "size " << size << " pixel " << x << "," << y;
                EXPECT_EQ(out.aov.depth[i], depth) << "size " << size << " pixel " << x << "," << y;
            }
    }

    size_t errorsBefore_ = 0;
};

// Size 1 at pixel centres: exactly those pixels, each with its point's id and depth.
TEST_F(PointsGraphicsTest, SizeOneAtAPixelCentreCoversThatPixelAlone)
{
    expectPixels({{5.5, 9.5, 0.25f}, {12.5, 3.5, 0.75f}, {0.5, 15.5, 0.5f}}, 1.0f);
}

// Odd sizes at a pixel centre cover the size x size block around it; even sizes do at a pixel corner.
// No pixel centre lies on a side of these squares.
TEST_F(PointsGraphicsTest, SizesAtCentresAndCornersCoverTheirBlocks)
{
    for (float size : {3.0f, 5.0f}) expectPixels({{7.5, 7.5, 0.5f}}, size);
    for (float size : {2.0f, 4.0f}) expectPixels({{8.0, 8.0, 0.5f}}, size);
    // Off the pixel grid, sizes cover the centres inside: [4.625, 7.625) x [8.625, 11.625) at size 3 and
    // [5.375, 6.875) x [9.375, 10.875) at size 1.5.
    expectPixels({{6.125, 10.125, 0.5f}}, 3.0f);
    expectPixels({{6.125, 10.125, 0.5f}}, 1.5f);
    RenderSettings s = unlitSettings(kSize, kSize);
    s.pointSize = 5.0f;
    EXPECT_EQ(countId(render(pointScene({{7.5, 7.5, 0.5f}}), s).aov, 0u), 25u);
}

// Samples on the square's sides: size 1 at a pixel corner and at a pixel's edge midpoint, size 2 and 4
// at a pixel centre, size 3 at a corner, and at 4x MSAA size 1 where sample 0 of pixels (5, 5) and
// (6, 5) lies on the left and right sides and the top and bottom ones. The spec does not say which side
// such a sample falls to; each must fall to exactly one (a whole-pixel size covers size^2 pixel
// centres), and lavapipe gives it to the left and top sides, like the top-left rule of a square drawn
// as two triangles.
TEST_F(PointsGraphicsTest, SamplesOnTheSidesGoToExactlyOneSideLavapipeTheTopLeft)
{
    struct Tie {
        WindowPoint p;
        float size;
        uint32_t msaa;
    };
    const Tie ties[] = {{{6.0, 6.0, 0.5f}, 1.0f, 1}, {{6.0, 6.5, 0.5f}, 1.0f, 1},
                        {{6.5, 6.5, 0.5f}, 2.0f, 1}, {{6.5, 6.5, 0.5f}, 4.0f, 1},
                        {{6.0, 6.0, 0.5f}, 3.0f, 1}, {{5.875, 5.625, 0.5f}, 1.0f, 4},
                        {{6.0, 6.0, 0.5f}, 2.0f, 4}, {{6.125, 6.375, 0.5f}, 2.0f, 4}};
    for (const Tie& tie : ties) {
        RenderSettings s = unlitSettings(kSize, kSize);
        s.pointSize = tie.size;
        s.msaa = tie.msaa;
        s.aovSamples = true;
        RenderOutput out = render(pointScene({tie.p}), s);
        ASSERT_EQ(out.samples.id.size(), size_t(tie.msaa) * kSize * kSize);
        const bool lavapipe = out.device.name.find("llvmpipe") != std::string::npos;
        size_t covered = 0, expected = 0;
        for (uint32_t k = 0; k < tie.msaa; ++k)
            for (uint32_t y = 0; y < kSize; ++y)
                for (uint32_t x = 0; x < kSize; ++x) {
                    const glm::dvec2 at = glm::dvec2(x, y) + (tie.msaa == 1 ? kCentre : kStandard4x[k]);
                    const bool topLeft = coversTopLeft(tie.p, tie.size, at);
                    const uint32_t id = out.samples.id[size_t(k) * kSize * kSize + size_t(y) * kSize + x];
                    covered += id == 0u;
                    expected += topLeft;
                    if (lavapipe) {
                        EXPECT_EQ(id, topLeft ? 0u : EMPTY_ID)
                            << "size " << tie.size << " at " << tie.p.x << "," << tie.p.y << ", " << tie.msaa
                            << "x: sample " << k << " of " << x << "," << y;
                    }
                }
        // Either side of each tie gives the same count: the square holds as many samples either way.
        EXPECT_EQ(covered, expected) << "size " << tie.size << " at " << tie.p.x << "," << tie.p.y;
    }
}

// At 4x MSAA a point covers exactly the standard sample locations inside its square, with its depth,
// and nothing else: size 1 at a pixel centre (the four samples of that pixel), at a pixel corner (one
// sample of each of four pixels), off the grid at size 1.5, and size 3. No sample lies on a side.
TEST_F(PointsGraphicsTest, MultisampledPointsCoverTheStandardSamplesInsideTheirSquare)
{
    struct Case {
        WindowPoint p;
        float size;
    };
    for (const Case& c : {Case{{5.5, 5.5, 0.25f}, 1.0f}, Case{{10.0, 6.0, 0.5f}, 1.0f},
                          Case{{6.25, 10.75, 0.5f}, 1.5f}, Case{{12.5, 12.5, 0.75f}, 3.0f}}) {
        RenderSettings s = unlitSettings(kSize, kSize);
        s.pointSize = c.size;
        s.msaa = 4;
        s.aovSamples = true;
        RenderOutput out = render(pointScene({c.p}), s);
        ASSERT_EQ(out.samples.samples, 4u);
        ASSERT_EQ(out.samples.id.size(), size_t(4) * kSize * kSize);
        size_t covered = 0;
        for (uint32_t k = 0; k < 4; ++k)
            for (uint32_t y = 0; y < kSize; ++y)
                for (uint32_t x = 0; x < kSize; ++x) {
                    const size_t i = size_t(k) * kSize * kSize + size_t(y) * kSize + x;
                    const bool inside = covers(c.p, c.size, glm::dvec2(x, y) + kStandard4x[k]);
                    covered += inside;
                    EXPECT_EQ(out.samples.id[i], inside ? 0u : EMPTY_ID)
                        << "size " << c.size << " at " << c.p.x << "," << c.p.y << ": sample " << k << " of "
                        << x << "," << y;
                    EXPECT_EQ(out.samples.depth[i], inside ? c.p.z : 1.0f)
                        << "sample " << k << " of " << x << "," << y;
                }
        // Size 1 has a pixel's area: 4 samples wherever it lies (off the sides).
        if (c.size == 1.0f) {
            EXPECT_EQ(covered, 4u) << c.p.x << "," << c.p.y;
        }
    }
}

// A point whose vertex lies outside the view volume is discarded whole, even where its square would
// reach into the viewport (points a quarter pixel beyond each side, and points before the near and
// beyond the far plane); points on the boundary planes are inside and drawn, clipped to the viewport
// like any other, and so is a point just inside an edge. Quarter-pixel positions keep pixel centres off
// the squares' sides at every size used; the points on the planes x = 0 and x = 16 only at even sizes.
TEST_F(PointsGraphicsTest, PointsOutsideTheViewVolumeAreCulledWhole)
{
    std::vector<WindowPoint> points = {{16.25, 8.25, 0.5f},  {-0.25, 4.25, 0.5f},  {8.25, 16.25, 0.5f},
                                       {4.25, -0.25, 0.5f},  {8.25, 8.25, -0.25f}, {11.25, 8.25, 1.25f},
                                       {15.75, 12.25, 0.5f}, {8.25, 4.25, 0.0f},   {16.0, 2.25, 0.5f},
                                       {0.0, 12.25, 0.5f}};
    for (size_t k = 0; k < 6; ++k) EXPECT_FALSE(inView(points[k])) << k;
    for (size_t k = 6; k < points.size(); ++k) EXPECT_TRUE(inView(points[k])) << k;
    expectPixels(points, 2.0f);
    expectPixels(points, 4.0f);
    points.resize(8);
    expectPixels(points, 5.0f);
}

// One depth buffer for triangles and points: a full-screen quad (two triangles, ids 0 and 1) at depth
// 0.5 hides a point behind it and loses to one in front; a point at the quad's own depth loses (the
// lower id wins a tie, as in the compute pipeline's visibility key); of two overlapping points at one
// depth the first wins. Point ids follow the triangles': point k is 2 + k.
TEST_F(PointsGraphicsTest, DepthTestOrdersPointsAndTriangles)
{
    const std::vector<WindowPoint> points = {
        {4.5, 4.5, 0.75f}, {11.5, 4.5, 0.25f}, {4.5, 11.5, 0.5f}, {11.5, 11.5, 0.25f}, {12.5, 11.5, 0.25f}};
    RenderSettings s = unlitSettings(kSize, kSize);
    s.pointSize = 3.0f;
    for (uint32_t msaa : {1u, 4u}) {
        s.msaa = msaa;
        RenderOutput out = render(pointScene(points, clipQuad(-1, -1, 1, 1, 0.5f)), s);
        ASSERT_EQ(out.aov.id.size(), size_t(kSize) * kSize);
        for (uint32_t y = 0; y < kSize; ++y)
            for (uint32_t x = 0; x < kSize; ++x) {
                // The nearest point covering the AOV sample (sample 0), the first of equal depths, if
                // it is nearer than the quad.
                const glm::dvec2 at = glm::dvec2(x, y) + (msaa == 1 ? kCentre : kStandard4x[0]);
                uint32_t id = EMPTY_ID;
                float depth = 0.5f;
                for (uint32_t k = 0; k < points.size(); ++k)
                    if (covers(points[k], s.pointSize, at) && points[k].z < depth) {
                        id = 2 + k;
                        depth = points[k].z;
                    }
                const size_t i = size_t(y) * kSize + x;
                if (id == EMPTY_ID) {
                    EXPECT_LT(out.aov.id[i], 2u) << msaa << "x pixel " << x << "," << y;
                } else {
                    EXPECT_EQ(out.aov.id[i], id) << msaa << "x pixel " << x << "," << y;
                }
                EXPECT_EQ(out.aov.depth[i], depth) << msaa << "x pixel " << x << "," << y;
            }
        EXPECT_EQ(countId(out.aov, 2u), 0u) << msaa;  // behind the quad
        EXPECT_EQ(countId(out.aov, 4u), 0u) << msaa;  // at the quad's depth
        EXPECT_EQ(countId(out.aov, 3u), 9u) << msaa;  // in front
        EXPECT_EQ(countId(out.aov, 5u), 9u) << msaa;  // first of two at one depth
        EXPECT_EQ(countId(out.aov, 6u), 3u) << msaa;  // its right column only
        EXPECT_EQ(out.stats.pointsIn, points.size());
    }
}

// Points are unlit: their colour is the vertex colour times the material's base colour factor, in
// every lighting setup (here Blinn-Phong with a strong light and no ambient), sRGB-encoded at 1x and
// the linear mean of the samples with anti-aliasing (a fully covered pixel: the colour itself).
TEST_F(PointsGraphicsTest, PointColourIsTheVertexColourTimesTheMaterialFactorUnlit)
{
    Scene scene = pointScene({{4.5, 4.5, 0.5f}, {11.5, 11.5, 0.5f}});
    scene.colors = {glm::vec4(0.9f, 0.5f, 0.2f, 1.0f), glm::vec4(0.3f, 0.8f, 0.6f, 1.0f)};
    SceneMaterial warm, cool;
    warm.baseColorFactor = glm::vec4(0.5f, 1.0f, 0.75f, 1.0f);
    cool.baseColorFactor = glm::vec4(1.0f, 0.25f, 0.5f, 1.0f);
    scene.materials = {warm, cool};
    scene.pointMaterials = {1, 0};
    RenderSettings s = testSettings(kSize, kSize);
    s.shadingMode = SHADING_BLINN_PHONG;
    s.ambient = 0.0f;
    s.lightColor = glm::vec3(3.0f);
    s.pointSize = 3.0f;
    const glm::vec3 expected[2] = {glm::vec3(scene.colors[0] * cool.baseColorFactor),
                                   glm::vec3(scene.colors[1] * warm.baseColorFactor)};
    for (uint32_t msaa : {1u, 4u}) {
        s.msaa = msaa;
        RenderOutput out = render(scene, s);
        ASSERT_EQ(out.color.pixels.size(), size_t(kSize) * kSize);
        for (uint32_t k = 0; k < 2; ++k) {
            const uint32_t c = 4 + 7 * k;  // the point's pixel, the centre of its 3 x 3 block
            for (uint32_t dy = 0; dy < 3; ++dy)
                for (uint32_t dx = 0; dx < 3; ++dx) {
                    const size_t i = size_t(c - 1 + dy) * kSize + c - 1 + dx;
                    EXPECT_EQ(out.aov.id[i], k);
                    EXPECT_LE(channelDifference(out.color.pixels[i], packRgba8(expected[k])), 1)
                        << msaa << "x point " << k << std::hex << ": " << out.color.pixels[i] << " vs "
                        << packRgba8(expected[k]);
                }
        }
        EXPECT_EQ(out.color.pixels[0], packRgba8(s.background)) << msaa;
    }
}

// A points-only scene renders in every output mode: 1x, the visibility pass, 4x MSAA (with and without
// the visibility pass) and SSAA 2 (with and without MSAA). The id and Z AOVs report each output
// pixel's representative sample (aovSampleIndex), and the point size counts raster pixels, as in the
// compute pipeline (under SSAA 2 the square is [11, 14) raster pixels per side here).
TEST_F(PointsGraphicsTest, PointsRenderInEveryOutputMode)
{
    const std::vector<WindowPoint> points = {{6.25, 6.25, 0.25f}, {12.25, 3.25, 0.5f}};
    const Scene scene = pointScene(points);
    for (const OutputMode& mode : kOutputModes) {
        RenderSettings s = outputModeSettings(mode, kSize, kSize);
        s.pointSize = 3.0f;
        RenderOutput out = render(scene, s);
        ASSERT_EQ(out.aov.id.size(), size_t(kSize) * kSize);
        EXPECT_EQ(out.stats.pointsIn, 2u);
        EXPECT_EQ(out.stats.trianglesIn, 0u);
        const uint32_t n = mode.ssaa;
        const glm::dvec2 offset = mode.msaa == 1 ? kCentre : kStandard4x[0];
        for (uint32_t y = 0; y < kSize; ++y)
            for (uint32_t x = 0; x < kSize; ++x) {
                const glm::dvec2 at = glm::dvec2(x * n + n / 2, y * n + n / 2) + offset;
                uint32_t id = EMPTY_ID;
                float depth = 1.0f;
                for (uint32_t k = 0; k < points.size() && id == EMPTY_ID; ++k)
                    if (covers(points[k], s.pointSize, at, n)) {
                        id = k;
                        depth = points[k].z;
                    }
                const size_t i = size_t(y) * kSize + x;
                EXPECT_EQ(out.aov.id[i], id) << mode.msaa << "x ssaa " << n << " vis " << mode.visibilityOnly
                                             << " pixel " << x << "," << y;
                EXPECT_EQ(out.aov.depth[i], depth)
                    << mode.msaa << "x ssaa " << n << " pixel " << x << "," << y;
            }
        // The visibility pass writes the background; the full pass the point's colour (white).
        const uint32_t covered = out.color.pixels[size_t(6) * kSize + 6];
        EXPECT_EQ(covered, mode.visibilityOnly ? packRgba8(s.background) : packRgba8(glm::vec3(1.0f)))
            << mode.msaa << "x ssaa " << n;
    }
}

// A point size the device cannot draw exactly, or outside 1..MAX_POINT_SIZE, is refused with one Usage
// line before anything is drawn (lavapipe draws 0 to 255 in steps of 1/8).
TEST_F(PointsGraphicsTest, AnUnsupportedPointSizeIsAOneLineUsageError)
{
    const Scene scene = pointScene({{8.5, 8.5, 0.5f}});
    for (float size : {0.5f, 1.0625f, 2.3f, 65.0f, 300.0f, std::numeric_limits<float>::quiet_NaN()}) {
        RenderSettings s = unlitSettings(kSize, kSize);
        s.pointSize = size;
        auto out = renderVulkanGraphics(scene, identityCamera(), s, -1);
        ASSERT_FALSE(out.ok()) << "size " << size << " accepted";
        EXPECT_EQ(out.error().code, ExitCode::Usage) << out.error().message;
        EXPECT_TRUE(isOneLine(out.error().message)) << out.error().message;
    }
}

}  // namespace
}  // namespace sr::test
