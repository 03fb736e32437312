// turntable_test.cpp - RenderSession (one upload, reused buffers, images identical to fresh renders) and
// `raster render --frames N --orbit AZ0:AZ1`: frame k equals `raster render --camera orbit:AZk,...`, and
// bad patterns are one-line usage errors.
#include <algorithm>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "batch/turntable.h"
#include "io/image_io.h"
#include "test_util.h"

namespace sr::test {
namespace {

// A device that counts what the renderer asks of the real one.
class CountingDevice : public ComputeDevice {
public:
    explicit CountingDevice(ComputeDevice& inner) : inner_(inner) {}
    const DeviceInfo& info() const override { return inner_.info(); }
    Status resize(uint32_t buffer, size_t bytes) override
    {
        ++resizes;
        return inner_.resize(buffer, bytes);
    }
    size_t size(uint32_t buffer) const override { return inner_.size(buffer); }
    Status upload(uint32_t buffer, const void* data, size_t bytes) override
    {
        ++uploads;
        return inner_.upload(buffer, data, bytes);
    }
    Status download(uint32_t buffer, void* data, size_t bytes, size_t offset) override
    {
        return inner_.download(buffer, data, bytes, offset);
    }
    Status run(const RasterParams& params, const std::vector<Dispatch>& dispatches,
               std::vector<double>& gpuMs) override
    {
        return inner_.run(params, dispatches, gpuMs);
    }
    size_t allocatedBytes() const override { return inner_.allocatedBytes(); }
    size_t peakAllocatedBytes() const override { return inner_.peakAllocatedBytes(); }

