// oracle_test.cpp - the compute pipeline against a conformant rasterizer: the same scenes through the
// real Vulkan graphics pipeline (`vulkan-graphics`; Mesa's rasterizer on lavapipe, 8 subpixel bits,
// top-left rule), on scenes built to probe the rules in docs/rasterization-rules.md.
//
// Criteria: scenes whose vertices sit on the 1/256-pixel grid and need no clipping must give identical
// triangle ids at every pixel (0 differing) and identical depth. Scenes that go through the clipper, or
// whose vertices are projected with w != 1, may differ where a clip-generated or projected vertex rounds
// to the other neighbouring subpixel: at most kClippedBound pixels, and depth by at most what the plane
// moves over two subpixels (gradient estimated from neighbouring pixels of the same triangle) plus 1e-6.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "test_util.h"
#include "vulkan/vulkan_graphics.h"

namespace sr::test {
namespace {

constexpr uint32_t kSize = 256;       // power of two: window <-> NDC conversions are exact
constexpr size_t kClippedBound = 64;  // differing pixels allowed in clipped/projected scenes

struct Agreement {
    size_t differingIds = 0;
    size_t covered = 0;
    double maxDepthDiff = 0.0;       // where ids agree
    size_t depthBeyondBound = 0;     // pixels whose depth differs by more than a 2/256 px plane shift
    std::vector<uint32_t> hitCount;  // from the compute backend
};

class OracleTest : public ComputeOracleTest {
protected:
    Agreement agree(const Scene& scene, const CameraMatrices& camera = identityCamera(),
                    uint32_t size = kSize)
    {
        RenderSettings s = testSettings(size, size);
        s.countHits = true;
        Agreement a;
        auto ours = renderScene(*compute_, scene, camera, s);
        auto oracle = renderVulkanGraphics(scene, camera, s, -1);
        EXPECT_TRUE(ours.ok()) << (ours.ok() ? "" : ours.error().message);
        EXPECT_TRUE(oracle.ok()) << (oracle.ok() ? "" : oracle.error().message);
        if (!ours.ok() || !oracle.ok()) return a;
        const std::vector<uint32_t>& id = ours->aov.id;
        const std::vector<float>& z = ours->aov.depth;
        for (size_t i = 0; i < id.size(); ++i) {
            a.covered += id[i] != EMPTY_ID;
            if (id[i] != oracle->aov.id[i]) {
                ++a.differingIds;
                continue;
            }
            if (id[i] == EMPTY_ID) continue;
            double diff = std::abs(double(z[i]) - oracle->aov.depth[i]);
            a.maxDepthDiff = std::max(a.maxDepthDiff, diff);
            // Depth change per pixel of this triangle's plane, from neighbours it also covers.
            double gradient = 0.0;
            size_t x = i % size;
            for (size_t j : {i + 1, i - 1, i + size, i - size}) {
                bool sameRow = (j == i + 1 && x + 1 < size) || (j == i - 1 && x > 0);
                bool sameCol = j != i + 1 && j != i - 1 && j < id.size();
                if ((sameRow || sameCol) && id[j] == id[i])
                    gradient = std::max(gradient, std::abs(double(z[j]) - z[i]));
            }
            if (diff > gradient / 256.0 * 2.0 + 1e-6) ++a.depthBeyondBound;
        }
        a.hitCount = ours->hitCount;
        std::printf("oracle %s: %zu differing ids of %zu covered pixels\n",
                    ::testing::UnitTest::GetInstance()->current_test_info()->name(), a.differingIds,
                    a.covered);
        return a;
    }
};

// Window position (x, y) in pixels, depth z, as a clip-space vertex with w = 1.
glm::vec4 win(double x, double y, float z)
{
    return {float(x * 2.0 / kSize - 1.0), float(y * 2.0 / kSize - 1.0), z, 1};
}

double onGrid(double v)
{
    return std::round(v * 256.0) / 256.0;
}

std::vector<glm::vec4> quadMesh(const std::vector<std::vector<glm::dvec2>>& grid, bool alternate)
{
    return windowQuadMesh(grid, kSize, kSize, alternate);
}

// Triangles of each power-of-two size with random vertices on the 1/256 grid, each at its own
// constant depth so that the nearer one wins wherever they overlap, in both pipelines. They stay inside
// the viewport: lavapipe clips to the viewport in float (no guard band), which would make them clipped.
TEST_F(OracleTest, GridSnappedTrianglesOfEverySize)
{
    std::mt19937 rng(7);
    for (int k = 0; k <= 8; ++k) {
        double size = std::ldexp(1.0, k);
        std::uniform_real_distribution<double> pos(0.0, kSize - size);
        std::uniform_real_distribution<double> unit(0.0, 1.0);
        std::vector<glm::vec4> corners;
        for (int t = 0; t < 48; ++t) {
            double x = pos(rng), y = pos(rng);
            float z = 0.01f + 0.015f * float(t);
            for (int c = 0; c < 3; ++c)
                corners.push_back(win(onGrid(x + unit(rng) * size), onGrid(y + unit(rng) * size), z));
        }
        Agreement a = agree(clipSpaceScene(corners));
        EXPECT_EQ(a.differingIds, 0u) << "size 2^" << k;
        EXPECT_EQ(a.maxDepthDiff, 0.0) << "size 2^" << k;
        EXPECT_GT(a.covered, 0u);
    }
}

// Vertices exactly on pixel centres: every edge runs through sample points, so only the fill rule
// decides, and a mesh of such triangles must be covered exactly once.
TEST_F(OracleTest, EdgesThroughPixelCentres)
{
    std::mt19937 rng(11);
    std::uniform_int_distribution<int> jitter(-3, 3);
    const int n = 12, step = 20;
    auto vertex = [&](int i, int j) {
        // Interior vertices move by whole pixels, staying on pixel centres; the border stays put.
        int dx = (i > 0 && i < n) ? jitter(rng) : 0, dy = (j > 0 && j < n) ? jitter(rng) : 0;
        return glm::dvec2(8.5 + i * step + dx, 8.5 + j * step + dy);
    };
    std::vector<std::vector<glm::dvec2>> grid(n + 1, std::vector<glm::dvec2>(n + 1));
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) grid[j][i] = vertex(i, j);
    Agreement a = agree(clipSpaceScene(quadMesh(grid, false)));
    EXPECT_EQ(a.differingIds, 0u);
    // Pixels strictly inside the mesh outline are hit exactly once.
    for (int y = 30; y < 220; ++y)
        for (int x = 30; x < 220; ++x) ASSERT_EQ(a.hitCount[y * kSize + x], 1u) << x << "," << y;
}

// A closed fan of more than 1,000 slivers around an off-centre point: no cracks, no double hits, and
// the same owner for every pixel as the conformant rasterizer.
TEST_F(OracleTest, ClosedFanOfSliversIsWatertight)
{
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> step(0.0, 0.8);
    std::vector<glm::dvec2> ring;
    const double x0 = 24, y0 = 16, x1 = 232, y1 = 240;
    for (double x = x0; x < x1; x += step(rng)) ring.push_back({onGrid(x), y0});
    for (double y = y0; y < y1; y += step(rng)) ring.push_back({x1, onGrid(y)});
    for (double x = x1; x > x0; x -= step(rng)) ring.push_back({onGrid(x), y1});
    for (double y = y1; y > y0; y -= step(rng)) ring.push_back({x0, onGrid(y)});
    ASSERT_GT(ring.size(), 1000u);
    glm::dvec2 centre(onGrid(101.37), onGrid(77.81));
    std::vector<glm::vec4> corners;
    for (size_t i = 0; i < ring.size(); ++i) {
        glm::dvec2 b = ring[i], c = ring[(i + 1) % ring.size()];
        for (glm::dvec2 p : {centre, b, c}) corners.push_back(win(p.x, p.y, 0.5f));
    }
    Agreement a = agree(clipSpaceScene(corners));
    EXPECT_EQ(a.differingIds, 0u);
    for (uint32_t y = 0; y < kSize; ++y)
        for (uint32_t x = 0; x < kSize; ++x) {
            bool inside = x >= x0 && x < x1 && y >= y0 && y < y1;
            ASSERT_EQ(a.hitCount[y * kSize + x], inside ? 1u : 0u) << x << "," << y;
        }
}

// A 48x48 grid mesh whose shared vertices are jittered on the 1/256 grid (by less than a fifth of a
// cell, so no cell folds over its neighbour): watertight and identical.
TEST_F(OracleTest, JitteredGridMesh)
{
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> jitter(-0.99, 0.99);
    const int n = 48;
    const double step = 240.0 / n;
    std::vector<std::vector<glm::dvec2>> grid(n + 1, std::vector<glm::dvec2>(n + 1));
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            bool border = i == 0 || j == 0 || i == n || j == n;
            grid[j][i] = {onGrid(8 + i * step + (border ? 0 : jitter(rng))),
                          onGrid(8 + j * step + (border ? 0 : jitter(rng)))};
        }
    Agreement a = agree(clipSpaceScene(quadMesh(grid, true)));
    EXPECT_EQ(a.differingIds, 0u);
    for (int y = 8; y < 248; ++y)
        for (int x = 8; x < 248; ++x) ASSERT_EQ(a.hitCount[y * kSize + x], 1u) << x << "," << y;
}

