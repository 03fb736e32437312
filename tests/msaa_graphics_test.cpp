// msaa_graphics_test.cpp - anti-aliasing (MSAA and SSAA) of the `vulkan-graphics` reference backend on
// the machine's first suitable Vulkan device (lavapipe in CI) with validation on, against expectations
// that owe nothing to the backend: the spec's table of standard sample locations, per-sample coverage of
// straight edges worked out from that table, the linear mix of a flat colour with the background, and
// SSAA as the box filter of a render at the larger size. The device's own refusal of a sample count it
// does not offer is checked too. No Vulkan device is a failure unless SR_ALLOW_MISSING_BACKENDS lists
// vulkan.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "test_util.h"
#include "vulkan/vulkan_device_internal.h"
#include "vulkan/vulkan_graphics.h"

namespace sr::test {
namespace {

// The spec's standard sample locations at 4 samples per pixel ("Standard sample locations"), in pixels
// from the pixel's top-left corner, sample 0 first.
const glm::dvec2 kStandard4x[4] = {{0.375, 0.125}, {0.875, 0.375}, {0.125, 0.625}, {0.625, 0.875}};

// Clip coordinates (w = 1, depth z) of the point (x, y) in pixels of a width x height image; NDC y = -1
// is the top row. Every coordinate the tests use is a multiple of 1/16 pixel on power-of-two images,
// so the conversion is exact and the hardware's 1/256 pixel snapping moves nothing.
glm::vec4 atPixel(double x, double y, uint32_t width, uint32_t height, float z = 0.5f)
{
    return glm::vec4(float(2.0 * x / width - 1.0), float(2.0 * y / height - 1.0), z, 1.0f);
}

double srgbToLinear(double c)
{
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// Linear RGB of a packed sRGB RGBA8 word.
glm::vec3 unpackLinear(uint32_t word)
{
    glm::vec3 c;
    for (int k = 0; k < 3; ++k) c[k] = float(srgbToLinear(double((word >> (8 * k)) & 0xffu) / 255.0));
    return c;
}

class MsaaGraphicsTest : public GraphicsTest {
protected:
    RenderOutput render(const Scene& scene, const RenderSettings& settings,
                        const CameraMatrices& camera = identityCamera())
    {
        auto out = renderVulkanGraphics(scene, camera, settings, -1);
        EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
        return out.ok() ? std::move(*out) : RenderOutput{};
    }

    size_t errorsBefore_ = 0;
};

// One tiny triangle per standard sample location of a 4x pixel: triangle k surrounds sample k of pixel
// (2k + 1, 3) by 1/8 pixel and lies at least 1/8 pixel from every other sample location, so exactly
// that one sample reports its id, with the triangle's depth, and every other sample of the image stays
// empty.
TEST_F(MsaaGraphicsTest, EachStandardSampleLocationIsCoveredAlone)
{
    const uint32_t w = 8, h = 8;
    std::vector<glm::vec4> corners;
    for (int k = 0; k < 4; ++k) {
        const glm::dvec2 p = glm::dvec2(2 * k + 1, 3) + kStandard4x[k];
        const float z = 0.25f + 0.125f * float(k);
        corners.push_back(atPixel(p.x - 0.0625, p.y - 0.0625, w, h, z));
        corners.push_back(atPixel(p.x + 0.125, p.y - 0.0625, w, h, z));
        corners.push_back(atPixel(p.x - 0.0625, p.y + 0.125, w, h, z));
    }
    RenderSettings s = unlitSettings(w, h);
    s.msaa = 4;
    s.aovSamples = true;
    RenderOutput out = render(clipSpaceScene(corners), s);
    const SampleAovs& samples = out.samples;
    ASSERT_EQ(samples.rasterWidth, w);
    ASSERT_EQ(samples.rasterHeight, h);
    ASSERT_EQ(samples.samples, 4u);
    ASSERT_EQ(samples.id.size(), size_t(4) * w * h);
    ASSERT_EQ(samples.depth.size(), size_t(4) * w * h);
    for (uint32_t s4 = 0; s4 < 4; ++s4)
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                const size_t i = size_t(s4) * w * h + size_t(y) * w + x;
                const bool owned = y == 3 && x % 2 == 1 && (x - 1) / 2 == s4;
                if (owned) {
                    EXPECT_EQ(samples.id[i], s4) << "sample " << s4 << " of " << x << "," << y;
                    EXPECT_EQ(samples.depth[i], 0.25f + 0.125f * float(s4)) << "sample " << s4;
                } else {
                    EXPECT_EQ(samples.id[i], EMPTY_ID) << "sample " << s4 << " of " << x << "," << y;
                    EXPECT_EQ(samples.depth[i], 1.0f) << "sample " << s4 << " of " << x << "," << y;
                }
            }
    // The id and Z AOVs report sample 0: only pixel (1, 3) holds a triangle there.
    ASSERT_EQ(out.aov.id.size(), size_t(w) * h);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x)
            EXPECT_EQ(out.aov.id[size_t(y) * w + x], x == 1 && y == 3 ? 0u : EMPTY_ID) << x << "," << y;
}

// A 45-degree edge y = x + b (pixels) bounding a large triangle that covers y - x > b. Sample s of pixel
// (px, py) is covered when (py + sy) - (px + sx) > b; no sample lies on the edge for these offsets
// (b is an odd multiple of 1/8, y - x at a sample is a multiple of 1/4). Per pixel the number of
// covered samples is worked out from the spec's table; along the edge it is 3, 2 and 1 for the three
// offsets, and 4 or 0 away from it.
TEST_F(MsaaGraphicsTest, DiagonalEdgeCoverageMatchesTheStandardLocations)
{
    const uint32_t w = 16, h = 16;
    RenderSettings s = unlitSettings(w, h);
    s.msaa = 4;
    s.aovSamples = true;
    std::vector<int> edgeCounts;
    for (double b : {-0.375, 0.125, 0.375}) {
        const std::vector<glm::vec4> corners = {atPixel(-8, -8 + b, w, h), atPixel(24, 24 + b, w, h),
                                                atPixel(-8, 24 + b, w, h)};
        RenderOutput out = render(clipSpaceScene(corners), s);
        ASSERT_EQ(out.samples.id.size(), size_t(4) * w * h) << b;
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                int expected = 0, covered = 0;
                for (uint32_t k = 0; k < 4; ++k) {
                    expected += (y + kStandard4x[k].y) - (x + kStandard4x[k].x) > b;
                    const uint32_t id = out.samples.id[size_t(k) * w * h + size_t(y) * w + x];
                    ASSERT_TRUE(id == 0 || id == EMPTY_ID) << id;
                    covered += id == 0;
                }
                EXPECT_EQ(covered, expected) << "b " << b << " pixel " << x << "," << y;
                if (x == y) edgeCounts.push_back(expected);
            }
    }
    // The expectation itself goes through every partial count.
    for (int count : {1, 2, 3})
        EXPECT_NE(std::find(edgeCounts.begin(), edgeCounts.end(), count), edgeCounts.end()) << count;
}

