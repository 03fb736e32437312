// lines_graphics_test.cpp - line segments in the `vulkan-graphics` reference backend on the machine's
// first suitable Vulkan device (lavapipe in CI) with validation on, against expectations that owe
// nothing to the backend: Vulkan's rectangular line rasterization (a sample is covered when it lies
// inside the rectangle of the line width centred on the segment, its ends cut square at the endpoints),
// the spec's standard sample locations, clipping of the segment at the near plane, the perspective-
// correct parameter along the segment, the depth bias z - b (1 - z), the depth test against triangles
// and points, and the primitive id space (triangles, then segments, then points). Positions keep every
// sample at least kMargin away from the rectangles' sides, except in the test of such ties, which the
// spec leaves open: there every device must give each tied sample to exactly one side, and lavapipe
// gives it to the top and left sides (as a rectangle drawn as two triangles under the top-left rule).
// Where devices differ, at wide lines crossing a side plane (clipped segment or guard band), any of the
// ways is accepted and lavapipe's is required of lavapipe. Under MSAA lavapipe interpolates line depths
// and attributes half a pixel off (lineInterpolationAt), which the tests expect of it.
// Lavapipe (Mesa 22.3) offers VK_EXT_line_rasterization with rectangularLines, strictLines, widths 1 to
// 255 in steps of 1/128 and 8 bits of line sub-pixel precision.
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
#include "vulkan/vulkan_graphics.h"

