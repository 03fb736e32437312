// shared_math_test.cpp - the maths of common/raster_shared.h, run on the host against hand-derived
// values: deterministic reciprocal, snapping and its rounding, edge functions and the top-left
// rule, culling, clipping, depth interpolation, perspective-correct barycentrics and the visibility
// key.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "raster_shared.h"

namespace sr {
namespace {

constexpr uint32_t kSize = 256;  // power of two: window <-> NDC conversions below are exact

// Clip-space vertex (w = 1) landing exactly on window position (x, y) of a kSize x kSize image.
vec4 atWindow(float x, float y, float z = 0.5f)
{
    return vec4(x * 2.0f / float(kSize) - 1.0f, y * 2.0f / float(kSize) - 1.0f, z, 1.0f);
}

// Pixels of a kSize^2 image covered by the triangle (window coordinates), in row-major order.
std::vector<int> coveredPixels(vec2 a, vec2 b, vec2 c)
{
    TriSetup t;
    std::vector<int> pixels;
    if (!setupTriangle(atWindow(a.x, a.y), atWindow(b.x, b.y), atWindow(c.x, c.y), 0, true, CULL_NONE, kSize,
                       kSize, PIXEL_CENTER_BOUNDS, t))
        return pixels;
    ivec4 bounds = setupPixelBounds(t, kSize, kSize, PIXEL_CENTER_BOUNDS);
    for (int y = bounds.y; y <= bounds.w; ++y)
        for (int x = bounds.x; x <= bounds.z; ++x) {
            float depth;
            if (rasterPixel(t, x, y, depth)) pixels.push_back(y * int(kSize) + x);
        }
    return pixels;
}

TEST(SharedMath, RecipDetIsExactForPowersOfTwoAndWithinOneUlpOtherwise)
{
    for (float b : {1.0f, 2.0f, 0.5f, 1024.0f, -0.25f}) EXPECT_EQ(recipDet(b), 1.0f / b) << b;
    for (float b : {3.0f, 7.0f, 1e-3f, 123456.7f, -5.0f, 0.3f, 1.5e30f, 6e-30f}) {
        double exact = 1.0 / double(b);
        EXPECT_LE(std::abs(double(recipDet(b)) - exact), std::abs(exact) * std::ldexp(1.0, -23)) << b;
    }
    EXPECT_TRUE(std::isinf(recipDet(0.0f)));
    EXPECT_EQ(recipDet(1e38f), 0.0f);
    EXPECT_EQ(divDet(6.0f, 2.0f), 3.0f);
}

TEST(SharedMath, RecipAreaMatchesDivision)
{
    for (int64_t area : {int64_t(1), int64_t(3), int64_t(255), int64_t(65536), int64_t(123456789),
                         int64_t(1) << 40, (int64_t(1) << 60) + 12345}) {
        double exact = 1.0 / double(area);
        EXPECT_LE(std::abs(double(recipArea(area)) - exact), exact * std::ldexp(1.0, -23)) << area;
    }
}

// recipArea's oracle: the nearest float to floor(2^47 / d) (a correctly rounded conversion of the 64-bit
// quotient) times 2^-(47 + shift), as the function was first written with a 64-bit division.
float recipAreaByDivision(int64_t area)
{
    uint64_t a = uint64_t(area);
    int shift = 0;
    while ((a >> shift) >= (uint64_t(1) << 24)) ++shift;
    uint64_t q = (uint64_t(1) << 47) / (a >> shift);
    return float(q) * std::ldexp(1.0f, -47 - shift);
}

// recipArea builds the quotient without a 64-bit division and rounds it by hand: every 24-bit d (all
// areas below 2^24, and the top bits of every larger one), and larger areas at random, give the bits of
// the division.
TEST(SharedMath, RecipAreaWithoutDivisionIsTheDivisionsBitsForEveryTopBits)
{
    uint32_t wrong = 0;
    for (int64_t d = 1; d < (int64_t(1) << 24); ++d)
        if (floatBitsToUint(recipArea(d)) != floatBitsToUint(recipAreaByDivision(d))) ++wrong;
    EXPECT_EQ(wrong, 0u);
    std::mt19937_64 rng(11);
    for (int k = 0; k < 100000; ++k) {
        int64_t area = int64_t(rng() >> (1 + rng() % 40));
        if (area <= 0) continue;
        ASSERT_EQ(floatBitsToUint(recipArea(area)), floatBitsToUint(recipAreaByDivision(area))) << area;
    }
}

// setup's small-triangle loop steps SmallEdges in 32-bit integers where rasterPixel evaluates 64-bit edge
// functions: over random snapped triangles up to SMALL_EDGE_EXTENT wide and high (the bound of the
// exactness argument, also reached exactly, with corners on the bbox's corners where the products peak),
// anywhere from inside the image to far outside it, every pixel of every triangle's bounds gets the
// same coverage and the same depth bits.
TEST(SharedMath, SmallEdgesGiveRasterPixelsCoverageAndDepth)
{
    std::mt19937 rng(23);
    std::uniform_int_distribution<int> origin(-40 * SUBPIXEL_SCALE, int(kSize) * SUBPIXEL_SCALE);
    std::uniform_int_distribution<int> extent(0, SMALL_EDGE_EXTENT);
    std::uniform_real_distribution<float> depth(0.0f, 1.0f);
    size_t pixels = 0, covered = 0, fits = 0;
    for (int i = 0; i < 20000; ++i) {
        ivec2 o(origin(rng), origin(rng));
        int w = i % 5 == 0 ? SMALL_EDGE_EXTENT : extent(rng) >> (rng() % 8);
        int h = i % 5 == 0 ? SMALL_EDGE_EXTENT : extent(rng) >> (rng() % 8);
        std::uniform_int_distribution<int> dx(0, w), dy(0, h);
        ivec2 v[3] = {o + ivec2(dx(rng), dy(rng)), o + ivec2(dx(rng), dy(rng)), o + ivec2(dx(rng), dy(rng))};
        if (i % 5 == 0) v[0] = o, v[1] = o + ivec2(w, 0), v[2] = o + ivec2(rng() % 2 ? w : 0, h);
        TriSetup t;
        if (!setupSnappedTriangle(v[0], v[1], v[2], depth(rng), depth(rng), depth(rng), 0, true, CULL_NONE,
                                  kSize, kSize, PIXEL_CENTER_BOUNDS, t))
            continue;
        ASSERT_TRUE(smallEdgesFit(t));
        ++fits;
        ivec4 b = setupPixelBounds(t, kSize, kSize, PIXEL_CENTER_BOUNDS);
        SmallEdges edges = smallEdges(t, b.x, b.y);
        ivec3 row = edges.start;
        for (int y = b.y; y <= b.w; ++y) {
            ivec3 e = row;
            for (int x = b.x; x <= b.z; ++x) {
                float d64 = 0.0f, d32 = 0.0f;
                bool in64 = rasterPixel(t, x, y, d64);
                bool in32 = smallEdgesPixel(t, edges, e, d32);
                ASSERT_EQ(in32, in64) << "triangle " << i << " pixel " << x << "," << y;
                if (in64) {
                    ASSERT_EQ(floatBitsToUint(d32), floatBitsToUint(d64)) << "triangle " << i;
                }
                covered += in64 ? 1u : 0u;
                ++pixels;
                e += edges.stepX;
            }
            row += edges.stepY;
        }
    }
    EXPECT_GT(fits, 5000u);
    EXPECT_GT(covered, 100000u);
    EXPECT_GT(pixels, covered + 100000u);  // and uncovered pixels too
    // One subpixel wider than the bound does not fit, and takes rasterPixel.
    TriSetup t;
    ASSERT_TRUE(setupSnappedTriangle(ivec2(0, 0), ivec2(SMALL_EDGE_EXTENT + 1, 0), ivec2(0, 512), 0.5f, 0.5f,
                                     0.5f, 0, true, CULL_NONE, kSize, kSize, PIXEL_CENTER_BOUNDS, t));
    EXPECT_FALSE(smallEdgesFit(t));
}

TEST(SharedMath, SnapRoundsHalfSubpixelsToEven)
{
    ivec2 xy;
    float z;
    // 10 + 1/512 px = 2560.5 subpixels -> 2560; 10 + 3/512 px = 2561.5 -> 2562.
    ASSERT_TRUE(snapVertex(atWindow(10.0f + 1.0f / 512.0f, 7.0f + 3.0f / 512.0f), kSize, kSize, xy, z));
    EXPECT_EQ(xy.x, 2560);
    EXPECT_EQ(xy.y, 7 * 256 + 2);
    ASSERT_TRUE(snapVertex(atWindow(10.0f + 3.0f / 512.0f, 0.0f), kSize, kSize, xy, z));
    EXPECT_EQ(xy.x, 2562);
    EXPECT_EQ(z, 0.5f);
    // w <= 0 never snaps: such vertices must have been clipped away.
    EXPECT_FALSE(snapVertex(vec4(0.0f, 0.0f, 0.5f, -1.0f), kSize, kSize, xy, z));
    EXPECT_FALSE(snapVertex(vec4(0.0f, 0.0f, 0.0f, 0.0f), kSize, kSize, xy, z));
}

TEST(SharedMath, EdgeFunctionAndAreaByHand)
{
    // Edge (0,0)->(4,0) at (1,2): 4*2 - 0*1 = 8; area2 of (0,0),(4,0),(0,4) = 16 (clockwise in
    // y-down).
    EXPECT_EQ(edgeFunction(ivec2(0, 0), ivec2(4, 0), ivec2(1, 2)), 8);
    EXPECT_EQ(signedArea2(ivec2(0, 0), ivec2(4, 0), ivec2(0, 4)), 16);
    EXPECT_EQ(signedArea2(ivec2(0, 0), ivec2(0, 4), ivec2(4, 0)), -16);
    // Products near 2^58 stay exact in int64.
    int64_t big = int64_t(1) << 29;
    EXPECT_EQ(edgeFunction(ivec2(-int(big), 0), ivec2(int(big), 0), ivec2(0, int(big))), (2 * big) * big);
    EXPECT_TRUE(isTopLeftEdge(ivec2(0, 0), ivec2(4, 0)));   // top: horizontal, interior below
    EXPECT_TRUE(isTopLeftEdge(ivec2(0, 4), ivec2(0, 0)));   // left: going up in y-down
    EXPECT_FALSE(isTopLeftEdge(ivec2(4, 0), ivec2(0, 4)));  // right edge
    EXPECT_FALSE(isTopLeftEdge(ivec2(4, 4), ivec2(0, 4)));  // bottom: horizontal, interior above
}

// The D3D rasterization-rules example: two triangles sharing the diagonal of a 5x5 pixel square get
// 15 and 10 pixels; the 5 pixel centres on the diagonal go to the triangle for which it is a left
// edge.
TEST(SharedMath, TopLeftRuleSplitsSharedDiagonal)
{
    std::vector<int> upper = coveredPixels(vec2(0, 0), vec2(5, 0), vec2(5, 5));
    std::vector<int> lower = coveredPixels(vec2(0, 5), vec2(0, 0), vec2(5, 5));
    EXPECT_EQ(upper.size(), 15u);
    EXPECT_EQ(lower.size(), 10u);
    for (int p : upper) EXPECT_EQ(std::count(lower.begin(), lower.end(), p), 0) << p;
    for (int i = 0; i < 5; ++i) EXPECT_EQ(std::count(upper.begin(), upper.end(), i * int(kSize) + i), 1);
}

TEST(SharedMath, SamplesOnTopAndLeftEdgesAreInsideBottomAndRightAreNot)
{
    // Top edge on the centres of row 0 and left edge on the centres of column 0: both included.
    std::vector<int> a = coveredPixels(vec2(0.5f, 0.5f), vec2(8.5f, 0.5f), vec2(0.5f, 8.5f));
    // Centres (x+0.5, y+0.5) with x + y <= 7 for the hypotenuse x + y + 1 < 8.5 -> 36 pixels, and
    // the hypotenuse passes through no centre.
    EXPECT_EQ(a.size(), 36u);
    EXPECT_EQ(std::count(a.begin(), a.end(), 0), 1);
    // The same shape mirrored: bottom edge on the centres of row 8 and right edge on column 8:
    // excluded.
    std::vector<int> b = coveredPixels(vec2(8.5f, 8.5f), vec2(0.5f, 8.5f), vec2(8.5f, 0.5f));
    for (int p : b) {
        EXPECT_NE(p / int(kSize), 8);
        EXPECT_NE(p % int(kSize), 8);
    }
    // Centres strictly inside: x + y > 8 with x, y <= 7 -> 28 pixels.
    EXPECT_EQ(b.size(), 28u);
}

// A closed fan of ~1,000 slivers around a rectangle with vertices on the 1/256 grid covers every
// pixel centre inside exactly once: no cracks, no double hits.
TEST(SharedMath, ClosedFanIsWatertight)
{
    std::mt19937 rng(12345);
    std::uniform_real_distribution<float> step(0.0f, 1.0f);
    auto snap = [](float v) { return std::round(v * 256.0f) / 256.0f; };
    std::vector<vec2> ring;
    const float x0 = 20, y0 = 20, x1 = 180, y1 = 140;
    for (float x = x0; x < x1; x += step(rng)) ring.push_back(vec2(snap(x), y0));
    for (float y = y0; y < y1; y += step(rng)) ring.push_back(vec2(x1, snap(y)));
    for (float x = x1; x > x0; x -= step(rng)) ring.push_back(vec2(snap(x), y1));
    for (float y = y1; y > y0; y -= step(rng)) ring.push_back(vec2(x0, snap(y)));
    ASSERT_GT(ring.size(), 500u);
    vec2 centre(snap(97.3f), snap(61.7f));
    std::vector<int> hits(kSize * kSize, 0);
    for (size_t i = 0; i < ring.size(); ++i)
        for (int p : coveredPixels(centre, ring[i], ring[(i + 1) % ring.size()])) ++hits[p];
    for (int y = 0; y < int(kSize); ++y)
        for (int x = 0; x < int(kSize); ++x) {
            bool inside = x >= int(x0) && x < int(x1) && y >= int(y0) && y < int(y1);
            ASSERT_EQ(hits[y * kSize + x], inside ? 1 : 0) << x << "," << y;
        }
}

TEST(SharedMath, ZeroAreaAndFacingCulling)
{
    TriSetup t;
    // Collinear after snapping.
    EXPECT_FALSE(setupTriangle(atWindow(1, 1), atWindow(5, 5), atWindow(9, 9), 0, false, CULL_NONE, kSize,
                               kSize, PIXEL_CENTER_BOUNDS, t));
    // Counter-clockwise on screen (front face): (0,0) -> (0,8) -> (8,0) in y-down.
    vec4 a = atWindow(0, 0), b = atWindow(0, 8), c = atWindow(8, 0);
    EXPECT_TRUE(setupTriangle(a, b, c, 0, false, CULL_BACK, kSize, kSize, PIXEL_CENTER_BOUNDS, t));
    EXPECT_FALSE(setupTriangle(a, b, c, 0, false, CULL_FRONT, kSize, kSize, PIXEL_CENTER_BOUNDS, t));
    EXPECT_FALSE(setupTriangle(a, c, b, 0, false, CULL_BACK, kSize, kSize, PIXEL_CENTER_BOUNDS, t));
    EXPECT_TRUE(setupTriangle(a, c, b, 0, false, CULL_FRONT, kSize, kSize, PIXEL_CENTER_BOUNDS, t));
    EXPECT_TRUE(
        setupTriangle(a, c, b, 0, true, CULL_BACK, kSize, kSize, PIXEL_CENTER_BOUNDS, t));  // double-sided
    // Between pixel centres: a sliver inside one pixel covers no centre.
    EXPECT_FALSE(setupTriangle(atWindow(3.1f, 3.1f), atWindow(3.2f, 3.1f), atWindow(3.1f, 3.2f), 0, true,
                               CULL_NONE, kSize, kSize, PIXEL_CENTER_BOUNDS, t));
}

TEST(SharedMath, DepthIsLinearInScreenSpace)
{
    TriSetup t;
    ASSERT_TRUE(setupTriangle(atWindow(0, 0, 0.2f), atWindow(64, 0, 0.6f), atWindow(0, 64, 0.4f), 0, true,
                              CULL_NONE, kSize, kSize, PIXEL_CENTER_BOUNDS, t));
    for (int y = 0; y < 60; y += 7)
        for (int x = 0; x < 60 - y; x += 5) {
            float depth;
            ASSERT_TRUE(rasterPixel(t, x, y, depth));
            double expected = 0.2 + 0.4 * (x + 0.5) / 64.0 + 0.2 * (y + 0.5) / 64.0;
            EXPECT_NEAR(depth, expected, 1e-6) << x << "," << y;
        }
}

TEST(SharedMath, PerspectiveBarycentricsRecoverTheWeightsOfA3DPoint)
{
    // A simple projection: clip = (x, y, z + 2, -z), i.e. w is the view depth.
    auto project = [](vec3 p) { return vec4(p.x, p.y, p.z + 2.0f, -p.z); };
    vec3 v0(-1.0f, -0.5f, -2.0f), v1(2.0f, -1.0f, -9.0f), v2(0.5f, 1.5f, -4.0f);
    vec3 weights(0.2f, 0.3f, 0.5f);
    vec3 q = v0 * weights.x + v1 * weights.y + v2 * weights.z;
    vec4 cq = project(q);
    vec3 b = perspectiveBarycentrics(project(v0), project(v1), project(v2), vec2(cq.x / cq.w, cq.y / cq.w));
    EXPECT_NEAR(b.x, 0.2f, 1e-5f);
    EXPECT_NEAR(b.y, 0.3f, 1e-5f);
    EXPECT_NEAR(b.z, 0.5f, 1e-5f);
    // Screen-space (affine) weights differ markedly here, so the test can tell the two apart.
    EXPECT_GT(std::abs(cq.x / cq.w - (0.2f * v0.x / 2.0f + 0.3f * v1.x / 9.0f + 0.5f * v2.x / 4.0f)), 0.01f);
}

TEST(SharedMath, NearPlaneClipCutsAtTheExpectedPoint)
{
    vec4 poly[MAX_CLIP_VERTS];
    vec4 guard(1000.0f, 1000.0f, 0.0f, 0.0f);
    vec4 c0(0.0f, 0.0f, 0.5f, 1.0f), c1(0.5f, 0.0f, 0.5f, 1.0f), c2(0.0f, 0.5f, -2.0f, -1.0f);
    uint count = 0;
    ASSERT_EQ(prepareTriangle(c0, c1, c2, guard, poly, count), PREPARE_CLIPPED);
    ASSERT_EQ(count, 4u);
    // Edge c1 -> c2 crosses z = 0 at t = 0.5 / 2.5 = 0.2: (0.4, 0.1, 0, 0.6).
    bool found = false;
    for (uint i = 0; i < count; ++i) {
        EXPECT_GE(poly[i].z, -1e-6f);
        EXPECT_GT(poly[i].w, 0.0f);
        if (std::abs(poly[i].x - 0.4f) < 1e-6f && std::abs(poly[i].y - 0.1f) < 1e-6f &&
            std::abs(poly[i].w - 0.6f) < 1e-6f)
            found = true;
    }
    EXPECT_TRUE(found);
    // All three vertices behind the camera: nothing left.
    EXPECT_EQ(prepareTriangle(vec4(0, 0, -1, -1), vec4(1, 0, -1, -1), vec4(0, 1, -1, -1), guard, poly, count),
              PREPARE_CULLED);
    EXPECT_EQ(prepareTriangle(vec4(NAN, 0, 0.5f, 1), c1, c0, guard, poly, count), PREPARE_INVALID);
    EXPECT_EQ(
        prepareTriangle(vec4(2, 0, 0.5f, 1), vec4(3, 0, 0.5f, 1), vec4(2, 1, 0.5f, 1), guard, poly, count),
        PREPARE_CULLED);
}

TEST(SharedMath, SharedClippedEdgeGivesBitIdenticalPoints)
{
    vec4 guard(1000.0f, 1000.0f, 0.0f, 0.0f);
    vec4 a(0.3f, -0.7f, 0.9f, 1.3f), b(-0.2f, 0.4f, -1.7f, -0.6f);
    vec4 c(0.9f, 0.8f, 0.2f, 1.1f), d(-0.9f, -0.8f, 0.4f, 0.9f);
    vec4 p[MAX_CLIP_VERTS] = {a, b, c};
    vec4 q[MAX_CLIP_VERTS] = {b, a, d};
    uint n = clipPolygonAgainstPlane(p, 3, 0, guard);
    uint m = clipPolygonAgainstPlane(q, 3, 0, guard);
    int shared = 0;
    for (uint i = 0; i < n; ++i)
        for (uint j = 0; j < m; ++j)
            if (std::memcmp(&p[i], &q[j], sizeof(vec4)) == 0) ++shared;
    EXPECT_EQ(shared, 2);  // vertex a and the cut point on edge a-b
}

TEST(SharedMath, VisibilityKeyOrdersByDepthThenId)
{
    EXPECT_LT(packVisibility(0.25f, 900), packVisibility(0.5f, 1));
    EXPECT_LT(packVisibility(0.5f, 1), packVisibility(0.5f, 2));
    EXPECT_LT(packVisibility(1.0f, 0xfffffffeu), ~uint64_t(0));
    EXPECT_EQ(visibilityId(packVisibility(0.75f, 1234)), 1234u);
    EXPECT_EQ(visibilityDepth(packVisibility(0.75f, 1234)), 0.75f);
    EXPECT_EQ(visibilityId(~uint64_t(0)), EMPTY_ID);
    EXPECT_EQ(visibilityDepth(~uint64_t(0)), 1.0f);
}

TEST(SharedMath, PixelSpanFindsCentresInsideTheRange)
{
    // Centres of pixels 2, 3 lie at 640 and 896 subpixels.
    EXPECT_EQ(pixelSpan(640, 896, 100), ivec2(2, 3));
    EXPECT_EQ(pixelSpan(641, 895, 100), ivec2(3, 2));  // between centres: empty
    EXPECT_EQ(pixelSpan(-5000, 100000, 100), ivec2(0, 99));
}

TEST(SharedMath, SrgbEncodingEndpoints)
{
    EXPECT_EQ(packRgba8(vec3(0.0f)), 0xff000000u);
    EXPECT_EQ(packRgba8(vec3(1.0f)), 0xffffffffu);
    // Linear 0.5 encodes to sRGB 0.7354 -> 188.
    EXPECT_EQ(packRgba8(vec3(0.5f, 0.0f, 0.0f)) & 0xffu, 188u);
}

// recipDet's and recipArea's quotient: quotient47NoDivide gives floor(2^47 / m) for every one of the 2^23
// mantissas; floorQuotient47 corrects any estimate within 3, what a division 2.5 ulp off can give.
TEST(SharedMath, QuotientWithoutDivisionIsExactForEveryMantissa)
{
    uint32_t wrong = 0, wrongFromEstimate = 0;
    for (uint32_t m = 1u << 23; m < (1u << 24); ++m) {
        uint32_t exact = uint32_t((uint64_t(1) << 47) / m);
        if (quotient47NoDivide(m) != exact) ++wrong;
        if (m % 61u != 0u) continue;
        for (int d = -3; d <= 3; ++d)
            if (floorQuotient47(m, uint32_t(int64_t(exact) + d)) != exact) ++wrongFromEstimate;
    }
    EXPECT_EQ(wrong, 0u);
    EXPECT_EQ(wrongFromEstimate, 0u);
}

// wrapTexel's floored remainder without division (the CPU builds) against the integer one, over the whole
// range of texel indices textureTexelCoords gives, for periods of 1 to 2^15.
TEST(SharedMath, FloorModWithoutDivisionMatchesIntegerRemainder)
{
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> index(-(1 << 22) - 1, (1 << 22) + 1);
    uint32_t wrong = 0;
    for (int period : {1, 2, 3, 7, 64, 255, 256, 1000, 4096, 32768}) {
        auto check = [&](int i) {
            int expected = ((i % period) + period) % period;
            if (floorModNoDivide(i, period) != expected) ++wrong;
        };
        for (int k = 0; k < 200000; ++k) check(index(rng));
        for (int i :
             {-(1 << 22) - 1, -(1 << 22), -period, -1, 0, 1, period - 1, period, (1 << 22), (1 << 22) + 1})
            check(i);
    }
    EXPECT_EQ(wrong, 0u);
}

// srgbEncode8 (shade's CPU build) against linearToSrgb in double precision, correctly rounded: never more
// than 1 level off, and off only where the exact value lies within 5e-5 of a rounding boundary (where
// single-precision pow on two devices disagrees too). Every 16th float of [2^-12, 1] plus the boundaries.
TEST(SharedMath, SrgbEncodingWithoutPowMatchesDoublePrecision)
{
    auto exact = [](float c) {
        double d = c <= 0.0031308f ? 12.92 * double(c) : 1.055 * std::pow(double(c), 1.0 / 2.4) - 0.055;
        return d * 255.0 + 0.5;
    };
    uint32_t off = 0, farOff = 0, offAwayFromBoundary = 0, tested = 0;
    auto check = [&](float c) {
        double e = exact(c);
        int expected = int(std::floor(e));
        int got = int(srgbEncode8(c));
        ++tested;
        if (got == expected) return;
        ++off;
        if (std::abs(got - expected) > 1) ++farOff;
        if (std::abs(e - std::round(e)) > 5e-5) ++offAwayFromBoundary;
    };
    for (uint32_t bits = floatBitsToUint(1.0f / 4096.0f); bits <= floatBitsToUint(1.0f); bits += 16)
        check(uintBitsToFloat(bits));
    for (int k = 0; k < 256; ++k) {
        // The linear value whose sRGB code is exactly k - 0.5, and its float neighbours.
        double s = (k - 0.5) / 255.0;
        double c = s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
        float f = float(c);
        for (int d = -3; d <= 3; ++d) check(uintBitsToFloat(uint32_t(int32_t(floatBitsToUint(f)) + d)));
    }
    EXPECT_GT(tested, 1000000u);
    EXPECT_EQ(farOff, 0u);
    EXPECT_EQ(offAwayFromBoundary, 0u);
    EXPECT_EQ(srgbEncode8(0.0f), 0u);
    EXPECT_EQ(srgbEncode8(1.0f), 255u);
    EXPECT_EQ(srgbEncode8(2.0f), 255u);
    EXPECT_EQ(srgbEncode8(-1.0f), 0u);
    EXPECT_EQ(packRgba8NoPow(vec3(0.5f, 0.0f, 1.0f)), packRgba8(vec3(0.5f, 0.0f, 1.0f)));
    RecordProperty("off_by_one_at_boundaries", int(off));
}

}  // namespace
// raster_tiles skips a triangle at a pixel whose key is already nearer than triangleMinDepthBits: the
// bound must hold at every covered pixel, or the early depth test would drop a visible fragment. Random
// triangles with steep depth ranges, slivers and large areas (where 1 / area is truncated) all stay at
// or above it.
TEST(SharedMath, MinDepthBoundHoldsAtEveryCoveredPixel)
{
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> pos(-0.2f * kSize, 1.2f * kSize), depth(0.0f, 1.0f);
    size_t checked = 0;
    for (int i = 0; i < 400; ++i) {
        vec4 c[3];
        for (vec4& v : c) v = atWindow(pos(rng), pos(rng), depth(rng));
        if (i % 4 == 0) c[2] = atWindow(pos(rng), pos(rng), 0.0f);  // touching the near plane
        TriSetup t;
        if (!setupTriangle(c[0], c[1], c[2], 0, true, CULL_NONE, kSize, kSize, PIXEL_CENTER_BOUNDS, t))
            continue;
        uint bound = triangleMinDepthBits(t);
        ivec4 b = setupPixelBounds(t, kSize, kSize, PIXEL_CENTER_BOUNDS);
        for (int y = b.y; y <= b.w; ++y)
            for (int x = b.x; x <= b.z; ++x) {
                float d;
                if (!rasterPixel(t, x, y, d)) continue;
                ASSERT_GE(floatBitsToUint(d), bound) << "triangle " << i << " pixel " << x << "," << y;
                ++checked;
            }
    }
    EXPECT_GT(checked, 100000u);
}

// bin_count and bin_fill drop the tiles where triangleTouchesTile is false: it must be true for every
// tile holding a covered pixel (never lose coverage), and false for tiles that lie entirely outside one
// edge (the reason it exists).
TEST(SharedMath, TileTestKeepsEveryCoveredTileAndDropsTilesOutsideAnEdge)
{
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> pos(-10.0f, kSize + 10.0f);
    size_t dropped = 0;
    for (int i = 0; i < 300; ++i) {
        TriSetup t;
        if (!setupTriangle(atWindow(pos(rng), pos(rng)), atWindow(pos(rng), pos(rng)),
                           atWindow(pos(rng), pos(rng)), 0, true, CULL_NONE, kSize, kSize,
                           PIXEL_CENTER_BOUNDS, t))
            continue;
        ivec4 b = setupPixelBounds(t, kSize, kSize, PIXEL_CENTER_BOUNDS);
        ivec4 r = tileRect(b);
        EXPECT_EQ(tileCount(b), uint(r.z - r.x + 1) * uint(r.w - r.y + 1));
        for (int ty = r.y; ty <= r.w; ++ty)
            for (int tx = r.x; tx <= r.z; ++tx) {
                bool covered = false;
                for (int y = max(ty * TILE_SIZE, b.y); y <= min(ty * TILE_SIZE + TILE_SIZE - 1, b.w); ++y)
                    for (int x = max(tx * TILE_SIZE, b.x); x <= min(tx * TILE_SIZE + TILE_SIZE - 1, b.z);
                         ++x) {
                        float d;
                        covered = covered || rasterPixel(t, x, y, d);
                    }
                bool kept = triangleTouchesTile(t, b, tx, ty, PIXEL_CENTER_BOUNDS);
                if (covered) {
                    ASSERT_TRUE(kept) << "triangle " << i << " tile " << tx << "," << ty;
                }
                dropped += kept ? 0 : 1;
            }
    }
    EXPECT_GT(dropped, 1000u);  // the diagonal half of the bbox tiles of a big triangle
}

// Pieces cut a big triangle's bbox tiles into runs that cover each tile exactly once, TILES_PER_PIECE
// long until there would be more than MAX_PIECES of them.
TEST(SharedMath, PiecesCoverEveryTileOnce)
{
    for (uint tiles : {1u, 9u, 16u, 17u, 1000u, 16384u, 16385u, 32400u, 4194304u}) {
        uint n = pieceCount(tiles), len = pieceTiles(tiles);
        EXPECT_LE(n, uint(MAX_PIECES)) << tiles;
        EXPECT_GE(uint64_t(n) * len, tiles) << tiles;      // the last piece ends at or past the end...
        EXPECT_LT(uint64_t(n - 1) * len, tiles) << tiles;  // ...and every piece starts inside
        if (uint64_t(tiles) <= uint64_t(TILES_PER_PIECE) * MAX_PIECES) {
            EXPECT_EQ(len, uint(TILES_PER_PIECE)) << tiles;
        }
    }
}

}  // namespace sr