// A triangle whose only edge inside the image is vertical, through the middle of column 4, covers
// samples 0 and 2 of that column's pixels (x offsets 0.375 and 0.125): their colour is the linear mean
// of the triangle's colour and the background, then sRGB-encoded, not the mean of the encoded values.
// (The other edges stay outside: a pixel centre outside the triangle would shade with clamped,
// extrapolated barycentrics.)
TEST_F(MsaaGraphicsTest, HalfCoveredPixelIsTheLinearMixOfColourAndBackground)
{
    const uint32_t w = 8, h = 8;
    const glm::vec4 color(0.9f, 0.6f, 0.1f, 1.0f);
    Scene scene = clipSpaceScene({atPixel(4.5, -96, w, h), atPixel(4.5, 104, w, h), atPixel(-196, 4, w, h)});
    scene.colors.assign(scene.vertexCount(), color);
    RenderSettings s = unlitSettings(w, h);
    s.background = glm::vec3(0.05f, 0.1f, 0.4f);
    s.msaa = 4;
    RenderOutput out = render(scene, s);
    ASSERT_EQ(out.color.pixels.size(), size_t(w) * h);
    const glm::vec3 full(color), empty = s.background;
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const glm::vec3 expected = x < 4 ? full : x == 4 ? 0.5f * (full + empty) : empty;
            EXPECT_LE(channelDifference(out.color.pixels[size_t(y) * w + x], packRgba8(expected)), 1)
                << x << "," << y;
        }
    // The mean of the encoded bytes is far off: the mean is taken in linear space.
    const uint32_t a = packRgba8(full), b = packRgba8(empty);
    uint32_t encodedMean = 0;
    for (int shift = 0; shift < 32; shift += 8)
        encodedMean |= ((((a >> shift) & 0xffu) + ((b >> shift) & 0xffu) + 1) / 2) << shift;
    EXPECT_GT(channelDifference(out.color.pixels[4], encodedMean), 10);
}

