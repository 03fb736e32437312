// msaa_oracle_test.cpp - the compute pipeline's samples against a conformant rasterizer: the same scenes
// through the real Vulkan graphics pipeline (`vulkan-graphics`) with the same sample count, at every
// count the device offers (lavapipe: 4x; an NVIDIA GPU: 2x, 4x, 8x), read back sample by sample.
//
// Criteria, per sample, as the one-sample oracle (oracle_test.cpp) per pixel: scenes whose vertices sit
// on the 1/256-pixel grid and need no clipping must give identical triangle ids at every sample and
// identical depth; projected scenes (w != 1) may differ in at most kProjectedBound samples, where one
// pipeline's float arithmetic rounds a vertex to the neighbouring subpixel, and depth by at most
// kProjectedDepthBound. The resolved colour must be within 2/255 wherever both pipelines see the same
// triangles in every sample of the pixel (the shading is the same function, evaluated at the pixel
// centre by both).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "test_util.h"
#include "vulkan/vulkan_graphics.h"

namespace sr::test {
namespace {

constexpr uint32_t kSize = 64;          // power of two: window <-> NDC conversions are exact
constexpr size_t kProjectedBound = 64;  // differing samples allowed in projected scenes
// Depth difference allowed in projected scenes: lavapipe interpolates depth from the unsnapped vertices
// (docs/rasterization-rules.md, section 3). Measured on the built-in scene at 64x48: 1.1e-4 at
// the pixel centres (1x), 4.4e-4 at the 4x samples, which reach further along the steep ground plane.
constexpr double kProjectedDepthBound = 1e-3;

struct SampleAgreement {
    bool offered = false;  // the device renders this sample count through its graphics pipeline
    size_t samples = 0, covered = 0, differingIds = 0;
    double maxDepthDiff = 0.0;  // where ids agree
    int maxColorDiff = 0;       // 8-bit, over pixels whose samples all agree
    size_t comparedPixels = 0;  // such pixels
    size_t partlyCovered = 0;   // of them, pixels with covered and empty samples (edges)
};

class MsaaOracleTest : public ComputeOracleTest {
protected:
    SampleAgreement agree(const Scene& scene, RenderSettings s, const CameraMatrices& camera)
    {
        s.aovSamples = true;
        SampleAgreement a;
        auto oracle = renderVulkanGraphics(scene, camera, s, -1);
        if (!oracle.ok() && oracle.error().message.find("does not offer") != std::string::npos) return a;
        auto ours = renderScene(*compute_, scene, camera, s);
        EXPECT_TRUE(ours.ok()) << (ours.ok() ? "" : ours.error().message);
        EXPECT_TRUE(oracle.ok()) << (oracle.ok() ? "" : oracle.error().message);
        if (!ours.ok() || !oracle.ok()) return a;
        a.offered = true;
        const SampleAovs& x = ours->samples;
        const SampleAovs& y = oracle->samples;
        EXPECT_EQ(x.id.size(), y.id.size());
        if (x.id.size() != y.id.size()) return a;
        a.samples = x.id.size();
        for (size_t i = 0; i < x.id.size(); ++i) {
            a.covered += x.id[i] != EMPTY_ID;
            if (x.id[i] != y.id[i]) {
                ++a.differingIds;
                continue;
            }
            if (x.id[i] != EMPTY_ID)
                a.maxDepthDiff = std::max(a.maxDepthDiff, std::abs(double(x.depth[i]) - y.depth[i]));
        }
        // Colour where every sample of the output pixel shows the same triangle in both.
        const uint64_t plane = uint64_t(x.rasterWidth) * x.rasterHeight;
        for (uint32_t py = 0; py < s.height; ++py)
            for (uint32_t px = 0; px < s.width; ++px) {
                bool same = true, empty = false, full = false;
                for (uint32_t j = 0; j < s.ssaa; ++j)
                    for (uint32_t i = 0; i < s.ssaa; ++i)
                        for (uint32_t k = 0; k < s.msaa; ++k) {
                            uint64_t at =
                                k * plane + uint64_t(py * s.ssaa + j) * x.rasterWidth + px * s.ssaa + i;
                            same = same && x.id[at] == y.id[at];
                            (x.id[at] == EMPTY_ID ? empty : full) = true;
                        }
                if (!same) continue;
                ++a.comparedPixels;
                a.partlyCovered += empty && full;
                uint32_t c0 = ours->color.pixels[size_t(py) * s.width + px];
                uint32_t c1 = oracle->color.pixels[size_t(py) * s.width + px];
                for (int c = 0; c < 3; ++c)
                    a.maxColorDiff = std::max(
                        a.maxColorDiff, std::abs(int((c0 >> (8 * c)) & 255u) - int((c1 >> (8 * c)) & 255u)));
            }
        std::printf(
            "msaa oracle %s, %ux MSAA, SSAA %u: %zu differing ids of %zu samples (%zu covered), max "
            "depth diff %g, max colour diff %d over %zu pixels (%zu at edges)\n",
            ::testing::UnitTest::GetInstance()->current_test_info()->name(), s.msaa, s.ssaa, a.differingIds,
            a.samples, a.covered, a.maxDepthDiff, a.maxColorDiff, a.comparedPixels, a.partlyCovered);
        return a;
    }

