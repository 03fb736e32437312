// compare_test.cpp - `raster compare` statistics against hand-computed values, and its exit codes.
#include <cmath>
#include <filesystem>
#include <utility>

#include <gtest/gtest.h>

#include "io/compare.h"
#include "io/image_io.h"
#include "test_util.h"

namespace sr::test {
namespace {

RgbaImage flat(uint32_t w, uint32_t h, uint32_t rgba)
{
    RgbaImage img;
    img.width = w;
    img.height = h;
    img.pixels.assign(size_t(w) * h, rgba);
    return img;
}

TEST(Compare, ColorStatisticsByHand)
{
    RgbaImage a = flat(4, 2, 0xff102030u), b = a;
    b.pixels[5] = 0xff10202au;  // red channel 0x30 -> 0x2a at (1, 1): difference 6
    auto r = compareColor(a, b, CompareTolerance{5, 0, 0.0f});
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r->maxError, 6);
    EXPECT_EQ(r->maxX, 1u);
    EXPECT_EQ(r->maxY, 1u);
    EXPECT_DOUBLE_EQ(r->meanError, 6.0 / 24.0);
    EXPECT_DOUBLE_EQ(r->rmsError, std::sqrt(36.0 / 24.0));
    EXPECT_EQ(r->pixelsOverTolerance, 1u);
    EXPECT_FALSE(r->pass);
    EXPECT_TRUE(compareColor(a, b, CompareTolerance{6, 0, 0.0f})->pass);
    EXPECT_TRUE(std::isinf(compareColor(a, a, {})->psnr));
    EXPECT_FALSE(compareColor(a, flat(2, 4, 0), {}).ok());
}

TEST(Compare, AovCountsIdsCoverageAndDepth)
{
    AovImage a;
    a.width = 3;
    a.height = 1;
    a.id = {1, 2, 0xFFFFFFFFu};
    a.depth = {0.5f, 0.25f, 1.0f};
    AovImage b = a;
    b.id[1] = 7;           // id mismatch
    b.id[2] = 3;           // coverage mismatch
    b.depth[0] = 0.5001f;  // depth difference where both are covered
    auto r = compareAov(a, b, CompareTolerance{0, 2, 0.001f});
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r->idMismatches, 1u);
    EXPECT_EQ(r->coverageMismatches, 1u);
    EXPECT_NEAR(r->maxDepthDiff, 1e-4, 1e-7);
    EXPECT_TRUE(r->pass);
    EXPECT_FALSE(compareAov(a, b, CompareTolerance{0, 1, 0.001f})->pass);
    EXPECT_FALSE(compareAov(a, b, CompareTolerance{0, 2, 0.0f})->pass);
}

TEST(Compare, ToolExitCodes)
{
    std::string dir = ::testing::TempDir();
    ASSERT_TRUE(writePng(dir + "c1.png", flat(8, 8, 0xff000000u)).ok());
    RgbaImage other = flat(8, 8, 0xff000000u);
    other.pixels[9] = 0xff000009u;
    ASSERT_TRUE(writePng(dir + "c2.png", other).ok());
    EXPECT_EQ(runTool("compare " + dir + "c1.png " + dir + "c1.png").exitCode, 0);
    ToolRun differ = runTool("compare " + dir + "c1.png " + dir + "c2.png -o " + dir + "diff.png");
    EXPECT_EQ(differ.exitCode, 1);
    EXPECT_NE(differ.stdoutText.find("FAILURE"), std::string::npos);
    EXPECT_TRUE(readPng(dir + "diff.png").ok());
    EXPECT_EQ(runTool("compare " + dir + "c1.png " + dir + "c2.png --tolerance 9").exitCode, 0);
    EXPECT_EQ(runTool("compare " + dir + "c1.png " + dir + "missing.png").exitCode, 2);
}

