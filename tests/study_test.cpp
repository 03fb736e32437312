// study_test.cpp - the accuracy half of `raster study` (host/cli/study.h): its image metric against
// hand-computed values, and two of the study's central claims against the supersampled reference:
// anti-aliasing error falls with every doubling of the sample count, and trilinear filtering beats
// bilinear on a minified grazing texture. The stability half is in study_stress_test.cpp.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "cli/study.h"
#include "test_util.h"

namespace sr::test {
namespace {

// PSNR of one channel off by d in one of n pixels: MSE = d^2 / (3 n) over R, G and B.
TEST(StudyMetrics, PsnrAndMaxErrorMatchTheirDefinitions)
{
    RgbaImage a{4, 2, std::vector<uint32_t>(8, 0xff204060u)};
    RgbaImage b = a;
    EXPECT_TRUE(std::isinf(imageError(a, b).psnr));
    EXPECT_EQ(imageError(a, b).maxError, 0);
    b.pixels[3] = 0xff20406au;  // R + 10
    ImageError e = imageError(b, a);
    EXPECT_EQ(e.maxError, 10);
    EXPECT_NEAR(e.psnr, 10.0 * std::log10(255.0 * 255.0 / (100.0 / 24.0)), 1e-9);
    b.pixels[5] = 0x00204060u;  // alpha is not compared
    EXPECT_EQ(imageError(b, a).maxError, 10);
}

class StudyClaimsTest : public BackendTest {
protected:
    // PSNR of `s` against the study's reference (SSAA 4 x MSAA 16, trilinear) of the same frame.
    double psnr(const FramedScene& f, RenderSettings s)
    {
        RenderSettings ref = f.settings;
        ref.msaa = 16;
        ref.ssaa = 4;
        ref.textureFilter = TEXTURE_FILTER_TRILINEAR;
        return imageError(render(f.scene, s, f.camera).color, render(f.scene, ref, f.camera).color).psnr;
    }
};

// Each doubling of the coverage samples brings the built-in scene's edges closer to the 64-sample
// reference: the box filter's estimate of a pixel's coverage has less error with more samples.
TEST_P(StudyClaimsTest, AntiAliasingErrorFallsWithTheSampleCount)
{
    FramedScene f = framedBuiltin(64, 48);
    double previous = 0.0;
    for (uint32_t msaa : {1u, 2u, 4u, 8u, 16u}) {
        RenderSettings s = f.settings;
        s.msaa = msaa;
        double p = psnr(f, s);
        EXPECT_GT(p, previous) << msaa << "x";
        previous = p;
    }
}

// The checkerboard plane seen at a grazing angle is minified far from the camera: bilinear filtering
// of the full-resolution texture aliases there, trilinear averages the texels a pixel covers, as the
// reference's 64 samples per pixel do.
TEST_P(StudyClaimsTest, TrilinearBeatsBilinearOnAGrazingPlane)
{
    auto scene = builtinSceneNamed("builtin:checker");
    ASSERT_TRUE(scene.ok());
    auto spec = parseCameraSpec("orbit:0,6,12");
    ASSERT_TRUE(spec.ok());
    auto camera = resolveCamera(*spec, *scene, 96, 72);
    ASSERT_TRUE(camera.ok());
    FramedScene f{std::move(*scene), *camera, testSettings(96, 72)};
    RenderSettings bilinear = f.settings, trilinear = f.settings;
    bilinear.textureFilter = TEXTURE_FILTER_BILINEAR;
    trilinear.textureFilter = TEXTURE_FILTER_TRILINEAR;
    EXPECT_GT(psnr(f, trilinear), psnr(f, bilinear) + 1.0);
}

INSTANTIATE_TEST_SUITE_P(Backends, StudyClaimsTest, ::testing::Values("vulkan", "cuda"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace sr::test