namespace sr::test {
namespace {

constexpr uint32_t kSize = 16;  // power of two: every window position below converts to NDC exactly

// Samples this close to a side of a rectangle count as ties. Vertices snap to 1/256 pixel, which moves
// the sides of a segment of this image by less than 1/128 pixel.
constexpr double kMargin = 1.0 / 64.0;

// The spec's standard sample locations at 4 samples per pixel ("Standard sample locations"), in pixels
// from the pixel's top-left corner, sample 0 first.
const glm::dvec2 kStandard4x[4] = {{0.375, 0.125}, {0.875, 0.375}, {0.125, 0.625}, {0.625, 0.875}};
const glm::dvec2 kCentre(0.5, 0.5);

// A segment between two window positions (pixels, window depth).
struct WindowLine {
    WindowPoint a, b;
};

// The triangles (clip space, as clipSpaceScene builds them), then two vertices (normal +z) and one
// segment per entry of `lines`, then one vertex and one point per entry of `points`, all window
// positions of the kSize x kSize viewport with w = 1: segment k has id triangleCount + k, point k id
// triangleCount + lines.size() + k.
Scene lineScene(const std::vector<WindowLine>& lines, const std::vector<glm::vec4>& triangles = {},
                const std::vector<WindowPoint>& points = {})
{
    Scene scene = clipSpaceScene(triangles);
    for (const WindowLine& l : lines)
        for (const WindowPoint& p : {l.a, l.b}) {
            scene.lines.push_back(uint32_t(scene.positions.size()));
            scene.positions.push_back(windowVertex(p.x, p.y, kSize, kSize, p.z));
            scene.normals.push_back(glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
        }
    for (const WindowPoint& p : points) {
        scene.points.push_back(uint32_t(scene.positions.size()));
        scene.positions.push_back(windowVertex(p.x, p.y, kSize, kSize, p.z));
        scene.normals.push_back(glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
    }
    return scene;
}

// Where a sample lies against the rectangle of a segment.
enum class Place { Outside, Inside, Tie };

// The rectangular-line rule for the segment a-b of width `width` at sample s: the signed distances of
// s from the caps (along the segment) and from the long sides (across it), positive inside; the nearer
// one decides, and within kMargin of 0 it is a tie. `scale` maps window positions to raster ones (SSAA);
// the width is in raster pixels.
Place place(const WindowLine& l, double width, glm::dvec2 s, double scale = 1.0)
{
    const glm::dvec2 a = glm::dvec2(l.a.x, l.a.y) * scale, b = glm::dvec2(l.b.x, l.b.y) * scale;
    const double length = glm::length(b - a);
    const glm::dvec2 u = (b - a) / length, n(-u.y, u.x);
    const double along = glm::dot(s - a, u), across = std::abs(glm::dot(s - a, n));
    const double inside = std::min({along, length - along, width / 2 - across});
    if (std::abs(inside) < kMargin) return Place::Tie;
    return inside > 0.0 ? Place::Inside : Place::Outside;
}

// The rule where no sample may be a tie: a tie fails the test.
bool covers(const WindowLine& l, double width, glm::dvec2 s, double scale = 1.0)
{
    const Place p = place(l, width, s, scale);
    EXPECT_NE(p, Place::Tie) << "sample " << s.x << "," << s.y << " on a side of the segment " << l.a.x << ","
                             << l.a.y << " - " << l.b.x << "," << l.b.y << " of width " << width;
    return p == Place::Inside;
}

// The window depth of segment l at sample s: linear in window space along the segment (w = 1 at both
// ends), at the projection of s onto it.
double depthAt(const WindowLine& l, glm::dvec2 s)
{
    const glm::dvec2 a(l.a.x, l.a.y), b(l.b.x, l.b.y);
    const double t = glm::dot(s - a, b - a) / glm::dot(b - a, b - a);
    return (1.0 - t) * l.a.z + t * l.b.z;
}

// Where a device interpolates a segment's depth and attributes for the sample at `at` (or, for the
// shading, for the pixel centre at `at`): there, except on lavapipe (Mesa 22.3) under MSAA, which
// interpolates them half a pixel right of and below it, at + (0.5, 0.5), while it covers the right
// samples (its triangles are not affected).
glm::dvec2 lineInterpolationAt(const RenderOutput& out, uint32_t msaa, glm::dvec2 at)
{
    const bool lavapipe = out.device.name.find("llvmpipe") != std::string::npos;
    return lavapipe && msaa > 1 ? at + glm::dvec2(0.5) : at;
}

// The segment's part inside the viewport (0 <= x, y <= kSize), or false when none is left: the clipped
// segment in window terms (w = 1 at both ends, so the clip planes are these lines).
bool clipToViewport(WindowLine& l)
{
    double t0 = 0.0, t1 = 1.0;
    const glm::dvec2 a(l.a.x, l.a.y), d = glm::dvec2(l.b.x, l.b.y) - a;
    for (int axis = 0; axis < 2; ++axis)
        for (double bound : {0.0, double(kSize)}) {
            if (d[axis] == 0.0) {
                if (a[axis] < 0.0 || a[axis] > kSize) return false;
                continue;
            }
            const double t = (bound - a[axis]) / d[axis];
            const bool entering = (bound == 0.0) == (d[axis] > 0.0);
            if (entering)
                t0 = std::max(t0, t);
            else
                t1 = std::min(t1, t);
        }
    if (t0 >= t1) return false;
    const WindowLine whole = l;
    const auto at = [&](double t) {
        return WindowPoint{whole.a.x + t * d.x, whole.a.y + t * d.y,
                           float((1.0 - t) * whole.a.z + t * whole.b.z)};
    };
    l = {at(t0), at(t1)};
    return true;
}

class LinesGraphicsTest : public GraphicsTest {
protected:
    // Renders the segments alone at 1x and width `width` and checks every pixel: the nearest segment
    // whose rectangle covers the pixel centre (the first of equal depths), with its depth at the
    // centre, else empty.
    void expectPixels(const std::vector<WindowLine>& lines, float width)
    {
        RenderSettings s = unlitSettings(kSize, kSize);
        s.lineWidth = width;
        RenderOutput out = render(lineScene(lines), s);
        ASSERT_EQ(out.aov.id.size(), size_t(kSize) * kSize);
        EXPECT_EQ(out.stats.linesIn, lines.size());
        for (uint32_t y = 0; y < kSize; ++y)
            for (uint32_t x = 0; x < kSize; ++x) {
                const glm::dvec2 c = glm::dvec2(x, y) + kCentre;
                uint32_t id = EMPTY_ID;
                double depth = 1.0;
                for (uint32_t k = 0; k < lines.size(); ++k)
                    if (covers(lines[k], width, c) && depthAt(lines[k], c) < depth) {
                        id = k;
                        depth = depthAt(lines[k], c);
                    }
                const size_t i = size_t(y) * kSize + x;
                EXPECT_EQ(out.aov.id[i], id) << "width " << width << " pixel " << x << "," << y;
                EXPECT_NEAR(out.aov.depth[i], depth, 1e-6) << "width " << width << " pixel " << x << "," << y;
            }
    }
};

// A horizontal segment of width 1 from pixel centre (2.5, 3.5) to (9.5, 3.5) covers pixels 2 to 8 of
// row 3: its long sides run along the row's top and bottom edges, away from every centre, and its caps
// pass through the centres of pixels 2 and 9. The spec does not say which side such a centre falls to;
// each must fall to exactly one (a segment of whole length n covers n centres), and lavapipe, as the
// top-left rule, keeps the left cap's centre and drops the right one's, whichever end comes first.
// The same for vertical segments (the top cap's centre in, the bottom one's out) and for width 2 on a
// row of centres (its long sides through the centres of rows 7 and 9: the top one in).
TEST_F(LinesGraphicsTest, CentresOnTheSidesGoToExactlyOneSideLavapipeTheTopLeft)
{
    struct Tie {
        WindowLine line;
        float width;
        uint32_t x0, x1, y0, y1;  // lavapipe's pixels: [x0, x1) x [y0, y1)
    };
    const Tie ties[] = {
        {{{2.5, 3.5, 0.5f}, {9.5, 3.5, 0.5f}}, 1.0f, 2, 9, 3, 4},
        {{{9.5, 3.5, 0.5f}, {2.5, 3.5, 0.5f}}, 1.0f, 2, 9, 3, 4},
        {{{5.5, 2.5, 0.5f}, {5.5, 9.5, 0.5f}}, 1.0f, 5, 6, 2, 9},
        {{{5.5, 9.5, 0.5f}, {5.5, 2.5, 0.5f}}, 1.0f, 5, 6, 2, 9},
        {{{3.0, 8.5, 0.5f}, {12.0, 8.5, 0.5f}}, 2.0f, 3, 12, 7, 9},
        {{{10.5, 4.0, 0.5f}, {10.5, 14.0, 0.5f}}, 2.0f, 9, 11, 4, 14},
    };
    for (const Tie& tie : ties) {
        RenderSettings s = unlitSettings(kSize, kSize);
        s.lineWidth = tie.width;
        RenderOutput out = render(lineScene({tie.line}), s);
        ASSERT_EQ(out.aov.id.size(), size_t(kSize) * kSize);
        const bool lavapipe = out.device.name.find("llvmpipe") != std::string::npos;
        size_t covered = 0, ties = 0;
        for (uint32_t y = 0; y < kSize; ++y)
            for (uint32_t x = 0; x < kSize; ++x) {
                const Place p = place(tie.line, tie.width, glm::dvec2(x, y) + kCentre);
                const uint32_t id = out.aov.id[size_t(y) * kSize + x];
                covered += id == 0u;
                ties += p == Place::Tie;
                if (p != Place::Tie) {
                    EXPECT_EQ(id, p == Place::Inside ? 0u : EMPTY_ID) << "pixel " << x << "," << y;
                }
                if (lavapipe) {
                    const bool topLeft = x >= tie.x0 && x < tie.x1 && y >= tie.y0 && y < tie.y1;
                    EXPECT_EQ(id, topLeft ? 0u : EMPTY_ID)
                        << tie.line.a.x << "," << tie.line.a.y << " - " << tie.line.b.x << "," << tie.line.b.y
                        << " width " << tie.width << ": pixel " << x << "," << y;
                }
            }
        EXPECT_GT(ties, 0u);
        // The rectangle's area in whole pixels: as many centres either way each tie goes.
        EXPECT_EQ(covered, size_t(tie.x1 - tie.x0) * (tie.y1 - tie.y0));
    }
}

// Segments at a slant cover exactly the pixels whose centre lies inside their rectangle: 45 degrees
// with two pixels per row (the centre line halfway between two rows of centres), 45 degrees through a
// diagonal of centres with the caps off them, shallow and steep slopes both ways, and widths 1, 1.5, 3
// and 4.25. Their depth is the segment's, linear along it.
TEST_F(LinesGraphicsTest, SlantedSegmentsCoverTheCentresInsideTheirRectangle)
{
    expectPixels({{{2.0, 2.5, 0.5f}, {12.0, 12.5, 0.5f}}}, 1.0f);
    expectPixels({{{2.25, 2.25, 0.25f}, {10.75, 10.75, 0.75f}}}, 1.0f);
    // Crossing: the second is nearer where they overlap.
    expectPixels({{{0.875, 2.625, 0.5f}, {14.0, 7.0, 0.5f}}, {{2.75, 15.0, 0.2f}, {6.25, 1.0, 0.3f}}}, 1.0f);
    expectPixels({{{14.125, 2.125, 0.5f}, {2.25, 9.25, 0.3f}}}, 1.5f);
    expectPixels({{{1.875, 3.75, 0.5f}, {13.125, 11.25, 0.5f}}}, 3.0f);
    expectPixels({{{3.0, 8.375, 0.5f}, {12.0, 8.375, 0.5f}}}, 3.0f);
    expectPixels({{{3.75, 13.125, 0.5f}, {11.25, 1.875, 0.5f}}}, 4.25f);
}

// At 4x MSAA a segment covers exactly the standard sample locations inside its rectangle, each with the
// segment's depth there (on lavapipe half a pixel off: lineInterpolationAt): a horizontal segment of
// width 1 on a row of centres (no sample on a side: samples sit 1/8 pixel or more off the centre), a
// slanted one of width 1, and one of width 2.5, all with depths varying along them.
TEST_F(LinesGraphicsTest, MultisampledSegmentsCoverTheStandardSamplesInsideTheirRectangle)
{
    struct Case {
        WindowLine line;
        float width;
    };
    for (const Case& c : {Case{{{2.5, 3.5, 0.25f}, {9.5, 3.5, 0.75f}}, 1.0f},
                          Case{{{1.125, 3.375, 0.25f}, {13.875, 7.625, 0.75f}}, 1.0f},
                          Case{{{3.25, 13.625, 0.75f}, {12.125, 4.75, 0.5f}}, 2.5f}}) {
        RenderSettings s = unlitSettings(kSize, kSize);
        s.lineWidth = c.width;
        s.msaa = 4;
        s.aovSamples = true;
        RenderOutput out = render(lineScene({c.line}), s);
        ASSERT_EQ(out.samples.samples, 4u);
        ASSERT_EQ(out.samples.id.size(), size_t(4) * kSize * kSize);
        for (uint32_t k = 0; k < 4; ++k)
            for (uint32_t y = 0; y < kSize; ++y)
                for (uint32_t x = 0; x < kSize; ++x) {
                    const size_t i = size_t(k) * kSize * kSize + size_t(y) * kSize + x;
                    const glm::dvec2 at = glm::dvec2(x, y) + kStandard4x[k];
                    const bool inside = covers(c.line, c.width, at);
                    EXPECT_EQ(out.samples.id[i], inside ? 0u : EMPTY_ID)
                        << "width " << c.width << ": sample " << k << " of " << x << "," << y;
                    const glm::dvec2 interpolated = lineInterpolationAt(out, s.msaa, at);
                    EXPECT_NEAR(out.samples.depth[i], inside ? depthAt(c.line, interpolated) : 1.0, 1e-6)
                        << "sample " << k << " of " << x << "," << y;
                }
    }
}

// One id space and one depth buffer for triangles, segments and points: a full-screen quad (two
// triangles, ids 0 and 1) at depth 0.5 hides a segment behind it and loses to one in front; a segment at
// the quad's own depth loses (the lower id wins a tie, as in the compute pipeline's visibility key); a
// point at a segment's depth loses to it too. Segment k is 2 + k, point k is 2 + 4 + k.
TEST_F(LinesGraphicsTest, IdsAndDepthOrderTrianglesSegmentsAndPoints)
{
    const std::vector<WindowLine> lines = {{{2.0, 2.5, 0.75f}, {14.0, 2.5, 0.75f}},
                                           {{2.0, 5.5, 0.25f}, {14.0, 5.5, 0.25f}},
                                           {{2.0, 8.5, 0.5f}, {14.0, 8.5, 0.5f}},
                                           {{2.0, 11.5, 0.25f}, {14.0, 11.5, 0.25f}}};
    // On segment 3 at its depth, and alone in front of the quad.
    const std::vector<WindowPoint> points = {{7.5, 11.5, 0.25f}, {7.5, 14.5, 0.125f}};
    RenderSettings s = unlitSettings(kSize, kSize);
    s.pointSize = 1.0f;
    for (uint32_t msaa : {1u, 4u}) {
        s.msaa = msaa;
        RenderOutput out = render(lineScene(lines, clipQuad(-1, -1, 1, 1, 0.5f), points), s);
        ASSERT_EQ(out.aov.id.size(), size_t(kSize) * kSize);
        EXPECT_EQ(out.stats.trianglesIn, 2u);
        EXPECT_EQ(out.stats.linesIn, 4u);
        EXPECT_EQ(out.stats.pointsIn, 2u);
        EXPECT_EQ(countId(out.aov, 2u), 0u) << msaa;   // behind the quad
        EXPECT_EQ(countId(out.aov, 3u), 12u) << msaa;  // in front: pixels 2 to 13
        EXPECT_EQ(countId(out.aov, 4u), 0u) << msaa;   // at the quad's depth
        EXPECT_EQ(countId(out.aov, 5u), 12u) << msaa;  // in front, and before the point at its depth
        EXPECT_EQ(countId(out.aov, 6u), 0u) << msaa;   // the point on segment 3
        EXPECT_EQ(countId(out.aov, 7u), 1u) << msaa;   // the point alone
        EXPECT_EQ(out.aov.id[size_t(14) * kSize + 7], 7u) << msaa;
        EXPECT_EQ(out.aov.depth[size_t(14) * kSize + 7], 0.125f) << msaa;
        for (uint32_t x = 2; x < 14; ++x) {
            EXPECT_EQ(out.aov.id[size_t(5) * kSize + x], 3u) << msaa << "x pixel " << x;
            EXPECT_EQ(out.aov.depth[size_t(5) * kSize + x], 0.25f) << msaa << "x pixel " << x;
            EXPECT_LT(out.aov.id[size_t(8) * kSize + x], 2u) << msaa << "x pixel " << x;
            EXPECT_EQ(out.aov.depth[size_t(8) * kSize + x], 0.5f) << msaa << "x pixel " << x;
        }
    }
}

// RenderSettings::lineDepthBias b draws a segment's window depth z as z - b (1 - z): a segment on the
// plane of a quad then wins the depth test against it, at exactly that depth, also where the quad and
// the segment slant in depth together; the triangles are not biased.
TEST_F(LinesGraphicsTest, DepthBiasLetsASegmentOnAQuadWin)
{
    const float b = 1.0f / 512.0f;
    // The quad's depth runs from 0.25 at the left edge to 0.75 at the right one, as the segment's does.
    const std::vector<glm::vec4> quad = {{-1, -1, 0.25f, 1}, {1, -1, 0.75f, 1}, {1, 1, 0.75f, 1},
                                         {-1, -1, 0.25f, 1}, {1, 1, 0.75f, 1},  {-1, 1, 0.25f, 1}};
    const std::vector<WindowLine> onPlane = {{{0.0, 4.5, 0.25f}, {16.0, 4.5, 0.75f}},
                                             {{0.0, 10.75, 0.25f}, {16.0, 10.75, 0.75f}}};
    RenderSettings s = unlitSettings(kSize, kSize);
    for (float bias : {0.0f, b}) {
        s.lineDepthBias = bias;
        RenderOutput out = render(lineScene(onPlane, quad), s);
        ASSERT_EQ(out.aov.id.size(), size_t(kSize) * kSize);
        for (uint32_t row : {4u, 10u})
            for (uint32_t x = 0; x < kSize; ++x) {
                const size_t i = size_t(row) * kSize + x;
                const double z = 0.25 + 0.5 * (x + 0.5) / kSize;
                if (bias == 0.0f) {
                    // On the plane without a bias the depths tie up to rounding, which decides who wins.
                    EXPECT_NEAR(out.aov.depth[i], z, 1e-6) << "pixel " << x << "," << row;
                } else {
                    EXPECT_EQ(out.aov.id[i], row == 4u ? 2u : 3u) << "bias pixel " << x << "," << row;
                    EXPECT_NEAR(out.aov.depth[i], z - bias * (1.0 - z), 1e-6)
                        << "bias pixel " << x << "," << row;
                }
            }
    }
}

// A segment crossing the near plane is clipped there (no depth clamp): only its part at z >= 0 is drawn,
// each pixel at the segment's depth. With a depth bias b the hardware clips where the biased depth
// z - b (1 - z) reaches 0, at z = b / (1 + b): the bias is applied to the clip-space vertices
// (reference_line.vert). The far plane stays at z = 1 either way.
TEST_F(LinesGraphicsTest, SegmentsAreClippedAtTheNearPlaneBiasedWithTheirDepth)
{
    // z = -0.5 .. 0.5 over x = 2 .. 14: z = 0 at x = 8; z = 1/3 (b = 0.5) at x = 12.
    const WindowLine nearCrossing = {{2.0, 8.5, -0.5f}, {14.0, 8.5, 0.5f}};
    // z = 0.5 .. 1.5 over x = 2 .. 14: z = 1 at x = 8.
    const WindowLine farCrossing = {{2.0, 4.5, 0.5f}, {14.0, 4.5, 1.5f}};
    for (float bias : {0.0f, 0.5f}) {
        RenderSettings s = unlitSettings(kSize, kSize);
        s.lineDepthBias = bias;
        RenderOutput out = render(lineScene({nearCrossing, farCrossing}), s);
        ASSERT_EQ(out.aov.id.size(), size_t(kSize) * kSize);
        const uint32_t firstNear = bias == 0.0f ? 8 : 12;
        for (uint32_t x = 0; x < kSize; ++x) {
            const glm::dvec2 c(x + 0.5, 8.5);
            const double z = depthAt(nearCrossing, c), biased = z - bias * (1.0 - z);
            const bool drawn = x >= firstNear && x < 14;
            EXPECT_EQ(out.aov.id[size_t(8) * kSize + x], drawn ? 0u : EMPTY_ID)
                << "bias " << bias << " x " << x;
            if (drawn) {
                EXPECT_NEAR(out.aov.depth[size_t(8) * kSize + x], biased, 1e-6) << "x " << x;
            }
            const bool farDrawn = x >= 2 && x < 8;
            EXPECT_EQ(out.aov.id[size_t(4) * kSize + x], farDrawn ? 1u : EMPTY_ID)
                << "bias " << bias << " x " << x;
        }
    }
}

// A wide segment crossing a side plane at a slant. Vulkan clips the segment (its centre line) to the
// view volume and rasterizes the rectangle of what is left, so its end at the plane is a square cap
// through the point where the centre line leaves the volume, and the corner of the rectangle beyond that
// cap is not drawn although it lies in the viewport; a device with a guard band may draw the whole
// rectangle up to the viewport's edge instead. Every device must draw one of the two; lavapipe from
// Mesa 22.3 draws the clipped one, lavapipe from Mesa 25.0 the whole one (both measured here). The
// segments reach 3 pixels beyond the left and the top edges.
TEST_F(LinesGraphicsTest, WideSegmentsCrossingASidePlaneEndAtTheClippedCentreLineOrTheViewportEdge)
{
    const float width = 5.0f;
    for (const WindowLine& line : {WindowLine{{-3.0, 1.0, 0.5f}, {12.0, 11.0, 0.5f}},
                                   WindowLine{{1.0, -3.0, 0.5f}, {11.0, 12.0, 0.5f}}}) {
        WindowLine clipped = line;
        ASSERT_TRUE(clipToViewport(clipped));
        RenderSettings s = unlitSettings(kSize, kSize);
        s.lineWidth = width;
        RenderOutput out = render(lineScene({line}), s);
        ASSERT_EQ(out.aov.id.size(), size_t(kSize) * kSize);
        size_t clippedMisses = 0, wholeMisses = 0, differ = 0;
        for (uint32_t y = 0; y < kSize; ++y)
            for (uint32_t x = 0; x < kSize; ++x) {
                const glm::dvec2 c = glm::dvec2(x, y) + kCentre;
                const bool inClipped = covers(clipped, width, c), inWhole = covers(line, width, c);
                const bool drawn = out.aov.id[size_t(y) * kSize + x] == 0u;
                clippedMisses += drawn != inClipped;
                wholeMisses += drawn != inWhole;
                differ += inClipped != inWhole;
            }
        EXPECT_GT(differ, 0u) << "the two expectations must differ somewhere";
        EXPECT_TRUE(clippedMisses == 0 || wholeMisses == 0)
            << clippedMisses << " pixels off the clipped segment's rectangle, " << wholeMisses
            << " off the whole one's";
        if (out.device.name.find("llvmpipe") != std::string::npos) {
            const size_t mesa = out.device.driver.find("Mesa ");
            ASSERT_NE(mesa, std::string::npos) << out.device.driver;
            const int major = std::atoi(out.device.driver.c_str() + mesa + 5);
            EXPECT_EQ(major >= 25 ? wholeMisses : clippedMisses, 0u)
                << line.a.x << "," << line.a.y << " on " << out.device.driver;
        }
    }
}

// Segments are unlit: their colour is the two vertex colours mixed at the perspective-correct parameter
// along the segment, times the material's base colour factor, in every lighting setup (here Blinn-Phong
// with a strong light and no ambient), at 4x MSAA too (shaded once per pixel, at its centre; on lavapipe
// half a pixel off: lineInterpolationAt). The second end's clip coordinates are scaled by w = 4 (the
// same window position), so the parameter at screen fraction f is (f / 4) / ((1 - f) + f / 4), not f.
TEST_F(LinesGraphicsTest, ColourIsTheVertexColoursMixedPerspectiveCorrectTimesTheMaterialUnlit)
{
    const WindowLine line = {{1.0, 6.5, 0.5f}, {15.0, 6.5, 0.5f}};
    Scene scene = lineScene({line, {{1.0, 10.5, 0.5f}, {15.0, 10.5, 0.5f}}});
    const float w = 4.0f;
    scene.positions[1] *= w;
    scene.colors = {glm::vec4(0.9f, 0.1f, 0.2f, 1.0f), glm::vec4(0.1f, 0.8f, 1.0f, 1.0f),
                    glm::vec4(0.5f, 0.5f, 0.5f, 1.0f), glm::vec4(0.5f, 0.5f, 0.5f, 1.0f)};
    SceneMaterial plain, tinted;
    tinted.baseColorFactor = glm::vec4(0.5f, 1.0f, 0.25f, 1.0f);
    scene.materials = {plain, tinted};
    scene.lineMaterials = {0, 1};
    RenderSettings s = testSettings(kSize, kSize);
    s.shadingMode = SHADING_BLINN_PHONG;
    s.ambient = 0.0f;
    s.lightColor = glm::vec3(3.0f);
    s.lineWidth = 3.0f;
    for (uint32_t msaa : {1u, 4u}) {
        s.msaa = msaa;
        RenderOutput out = render(scene, s);
        ASSERT_EQ(out.color.pixels.size(), size_t(kSize) * kSize);
        for (uint32_t x = 1; x < 15; ++x) {
            const glm::dvec2 centre = lineInterpolationAt(out, msaa, glm::dvec2(x, 6) + kCentre);
            const double f = (centre.x - line.a.x) / (line.b.x - line.a.x);
            const double t = (f / w) / ((1.0 - f) + f / w);
            const glm::vec3 mixed(glm::mix(glm::dvec3(scene.colors[0]), glm::dvec3(scene.colors[1]), t));
            for (uint32_t y = 6; y < 8; ++y) {
                const size_t i = size_t(y) * kSize + x;
                EXPECT_EQ(out.aov.id[i], 0u);
                EXPECT_LE(channelDifference(out.color.pixels[i], packRgba8(mixed)), 1)
                    << msaa << "x pixel " << x << "," << y << std::hex << ": " << out.color.pixels[i]
                    << " vs " << packRgba8(mixed);
            }
            const glm::vec3 grey = glm::vec3(0.5f) * glm::vec3(tinted.baseColorFactor);
            EXPECT_LE(channelDifference(out.color.pixels[size_t(10) * kSize + x], packRgba8(grey)), 1)
                << msaa << "x pixel " << x;
        }
        EXPECT_EQ(out.color.pixels[0], packRgba8(s.background)) << msaa;
    }
}

// A segments-only scene renders in every output mode: 1x, the visibility pass, 4x MSAA (with and
// without the visibility pass) and SSAA 2 (with and without MSAA). The id and Z AOVs report each output
// pixel's representative sample (aovSampleIndex), and the width counts raster pixels, as in the compute
// pipeline.
TEST_F(LinesGraphicsTest, SegmentsRenderInEveryOutputMode)
{
    // Width 4: the second segment, on a pixel boundary, then covers whole output pixels under SSAA 2
    // too (rows 12 and 13), where the colour is probed.
    const std::vector<WindowLine> lines = {{{2.9375, 2.125, 0.25f}, {13.0625, 8.875, 0.25f}},
                                           {{1.21875, 13.0, 0.5f}, {14.0, 13.0, 0.5f}}};
    const Scene scene = lineScene(lines);
    for (const OutputMode& mode : kOutputModes) {
        RenderSettings s = outputModeSettings(mode, kSize, kSize);
        s.lineWidth = 4.0f;
        RenderOutput out = render(scene, s);
        ASSERT_EQ(out.aov.id.size(), size_t(kSize) * kSize);
        EXPECT_EQ(out.stats.linesIn, 2u);
        EXPECT_EQ(out.stats.trianglesIn, 0u);
        const uint32_t n = mode.ssaa;
        const glm::dvec2 offset = mode.msaa == 1 ? kCentre : kStandard4x[0];
        size_t covered = 0;
        for (uint32_t y = 0; y < kSize; ++y)
            for (uint32_t x = 0; x < kSize; ++x) {
                const glm::dvec2 at = glm::dvec2(x * n + n / 2, y * n + n / 2) + offset;
                uint32_t id = EMPTY_ID;
                float depth = 1.0f;
                for (uint32_t k = 0; k < lines.size() && id == EMPTY_ID; ++k)
                    if (covers(lines[k], s.lineWidth, at, n)) {
                        id = k;
                        depth = lines[k].a.z;
                    }
                covered += id != EMPTY_ID;
                const size_t i = size_t(y) * kSize + x;
                EXPECT_EQ(out.aov.id[i], id) << mode.msaa << "x ssaa " << n << " vis " << mode.visibilityOnly
                                             << " pixel " << x << "," << y;
                EXPECT_EQ(out.aov.depth[i], depth)
                    << mode.msaa << "x ssaa " << n << " pixel " << x << "," << y;
            }
        EXPECT_GT(covered, 12u);
        // The visibility pass writes the background; the full pass the segment's colour (white).
        const uint32_t onLine = out.color.pixels[size_t(13) * kSize + 7];
        EXPECT_EQ(onLine, mode.visibilityOnly ? packRgba8(s.background) : packRgba8(glm::vec3(1.0f)))
            << mode.msaa << "x ssaa " << n;
    }
}

// What vulkan-graphics refuses with one Usage line before anything is drawn: a width the device cannot
// draw exactly or outside 1..MAX_LINE_WIDTH in steps of 1/8 (lavapipe draws 1 to 255 in steps of 1/128),
// a non-finite depth bias, a segment naming a vertex that does not exist, an odd number of line
// indices, and line materials that do not match the segments.
TEST_F(LinesGraphicsTest, BadWidthsAndMalformedSegmentsAreOneLineUsageErrors)
{
    const Scene scene = lineScene({{{2.0, 8.5, 0.5f}, {14.0, 8.5, 0.5f}}});
    const auto expectUsage = [](const Scene& scene, const RenderSettings& s, const std::string& what) {
        auto out = renderVulkanGraphics(scene, identityCamera(), s, -1);
        ASSERT_FALSE(out.ok()) << what << " accepted";
        EXPECT_EQ(out.error().code, ExitCode::Usage) << what << ": " << out.error().message;
        EXPECT_TRUE(isOneLine(out.error().message)) << out.error().message;
    };
    for (float width : {0.5f, 1.0625f, 2.3f, 65.0f, 300.0f, std::numeric_limits<float>::quiet_NaN()}) {
        RenderSettings s = unlitSettings(kSize, kSize);
        s.lineWidth = width;
        expectUsage(scene, s, "width " + std::to_string(width));
    }
    RenderSettings s = unlitSettings(kSize, kSize);
    s.lineDepthBias = std::numeric_limits<float>::infinity();
    expectUsage(scene, s, "an infinite bias");
    s.lineDepthBias = 0.0f;
    Scene bad = scene;
    bad.lines[1] = uint32_t(bad.positions.size());
    expectUsage(bad, s, "a vertex out of range");
    bad = scene;
    bad.lines.push_back(0);
    expectUsage(bad, s, "an odd index count");
    bad = scene;
    bad.materials = {SceneMaterial{}};
    expectUsage(bad, s, "missing line materials");
}

}  // namespace
}  // namespace sr::test