TEST(Compare, MaxFractionAllowsThatShareOfThePixelsOverTolerance)
{
    // 10x10 pixels, 3 of them 5 units off: over a tolerance of 2 they pass with 3% allowed, not 2.9%.
    RgbaImage a = flat(10, 10, 0xff101010u), b = a;
    for (size_t i : {7u, 42u, 99u}) b.pixels[i] = 0xff101015u;
    CompareTolerance tol;
    tol.colorLsb = 2;
    tol.maxFraction = 0.03;
    auto r = compareColor(a, b, tol);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r->pixelsOverTolerance, 3u);
    EXPECT_TRUE(r->pass);
    EXPECT_NE(formatReport(*r, tol).find("3 allowed (3%)"), std::string::npos) << formatReport(*r, tol);
    tol.maxFraction = 0.029;
    EXPECT_FALSE(compareColor(a, b, tol)->pass);

    // AOVs: depth over tolerance counts against the same share; id mismatches against their own count.
    AovImage x;
    x.width = 10;
    x.height = 10;
    x.id.assign(100, 1u);
    x.depth.assign(100, 0.5f);
    AovImage y = x;
    y.depth[3] = 0.6f;
    y.depth[4] = 0.6f;
    CompareTolerance aovTol;
    aovTol.depthTolerance = 0.01f;
    aovTol.maxFraction = 0.02;
    EXPECT_TRUE(compareAov(x, y, aovTol)->pass);
    aovTol.maxFraction = 0.01;
    EXPECT_FALSE(compareAov(x, y, aovTol)->pass);
    y.id[50] = 2u;
    aovTol.maxFraction = 1.0;
    EXPECT_FALSE(compareAov(x, y, aovTol)->pass);
}

TEST(Compare, DefaultsAreTheDocumentedBoundsOfThePair)
{
    const ImageOrigin cuda{"cuda", "NVIDIA H100 80GB HBM3"}, vulkanGpu{"vulkan", "NVIDIA H100 80GB HBM3"},
        vulkan{"vulkan", "llvmpipe"}, graphics{"vulkan-graphics", "llvmpipe"},
        graphicsGpu{"vulkan-graphics", "NVIDIA H100 80GB HBM3"}, none{};
    auto expectTol = [](const PairTolerance& p, int lsb, uint64_t ids, float depth, double fraction) {
        EXPECT_EQ(p.tolerance.colorLsb, lsb) << p.rule;
        EXPECT_EQ(p.tolerance.maxIdMismatches, ids) << p.rule;
        EXPECT_EQ(p.tolerance.depthTolerance, depth) << p.rule;
        EXPECT_EQ(p.tolerance.maxFraction, fraction) << p.rule;
        EXPECT_LT(p.tolerance.surfaceTolerance, 0.0) << p.rule;
    };
    // docs/building-and-testing.md "Goldens": ids and depth identical, colour within 1/255, on any devices,
    // either order.
    for (bool aov : {false, true}) {
        expectTol(documentedTolerance(cuda, vulkan, aov), 1, 0, 0.0f, 0.0);
        expectTol(documentedTolerance(vulkan, cuda, aov), 1, 0, 0.0f, 0.0);
        expectTol(documentedTolerance(vulkan, vulkanGpu, aov), 1, 0, 0.0f, 0.0);
        // One backend on one device: deterministic, exact.
        expectTol(documentedTolerance(vulkan, vulkan, aov), 0, 0, 0.0f, 0.0);
        expectTol(documentedTolerance(graphics, graphics, aov), 0, 0, 0.0f, 0.0);
        // Nothing documented, or nothing recorded: exact, as before.
        expectTol(documentedTolerance(graphics, graphicsGpu, aov), 0, 0, 0.0f, 0.0);
        expectTol(documentedTolerance(none, vulkan, aov), 0, 0, 0.0f, 0.0);
        expectTol(documentedTolerance(vulkan, {"vulkan", ""}, aov), 1, 0, 0.0f, 0.0);
        EXPECT_NE(documentedTolerance(none, vulkan, aov).rule.find("names no backend"), std::string::npos);
    }
    // Against the conformant rasterizer: the oracle tests' 64 pixels and 1e-3 depth
    // (docs/building-and-testing.md "Oracle criteria", docs/antialiasing.md), 2/255 colour on all but 10% of
    // the pixels.
    expectTol(documentedTolerance(vulkan, graphics, true), 0, 64, 1e-3f, 0.001);
    expectTol(documentedTolerance(graphicsGpu, cuda, true), 0, 64, 1e-3f, 0.001);
    expectTol(documentedTolerance(vulkan, graphics, false), 2, 0, 0.0f, 0.10);
    EXPECT_NE(documentedTolerance(vulkan, graphics, false).rule.find("vulkan vs vulkan-graphics"),
              std::string::npos);
}

