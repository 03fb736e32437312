// cpu_build_test.cpp - the stages' CPU builds (compute_glsl/shade.comp's SHADE_CPU, SR_CPU_BUILD): a
// Vulkan device keeps one shade pipeline per frame variant (shading mode, scene features, texture filters,
// SSAA), so one session switching between them must draw what a fresh device draws for each; the texel
// views the CPU builds read through follow every buffer a session replaces; and `raster bench` reports
// whole shaded frames beside the graphics pipeline's. On a GPU device the same tests run
// the GPU builds, where the images must agree just the same.
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "test_util.h"

namespace sr::test {
namespace {

// Differing pixels between two renders of the same size.
long differingPixels(const RgbaImage& a, const RgbaImage& b)
{
    if (a.width != b.width || a.height != b.height) return -1;
    long n = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i) n += a.pixels[i] != b.pixels[i];
    return n;
}

class CpuBuildTest : public BackendTest {};

// Frame variants in an order that revisits earlier ones: each must be the image a fresh device draws,
// so no pipeline of another variant is ever reused for it.
TEST_P(CpuBuildTest, EveryFrameVariantDrawsWhatAFreshDeviceDraws)
{
    auto checker = builtinSceneNamed("builtin:checker");
    ASSERT_TRUE(checker.ok()) << checker.error().message;
    FramedScene framed = framedBuiltin(64, 48);
    auto camera = resolveCamera(*parseCameraSpec("orbit:0,30,2.5"), *checker, 64, 48);
    ASSERT_TRUE(camera.ok());
    struct Variant {
        const char* name;
        uint32_t shading, filter, msaa, ssaa, uv;
    };
    const Variant variants[] = {
        {"blinn-phong", SHADING_BLINN_PHONG, TEXTURE_FILTER_AUTO, 1, 1, UV_PERSPECTIVE},
        {"normals", SHADING_NORMALS, TEXTURE_FILTER_AUTO, 1, 1, UV_PERSPECTIVE},
        {"nearest", SHADING_LAMBERT, TEXTURE_FILTER_NEAREST, 1, 1, UV_PERSPECTIVE},
        {"trilinear affine", SHADING_LAMBERT, TEXTURE_FILTER_TRILINEAR, 1, 1, UV_AFFINE},
        {"msaa 4", SHADING_LAMBERT, TEXTURE_FILTER_AUTO, 4, 1, UV_PERSPECTIVE},
        {"ssaa 2", SHADING_LAMBERT, TEXTURE_FILTER_BILINEAR, 1, 2, UV_PERSPECTIVE},
        {"msaa 4 ssaa 2", SHADING_PHONG, TEXTURE_FILTER_TRILINEAR, 4, 2, UV_PERSPECTIVE},
        {"blinn-phong again", SHADING_BLINN_PHONG, TEXTURE_FILTER_AUTO, 1, 1, UV_PERSPECTIVE},
        {"hit count", SHADING_HIT_COUNT, TEXTURE_FILTER_AUTO, 1, 1, UV_PERSPECTIVE},
    };
    auto session = RenderSession::create(*device_, *checker);
    ASSERT_TRUE(session.ok()) << session.error().message;
    for (const Variant& v : variants) {
        RenderSettings s = framed.settings;
        s.shadingMode = v.shading;
        s.textureFilter = v.filter;
        s.msaa = v.msaa;
        s.ssaa = v.ssaa;
        s.uvInterpolation = v.uv;
        s.width = 64 * v.ssaa;
        s.height = 48 * v.ssaa;
        auto inSession = session->render(*camera, s);
        ASSERT_TRUE(inSession.ok()) << v.name << ": " << inSession.error().message;
        bool skip = false;
        auto fresh = openBackend(GetParam(), skip);
        ASSERT_TRUE(fresh);
        auto alone = renderScene(*fresh, *checker, *camera, s);
        ASSERT_TRUE(alone.ok()) << v.name << ": " << alone.error().message;
        EXPECT_EQ(differingPixels(inSession->color, alone->color), 0) << v.name;
        EXPECT_GT(inSession->color.pixels.size(), 0u) << v.name;
    }
    // The variants differ from each other: a session that ignored the settings would fail above only by
    // luck, so check that the shading mode is honoured at all.
    RenderSettings a = framed.settings, b = framed.settings;
    a.width = b.width = 64;
    a.height = b.height = 48;
    a.shadingMode = SHADING_BLINN_PHONG;
    b.shadingMode = SHADING_NORMALS;
    auto ra = session->render(*camera, a), rb = session->render(*camera, b);
    ASSERT_TRUE(ra.ok() && rb.ok());
    EXPECT_GT(differingPixels(ra->color, rb->color), 100);
}

// On a CPU device setup stores every big triangle as a record, and raster_tiles and shade read records,
// bin entries, keys and the scene through texel views of the buffers, made again whenever a buffer is
// replaced. A session whose lists start at one entry (each overflows, grows and redraws) and whose frame
// then grows (new visibility and bin buffers) must draw the ids, depths and colours a fresh device draws
// with lists sized from the scene; and on a CPU device the records are exactly the big triangles.
TEST_P(CpuBuildTest, GrownListsAndBuffersDrawWhatAFreshDeviceDraws)
{
    FramedScene framed = framedBuiltin(64, 48);
    auto session = RenderSession::create(*device_, framed.scene);
    ASSERT_TRUE(session.ok()) << session.error().message;
    const uint32_t sizes[][2] = {{64, 48}, {200, 150}, {96, 64}};
    for (const auto& size : sizes) {
        RenderSettings s = framed.settings;
        s.width = size[0];
        s.height = size[1];
        auto camera = resolveCamera(*parseCameraSpec("auto"), framed.scene, s.width, s.height);
        ASSERT_TRUE(camera.ok());
        RenderSettings tiny = s;
        tiny.initialListCapacity = 1;
        auto grown = session->render(*camera, tiny);
        ASSERT_TRUE(grown.ok()) << grown.error().message;
        bool skip = false;
        auto fresh = openBackend(GetParam(), skip);
        ASSERT_TRUE(fresh);
        auto alone = renderScene(*fresh, framed.scene, *camera, s);
        ASSERT_TRUE(alone.ok()) << alone.error().message;
        EXPECT_EQ(grown->aov.id, alone->aov.id) << s.width << "x" << s.height;
        EXPECT_EQ(grown->aov.depth, alone->aov.depth) << s.width << "x" << s.height;
        EXPECT_EQ(differingPixels(grown->color, alone->color), 0) << s.width << "x" << s.height;
        EXPECT_GT(alone->stats.bigTris, 0u);
        if (device_->info().isCpu) {
            EXPECT_EQ(alone->stats.records, alone->stats.bigTris);
        }
        if (size[0] == 64) {
            EXPECT_GT(grown->stats.redraws, 0u) << "the one-entry lists never overflowed";
        }
    }
}

// The MSAA resolve (on a CPU device: each distinct triangle of a pixel shaded once per turn, weighted by
// its samples) against the one-sample build, another shader: a pixel whose samples all hold the triangle
// the one-sample render shows there is that triangle shaded at the pixel centre in both, so its colour
// must be the same bits; pixels with several triangles must exist, or the resolve loop went untested.
// (The MSAA goldens compare the same resolve with CUDA's.)
TEST_P(CpuBuildTest, MsaaResolveOfOneTrianglePixelsIsTheOneSampleColour)
{
    FramedScene framed = framedBuiltin(64, 48);
    RenderSettings one = framed.settings;
    one.msaa = 1;
    one.aovSamples = true;
    auto single = render(framed.scene, one, framed.camera);
    const size_t plane = size_t(64) * 48;
    ASSERT_EQ(single.samples.id.size(), plane);
    for (uint32_t msaa : {4u, 8u}) {
        RenderSettings s = one;
        s.msaa = msaa;
        auto multi = render(framed.scene, s, framed.camera);
        ASSERT_EQ(multi.samples.id.size(), plane * msaa);
        long uniform = 0, mixed = 0, differing = 0;
        for (size_t p = 0; p < plane; ++p) {
            bool same = true;
            for (uint32_t k = 0; k < msaa; ++k)
                same = same && multi.samples.id[k * plane + p] == single.samples.id[p];
            if (!same) {
                ++mixed;
                continue;
            }
            ++uniform;
            differing += multi.color.pixels[p] != single.color.pixels[p];
        }
        EXPECT_EQ(differing, 0) << msaa;
        EXPECT_GT(uniform, long(plane / 2)) << msaa;
        EXPECT_GT(mixed, 20) << msaa;
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, CpuBuildTest, ::testing::Values("vulkan", "cuda"));

// `raster bench` times whole shaded frames on both sides: frame_ms is the compute backend's total and a
// second, shaded run of the graphics pipeline; the table shows their ratio.
TEST(BenchFrames, WholeShadedFramesBesideTheGraphicsPipeline)
{
    bool skip = false;
    if (!openBackend("vulkan", skip)) {
        if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
        FAIL() << "no Vulkan device";
    }
    std::string json = ::testing::TempDir() + "bench_frames.json";
    ToolRun run = runTool(
        "bench --backends vulkan,vulkan-graphics --resolutions 64x48 --scenes builtin "
        "--warmup 1 --repeat 2 --json " +
        json);
    ASSERT_EQ(run.exitCode, 0) << run.stderrText;
    std::ifstream in(json);
    nlohmann::json bench = nlohmann::json::parse(in);
    ASSERT_EQ(bench["runs"].size(), 2u);
    for (const auto& r : bench["runs"]) {
        ASSERT_TRUE(r.contains("frame_ms")) << r["backend"];
        EXPECT_GT(r["frame_ms"].get<double>(), 0.0) << r["backend"];
        if (r["backend"] == "vulkan") {
            EXPECT_EQ(r["frame_ms"].get<double>(), r["gpu_total_ms"]["median"].get<double>());
        }
    }
    EXPECT_NE(run.stdoutText.find("| frame ms | x hardware frame |"), std::string::npos) << run.stdoutText;
    EXPECT_NE(run.stdoutText.find("| builtin | 64x48 | 1 | vulkan-graphics |"), std::string::npos);
}

// `--warmup-ms` draws untimed frames of each run's scene until that much wall time has passed before the
// timed ones, and says how many; without it there are none.
TEST(BenchFrames, WarmupByTimeDrawsFramesUntilItsTimeHasPassed)
{
    bool skip = false;
    if (!openBackend("vulkan", skip)) {
        if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
        FAIL() << "no Vulkan device";
    }
    for (double ms : {0.0, 60.0}) {
        std::string json = ::testing::TempDir() + "bench_prewarm.json";
        ToolRun run = runTool(
            "bench --backends vulkan --resolutions 32x24 --scenes builtin,layers-16 --warmup 0 "
            "--repeat 1 --warmup-ms " +
            std::to_string(ms) + " --json " + json);
        ASSERT_EQ(run.exitCode, 0) << run.stderrText;
        std::ifstream in(json);
        nlohmann::json bench = nlohmann::json::parse(in);
        EXPECT_EQ(bench["warmup_ms"].get<double>(), ms);
        ASSERT_EQ(bench["runs"].size(), 2u);
        for (const auto& r : bench["runs"]) {
            if (ms == 0.0) {
                EXPECT_EQ(r["prewarm_frames"].get<uint32_t>(), 0u) << r["scene"];
                EXPECT_EQ(r["prewarm_first_ms"].get<double>(), 0.0) << r["scene"];
                EXPECT_EQ(r["prewarm_ms"].get<double>(), 0.0) << r["scene"];
            } else {
                // The time starts after the first frame (the scene's upload): whatever that one took,
                // frames after it fill the time.
                EXPECT_GE(r["prewarm_frames"].get<uint32_t>(), 2u) << r["scene"];
                EXPECT_GT(r["prewarm_first_ms"].get<double>(), 0.0) << r["scene"];
                EXPECT_GE(r["prewarm_ms"].get<double>(), ms) << r["scene"];
            }
        }
    }
    // Refused where it cannot take effect as asked.
    EXPECT_NE(runTool("bench --warmup-ms -1").exitCode, 0);
}

}  // namespace
}  // namespace sr::test
