// study_stress_test.cpp - the stress cases of `raster study` (host/study/stress.h) on each backend: the
// claims the study makes for today's fixed-point rasterizer (vertices snapped to 1/256 px, exact int64
// edge functions, the top-left rule, a guard band of 16384 px), and the failure counter itself on
// hand-made outputs.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "study/stress.h"
#include "test_util.h"

namespace sr::test {
namespace {

// 64 x 64 keeps the whole file to a few seconds on lavapipe; the 10^5-sliver fan is the slowest case.
constexpr uint32_t kSize = 64;

size_t countDemand(const StressCase& c, PixelDemand d)
{
    size_t n = 0;
    for (PixelDemand p : c.demand) n += p == d;
    return n;
}

// A case rendered on the backend with its failures, printed so that a run shows the measured counts.
class StudyStressTest : public BackendTest {
protected:
    StressFailures measure(const StressCase& c)
    {
        RenderOutput out = render(c.scene, c.settings, c.camera);
        EXPECT_EQ(out.hitCount.size(), c.demand.size()) << c.axis << " x=" << c.x;
        StressFailures f = countFailures(c, out);
        std::printf(
            "[ stress   ] %s method %u %s x=%g: cracks %llu, double hits %llu, wrong depth order %llu\n",
            GetParam().c_str(), c.settings.rasterMethod, c.axis.c_str(), c.x, (unsigned long long)f.cracks,
            (unsigned long long)f.doubleHits, (unsigned long long)f.wrongDepthOrder);
        return f;
    }