// `raster compare` on renders of the two Vulkan backends: the pair's documented bound by default, said
// on stdout; an explicit flag replaces its part; files without an origin are compared exactly, as before.
TEST(Compare, ToolAppliesThePairsDocumentedToleranceAndSaysWhich)
{
    ScratchDir dir("sr_compare");
    for (const std::string backend : {"vulkan", "vulkan-graphics"}) {
        ToolRun r = runTool("render builtin --width 96 --height 72 --msaa 1 -q --backend " + backend +
                            " -o " + dir.file(backend + ".png") + " --aov " + dir.file(backend + ".exr"));
        ASSERT_EQ(r.exitCode, 0) << r.stderrText;
    }
    const std::string pair = dir.file("vulkan.exr") + " " + dir.file("vulkan-graphics.exr");
    ToolRun aov = runTool("compare " + pair);
    EXPECT_EQ(aov.exitCode, 0) << aov.stdoutText;
    EXPECT_NE(aov.stdoutText.find("Tolerance: vulkan vs vulkan-graphics: at most 64 pixels"),
              std::string::npos)
        << aov.stdoutText;
    EXPECT_NE(aov.stdoutText.find(": vulkan-graphics on "), std::string::npos) << aov.stdoutText;
    EXPECT_NE(aov.stdoutText.find("computed on the host from the ids"), std::string::npos) << aov.stdoutText;
    // Depth differs between the two rasterizers (interpolation from snapped vs unsnapped vertices): exact
    // depth, asked for, fails.
    ToolRun exactDepth = runTool("compare " + pair + " --depth-tolerance 0");
    EXPECT_EQ(exactDepth.exitCode, 1) << exactDepth.stdoutText;
    EXPECT_NE(exactDepth.stdoutText.find("overridden by --depth-tolerance"), std::string::npos)
        << exactDepth.stdoutText;
    ToolRun png = runTool("compare " + dir.file("vulkan.png") + " " + dir.file("vulkan-graphics.png"));
    EXPECT_EQ(png.exitCode, 0) << png.stdoutText;
    EXPECT_NE(png.stdoutText.find("colour within 2/255"), std::string::npos) << png.stdoutText;

    // The same pixels without an origin: exact, with the note.
    for (const std::string backend : {"vulkan", "vulkan-graphics"}) {
        auto aovImage = readAovExr(dir.file(backend + ".exr"));
        ASSERT_TRUE(aovImage.ok());
        ASSERT_TRUE(writeAovExr(dir.file(backend + "-plain.exr"), *aovImage).ok());
    }
    ToolRun plain =
        runTool("compare " + dir.file("vulkan-plain.exr") + " " + dir.file("vulkan-graphics-plain.exr"));
    EXPECT_EQ(plain.exitCode, 1) << plain.stdoutText;
    EXPECT_NE(plain.stdoutText.find("no backend recorded"), std::string::npos) << plain.stdoutText;
    EXPECT_NE(plain.stdoutText.find("Tolerance: exact: a file names no backend"), std::string::npos)
        << plain.stdoutText;
    EXPECT_EQ(runTool("compare " + pair + " --max-fraction 2").exitCode, 2);
}

// A golden names CUDA in its own metadata; a copy without metadata (a golden from before it was
// written) is known as CUDA's by the provenance JSON beside it. Against a Vulkan render of its
// arguments the goldens' criterion applies either way.
TEST(Compare, GoldensAreKnownByTheirMetadataOrProvenance)
{
    ScratchDir dir("sr_compare");
    const std::string golden = sourceDir() + "/tests/golden/builtin";
    ToolRun r = runTool("render builtin --width 256 --height 192 --msaa 1 -q --backend vulkan -o " +
                        dir.file("b.png") + " --aov " + dir.file("b.exr"));
    ASSERT_EQ(r.exitCode, 0) << r.stderrText;
    // The bare copy: pixels and channels alone, the provenance JSON under the same stem.
    auto png = readPng(golden + ".png");
    ASSERT_TRUE(png.ok()) << png.error().message;
    ASSERT_TRUE(writePng(dir.file("bare.png"), *png).ok());
    auto exr = readAovExr(golden + ".exr");
    ASSERT_TRUE(exr.ok()) << exr.error().message;
    ASSERT_TRUE(writeAovExr(dir.file("bare.exr"), *exr).ok());
    std::filesystem::copy_file(golden + ".json", dir.file("bare.json"));
    for (const std::string ext : {".png", ".exr"}) {
        for (const auto& [file, origin] :
             {std::pair<std::string, std::string>{golden + ext, "(from its metadata)"},
              {dir.file("bare" + ext), "bare.json"}}) {
            ToolRun c = runTool("compare " + file + " " + dir.file("b" + ext));
            EXPECT_EQ(c.exitCode, 0) << c.stdoutText;
            EXPECT_NE(c.stdoutText.find("cuda on NVIDIA"), std::string::npos) << c.stdoutText;
            EXPECT_NE(c.stdoutText.find(origin), std::string::npos) << c.stdoutText;
            EXPECT_NE(c.stdoutText.find("cuda vs vulkan: ids, coverage and depth exact, colour within 1/255"),
                      std::string::npos)
                << c.stdoutText;
        }
    }
}

}  // namespace
}  // namespace sr::test