// Needles: long triangles less than a pixel wide at angles near 0, 45 and 90 degrees.
TEST_F(OracleTest, Needles)
{
    std::vector<glm::vec4> corners;
    float z = 0.05f;
    for (double angle : {0.0, 0.01, 44.99, 45.0, 89.99, 90.0, 120.0, 179.99}) {
        for (double width : {0.1, 0.5, 0.99, 1.5}) {
            double rad = angle * M_PI / 180.0;
            glm::dvec2 dir(std::cos(rad), std::sin(rad)), normal(-dir.y, dir.x);
            glm::dvec2 a = glm::dvec2(128.3, 127.7) - dir * 120.0, b = glm::dvec2(128.3, 127.7) + dir * 120.0;
            glm::dvec2 c = b + normal * width;
            for (glm::dvec2 p : {a, b, c}) corners.push_back(win(onGrid(p.x), onGrid(p.y), z));
            z += 0.02f;
        }
    }
    Agreement a = agree(clipSpaceScene(corners));
    EXPECT_EQ(a.differingIds, 0u);
    EXPECT_GT(a.covered, 500u);
}

// Zero-area triangles draw nothing; triangles of +-1 subpixel^2 area draw what the oracle draws.
TEST_F(OracleTest, DegenerateAndOneSubpixelAreaTriangles)
{
    const double s = 1.0 / 256.0;
    std::vector<glm::vec4> corners;
    float z = 0.1f;
    auto add = [&](glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
        for (glm::dvec2 p : {a, b, c}) corners.push_back(win(p.x, p.y, z));
        z += 0.01f;
    };
    add({10.5, 10.5}, {10.5, 10.5}, {40.5, 12.5});          // repeated vertex
    add({20.0, 30.0}, {60.0, 50.0}, {100.0, 70.0});         // collinear
    add({50.5, 50.5}, {50.5 + s, 50.5}, {50.5, 50.5 + s});  // half a subpixel^2 at a centre, both windings
    add({60.5, 60.5}, {60.5, 60.5 + s}, {60.5 + s, 60.5});
    add({70.5 - s, 70.5}, {70.5 + s, 70.5}, {70.5, 70.5 + s});  // 1 subpixel^2 with an edge on a centre
    add({80.5, 80.5 - s}, {80.5 + s, 80.5 + s}, {80.5 - s, 80.5 + s});
    add({90.0, 90.0}, {200.0, 90.0 + s}, {90.0 + s, 90.0 + 2 * s});  // long sliver of tiny area
    Agreement a = agree(clipSpaceScene(corners));
    EXPECT_EQ(a.differingIds, 0u);
    RenderSettings settings = testSettings(kSize, kSize);
    auto out = renderScene(*compute_, clipSpaceScene(corners), identityCamera(), settings);
    ASSERT_TRUE(out.ok());
    EXPECT_EQ(countId(out->aov, 0) + countId(out->aov, 1), 0u);  // the zero-area ones
}

