// msaa_test.cpp - multisample and supersample anti-aliasing of the compute pipeline on each backend,
// against independent expectations: the Vulkan spec's table of standard sample locations, an exact
// point-in-triangle test per sample in double precision, the coverage-weighted mix of flat colours,
// per-sample watertightness of closed meshes, and SSAA as the box filter of a larger render. The
// conformant rasterizer's own samples are compared in msaa_oracle_test.cpp.
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <random>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/image_io.h"
#include "render/aov.h"
#include "test_util.h"

namespace sr::test {
namespace {

// Vulkan's standard sample locations as the spec tabulates them ("Standard sample locations"), in
// pixels from the top-left corner, sample 0 first.
const std::vector<std::vector<glm::dvec2>>& specTable()
{
    static const std::vector<std::vector<glm::dvec2>> table = {
        {{0.5, 0.5}},
        {{0.75, 0.75}, {0.25, 0.25}},
        {{0.375, 0.125}, {0.875, 0.375}, {0.125, 0.625}, {0.625, 0.875}},
        {{0.5625, 0.3125},
         {0.4375, 0.6875},
         {0.8125, 0.5625},
         {0.3125, 0.1875},
         {0.1875, 0.8125},
         {0.0625, 0.4375},
         {0.6875, 0.9375},
         {0.9375, 0.0625}},
        {{0.5625, 0.5625},
         {0.4375, 0.3125},
         {0.3125, 0.625},
         {0.75, 0.4375},
         {0.1875, 0.375},
         {0.625, 0.8125},
         {0.8125, 0.6875},
         {0.6875, 0.1875},
         {0.375, 0.875},
         {0.5, 0.0625},
         {0.25, 0.125},
         {0.125, 0.75},
         {0.0, 0.5},
         {0.9375, 0.25},
         {0.875, 0.9375},
         {0.0625, 0.0}},
    };
    return table;
}

const std::vector<glm::dvec2>& specPattern(uint32_t count)
{
    return specTable()[size_t(std::log2(double(count)))];
}

TEST(MsaaPattern, StandardSampleLocationsAreTheSpecTable)
{
    for (uint32_t count : {1u, 2u, 4u, 8u, 16u}) {
        const std::vector<glm::dvec2>& spec = specPattern(count);
        ASSERT_EQ(spec.size(), count);
        for (uint32_t s = 0; s < count; ++s) {
            ivec2 o = standardSample(count, s);
            EXPECT_EQ(o.x / 16.0, spec[s].x) << count << "x sample " << s;
            EXPECT_EQ(o.y / 16.0, spec[s].y) << count << "x sample " << s;
        }
    }
}

TEST(MsaaPattern, SampleBoundsAreThePatternsExtent)
{
    EXPECT_EQ(sampleBoundsOf(1), PIXEL_CENTER_BOUNDS);
    for (uint32_t count : {2u, 4u, 8u, 16u}) {
        double lo[2] = {1, 1}, hi[2] = {0, 0};
        for (glm::dvec2 p : specPattern(count))
            for (int a = 0; a < 2; ++a) {
                lo[a] = std::min(lo[a], p[a]);
                hi[a] = std::max(hi[a], p[a]);
            }
        uint32_t b = sampleBoundsOf(count);
        EXPECT_EQ(b & 255u, uint32_t(lo[0] * 256)) << count;
        EXPECT_EQ((b >> 8) & 255u, uint32_t(lo[1] * 256)) << count;
        EXPECT_EQ((b >> 16) & 255u, uint32_t(hi[0] * 256)) << count;
        EXPECT_EQ(b >> 24, uint32_t(hi[1] * 256)) << count;
    }
}

TEST(MsaaPattern, SampleWeightIsTheReciprocal)
{
    for (uint32_t count = 1; count <= 1024; ++count) {
        if ((count & (count - 1)) == 0)
            EXPECT_EQ(sampleWeight(count), 1.0f / float(count)) << count;  // exact for powers of two
        else
            EXPECT_NEAR(sampleWeight(count), 1.0 / count, std::ldexp(1.0, -23) / count) << count;  // < 1 ulp
    }
}

class MsaaTest : public BackendTest {};

// Window position (x, y) in pixels of a size x size viewport (a power of two, so the conversion to NDC
// is exact), at depth z, as a clip-space vertex with w = 1.
glm::vec4 win(uint32_t size, double x, double y, float z)
{
    return {float(x * 2.0 / size - 1.0), float(y * 2.0 / size - 1.0), z, 1};
}

double onGrid(double v)
{
    return std::round(v * 256.0) / 256.0;
}

RenderSettings msaaSettings(uint32_t size, uint32_t msaa, uint32_t ssaa = 1)
{
    RenderSettings s = testSettings(size, size);
    s.msaa = msaa;
    s.ssaa = ssaa;
    s.aovSamples = true;
    return s;
}

// Sample s of pixel (px, py) in window coordinates of the raster grid.
glm::dvec2 samplePoint(uint32_t count, uint32_t s, uint32_t px, uint32_t py)
{
    return glm::dvec2(px, py) + specPattern(count)[s];
}

// A triangle a 1/32 pixel around each sample location of a pixel of its own: every triangle covers its
// sample and no other, which names the sample each backend stores under each index.
TEST_P(MsaaTest, TinyTrianglesProbeEveryStandardLocation)
{
    const uint32_t size = 32;
    for (uint32_t count : {2u, 4u, 8u, 16u}) {
        std::vector<glm::vec4> corners;
        for (uint32_t s = 0; s < count; ++s) {
            glm::dvec2 c = samplePoint(count, s, 4 + s, 9);
            const double d = 1.0 / 32.0;
            for (glm::dvec2 p : {c + glm::dvec2(-d, -d), c + glm::dvec2(d, -d), c + glm::dvec2(0, d)})
                corners.push_back(win(size, p.x, p.y, 0.5f));
        }
        RenderOutput out = render(clipSpaceScene(corners), msaaSettings(size, count));
        ASSERT_EQ(out.samples.samples, count);
        ASSERT_EQ(out.samples.id.size(), size_t(size) * size * count);
        for (uint32_t k = 0; k < count; ++k)
            for (uint32_t p = 0; p < size * size; ++p) {
                // Triangle s covers sample s of pixel (4 + s, 9) and nothing else.
                uint32_t expected =
                    p >= 9 * size + 4 && p < 9 * size + 4 + count && p - 9 * size - 4 == k ? k : EMPTY_ID;
                ASSERT_EQ(out.samples.id[size_t(k) * size * size + p], expected)
                    << count << "x: sample " << k << " of pixel " << p % size << "," << p / size;
            }
    }
}

struct WindowTriangle {
    glm::dvec2 v[3];
    float z;
};

// Twice the signed area of (a, b, p): exact in double for coordinates on the 1/256 grid below 2^10.
double cross2(glm::dvec2 a, glm::dvec2 b, glm::dvec2 p)
{
    return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

// Random triangles of every size from a pixel to most of the viewport (both the setup path and the
// tiled path), vertices on the 1/256 grid, each at its own depth. Every sample must show the nearest
// triangle that contains it, by an exact point-in-triangle test; a sample exactly on an edge (where
// only the fill rule decides, checked against the conformant rasterizer elsewhere) is left out.
TEST_P(MsaaTest, EverySampleShowsTheNearestTriangleContainingIt)
{
    const uint32_t size = 64;
    std::mt19937 rng(23);
    std::vector<WindowTriangle> tris;
    std::vector<glm::vec4> corners;
    for (int t = 0; t < 40; ++t) {
        double extent = std::ldexp(1.0, t % 6);  // 1 .. 32 px
        std::uniform_real_distribution<double> pos(-2.0, size - extent + 2.0), unit(0.0, 1.0);
        double x = pos(rng), y = pos(rng);
        WindowTriangle w;
        w.z = 0.9f - 0.02f * float(t);  // later triangles are nearer
        for (glm::dvec2& v : w.v) {
            v = {onGrid(x + unit(rng) * extent * 1.8), onGrid(y + unit(rng) * extent * 1.8)};
            corners.push_back(win(size, v.x, v.y, w.z));
        }
        tris.push_back(w);
    }
    Scene scene = clipSpaceScene(corners);
    for (uint32_t count : {1u, 2u, 4u, 8u, 16u}) {
        RenderOutput out = render(scene, msaaSettings(size, count));
        ASSERT_EQ(out.samples.id.size(), size_t(size) * size * count);
        size_t onEdge = 0, covered = 0;
        for (uint32_t s = 0; s < count; ++s)
            for (uint32_t py = 0; py < size; ++py)
                for (uint32_t px = 0; px < size; ++px) {
                    glm::dvec2 p = samplePoint(count, s, px, py);
                    uint32_t expected = EMPTY_ID;
                    bool ambiguous = false;
                    for (uint32_t t = 0; t < tris.size(); ++t) {
                        const WindowTriangle& w = tris[t];
                        double e0 = cross2(w.v[1], w.v[2], p), e1 = cross2(w.v[2], w.v[0], p),
                               e2 = cross2(w.v[0], w.v[1], p);
                        bool inside = (e0 > 0 && e1 > 0 && e2 > 0) || (e0 < 0 && e1 < 0 && e2 < 0);
                        bool edge = !inside && (e0 == 0 || e1 == 0 || e2 == 0) &&
                                    ((e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0));
                        if (edge) ambiguous = true;
                        if (inside) expected = t;  // the last one containing it is the nearest
                        if (inside) ambiguous = false;
                    }
                    size_t i = size_t(s) * size * size + size_t(py) * size + px;
                    if (ambiguous) {
                        ++onEdge;
                        continue;
                    }
                    covered += expected != EMPTY_ID;
                    ASSERT_EQ(out.samples.id[i], expected)
                        << count << "x sample " << s << " of pixel " << px << "," << py;
                    if (expected != EMPTY_ID) {
                        ASSERT_EQ(out.samples.depth[i], tris[expected].z);
                    }
                }
        EXPECT_GT(covered, size_t(size) * size * count / 4) << count;
        EXPECT_LT(onEdge, size_t(size) * size * count / 50) << count;
        // The AOV's id is sample 0.
        for (size_t p = 0; p < size_t(size) * size; ++p) ASSERT_EQ(out.aov.id[p], out.samples.id[p]);
    }
}

// The resolve: each pixel's colour is the mean, in linear space, of its samples' colours. With the id
// view every triangle is one flat colour, so the expected pixel follows from the samples alone.
TEST_P(MsaaTest, ResolveIsTheLinearMeanOfTheSamples)
{
    const uint32_t size = 32;
    std::vector<glm::vec4> corners;
    for (glm::dvec2 p : {glm::dvec2(1.3, 2.1), glm::dvec2(30.7, 9.4), glm::dvec2(6.2, 29.8),
                         glm::dvec2(31.0, 31.0), glm::dvec2(2.0, 30.2), glm::dvec2(29.5, 4.0)})
        corners.push_back(win(size, onGrid(p.x), onGrid(p.y), 0.5f));
    corners[3].z = corners[4].z = corners[5].z = 0.25f;
    for (auto [msaa, ssaa] : {std::pair{4u, 1u}, {8u, 1u}, {2u, 2u}, {1u, 3u}}) {
        RenderSettings s = msaaSettings(size, msaa, ssaa);
        s.shadingMode = SHADING_PRIMITIVE_ID;
        s.background = {0.2f, 0.4f, 0.05f};
        RenderOutput out = render(clipSpaceScene(corners), s);
        const SampleAovs& all = out.samples;
        ASSERT_EQ(all.rasterWidth, size * ssaa);
        size_t mixed = 0;
        for (uint32_t y = 0; y < size; ++y)
            for (uint32_t x = 0; x < size; ++x) {
                glm::dvec3 sum(0.0);
                std::array<bool, 2> seen = {false, false};
                for (uint32_t j = 0; j < ssaa; ++j)
                    for (uint32_t i = 0; i < ssaa; ++i)
                        for (uint32_t k = 0; k < msaa; ++k) {
                            uint32_t id = all.id[size_t(k) * all.rasterWidth * all.rasterHeight +
                                                 size_t(y * ssaa + j) * all.rasterWidth + x * ssaa + i];
                            glm::vec3 c = id == EMPTY_ID ? s.background : idColor(id);
                            seen[id == EMPTY_ID] = true;
                            sum += glm::dvec3(c);
                        }
                mixed += seen[0] && seen[1];
                glm::vec3 mean = glm::vec3(sum / double(ssaa * ssaa * msaa));
                uint32_t expected = packRgba8(mean), got = out.color.pixels[size_t(y) * size + x];
                for (int c = 0; c < 3; ++c)
                    ASSERT_LE(std::abs(int((expected >> (8 * c)) & 255u) - int((got >> (8 * c)) & 255u)), 1)
                        << msaa << "x, ssaa " << ssaa << " at " << x << "," << y;
            }
        EXPECT_GT(mixed, size_t(20)) << "edges must produce partly covered pixels";
    }
}

// A closed mesh of jittered quads, split along alternating diagonals: every sample inside its outline
// is covered exactly once, at every sample count (no cracks, no double hits between samples either).
TEST_P(MsaaTest, ClosedMeshCoversEverySampleOnce)
{
    const uint32_t size = 64;
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> jitter(-2.2, 2.2);
    const int n = 8;
    const double step = 7.0, origin = 4.0;
    auto grid = jitteredGrid(n, origin, step, [&] { return onGrid(jitter(rng)); });
    // The mesh's cells are small triangles (setup's path); the same outline as two big triangles runs the
    // tiled path.
    std::vector<glm::vec4> corners = windowQuadMesh(grid, size, size, true);
    const double lo = origin, hi = origin + n * step;
    for (glm::dvec2 p : {glm::dvec2(lo, lo), glm::dvec2(hi, lo), glm::dvec2(hi, hi), glm::dvec2(lo, lo),
                         glm::dvec2(hi, hi), glm::dvec2(lo, hi)})
        corners.push_back(win(size, p.x, p.y, 0.5f));
    Scene mesh = clipSpaceScene(std::vector<glm::vec4>(corners.begin(), corners.end() - 6));
    Scene big = clipSpaceScene(std::vector<glm::vec4>(corners.end() - 6, corners.end()));
    for (const Scene* scene : {&mesh, &big})
        for (uint32_t count : {4u, 16u}) {
            RenderSettings s = msaaSettings(size, count);
            s.countHits = true;
            RenderOutput out = render(*scene, s);
            ASSERT_EQ(out.hitCount.size(), size_t(size) * size * count);
            for (uint32_t k = 0; k < count; ++k)
                for (uint32_t py = 0; py < size; ++py)
                    for (uint32_t px = 0; px < size; ++px) {
                        glm::dvec2 p = samplePoint(count, k, px, py);
                        bool inside = p.x > lo && p.x < hi && p.y > lo && p.y < hi;
                        bool outside = p.x < lo || p.x > hi || p.y < lo || p.y > hi;
                        uint32_t hits = out.hitCount[size_t(k) * size * size + size_t(py) * size + px];
                        uint32_t expected = inside ? 1u : 0u;
                        if (inside || outside) {
                            ASSERT_EQ(hits, expected)
                                << count << "x sample " << k << " at " << px << "," << py;
                        }
                    }
        }
}

// The linear value of an sRGB-encoded channel value v / 255 (v may be fractional).
double srgbToLinear(double v)
{
    double c = std::clamp(v / 255.0, 0.0, 1.0);
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// SSAA N is the N x N box filter of a render at N times the resolution: the same raster grid, so the
// AOV's sample is that render's pixel, and the colour its block's linear mean. The larger render's PNG
// holds each pixel rounded to 8 bits, so the true linear value of a pixel c lies between the decodes of
// c - 1/2 and c + 1/2; the mean of the block lies between the means of those bounds, and the output,
// rounded once more, within half a step of their encodings.
TEST_P(MsaaTest, SsaaIsTheBoxFilterOfALargerRender)
{
    for (uint32_t n : {2u, 3u}) {
        const uint32_t w = 40, h = 30;
        FramedScene small = framedBuiltin(w, h);
        FramedScene large = framedBuiltin(w * n, h * n);
        small.settings.ssaa = n;
        RenderOutput a = render(small.scene, small.settings, small.camera);
        RenderOutput b = render(large.scene, large.settings, large.camera);
        ASSERT_EQ(a.color.width, w);
        ASSERT_EQ(b.color.width, w * n);
        size_t edges = 0;
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                size_t rep = size_t(y * n + n / 2) * w * n + x * n + n / 2;
                ASSERT_EQ(a.aov.id[size_t(y) * w + x], b.aov.id[rep]) << x << "," << y;
                ASSERT_EQ(a.aov.depth[size_t(y) * w + x], b.aov.depth[rep]) << x << "," << y;
                uint32_t got = a.color.pixels[size_t(y) * w + x];
                for (int c = 0; c < 3; ++c) {
                    double lo = 0.0, hi = 0.0;
                    int minV = 255, maxV = 0;
                    for (uint32_t j = 0; j < n; ++j)
                        for (uint32_t i = 0; i < n; ++i) {
                            int v = int((b.color.pixels[size_t(y * n + j) * w * n + x * n + i] >> (8 * c)) &
                                        255u);
                            lo += srgbToLinear(v - 0.5) / double(n * n);
                            hi += srgbToLinear(v + 0.5) / double(n * n);
                            minV = std::min(minV, v);
                            maxV = std::max(maxV, v);
                        }
                    edges += maxV - minV > 16;
                    int value = int((got >> (8 * c)) & 255u);
                    ASSERT_GE(value, int(std::floor(255.0 * linearToSrgb(float(lo)) - 0.5)))
                        << "ssaa " << n << " at " << x << "," << y;
                    ASSERT_LE(value, int(std::ceil(255.0 * linearToSrgb(float(hi)) + 0.5)))
                        << "ssaa " << n << " at " << x << "," << y;
                }
            }
        EXPECT_GT(edges, size_t(50)) << "the scene has edges to filter";
    }
}

// Memory follows the request: one 8-byte key per sample, and no per-sample buffer at all at 1x.
TEST_P(MsaaTest, VisibilityMemoryScalesWithTheSampleCount)
{
    const uint32_t size = 32;
    Scene scene = clipSpaceScene({win(size, 1, 1, 0.5f), win(size, 30, 2, 0.5f), win(size, 9, 31, 0.5f)});
    for (uint32_t count : {1u, 2u, 4u, 8u, 16u})
        for (uint32_t ssaa : {1u, 2u}) {
            RenderSettings s = msaaSettings(size, count, ssaa);
            s.aovSamples = false;
            render(scene, s);
            EXPECT_EQ(device_->size(BUF_VISIBILITY), size_t(size) * size * ssaa * ssaa * count * 8);
            // Output pixels alone, whatever the samples: the colour, then stage aovs's id and depth.
            EXPECT_EQ(device_->size(BUF_FRAMEBUFFER), size_t(size) * size * 4 * 3);
            EXPECT_LE(device_->size(BUF_HIT_COUNT), size_t(16));
        }
}

INSTANTIATE_TEST_SUITE_P(Backends, MsaaTest, ::testing::Values("vulkan", "cuda"),
                         [](const auto& info) { return info.param; });

TEST(MsaaCommandLine, RejectsBadRequestsWithOneLine)
{
    for (const char* args : {"--msaa 3", "--msaa 32", "--ssaa 0", "--ssaa 9", "--aov-samples",
                             "--width 4096 --ssaa 8", "--ssaa 8 --msaa 4 --aov x.exr --aov-samples"}) {
        ToolRun run = runTool(std::string("render --backend vulkan -q -o never-written.png ") + args);
        EXPECT_EQ(run.exitCode, 2) << args;
        EXPECT_EQ(std::count(run.stderrText.begin(), run.stderrText.end(), '\n'), 1)
            << args << run.stderrText;
    }
}

// `raster render` makes anti-aliased pictures unless told otherwise (kImageMsaa, docs/cli.md), and says so in
// its statistics; `--msaa 1` is the exact one-sample path the tests and goldens use.
TEST(MsaaCommandLine, RenderDefaultsToMsaa4)
{
    ScratchDir dir("msaa-default");
    auto render = [&](const std::string& name, const std::string& args) {
        ToolRun run = runTool("render builtin --backend vulkan -q --width 64 --height 48 -o " +
                              dir.file(name + ".png") + " --stats " + dir.file(name + ".json") + args);
        EXPECT_EQ(run.exitCode, 0) << run.stderrText;
        auto png = readPng(dir.file(name + ".png"));
        EXPECT_TRUE(png.ok()) << (png.ok() ? "" : png.error().message);
        return png.ok() ? png->pixels : std::vector<uint32_t>{};
    };
    const std::vector<uint32_t> byDefault = render("default", "");
    const std::vector<uint32_t> msaa4 = render("msaa4", " --msaa 4");
    const std::vector<uint32_t> msaa1 = render("msaa1", " --msaa 1");
    ASSERT_EQ(byDefault.size(), size_t(64) * 48);
    EXPECT_EQ(byDefault, msaa4);
    // Edge pixels blend: the one-sample image differs from the default along every silhouette.
    size_t differing = 0;
    for (size_t i = 0; i < msaa1.size() && i < byDefault.size(); ++i) differing += msaa1[i] != byDefault[i];
    EXPECT_GT(differing, 50u);
    std::ifstream statsFile(dir.file("default.json"));
    ASSERT_TRUE(statsFile) << "no statistics written";
    const nlohmann::json stats = nlohmann::json::parse(statsFile);
    EXPECT_EQ(stats["settings"]["msaa"], 4) << stats.dump();
}

TEST(MsaaCommandLine, AovSamplesWritesEverySampleOfThePixel)
{
    ScratchDir dir("msaa");
    ToolRun run = runTool("render --backend vulkan -q --width 48 --height 32 --msaa 4 --ssaa 2 -o " +
                          dir.file("a.png") + " --aov " + dir.file("a.exr") + " --aov-samples");
    ASSERT_EQ(run.exitCode, 0) << run.stderrText;
    auto aov = readAovExr(dir.file("a.exr"));
    ASSERT_TRUE(aov.ok()) << aov.error().message;
    ASSERT_EQ(aov->sampleId.size(), 16u);
    // Channel k = (j * ssaa + i) * msaa + s; the id AOV is sample 0 of raster pixel (1, 1): k = 12.
    EXPECT_EQ(aov->sampleId[12], aov->id);
    EXPECT_EQ(aov->sampleDepth[12], aov->depth);
    size_t differing = 0;
    for (size_t p = 0; p < aov->id.size(); ++p)
        for (size_t k = 0; k < 16; ++k) differing += aov->sampleId[k][p] != aov->id[p];
    EXPECT_GT(differing, 0u) << "edge pixels hold several triangles";
}

}  // namespace
}  // namespace sr::test
