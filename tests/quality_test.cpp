// quality_test.cpp - `raster render --quality psnr:N` (study/quality.h, cli/study.h): the chooser on
// hand-made study rows, the target's parsing, the command line's usage errors, the choice read from a
// study file, and one choice measured on the device, checked by rendering the chosen setting again and
// measuring it against a reference rendered here, independently of the tool.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <regex>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "study/study_runner.h"
#include "study/quality.h"
#include "test_util.h"

namespace sr::test {
namespace {

nlohmann::json row(const std::string& setting, double ms, nlohmann::json psnr, double memory,
                   const std::string& method = "fixed8", uint32_t msaa = 1, uint32_t ssaa = 1)
{
    return {{"scene", "builtin"},
            {"backend", "vulkan"},
            {"group", method == "fixed8" ? "aa" : "method"},
            {"setting", setting},
            {"method", method},
            {"msaa", msaa},
            {"ssaa", ssaa},
            {"texture_filter", "trilinear"},
            {"uv", "perspective"},
            {"ms", ms},
            {"psnr", psnr},
            {"max_error", 10},
            {"memory_mib", memory}};
}

QualityTarget target(double psnr)
{
    auto t = parseQualityTarget(fmt::format("psnr:{}", psnr));
    EXPECT_TRUE(t.ok());
    return t.ok() ? *t : QualityTarget{};
}

std::string picked(const nlohmann::json& rows, double psnr)
{
    auto r = pickCheapest(rows, target(psnr));
    return r.ok() ? (*r)["setting"].get<std::string>() : "error: " + r.error().message;
}

TEST(QualityTarget, ParsesPsnrAndRejectsEverythingElse)
{
    auto t = parseQualityTarget("psnr:40");
    ASSERT_TRUE(t.ok());
    EXPECT_EQ(t->psnr, 40.0);
    EXPECT_EQ(t->text, "psnr:40");
    ASSERT_TRUE(parseQualityTarget("psnr:37.5").ok());
    EXPECT_EQ(parseQualityTarget("psnr:37.5")->psnr, 37.5);
    for (const char* bad : {"psnr:abc", "psnr:-1", "psnr:0", "psnr:", "psnr:40dB", "psnr:inf", "psnr:nan",
                            "ssim:3", "40", "", "PSNR:40"}) {
        auto r = parseQualityTarget(bad);
        ASSERT_FALSE(r.ok()) << bad;
        EXPECT_EQ(r.error().code, ExitCode::Usage) << bad;
        EXPECT_TRUE(isOneLine(r.error().message)) << bad;
    }
}

// The cheapest row meeting the target, whatever the order of the rows; an exact image meets any target.
TEST(QualityChooser, PicksTheCheapestSettingThatMeetsTheTarget)
{
    nlohmann::json rows = {row("msaa16", 9.0, 47.0, 60.0), row("msaa1", 1.0, 32.0, 30.0),
                           row("msaa4", 3.0, 41.0, 40.0), row("ssaa2", 2.5, 39.5, 45.0),
                           row("msaa8", 5.0, 44.0, 50.0)};
    EXPECT_EQ(picked(rows, 30.0), "msaa1");
    EXPECT_EQ(picked(rows, 32.0), "msaa1");  // meeting is PSNR >= N
    EXPECT_EQ(picked(rows, 39.0), "ssaa2");
    EXPECT_EQ(picked(rows, 40.0), "msaa4");
    EXPECT_EQ(picked(rows, 43.0), "msaa8");
    EXPECT_EQ(picked(rows, 47.0), "msaa16");
    rows.push_back(row("ssaa3", 4.0, "inf", 55.0));
    EXPECT_EQ(picked(rows, 45.0), "ssaa3");
    // A row without a PSNR (a reference written by hand) is not a candidate.
    rows.push_back(row("reference", 0.5, nullptr, 10.0));
    EXPECT_EQ(picked(rows, 45.0), "ssaa3");
}

TEST(QualityChooser, EqualTimesGoToTheSmallerMemory)
{
    nlohmann::json rows = {row("float", 2.0, 42.0, 31.0, "float"), row("fixed4", 2.0, 43.0, 30.0, "fixed4"),
                           row("scanline", 2.0, 44.0, 32.0, "scanline")};
    EXPECT_EQ(picked(rows, 40.0), "fixed4");
    std::swap(rows[0], rows[1]);
    EXPECT_EQ(picked(rows, 40.0), "fixed4");
    // Equal in both: the earlier row.
    nlohmann::json same = {row("a", 2.0, 42.0, 30.0), row("b", 2.0, 42.0, 30.0)};
    EXPECT_EQ(picked(same, 40.0), "a");
}

TEST(QualityChooser, NoneMeetingTheTargetNamesTheBestThereIs)
{
    nlohmann::json rows = {row("msaa1", 1.0, 32.0, 30.0), row("msaa16", 9.0, 38.25, 60.0),
                           row("ssaa2", 2.5, 36.0, 45.0)};
    auto r = pickCheapest(rows, target(40.0));
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ExitCode::Usage);
    EXPECT_TRUE(isOneLine(r.error().message));
    EXPECT_NE(r.error().message.find("psnr:40"), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find("msaa16 at PSNR 38.25 dB"), std::string::npos) << r.error().message;