    // Every case of the axis draws each covered pixel centre exactly once and nothing outside, with
    // raster method `method`.
    void expectWatertight(const std::string& axis, size_t cases, uint32_t method = RASTER_FIXED8)
    {
        std::vector<StressCase> all = stressCases(axis, kSize);
        ASSERT_EQ(all.size(), cases);
        for (StressCase& c : all) {
            ASSERT_EQ(c.demand.size(), size_t(kSize) * kSize);
            EXPECT_GT(countDemand(c, PixelDemand::kCoverOnce) + countDemand(c, PixelDemand::kEmpty), 0u);
            c.settings.rasterMethod = method;
            StressFailures f = measure(c);
            EXPECT_EQ(f.cracks, 0u) << axis << " x=" << c.x << " method " << method;
            EXPECT_EQ(f.doubleHits, 0u) << axis << " x=" << c.x << " method " << method;
        }
    }
};

// Vertices 2^k px from the viewport, k = 0..14: int64 edge functions of snapped coordinates are exact up
// to the guard band (products below 2^48), so magnitude alone can neither crack nor double a shared edge.
TEST_P(StudyStressTest, MagnitudeUpToTheGuardBandIsWatertight)
{
    expectWatertight("magnitude", 15);
}

// Slivers with rim steps down to 1/620 px (at 10^5, about half snap to zero area and draw nothing): exactness
// does not depend on the shape, and the top-left rule gives a pixel centre on a shared edge or on the
// shared hub to exactly one triangle. The 10^5 fan's screen tiles at the hub hold 6,000-47,000 bin
// entries each: on a CPU device raster_tiles resolves them in chunks (RASTER_CPU_CHUNK), since llvmpipe
// ends every loop of an invocation after 65,535 iterations in all; walked whole, 98 pixel centres near
// the hub stayed empty.
TEST_P(StudyStressTest, SliverFansAreWatertight)
{
    expectWatertight("slivers", 5);
}

// Vertices at clip w = 1 .. 10^-6: the guard-band clipper cuts each shared edge from its nearer endpoint
// whichever triangle it belongs to, so the two sides of the edge get the same cut vertex.
TEST_P(StudyStressTest, NearPlaneProximityIsWatertight)
{
    expectWatertight("near", 7);
}

// Two surfaces at window depths z = 0.75 and z + d, the farther drawn first. A flat triangle's depth is
// its vertices' float z exactly (zero depth slopes), so the order survives exactly while float(z + d) >
// float(z): for d = 2^-e that is e <= 24, since ulp(0.75) = 2^-24 and 0.75 + 2^-25 is a halfway case
// that rounds to the even 0.75. Below, the depths are equal floats and the visibility key's tie goes to
// the lowest id, the farther surface's: then every overlapped pixel shows it, a count that follows from
// the key's definition, not from rounding noise.
TEST_P(StudyStressTest, CoplanarSurfacesKeepTheirOrderDownToOneUlp)
{
    std::vector<StressCase> all = stressCases("coplanar", kSize);
    ASSERT_EQ(all.size(), 23u);
    const float z = 0.75f;
    for (const StressCase& c : all) {
        const size_t overlapped = countDemand(c, PixelDemand::kNearId);
        ASSERT_GT(overlapped, 0u);
        const bool separated = float(double(z) + c.x) > z;
        EXPECT_EQ(separated, c.x >= std::ldexp(1.0, -24)) << c.x;
        StressFailures f = measure(c);
        EXPECT_EQ(f.cracks, 0u) << c.x;
        EXPECT_EQ(f.doubleHits, 0u) << c.x;
        EXPECT_EQ(f.wrongDepthOrder, separated ? 0u : overlapped) << c.x;
    }
}

// fixed4 is fixed8's exact rule on a coarser grid: snapping moves vertices (by up to 1/32 px), never
// makes two triangles disagree about a shared edge, so every axis stays watertight.
TEST_P(StudyStressTest, Fixed4IsWatertight)
{
    expectWatertight("magnitude", 15, RASTER_FIXED4);
    expectWatertight("slivers", 5, RASTER_FIXED4);
    expectWatertight("near", 7, RASTER_FIXED4);
}

// scanline evaluates a shared edge in both of its triangles from the same operands (upper vertex, lower
// vertex, row), so both see the same x, and its half-open rows and spans hand a sample on the edge to
// exactly one. It fails only where rounding reorders two edges of different upper vertices on a row,
// which needs edges closer than a float ulp of their coordinates: about 2^-10 subpixels here (64 px
// viewport), while the 10^5-sliver fan's spokes lie 2 pi 25.6 px x 256 / 10^5 = 0.4 subpixels apart at
// one pixel from the hub. So none of these cases may fail.
TEST_P(StudyStressTest, ScanlineIsWatertight)
{
    expectWatertight("magnitude", 15, RASTER_SCANLINE);
    expectWatertight("slivers", 5, RASTER_SCANLINE);
    expectWatertight("near", 7, RASTER_SCANLINE);
}

// float counts a sample for every triangle whose barycentrics are all >= -eps (eps = FLOAT_EPSILON =
// 2^-16). Across a shared edge between triangles of heights hA, hB (from the edge), a sample at distance
// d from the edge is taken by both when d <= eps hA on B's side or d <= eps hB on A's side: a band of
// width eps (hA + hB) along every shared edge, so the expected number of double hits is that width times
// the shared edges' length in view (pixel centres are one per px^2). In the magnitude fan both heights
// are R sin(2 pi / 32), and the 32 spokes run from the viewport centre out of the viewport: about
// 32 x 36 px in view. Cracks would need the edge function's rounding to pass eps: its relative error is
// about 2^-23 |edge| |p - a| / (|edge| h) <= 2^-23 / sin(2 pi / 32) = 2^-20.6 < eps here.
TEST_P(StudyStressTest, FloatDoubleHitsFollowTheEpsilonBand)
{
    for (StressCase& c : stressCases("magnitude", kSize)) {
        c.settings.rasterMethod = RASTER_FLOAT;
        // The spokes' length inside the viewport, from the centre along each spoke's direction.
        double inView = 0.0;
        for (int i = 0; i < 32; ++i) {
            double angle = 0.1 + 2.0 * M_PI * i / 32;
            double reach =
                std::min(kSize / 2.0 / std::abs(std::cos(angle)), kSize / 2.0 / std::abs(std::sin(angle)));
            inView += std::min(reach, c.x);
        }
        const double band = double(FLOAT_EPSILON) * 2.0 * c.x * std::sin(2.0 * M_PI / 32);
        const double expected = band * inView;
        StressFailures f = measure(c);
        EXPECT_EQ(f.cracks, 0u) << c.x;
        if (expected < 0.5) {
            EXPECT_EQ(f.doubleHits, 0u) << c.x << " expected " << expected;
        } else if (expected >= 10.0) {
            EXPECT_GE(double(f.doubleHits), expected / 2.0) << c.x;
            EXPECT_LE(double(f.doubleHits), expected * 2.0) << c.x;
        }
    }
}

// With no tie rule, float double-hits every sample exactly on a shared edge, whatever eps: in the sliver
// fans the hub sits on a pixel centre (a vertex of all n triangles) and the spoke at angle 0 runs along
// the hub's pixel row, so the hub and every covered pixel centre on that spoke are hit at least twice.
TEST_P(StudyStressTest, FloatDoubleHitsEverySampleOnASharedEdge)
{
    for (StressCase& c : stressCases("slivers", kSize)) {
        c.settings.rasterMethod = RASTER_FLOAT;
        const uint32_t row = kSize / 2;
        uint64_t onSpoke = 0;
        for (uint32_t x = kSize / 2; x < kSize; ++x)
            onSpoke += c.demand[row * kSize + x] == PixelDemand::kCoverOnce;
        ASSERT_GT(onSpoke, 20u);
        StressFailures f = measure(c);
        EXPECT_EQ(f.cracks, 0u) << c.x;
        EXPECT_GE(f.doubleHits, onSpoke) << c.x;
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, StudyStressTest, ::testing::Values("vulkan", "cuda"),
                         [](const auto& info) { return info.param; });

// The cases are built from geometry alone: sizes, parameters and a few demands checked by hand.
TEST(StudyStressCases, ParametersAndDemands)
{
    std::vector<StressCase> magnitude = stressCases("magnitude", kSize);
    ASSERT_EQ(magnitude.size(), 15u);
    for (size_t k = 0; k < magnitude.size(); ++k) EXPECT_EQ(magnitude[k].x, std::ldexp(1.0, int(k)));
    // R = 1 px around the centre: the centre pixels' centres lie within a pixel of the outline, the
    // corner is empty; R = 2^14: every pixel is inside, far from the rim.
    EXPECT_EQ(countDemand(magnitude[0], PixelDemand::kCoverOnce), 0u);
    EXPECT_EQ(magnitude[0].demand[0], PixelDemand::kEmpty);
    EXPECT_EQ(countDemand(magnitude[14], PixelDemand::kCoverOnce), size_t(kSize) * kSize);
    for (const glm::vec4& p : magnitude[14].scene.positions) {
        EXPECT_LE(std::abs(p.x), 1.0f + 16384.0f / (kSize / 2)) << "inside the guard band";
        EXPECT_LE(std::abs(p.y), 1.0f + 16384.0f / (kSize / 2));
    }

    std::vector<StressCase> slivers = stressCases("slivers", kSize);
    ASSERT_EQ(slivers.size(), 5u);
    EXPECT_EQ(slivers[4].x, 1e5);
    EXPECT_EQ(slivers[4].scene.triangleCount(), 100000u);
    const size_t hub = (kSize / 2) * kSize + kSize / 2;  // the hub sits on this pixel's centre
    for (const StressCase& c : slivers) {
        EXPECT_EQ(c.demand[hub], PixelDemand::kCoverOnce);
        EXPECT_EQ(c.demand[0], PixelDemand::kEmpty);
    }

    // The near cases: top rows empty, bottom rows covered, the horizon rows free.
    for (const StressCase& c : stressCases("near", kSize)) {
        EXPECT_EQ(c.demand[0], PixelDemand::kEmpty) << c.x;
        EXPECT_EQ(c.demand[(kSize - 2) * kSize + 5], PixelDemand::kCoverOnce) << c.x;
        EXPECT_EQ(c.demand[(kSize / 2) * kSize + 5], PixelDemand::kFree) << c.x;
    }

    std::vector<StressCase> coplanar = stressCases("coplanar", kSize);
    EXPECT_EQ(coplanar.front().x, std::ldexp(1.0, -8));
    EXPECT_EQ(coplanar.back().x, std::ldexp(1.0, -30));
    EXPECT_EQ(coplanar.front().nearIdBegin, 32u);
    EXPECT_EQ(coplanar.front().nearIdEnd, 64u);
    EXPECT_TRUE(stressCases("unknown", kSize).empty());
}

// countFailures on hand-made 2 x 2 outputs: one failure of each kind where it is planted.
StressCase handMadeCase(std::vector<PixelDemand> demand)
{
    StressCase c;
    c.settings.width = 2;
    c.settings.height = 2;
    c.demand = std::move(demand);
    c.nearIdBegin = 4;
    c.nearIdEnd = 8;
    return c;
}

RenderOutput handMadeOutput(std::vector<uint32_t> ids, std::vector<uint32_t> hits)
{
    RenderOutput out;
    out.aov.width = 2;
    out.aov.height = 2;
    out.aov.id = std::move(ids);
    out.hitCount = std::move(hits);
    return out;
}

TEST(StudyStressFailures, CountsCracksDoubleHitsAndEmptyPixelsHit)
{
    using D = PixelDemand;
    StressCase c = handMadeCase({D::kCoverOnce, D::kCoverOnce, D::kEmpty, D::kFree});
    StressFailures clean = countFailures(c, handMadeOutput({0, 1, EMPTY_ID, 3}, {1, 1, 0, 5}));
    EXPECT_EQ(clean.total(), 0u);
    StressFailures crack = countFailures(c, handMadeOutput({EMPTY_ID, 1, EMPTY_ID, 3}, {0, 1, 0, 0}));
    EXPECT_EQ(crack.cracks, 1u);
    EXPECT_EQ(crack.total(), 1u);
    StressFailures twice = countFailures(c, handMadeOutput({0, 1, EMPTY_ID, 3}, {1, 2, 0, 0}));
    EXPECT_EQ(twice.doubleHits, 1u);
    EXPECT_EQ(twice.total(), 1u);
    StressFailures spill = countFailures(c, handMadeOutput({0, 1, 2, 3}, {1, 1, 1, 0}));
    EXPECT_EQ(spill.doubleHits, 1u);
    EXPECT_EQ(spill.total(), 1u);
    // A failed render (no pixels at all): every pixel that must be covered is a crack.
    StressFailures nothing = countFailures(c, RenderOutput{});
    EXPECT_EQ(nothing.cracks, 2u);
    EXPECT_EQ(nothing.total(), 2u);
}

TEST(StudyStressFailures, CountsWrongIdsOnNearPixels)
{
    using D = PixelDemand;
    StressCase c = handMadeCase({D::kNearId, D::kNearId, D::kNearId, D::kEmpty});
    // Ids 4..7 are the nearer surface's; 3 and 8 lie just outside the range, EMPTY_ID is a crack.
    StressFailures f = countFailures(c, handMadeOutput({4, 3, 8, EMPTY_ID}, {}));
    EXPECT_EQ(f.wrongDepthOrder, 2u);
    EXPECT_EQ(f.cracks, 0u);
    StressFailures hole = countFailures(c, handMadeOutput({7, EMPTY_ID, 5, EMPTY_ID}, {}));
    EXPECT_EQ(hole.cracks, 1u);
    EXPECT_EQ(hole.total(), 1u);
    // Without hit counts an empty pixel is read from its id.
    StressFailures spill = countFailures(c, handMadeOutput({7, 6, 5, 0}, {}));
    EXPECT_EQ(spill.doubleHits, 1u);
    EXPECT_EQ(spill.total(), 1u);
}

}  // namespace
}  // namespace sr::test
