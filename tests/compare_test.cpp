// compare_test.cpp - `raster compare` statistics against hand-computed values, and its exit codes.
#include <cmath>

#include <gtest/gtest.h>

#include "io/compare.h"
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

}  // namespace
}  // namespace sr::test