    EXPECT_FALSE(pickCheapest(nlohmann::json::array(), target(40.0)).ok());
    nlohmann::json noTime = {row("msaa1", 1.0, 45.0, 30.0)};
    noTime[0].erase("ms");
    auto malformed = pickCheapest(noTime, target(40.0));
    ASSERT_FALSE(malformed.ok());
    EXPECT_NE(malformed.error().message.find("\"ms\""), std::string::npos) << malformed.error().message;
}

TEST(QualityChooser, RowsForOneSceneAndBackend)
{
    nlohmann::json study = {{"accuracy", {row("msaa1", 1.0, 32.0, 30.0), row("msaa4", 3.0, 41.0, 40.0)}}};
    study["accuracy"][1]["backend"] = "cuda";
    auto vulkan = accuracyRowsFor(study, "builtin", "vulkan");
    ASSERT_TRUE(vulkan.ok());
    ASSERT_EQ(vulkan->size(), 1u);
    EXPECT_EQ((*vulkan)[0]["setting"], "msaa1");
    auto missing = accuracyRowsFor(study, "dense", "vulkan");
    ASSERT_FALSE(missing.ok());
    EXPECT_TRUE(isOneLine(missing.error().message));
    EXPECT_NE(missing.error().message.find("builtin on cuda, builtin on vulkan"), std::string::npos)
        << missing.error().message;
    EXPECT_FALSE(accuracyRowsFor(nlohmann::json::object(), "builtin", "vulkan").ok());
}

TEST(QualityChooser, TheChosenRowBecomesSettingsAndOneLine)
{
    nlohmann::json r = row("ssaa2+msaa4", 3.25, 44.5, 40.0, "fixed8", 4, 2);
    auto s = settingFromRow(r);
    ASSERT_TRUE(s.ok()) << s.error().message;
    EXPECT_EQ(s->msaa, 4u);
    EXPECT_EQ(s->ssaa, 2u);
    EXPECT_EQ(s->rasterMethod, uint32_t(RASTER_FIXED8));
    EXPECT_EQ(s->textureFilter, uint32_t(TEXTURE_FILTER_TRILINEAR));
    EXPECT_EQ(
        describeChoice(target(40.0), r, *s),
        "quality psnr:40 -> ssaa2+msaa4 (fixed8, msaa 4, ssaa 2, filter trilinear): PSNR 44.50 dB, 3.250 "
        "ms, 40.0 MiB");
    nlohmann::json scan = row("scanline", 1.0, 33.0, 30.0, "scanline");
    scan["uv"] = "affine";
    auto a = settingFromRow(scan);
    ASSERT_TRUE(a.ok());
    EXPECT_EQ(a->rasterMethod, uint32_t(RASTER_SCANLINE));
    EXPECT_EQ(a->uvInterpolation, uint32_t(UV_AFFINE));
    EXPECT_NE(describeChoice(target(30.0), scan, *a)
                  .find("(scanline, msaa 1, ssaa 1, filter trilinear, uv affine)"),
              std::string::npos);
    nlohmann::json bad = r;
    bad["msaa"] = 3;
    EXPECT_FALSE(settingFromRow(bad).ok());
    bad = r;
    bad["method"] = "fixed2";
    EXPECT_FALSE(settingFromRow(bad).ok());
}

// Usage errors come before any rendering, on one line, with exit code 2.
TEST(QualityCommand, BadTargetsAndConflictingOptionsAreUsageErrors)
{
    for (const char* args :
         {"--quality psnr:abc", "--quality psnr:-1", "--quality ssim:3", "--quality psnr:40 --msaa 4",
          "--quality psnr:40 --ssaa 2", "--quality psnr:40 --texture-filter nearest",
          "--quality psnr:40 --raster-method float", "--quality psnr:40 --uv-interpolation affine",
          "--study missing.json", "--quality psnr:40 --backend vulkan-graphics --width 8 --height 8"}) {
        ToolRun run = runTool(std::string("render -o never-written.png ") + args);
        EXPECT_EQ(run.exitCode, 2) << args;
        EXPECT_TRUE(isOneLine(run.stderrText.substr(0, run.stderrText.size() - 1))) << args << run.stderrText;
        EXPECT_EQ(run.stdoutText, "") << args;
    }
}

// A study file decides without measuring: its rows for the scene and the device's backend.
TEST(QualityCommand, ChoosesFromAStudyFile)
{
    bool skip = false;
    if (!openBackend("vulkan", skip)) {
        if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
        FAIL() << "no vulkan device";
    }
    ScratchDir dir("quality");
    nlohmann::json study = {{"accuracy",
                             {row("msaa1", 1.0, 32.0, 30.0), row("msaa4", 3.0, 41.0, 40.0),
                              row("fixed4", 1.5, 40.5, 30.0, "fixed4"), row("msaa16", 9.0, 47.0, 60.0)}}};
    study["accuracy"].push_back(row("sliver-msaa4", 0.5, 50.0, 10.0));
    study["accuracy"].back()["scene"] = "sliver-fan";
    std::ofstream(dir.file("study.json")) << study.dump();
    const std::string common = " --backend vulkan --width 32 --height 24 --study " + dir.file("study.json");
    ToolRun run = runTool("render --quality psnr:40 -o " + dir.file("a.png") + common);
    ASSERT_EQ(run.exitCode, 0) << run.stderrText;
    EXPECT_EQ(
        run.stdoutText.substr(0, run.stdoutText.find('\n')),
        "quality psnr:40 -> fixed4 (fixed4, msaa 1, ssaa 1, filter trilinear): PSNR 40.50 dB, 1.500 ms, 30.0 "
        "MiB");
    EXPECT_TRUE(readPng(dir.file("a.png")).ok());
    run = runTool("render study:sliver-fan --quality psnr:45 -o " + dir.file("b.png") + common);
    ASSERT_EQ(run.exitCode, 0) << run.stderrText;
    EXPECT_EQ(run.stdoutText.rfind("quality psnr:45 -> sliver-msaa4 (", 0), 0u) << run.stdoutText;

    run = runTool("render --quality psnr:48 -o " + dir.file("c.png") + common);
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_NE(run.stderrText.find("msaa16 at PSNR 47.00 dB"), std::string::npos) << run.stderrText;
    run = runTool("render builtin:dense --quality psnr:40 -o " + dir.file("d.png") + common);
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_NE(run.stderrText.find("no rows for scene 'dense' on vulkan"), std::string::npos)
        << run.stderrText;
}

class QualityRenderTest : public BackendTest {};

// The tool measures the built-in scene's settings itself, picks one, and writes its image: that image
// must be the chosen setting's render, and that render must meet the target against a reference
// rendered here (SSAA 4 x MSAA 16, the study's definition) -- with the PSNR the tool reported.
TEST_P(QualityRenderTest, MeasuredChoiceMeetsTheTarget)
{
    const uint32_t width = 64, height = 48;
    const double goal = 35.0;
    ScratchDir dir("quality");
    ToolRun run = runTool(fmt::format("render --quality psnr:{} --backend {} --width {} --height {} -o {}",
                                      goal, GetParam(), width, height, dir.file("q.png")));
    ASSERT_EQ(run.exitCode, 0) << run.stderrText;
    std::smatch m;
    const std::string line = run.stdoutText.substr(0, run.stdoutText.find('\n'));
    ASSERT_TRUE(
        std::regex_match(line, m,
                         std::regex(R"(quality psnr:35 -> (\S+) \((\w+), msaa (\d+), ssaa (\d+), filter )"
                                    R"((\w+)\): PSNR ([0-9.]+) dB, ([0-9.]+) ms, ([0-9.]+) MiB)")))
        << line;
    std::printf("[ quality  ] %s\n", line.c_str());
    RenderSettings chosen;  // the render command's defaults, as the tool used them
    chosen.width = width;
    chosen.height = height;
    chosen.msaa = uint32_t(std::stoul(m[3]));
    chosen.ssaa = uint32_t(std::stoul(m[4]));
    auto method = rasterMethodFromName(m[2]);
    auto filter = textureFilterFromName(m[5]);
    ASSERT_TRUE(method.ok() && filter.ok());
    chosen.rasterMethod = *method;
    chosen.textureFilter = *filter;
    FramedScene f = framedBuiltin(width, height);
    RenderOutput out = render(f.scene, chosen, f.camera);
    RenderSettings ref = chosen;
    ref.msaa = 16;
    ref.ssaa = 4;
    ref.rasterMethod = RASTER_FIXED8;
    ref.textureFilter = TEXTURE_FILTER_TRILINEAR;
    RenderOutput reference = render(f.scene, ref, f.camera);
    const double psnr = imageError(out.color, reference.color).psnr;
    EXPECT_GE(psnr, goal);
    EXPECT_NEAR(psnr, std::stod(m[6]), 0.005);
    auto written = readPng(dir.file("q.png"));
    ASSERT_TRUE(written.ok());
    EXPECT_EQ(written->pixels, out.color.pixels) << "the image written is the chosen setting's";
}

INSTANTIATE_TEST_SUITE_P(Backends, QualityRenderTest, ::testing::Values("vulkan", "cuda"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace sr::test