// Window depth of triangle `id` (clip-space corners) at the centre of pixel (px, py), in double: the
// point of the plane seen through that pixel, from perspective-correct barycentrics.
double analyticDepth(const std::vector<glm::vec4>& corners, uint32_t id, size_t px, size_t py)
{
    glm::dvec4 c[3];
    glm::dvec2 p[3];
    double nx = (double(px) + 0.5) * 2.0 / kSize - 1.0, ny = (double(py) + 0.5) * 2.0 / kSize - 1.0;
    for (int k = 0; k < 3; ++k) {
        c[k] = glm::dvec4(corners[3 * id + k]);
        p[k] = {c[k].x - nx * c[k].w, c[k].y - ny * c[k].w};
    }
    double a[3] = {p[1].x * p[2].y - p[1].y * p[2].x, p[2].x * p[0].y - p[2].y * p[0].x,
                   p[0].x * p[1].y - p[0].y * p[1].x};
    glm::dvec4 point = (a[0] * c[0] + a[1] * c[1] + a[2] * c[2]) / (a[0] + a[1] + a[2]);
    return point.z / point.w;
}

// Vertices behind the camera and triangles crossing near and far: both pipelines clip, each in its own
// float arithmetic, so clip-generated vertices may round to a neighbouring subpixel. The two depth
// buffers then differ by how each pipeline's clipped sub-triangles happen to snap (lavapipe also clips
// to the viewport, making slivers whose snapped planes tilt), so depth is held to the analytic plane
// instead: ours within two subpixels' worth of plane shift of it everywhere.
TEST_F(OracleTest, NearAndFarPlaneCrossings)
{
    std::mt19937 rng(13);
    std::uniform_real_distribution<float> xy(-1.5f, 1.5f), w(0.2f, 4.0f), zf(-0.6f, 1.6f);
    std::vector<glm::vec4> corners;
    for (int t = 0; t < 60; ++t)
        for (int c = 0; c < 3; ++c) {
            float ww = (t % 5 == 0 && c == 0) ? -w(rng) : w(rng);  // some vertices behind the eye
            corners.push_back(glm::vec4(xy(rng) * ww, xy(rng) * ww, zf(rng) * ww, ww));
        }
    Scene scene = clipSpaceScene(corners);
    Agreement a = agree(scene);
    EXPECT_LE(a.differingIds, kClippedBound);
    EXPECT_GT(a.covered, 1000u);
    auto ours = renderScene(*compute_, scene, identityCamera(), testSettings(kSize, kSize));
    auto oracle = renderVulkanGraphics(scene, identityCamera(), testSettings(kSize, kSize), -1);
    ASSERT_TRUE(ours.ok() && oracle.ok());
    double worstOurs = 0.0, worstOracle = 0.0;
    size_t beyond = 0;
    for (size_t i = 0; i < ours->aov.id.size(); ++i) {
        uint32_t id = ours->aov.id[i];
        if (id == EMPTY_ID) continue;
        size_t x = i % kSize, y = i / kSize;
        double exact = analyticDepth(corners, id, x, y);
        // Plane shift over two subpixels in x and y, from the analytic plane itself.
        double slope = std::abs(analyticDepth(corners, id, x + 1, y) - exact) +
                       std::abs(analyticDepth(corners, id, x, y + 1) - exact);
        double err = std::abs(double(ours->aov.depth[i]) - std::clamp(exact, 0.0, 1.0));
        worstOurs = std::max(worstOurs, err);
        beyond += err > slope * 2.0 / 256.0 + 1e-6;
        if (oracle->aov.id[i] == id)
            worstOracle =
                std::max(worstOracle, std::abs(double(oracle->aov.depth[i]) - std::clamp(exact, 0.0, 1.0)));
    }
    EXPECT_EQ(beyond, 0u) << "worst depth error " << worstOurs;
    RecordProperty("max_depth_error_ours", std::to_string(worstOurs));
    RecordProperty("max_depth_error_oracle", std::to_string(worstOracle));
    std::printf(
        "near/far crossings: %zu differing ids of %zu covered; depth error vs analytic: ours %.3g, "
        "graphics pipeline %.3g\n",
        a.differingIds, a.covered, worstOurs, worstOracle);
}