namespace sr::test {
namespace {

// setupTriangle repeats setupSnappedTriangle's body (for NVIDIA's Vulkan compiler, setup.h): the two must
// give the same record for the snapped corners, or the same refusal.
TEST(SharedMath, SetupTriangleEqualsSetupOfTheSnappedCorners)
{
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> coord(-1.3f, 1.3f), w(0.5f, 2.0f), z(-0.1f, 1.1f);
    int agreed = 0;
    for (int i = 0; i < 2000; ++i) {
        vec4 c[3];
        ivec2 v[3];
        float depth[3];
        bool snapped = true;
        for (int k = 0; k < 3; ++k) {
            float wk = w(rng);
            c[k] = vec4(coord(rng) * wk, coord(rng) * wk, z(rng) * wk, wk);
            snapped = snapVertex(c[k], 64, 48, v[k], depth[k]) && snapped;
        }
        ASSERT_TRUE(snapped);
        uint cull = uint(i % 3);
        TriSetup a{}, b{};
        bool okA = setupTriangle(c[0], c[1], c[2], 7u, false, cull, 64, 48, PIXEL_CENTER_BOUNDS, a);
        bool okB = setupSnappedTriangle(v[0], v[1], v[2], depth[0], depth[1], depth[2], 7u, false, cull, 64,
                                        48, PIXEL_CENTER_BOUNDS, b);
        ASSERT_EQ(okA, okB) << i;
        if (!okA) continue;
        ++agreed;
        EXPECT_EQ(a.xy01, b.xy01);
        EXPECT_EQ(a.xy2Id, b.xy2Id);
        EXPECT_EQ(a.depthPlane, b.depthPlane);
    }
    EXPECT_GT(agreed, 500);
}

// The statistics' shards (COUNTER_SHARD_WORD): each copy of a counter lies past the list counters' words,
// inside BUF_COUNTERS, in a 128-byte line of its own shard (the point of the shards: adds to different
// shards never share a cache line), and the shard index wraps modulo COUNTER_SHARDS. foldCounters adds
// every copy to its counter, checked against sums taken by byte offset.
TEST(SharedMath, CounterShardsAreCacheLinesApartAndFoldIntoTheirCounters)
{
    std::vector<uint> seen(COUNTER_WORDS, 0u);
    for (uint shard = 0u; shard < uint(COUNTER_SHARDS); ++shard) {
        for (uint c = 0u; c < uint(COUNTER_COUNT); ++c) {
            const uint word = COUNTER_SHARD_WORD(shard, c);
            ASSERT_GE(word, uint(COUNTER_COUNT));
            ASSERT_LT(word, uint(COUNTER_WORDS));
            EXPECT_EQ(word * 4u / 128u, 1u + shard) << "shard " << shard << " counter " << c;
            EXPECT_EQ(COUNTER_SHARD_WORD(shard + uint(COUNTER_SHARDS) * 7u, c), word);
            ++seen[word];
        }
    }
    for (uint w = 0u; w < uint(COUNTER_WORDS); ++w) ASSERT_LE(seen[w], 1u) << "word " << w;

    std::vector<uint> words(COUNTER_WORDS);
    std::mt19937 rng(46);
    for (uint& w : words) w = rng() & 0xFFFFu;
    std::vector<uint> folded(COUNTER_COUNT, 0u);
    foldCounters(words.data(), folded.data());
    for (uint c = 0u; c < uint(COUNTER_COUNT); ++c) {
        uint expected = words[c];
        for (uint shard = 0u; shard < uint(COUNTER_SHARDS); ++shard)
            expected += words[(128u + 128u * shard + 4u * c) / 4u];
        EXPECT_EQ(folded[c], expected) << "counter " << c;
    }
}

}  // namespace
}  // namespace sr::test