// SSAA 2 draws the raster grid of a render at twice the size: its ids and depths are those of the
// larger render's pixel (2x + 1, 2y + 1) (aovSampleIndex), bit for bit, and its colours the box filter of
// the larger render's four pixels in linear space (within 1/255: the larger render's colours are
// rounded to 8 bits). Also with MSAA 4 on top, against a 4x render at twice the size.
TEST_F(MsaaGraphicsTest, SupersamplingIsTheBoxFilterOfTheLargerRender)
{
    const uint32_t w = 32, h = 32;
    for (uint32_t msaa : {1u, 4u}) {
        FramedScene framed = framedBuiltin(w, h);
        RenderSettings small = framed.settings, large = framed.settings;
        small.ssaa = 2;
        small.msaa = large.msaa = msaa;
        large.width = 2 * w;
        large.height = 2 * h;
        RenderOutput out = render(framed.scene, small, framed.camera);
        RenderOutput reference = render(framed.scene, large, framed.camera);
        ASSERT_EQ(out.color.pixels.size(), size_t(w) * h) << msaa;
        ASSERT_EQ(out.color.width, w);
        ASSERT_EQ(out.aov.id.size(), size_t(w) * h);
        ASSERT_EQ(reference.color.pixels.size(), size_t(4) * w * h) << msaa;
        EXPECT_EQ(out.params.width, 2 * w);
        EXPECT_EQ(out.params.ssaa, 2u);
        size_t covered = 0;
        int worst = 0;
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                const size_t i = size_t(y) * w + x;
                const size_t representative = aovSampleIndex(x, y, 2 * w, 2);
                ASSERT_EQ(out.aov.id[i], reference.aov.id[representative]) << msaa << ": " << x << "," << y;
                ASSERT_EQ(out.aov.depth[i], reference.aov.depth[representative])
                    << msaa << ": " << x << "," << y;
                covered += out.aov.id[i] != EMPTY_ID;
                glm::vec3 sum(0.0f);
                for (uint32_t dy = 0; dy < 2; ++dy)
                    for (uint32_t dx = 0; dx < 2; ++dx)
                        sum += unpackLinear(reference.color.pixels[size_t(2 * y + dy) * 2 * w + 2 * x + dx]);
                worst = std::max(worst, channelDifference(out.color.pixels[i], packRgba8(0.25f * sum)));
            }
        EXPECT_GT(covered, size_t(w) * h / 10) << msaa;  // the camera frames the scene: a real comparison
        EXPECT_LE(worst, 1) << msaa;
    }
}

// Without aovSamples no samples come back; the id and Z AOVs are sample 0 either way, and a render
// without anti-aliasing reports its one sample per pixel when asked.
TEST_F(MsaaGraphicsTest, SampleAovsOnlyWhenAskedAndConsistentWithTheAovs)
{
    const uint32_t w = 16, h = 16;
    const Scene scene = clipSpaceScene(cullingTriangles());
    RenderSettings s = unlitSettings(w, h);
    s.msaa = 4;
    RenderOutput plain = render(scene, s);
    EXPECT_TRUE(plain.samples.id.empty());
    EXPECT_TRUE(plain.samples.depth.empty());
    s.aovSamples = true;
    RenderOutput all = render(scene, s);
    ASSERT_EQ(all.samples.id.size(), size_t(4) * w * h);
    EXPECT_EQ(plain.aov.id, all.aov.id);
    EXPECT_EQ(plain.color.pixels, all.color.pixels);
    for (size_t i = 0; i < size_t(w) * h; ++i) {
        EXPECT_EQ(all.aov.id[i], all.samples.id[i]) << i;
        EXPECT_EQ(all.aov.depth[i], all.samples.depth[i]) << i;
    }
    // The bench's visibility-only pass sees the same samples.
    s.visibilityOnly = true;
    EXPECT_EQ(render(scene, s).samples.id, all.samples.id);

    s.msaa = 1;
    s.visibilityOnly = false;
    RenderOutput single = render(scene, s);
    EXPECT_EQ(single.samples.samples, 1u);
    EXPECT_EQ(single.samples.rasterWidth, w);
    EXPECT_EQ(single.samples.id, single.aov.id);
    EXPECT_EQ(single.samples.depth, single.aov.depth);
}

// A sample count the device does not offer for these attachments is one Usage line naming the counts
// it does offer. lavapipe offers 1 and 4 only, so there 2, 8 and 16 must all be refused; other devices
// may accept some of them, which then must render.
TEST_F(MsaaGraphicsTest, UnofferedSampleCountIsAOneLineUsageError)
{
    const Scene scene = clipSpaceScene(clipQuad(-1, -1, 1, 1, 0.5f));
    std::string deviceName;
    for (uint32_t msaa : {2u, 8u, 16u}) {
        RenderSettings s = testSettings(8, 8);
        s.msaa = msaa;
        auto out = renderVulkanGraphics(scene, identityCamera(), s, -1);
        if (out.ok()) {
            deviceName = out->device.name;
            EXPECT_EQ(deviceName.find("llvmpipe"), std::string::npos) << msaa << "x accepted on lavapipe";
            EXPECT_EQ(countId(out->aov, EMPTY_ID), 0u) << msaa;
            continue;
        }
        EXPECT_EQ(out.error().code, ExitCode::Usage) << out.error().message;
        EXPECT_TRUE(isOneLine(out.error().message)) << out.error().message;
        EXPECT_NE(out.error().message.find(std::to_string(msaa) + "x MSAA"), std::string::npos)
            << out.error().message;
        EXPECT_NE(out.error().message.find("it offers 1x"), std::string::npos) << out.error().message;
        if (out.error().message.find("llvmpipe") != std::string::npos) {
            EXPECT_NE(out.error().message.find("it offers 1x, 4x"), std::string::npos) << out.error().message;
        }
    }
}

}  // namespace
}  // namespace sr::test