// Triangles 1e3 to 1e7 times the viewport: guard-band clipping in ours, full clipping in the oracle.
TEST_F(OracleTest, HugeTriangles)
{
    for (float size : {1e3f, 1e5f, 1e7f}) {
        std::vector<glm::vec4> corners = {{-size, -size * 0.7f, 0.3f, 1},
                                          {size * 1.3f, -size, 0.3f, 1},
                                          {-size * 0.2f, size * 1.1f, 0.3f, 1},
                                          // a second one crossing the first edge-on, at another depth
                                          {-size, size, 0.2f, 1},
                                          {0.3f, -0.4f, 0.2f, 1},
                                          {size, size * 0.9f, 0.2f, 1}};
        Agreement a = agree(clipSpaceScene(corners));
        EXPECT_LE(a.differingIds, kClippedBound) << size;
        EXPECT_EQ(a.covered, size_t(kSize) * kSize) << size;
    }
}

// Perspective-projected vertices (w != 1): snapping follows the divide, which may round differently.
TEST_F(OracleTest, ProjectedFillRuleQuads)
{
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> w(0.1f, 4.0f);
    std::vector<glm::vec4> corners;
    for (int q = 0; q < 16; ++q) {
        float cx = -0.75f + 0.5f * float(q % 4), cy = -0.75f + 0.5f * float(q / 4), r = 0.15f;
        float angle = 0.3f * float(q);
        glm::vec2 p[4];
        for (int k = 0; k < 4; ++k) {
            float a = angle + float(k) * float(M_PI) / 2.0f;
            p[k] = {cx + r * std::cos(a), cy + r * std::sin(a)};
        }
        float ws[4] = {w(rng), w(rng), w(rng), w(rng)};
        for (int k : {0, 1, 2, 0, 2, 3})
            corners.push_back(glm::vec4(p[k].x * ws[k], p[k].y * ws[k], 0.5f * ws[k], ws[k]));
    }
    Agreement a = agree(clipSpaceScene(corners));
    EXPECT_LE(a.differingIds, kClippedBound);
    for (uint32_t hits : a.hitCount) ASSERT_LE(hits, 1u);  // shared diagonals never double-hit
}