    int resizes = 0, uploads = 0;

private:
    ComputeDevice& inner_;
};

class SessionTest : public BackendTest {};

// Frames of one session, with cameras, sizes, sample counts and shading changing between them, are the
// frames fresh renders give; the scene is uploaded once and an unchanged frame resizes nothing.
TEST_P(SessionTest, FramesEqualFreshRendersAndTheSceneIsUploadedOnce)
{
    const Scene scene = builtinScene();
    CountingDevice counting(*device_);
    auto session = RenderSession::create(counting, scene);
    ASSERT_TRUE(session.ok()) << session.error().message;
    const int sceneUploads = counting.uploads;
    EXPECT_GT(sceneUploads, 0);

    struct Frame {
        std::string camera;
        uint32_t width, height, msaa, shading;
    };
    const std::vector<Frame> frames = {{"orbit:0,20,9", 64, 48, 1, SHADING_BLINN_PHONG},
                                       {"orbit:40,20,9", 64, 48, 1, SHADING_BLINN_PHONG},
                                       {"orbit:40,70,3,0.5,0,0", 80, 40, 4, SHADING_NORMALS},
                                       {"orbit:-150,-10,20", 48, 64, 1, SHADING_HIT_COUNT},
                                       {"orbit:0,20,9", 64, 48, 1, SHADING_BLINN_PHONG}};
    for (const Frame& f : frames) {
        RenderSettings s = testSettings(f.width, f.height);
        s.msaa = f.msaa;
        s.shadingMode = f.shading;
        auto camera = resolveCamera(*parseCameraSpec(f.camera), scene, f.width, f.height);
        ASSERT_TRUE(camera.ok());
        auto fromSession = session->render(*camera, s);
        ASSERT_TRUE(fromSession.ok()) << fromSession.error().message;
        auto fresh = renderScene(*device_, scene, *camera, s);
        ASSERT_TRUE(fresh.ok()) << fresh.error().message;
        EXPECT_EQ(fromSession->color.pixels, fresh->color.pixels) << f.camera;
        EXPECT_EQ(fromSession->aov.id, fresh->aov.id) << f.camera;
        EXPECT_EQ(fromSession->aov.depth, fresh->aov.depth) << f.camera;
        // renderScene above overwrote the device's buffers: a new session restores them.
        session = RenderSession::create(counting, scene);
        ASSERT_TRUE(session.ok());
        // Drawn once more on the fresh session, then again unchanged: the repeat uploads and resizes
        // nothing.
        ASSERT_TRUE(session->render(*camera, s).ok());
        const int resizes = counting.resizes, uploads = counting.uploads;
        auto again = session->render(*camera, s);
        ASSERT_TRUE(again.ok());
        EXPECT_EQ(counting.resizes, resizes) << f.camera;
        EXPECT_EQ(counting.uploads, uploads) << f.camera;
        EXPECT_EQ(again->color.pixels, fresh->color.pixels) << f.camera;
    }
}

// Lists forced tiny in the first frame grow there and carry over: the next frame draws without redraws.
TEST_P(SessionTest, ListCapacitiesCarryOver)
{
    const Scene scene = builtinScene();
    auto session = RenderSession::create(*device_, scene);
    ASSERT_TRUE(session.ok());
    RenderSettings s = testSettings(64, 48);
    auto camera = resolveCamera(CameraSpec{}, scene, 64, 48);
    s.initialListCapacity = 1;
    auto first = session->render(*camera, s);
    ASSERT_TRUE(first.ok());
    EXPECT_GT(first->stats.redraws, 0u);
    s.initialListCapacity = 0;
    auto second = session->render(*camera, s);
    ASSERT_TRUE(second.ok());
    EXPECT_EQ(second->stats.redraws, 0u);
    EXPECT_EQ(second->color.pixels, first->color.pixels);
}

TEST_P(SessionTest, RejectsASceneWithNothingToDraw)
{
    auto session = RenderSession::create(*device_, Scene{});
    ASSERT_FALSE(session.ok());
    EXPECT_EQ(session.error().code, ExitCode::Usage);
}

INSTANTIATE_TEST_SUITE_P(Backends, SessionTest, ::testing::Values("vulkan", "cuda"),
                         [](const auto& info) { return info.param; });

// ---- frame patterns and azimuths --------------------------------------------------------------

TEST(Turntable, FramePatterns)
{
    struct Case {
        const char* pattern;
        uint32_t frame;
        const char* path;
    };
    for (const Case& c : {Case{"frame_%04d.png", 7, "frame_0007.png"}, Case{"f%d.png", 123, "f123.png"},
                          Case{"%02d", 3, "03"}, Case{"a%%b_%03d_%%.exr", 12, "a%b_012_%.exr"},
                          Case{"%09d", 5, "000000005"}, Case{"x%02d", 1234, "x1234"}}) {
        auto p = parseFramePattern("-o", c.pattern);
        ASSERT_TRUE(p.ok()) << c.pattern << ": " << p.error().message;
        EXPECT_EQ(framePath(*p, c.frame), c.path) << c.pattern;
    }
    for (const char* bad : {"render.png", "a%d%d.png", "%s.png", "%5d.png", "%0d.png", "%010d.png", "frame%",
                            "%ld.png", "%04x.png", "%%d.png", "%-4d.png"}) {
        auto p = parseFramePattern("--aov", bad);
        ASSERT_FALSE(p.ok()) << "accepted " << bad;
        EXPECT_EQ(p.error().code, ExitCode::Usage);
        EXPECT_TRUE(isOneLine(p.error().message));
        EXPECT_EQ(p.error().message.rfind(fmt::format("invalid --aov '{}'", bad), 0), 0u)
            << p.error().message;
    }
}

TEST(Turntable, AzimuthsIncludeBothEnds)
{
    const AzimuthRange range{0.1f, 0.3f};
    EXPECT_EQ(turntableAzimuth(range, 0, 5), 0.1f);
    EXPECT_EQ(turntableAzimuth(range, 4, 5), 0.3f);
    EXPECT_FLOAT_EQ(turntableAzimuth(range, 2, 5), 0.2f);
    EXPECT_EQ(turntableAzimuth(range, 0, 1), 0.1f);
    EXPECT_EQ(turntableAzimuth({0.0f, 90.0f}, 1, 4), 30.0f);
    EXPECT_EQ(turntableAzimuth({360.0f, 0.0f}, 3, 5), 90.0f);
    for (const char* bad : {"", "10", "a:b", "1:", ":2", "1:2:3", "nan:1", " 1:2"})
        EXPECT_FALSE(parseAzimuthRange(bad).ok()) << bad;
    auto range2 = parseAzimuthRange("-45:315.5");
    ASSERT_TRUE(range2.ok());
    EXPECT_EQ(range2->from, -45.0f);
    EXPECT_EQ(range2->to, 315.5f);
}

// `AZ0:AZ1)` leaves AZ1 out: N frames of 0:360) step 360 / N and end one step before 360, so a looped
// video does not show the first view twice.
TEST(Turntable, EndExclusiveAzimuthsLeaveTheLastOut)
{
    auto loop = parseAzimuthRange("0:360)");
    ASSERT_TRUE(loop.ok()) << loop.error().message;
    EXPECT_TRUE(loop->endExclusive);
    EXPECT_EQ(loop->from, 0.0f);
    EXPECT_EQ(loop->to, 360.0f);
    const float expected[] = {0.0f, 90.0f, 180.0f, 270.0f};
    for (uint32_t k = 0; k < 4; ++k) EXPECT_EQ(turntableAzimuth(*loop, k, 4), expected[k]) << k;
    EXPECT_EQ(turntableAzimuth(*loop, 0, 1), 0.0f);
    auto backwards = parseAzimuthRange("90:-30)");
    ASSERT_TRUE(backwards.ok());
    EXPECT_EQ(turntableAzimuth(*backwards, 2, 3), 10.0f);
    // The inclusive form is unchanged: 0:360 over 4 frames ends on 360.
    auto closed = parseAzimuthRange("0:360");
    ASSERT_TRUE(closed.ok());
    EXPECT_FALSE(closed->endExclusive);
    EXPECT_EQ(turntableAzimuth(*closed, 3, 4), 360.0f);
    for (const char* bad : {"0:360))", "0:360(", ")", "0)", "(0:360)", "0:)", "0:360 )"}) {
        auto range = parseAzimuthRange(bad);
        ASSERT_FALSE(range.ok()) << bad;
        EXPECT_TRUE(isOneLine(range.error().message));
        EXPECT_NE(range.error().message.find("AZ0:AZ1)"), std::string::npos) << range.error().message;
    }
}

// ---- the command line -------------------------------------------------------------------------

class TurntableToolTest : public BackendTest {};

::testing::AssertionResult sameFrame(const std::string& pngA, const std::string& exrA,
                                     const std::string& pngB, const std::string& exrB)
{
    auto a = readAovExr(exrA), b = readAovExr(exrB);
    auto ca = readPng(pngA), cb = readPng(pngB);
    if (!a.ok() || !b.ok() || !ca.ok() || !cb.ok())
        return ::testing::AssertionFailure() << "unreadable output";
    size_t covered = std::count_if(a->id.begin(), a->id.end(), [](uint32_t id) { return id != EMPTY_ID; });
    if (covered == 0) return ::testing::AssertionFailure() << exrA << " shows nothing";
    if (a->id != b->id) return ::testing::AssertionFailure() << "ids differ: " << exrA << " vs " << exrB;
    if (a->depth != b->depth) return ::testing::AssertionFailure() << "depths differ: " << exrA;
    if (ca->pixels != cb->pixels) return ::testing::AssertionFailure() << "colours differ: " << pngA;
    return ::testing::AssertionSuccess();
}

// Frame k of a turntable is `raster render --camera orbit:AZk,EL,DIST[,TX,TY,TZ]`, with AZk = 30 k, and
// with a --model the same render of the moved model (the camera orbits the unmoved scene's centre).
TEST_P(TurntableToolTest, FrameKEqualsTheOrbitRender)
{
    ScratchDir dir("turntable");
    for (const auto& [tail, model] : std::vector<std::pair<std::string, std::string>>{
             {"20,9", ""}, {"20,9,0.75,-0.25,0.5", " --model translate:0.25,0,0,rotate:0,0,10,scale:1.25"}}) {
        const std::string common =
            fmt::format(" --backend {} --width 64 --height 48 -q{}", GetParam(), model);
        ToolRun run = runTool("render --frames 4 --orbit 0:90 --camera orbit:0," + tail + common + " -o " +
                              dir.file("t_%02d.png") + " --aov " + dir.file("t_%02d.exr") + " --stats " +
                              dir.file("t_%d.json"));
        ASSERT_EQ(run.exitCode, 0) << run.stderrText;
        EXPECT_EQ(run.stdoutText, "");
        for (int k = 0; k < 4; ++k) {
            ToolRun single = runTool(fmt::format("render --camera orbit:{},{}{} -o {} --aov {}", 30 * k, tail,
                                                 common, dir.file("r.png"), dir.file("r.exr")));
            ASSERT_EQ(single.exitCode, 0) << single.stderrText;
            const std::string frame = dir.file(fmt::format("t_{:02}", k));
            EXPECT_TRUE(sameFrame(frame + ".png", frame + ".exr", dir.file("r.png"), dir.file("r.exr")))
                << "frame " << k << " of orbit:0," << tail;
            std::ifstream in(dir.file(fmt::format("t_{}.json", k)));
            ASSERT_TRUE(in.good()) << k;
            EXPECT_EQ(nlohmann::json::parse(in)["backend"], GetParam());
        }
    }
}

// Without --camera the turntable orbits at the auto camera's elevation and distance: a frame at the
// auto azimuth is the auto render. The summary line names the frames.
TEST_P(TurntableToolTest, AutoCameraFramesAndSummary)
{
    ScratchDir dir("turntable-auto");
    const std::string common = fmt::format(" --backend {} --width 48 --height 64", GetParam());
    ToolRun run = runTool("render --frames 1 --orbit 35:200" + common + " -o " + dir.file("a%d.png") +
                          " --aov " + dir.file("a%d.exr"));
    ASSERT_EQ(run.exitCode, 0) << run.stderrText;
    EXPECT_NE(run.stdoutText.find("1 frame from --camera orbit:35,25,"), std::string::npos) << run.stdoutText;
    ToolRun single =
        runTool("render -q" + common + " -o " + dir.file("r.png") + " --aov " + dir.file("r.exr"));
    ASSERT_EQ(single.exitCode, 0) << single.stderrText;
    EXPECT_TRUE(sameFrame(dir.file("a0.png"), dir.file("a0.exr"), dir.file("r.png"), dir.file("r.exr")));
}

// `--orbit '0:360)'`: the last of 4 frames is the render at azimuth 270, and the summary names it.
TEST_P(TurntableToolTest, EndExclusiveOrbitEndsOneStepShort)
{
    ScratchDir dir("turntable-loop");
    const std::string common = fmt::format(" --backend {} --width 48 --height 32", GetParam());
    ToolRun run = runTool("render --frames 4 --orbit '0:360)' --camera orbit:0,20,9" + common + " -o " +
                          dir.file("l%d.png") + " --aov " + dir.file("l%d.exr"));
    ASSERT_EQ(run.exitCode, 0) << run.stderrText;
    EXPECT_NE(run.stdoutText.find("4 frames from --camera orbit:0,20,9 to orbit:270,20,9:"),
              std::string::npos)
        << run.stdoutText;
    ToolRun single = runTool("render -q --camera orbit:270,20,9" + common + " -o " + dir.file("r.png") +
                             " --aov " + dir.file("r.exr"));
    ASSERT_EQ(single.exitCode, 0) << single.stderrText;
    EXPECT_TRUE(sameFrame(dir.file("l3.png"), dir.file("l3.exr"), dir.file("r.png"), dir.file("r.exr")));
}

INSTANTIATE_TEST_SUITE_P(Backends, TurntableToolTest, ::testing::Values("vulkan", "cuda"),
                         [](const auto& info) { return info.param; });

TEST(TurntableTool, BadRequestsAreOneLineUsageErrors)
{
    ScratchDir dir("turntable-bad");
    const std::string out = " -o " + dir.file("f_%03d.png");
    for (std::string args :
         {std::string("--frames 3 --orbit 0:90 -o ") + dir.file("plain.png"),
          "--frames 3 --orbit 0:90 -o " + dir.file("f_%d_%d.png"),
          "--frames 3 --orbit 0:90 -o " + dir.file("f_%s.png"),
          "--frames 3 --orbit 0:90 --aov " + dir.file("a.exr") + out,
          "--frames 3 --orbit 0:90 --stats " + dir.file("s_%x.json") + out, "--frames 3" + out,
          "--orbit 0:90" + out, "--frames 0 --orbit 0:90" + out, "--frames 3 --orbit 90" + out,
          "--frames 3 --orbit 0:90 --backend vulkan-graphics" + out,
          "--frames 3 --orbit 0:90 --camera gltf:0" + out}) {
        ToolRun run = runTool("render " + args);
        EXPECT_EQ(run.exitCode, 2) << args << ": " << run.stderrText;
        EXPECT_EQ(std::count(run.stderrText.begin(), run.stderrText.end(), '\n'), 1)
            << args << run.stderrText;
        EXPECT_EQ(run.stderrText.rfind("raster: error: ", 0), 0u) << run.stderrText;
    }
    // Nothing was rendered for any of them.
    std::ifstream first(dir.file("f_000.png"));
    EXPECT_FALSE(first.good());
}

}  // namespace
}  // namespace sr::test
