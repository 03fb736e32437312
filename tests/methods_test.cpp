// methods_test.cpp - the raster methods of --raster-method (common/shared/methods.h) on each backend,
// against each method's rule written out here once more, independently and in double or exact integer
// arithmetic: every sample (one and four per pixel, small triangles rasterized by setup and big ones
// binned) must show what the rule says, except where float rounding is allowed to decide (a sample within
// a stated distance of the rule's boundary).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

#include <gtest/gtest.h>

#include "test_util.h"

namespace sr::test {
namespace {

constexpr uint32_t kWidth = 256, kHeight = 128, kCell = 32;

struct Tri {
    glm::dvec2 v[3];  // window position in pixels
};

// One random triangle per 32 x 32 cell, so that no two overlap: each covered sample shows its cell's
// triangle. Vertices on the 1/1024 px grid are exact in float through the viewport transform; the sizes
// span small triangles (setup's path) and big ones (binned), some of them slivers.
std::vector<Tri> cellTriangles()
{
    std::mt19937 rng(1234);
    std::uniform_int_distribution<int> pos(1024, (kCell - 1) * 1024);
    std::vector<Tri> tris;
    for (uint32_t cy = 0; cy < kHeight / kCell; ++cy)
        for (uint32_t cx = 0; cx < kWidth / kCell; ++cx) {
            // Every third cell a small triangle (about 6 px), every fifth a sliver along a diagonal.
            double scale = (cx + cy) % 3 == 0 ? 0.2 : 1.0;
            Tri t;
            for (glm::dvec2& v : t.v)
                v = glm::dvec2(cx * kCell + 1 + (pos(rng) / 1024.0 - 1) * scale,
                               cy * kCell + 1 + (pos(rng) / 1024.0 - 1) * scale);
            if ((cx + 2 * cy) % 5 == 0) t.v[2] = (t.v[0] + t.v[1]) * 0.5 + glm::dvec2(0.37, -0.21);
            tris.push_back(t);
        }
    return tris;
}

Scene sceneOf(const std::vector<Tri>& tris)
{
    std::vector<glm::vec4> corners;
    for (const Tri& t : tris)
        for (const glm::dvec2& v : t.v) corners.push_back(windowVertex(v.x, v.y, kWidth, kHeight, 0.5f));
    return clipSpaceScene(corners);
}

double cross(glm::dvec2 a, glm::dvec2 b, glm::dvec2 p)
{
    return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

// The rule's verdict at sample position p (pixels): 1 covered, 0 not, -1 too close to call.
using Rule = int (*)(const Tri&, glm::dvec2);

// fixed4: vertices rounded half-to-even to 1/16 px; exact integer edge functions in 1/256 px; a sample on
// an edge is covered when the edge is a top edge (horizontal, interior below) or a left edge.
int fixed4Rule(const Tri& tri, glm::dvec2 p)
{
    int64_t x[3], y[3];
    for (int k = 0; k < 3; ++k) {
        x[k] = int64_t(std::nearbyint(tri.v[k].x * 16.0)) * 16;
        y[k] = int64_t(std::nearbyint(tri.v[k].y * 16.0)) * 16;
    }
    int64_t area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
    if (area == 0) return 0;
    if (area < 0) {
        std::swap(x[1], x[2]);
        std::swap(y[1], y[2]);
    }
    int64_t px = int64_t(p.x * 256.0), py = int64_t(p.y * 256.0);
    for (int k = 0; k < 3; ++k) {
        int a = (k + 1) % 3, b = (k + 2) % 3;
        int64_t dx = x[b] - x[a], dy = y[b] - y[a];
        int64_t e = dx * (py - y[a]) - dy * (px - x[a]);
        bool topLeft = (dy == 0 && dx > 0) || dy < 0;
        if (e < 0 || (e == 0 && !topLeft)) return 0;
    }
    return 1;
}

// float: inside the vertices' bbox (rounded outwards to 1/256 px) and every barycentric >= -eps.
int floatRule(const Tri& t, glm::dvec2 p)
{
    double lo[2], hi[2];
    for (int a = 0; a < 2; ++a) {
        lo[a] = std::floor(std::min({t.v[0][a], t.v[1][a], t.v[2][a]}) * 256.0) / 256.0;
        hi[a] = std::ceil(std::max({t.v[0][a], t.v[1][a], t.v[2][a]}) * 256.0) / 256.0;
    }
    if (p.x < lo[0] || p.x > hi[0] || p.y < lo[1] || p.y > hi[1]) return 0;
    double area = cross(t.v[0], t.v[1], t.v[2]);
    double margin = 1e-5;  // float barycentrics carry relative errors near 2^-23 times the slivers' aspect
    bool unsure = false;
    for (int k = 0; k < 3; ++k) {
        double b = cross(t.v[(k + 1) % 3], t.v[(k + 2) % 3], p) / area;
        if (b < -double(FLOAT_EPSILON) - margin) return 0;
        unsure = unsure || b < -double(FLOAT_EPSILON) + margin;
    }
    return unsure ? -1 : 1;
}

// scanline: rows y in [y_top, y_bottom); on a row, x in [left, right) between the long edge (top to
// bottom) and the half's short edge, each evaluated from its upper vertex.
int scanlineRule(const Tri& t, glm::dvec2 p)
{
    glm::dvec2 v[3] = {t.v[0], t.v[1], t.v[2]};
    std::sort(v, v + 3, [](glm::dvec2 a, glm::dvec2 b) { return a.y < b.y; });
    if (!(p.y >= v[0].y && p.y < v[2].y)) return 0;
    auto edgeX = [&](glm::dvec2 a, glm::dvec2 b) { return a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y); };
    double xLong = edgeX(v[0], v[2]);
    double xShort = p.y < v[1].y ? edgeX(v[0], v[1]) : edgeX(v[1], v[2]);
    double left = std::min(xLong, xShort), right = std::max(xLong, xShort);
    // Float x of an edge at coordinates below 2^16 subpixels: a few ulp of 2^-8 subpixels.
    double margin = 1.0 / 4096.0;
    if (std::abs(p.x - left) < margin || std::abs(p.x - right) < margin) return -1;
    return p.x >= left && p.x < right ? 1 : 0;
}

class MethodsTest : public BackendTest {
protected:
    // Every sample of the cell triangles with `msaa` samples per pixel, against the rule.
    void expectRule(uint32_t method, Rule rule, uint32_t msaa)
    {
        std::vector<Tri> tris = cellTriangles();
        RenderSettings s = unlitSettings(kWidth, kHeight);
        s.cullMode = CULL_NONE;
        s.msaa = msaa;
        s.aovSamples = true;
        s.rasterMethod = method;
        RenderOutput out = render(sceneOf(tris), s);
        ASSERT_EQ(out.samples.id.size(), size_t(kWidth) * kHeight * msaa);
        long differing = 0, covered = 0, unsure = 0;
        for (uint32_t py = 0; py < kHeight; ++py)
            for (uint32_t px = 0; px < kWidth; ++px) {
                uint32_t cell = (py / kCell) * (kWidth / kCell) + px / kCell;
                for (uint32_t s = 0; s < msaa; ++s) {
                    ivec2 o = standardSample(msaa, s);
                    glm::dvec2 p(px + o.x / 16.0, py + o.y / 16.0);
                    int verdict = rule(tris[cell], p);
                    uint32_t id = out.samples.id[size_t(s) * kWidth * kHeight + py * kWidth + px];
                    covered += id != EMPTY_ID;
                    if (verdict < 0) {
                        ++unsure;
                        continue;
                    }
                    uint32_t expected = verdict == 1 ? cell : EMPTY_ID;
                    if (id != expected && differing++ < 5)
                        ADD_FAILURE()
                            << "method " << method << " msaa " << msaa << " pixel (" << px << ", " << py
                            << ") sample " << s << ": id " << id << ", rule says " << expected;
                }
            }
        EXPECT_EQ(differing, 0) << "method " << method << " msaa " << msaa;
        EXPECT_GT(covered, long(kWidth * kHeight * msaa / 40));  // random triangles cover about 1/32
        // The undecided band must stay a sliver of the samples, or the test would prove little.
        EXPECT_LT(unsure, covered / 100 + 2) << "method " << method;
    }
};

TEST_P(MethodsTest, Fixed4FollowsTheExactRuleOnTheSixteenthPixelGrid)
{
    expectRule(RASTER_FIXED4, fixed4Rule, 1);
    expectRule(RASTER_FIXED4, fixed4Rule, 4);
}

TEST_P(MethodsTest, FloatFollowsTheBarycentricEpsilonRule)
{
    expectRule(RASTER_FLOAT, floatRule, 1);
    expectRule(RASTER_FLOAT, floatRule, 4);
}

TEST_P(MethodsTest, ScanlineFollowsTheSpanRule)
{
    expectRule(RASTER_SCANLINE, scanlineRule, 1);
    expectRule(RASTER_SCANLINE, scanlineRule, 4);
}

// Depth under the float methods: the plane through the vertex depths, so a tilted triangle's depth at a
// covered pixel centre matches the exact plane to float precision, and never leaves the vertices' range.
TEST_P(MethodsTest, FloatMethodsInterpolateDepthOnThePlane)
{
    const glm::dvec2 a(10.25, 8.5), b(120.75, 20.125), c(40.5, 110.0);
    const float za = 0.2f, zb = 0.7f, zc = 0.45f;
    Scene scene = clipSpaceScene({windowVertex(a.x, a.y, kWidth, kHeight, za),
                                  windowVertex(b.x, b.y, kWidth, kHeight, zb),
                                  windowVertex(c.x, c.y, kWidth, kHeight, zc)});
    for (uint32_t method : {RASTER_FLOAT, RASTER_SCANLINE}) {
        RenderSettings s = unlitSettings(kWidth, kHeight);
        s.cullMode = CULL_NONE;
        s.rasterMethod = method;
        RenderOutput out = render(scene, s);
        ASSERT_EQ(out.aov.id.size(), size_t(kWidth) * kHeight);
        double area = cross(a, b, c);
        size_t checked = 0;
        for (uint32_t py = 0; py < kHeight; ++py)
            for (uint32_t px = 0; px < kWidth; ++px) {
                size_t i = py * kWidth + px;
                if (out.aov.id[i] != 0u) continue;
                glm::dvec2 p(px + 0.5, py + 0.5);
                double wa = cross(b, c, p) / area, wb = cross(c, a, p) / area, wc = 1.0 - wa - wb;
                double z = std::clamp(wa * za + wb * zb + wc * zc, 0.2, 0.7);
                EXPECT_NEAR(out.aov.depth[i], z, 1e-5)
                    << "method " << method << " (" << px << ", " << py << ")";
                ++checked;
            }
        EXPECT_GT(checked, 3000u);
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, MethodsTest, ::testing::Values("vulkan", "cuda"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace sr::test