// The reference backend is deterministic too: 20 renders, bit-identical ids, depth and colour.
TEST_F(OracleTest, GraphicsBackendIsDeterministic)
{
    FramedScene f = framedBuiltin(64, 48);
    RenderSettings s = f.settings;
    auto first = renderVulkanGraphics(f.scene, f.camera, s, -1);
    ASSERT_TRUE(first.ok());
    for (int run = 1; run < 20; ++run) {
        auto again = renderVulkanGraphics(f.scene, f.camera, s, -1);
        ASSERT_TRUE(again.ok());
        ASSERT_EQ(again->aov.id, first->aov.id);
        ASSERT_EQ(again->aov.depth, first->aov.depth);
        ASSERT_EQ(again->color.pixels, first->color.pixels);
    }
}

// The bench's hardware baseline, the visibility-only pass (pipeline culling, early depth test, id only),
// must see exactly what the full reference pass sees.
TEST_F(OracleTest, VisibilityOnlyPassMatchesTheFullPass)
{
    FramedScene f = framedBuiltin(160, 120);
    RenderSettings s = f.settings;
    auto full = renderVulkanGraphics(f.scene, f.camera, s, -1);
    s.visibilityOnly = true;
    auto visibility = renderVulkanGraphics(f.scene, f.camera, s, -1);
    ASSERT_TRUE(full.ok() && visibility.ok());
    EXPECT_EQ(visibility->aov.id, full->aov.id);
    EXPECT_EQ(visibility->aov.depth, full->aov.depth);
    for (uint32_t c : visibility->color.pixels) ASSERT_EQ(c, packRgba8(s.background));
}

}  // namespace
}  // namespace sr::test