    // Runs `check` at every sample count the device offers through its graphics pipeline; at least one
    // besides 1x must be offered (every conformant implementation offers 4x).
    template <typename Check>
    void forOfferedCounts(const Scene& scene, RenderSettings s, const CameraMatrices& camera, Check check)
    {
        std::vector<uint32_t> offered;
        for (uint32_t count : {2u, 4u, 8u, 16u}) {
            s.msaa = count;
            SampleAgreement a = agree(scene, s, camera);
            if (!a.offered) continue;
            offered.push_back(count);
            check(a, count);
        }
        EXPECT_FALSE(offered.empty()) << "the device offers no multisample count";
        EXPECT_TRUE(std::find(offered.begin(), offered.end(), 4u) != offered.end()) << "4x is required";
    }
};

glm::vec4 win(double x, double y, float z)
{
    return {float(x * 2.0 / kSize - 1.0), float(y * 2.0 / kSize - 1.0), z, 1};
}

double onGrid(double v, double step = 1.0 / 256.0)
{
    return std::round(v / step) * step;
}

// Triangles from a pixel to most of the image with random vertices on the 1/256 grid, each at its own
// constant depth, inside the viewport (lavapipe clips to the viewport in float, which would make them
// clipped): every sample must agree.
TEST_F(MsaaOracleTest, GridSnappedTrianglesAgreeAtEverySample)
{
    std::mt19937 rng(31);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<glm::vec4> corners;
    for (int t = 0; t < 60; ++t) {
        double size = std::ldexp(1.0, t % 6);
        std::uniform_real_distribution<double> pos(0.0, kSize - size);
        double x = pos(rng), y = pos(rng);
        float z = 0.02f + 0.015f * float(t);
        for (int c = 0; c < 3; ++c)
            corners.push_back(win(onGrid(x + unit(rng) * size), onGrid(y + unit(rng) * size), z));
    }
    Scene scene = clipSpaceScene(corners);
    RenderSettings s = testSettings(kSize, kSize);
    s.shadingMode = SHADING_PRIMITIVE_ID;
    forOfferedCounts(scene, s, identityCamera(), [](const SampleAgreement& a, uint32_t count) {
        EXPECT_EQ(a.differingIds, 0u) << count << "x";
        EXPECT_EQ(a.maxDepthDiff, 0.0) << count << "x";
        EXPECT_GT(a.covered, a.samples / 8) << count << "x";
        EXPECT_LE(a.maxColorDiff, 2) << count << "x";
        EXPECT_GT(a.partlyCovered, 50u) << count << "x";
    });
}

// Vertices on the 1/16-pixel lattice that holds every standard sample location: edges run through
// samples everywhere, so the top-left rule decides per sample. A jittered mesh along alternating
// diagonals must agree at every sample.
TEST_F(MsaaOracleTest, EdgesThroughSampleLocationsFollowTheFillRule)
{
    std::mt19937 rng(3);
    std::uniform_int_distribution<int> jitter(-20, 20);  // sixteenths of a pixel
    const int n = 7;
    const double step = 8.0, origin = 4.0;
    auto grid = jitteredGrid(n, origin, step, [&] { return jitter(rng) / 16.0; });
    std::vector<glm::vec4> corners = windowQuadMesh(grid, kSize, kSize, true);
    RenderSettings s = testSettings(kSize, kSize);
    s.shadingMode = SHADING_PRIMITIVE_ID;
    forOfferedCounts(clipSpaceScene(corners), s, identityCamera(),
                     [](const SampleAgreement& a, uint32_t count) {
                         EXPECT_EQ(a.differingIds, 0u) << count << "x";
                         EXPECT_EQ(a.maxDepthDiff, 0.0) << count << "x";
                         EXPECT_LE(a.maxColorDiff, 2) << count << "x";
                     });
}

// The built-in scene under a perspective camera (projected vertices, smooth shading, several
// materials), alone and with 2x2 supersampling on top.
TEST_F(MsaaOracleTest, ProjectedSceneAgreesWithinTheBound)
{
    for (uint32_t ssaa : {1u, 2u}) {
        FramedScene f = framedBuiltin(kSize, kSize * 3 / 4);
        f.settings.ssaa = ssaa;
        forOfferedCounts(f.scene, f.settings, f.camera, [&](const SampleAgreement& a, uint32_t count) {
            EXPECT_LE(a.differingIds, kProjectedBound) << count << "x, ssaa " << ssaa;
            EXPECT_LE(a.maxDepthDiff, kProjectedDepthBound) << count << "x, ssaa " << ssaa;
            EXPECT_LE(a.maxColorDiff, 2) << count << "x, ssaa " << ssaa;
            EXPECT_GT(a.partlyCovered, 20u) << count << "x, ssaa " << ssaa;
        });
    }
}

}  // namespace
}  // namespace sr::test
