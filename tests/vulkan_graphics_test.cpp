// vulkan_graphics_test.cpp - the `vulkan-graphics` reference backend on the machine's first suitable
// Vulkan device (lavapipe in CI) with validation on: coverage, depth and tie rules on clip-space
// scenes, facing culling as the compute backend does it, agreement with the compute backend on the
// built-in scene, and the error paths. No Vulkan device is a failure, never a skip.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "test_util.h"
#include "vulkan/vulkan_device_internal.h"
#include "vulkan/vulkan_graphics.h"

namespace sr::test {
namespace {

// Two triangles forming an axis-aligned rectangle in NDC at depth z (as in render_test.cpp).
std::vector<glm::vec4> quad(float x0, float y0, float x1, float y1, float z)
{
    return {{x0, y0, z, 1}, {x1, y0, z, 1}, {x1, y1, z, 1}, {x0, y0, z, 1}, {x1, y1, z, 1}, {x0, y1, z, 1}};
}

std::vector<glm::vec4> concat(std::vector<glm::vec4> a, const std::vector<glm::vec4>& b)
{
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

bool isOneLine(const std::string& message)
{
    return !message.empty() && message.find('\n') == std::string::npos;
}

// Largest difference of the R, G, B and A bytes of two packed RGBA8 words.
int channelDifference(uint32_t a, uint32_t b)
{
    int worst = 0;
    for (int shift = 0; shift < 32; shift += 8) {
        int ca = int((a >> shift) & 0xffu);
        int cb = int((b >> shift) & 0xffu);
        worst = std::max(worst, std::abs(ca - cb));
    }
    return worst;
}

class VulkanGraphicsTest : public ::testing::Test {
protected:
    void SetUp() override
    {
        // ctest sets this too; setting it here keeps validation on when the binary is run by hand.
        setenv("SR_VULKAN_VALIDATION", "1", 1);
        errorsBefore_ = vulkanValidationErrorCount();
    }

    // Every render creates and destroys its own device, so leaks would already be reported here.
    void TearDown() override { EXPECT_EQ(vulkanValidationErrorCount(), errorsBefore_); }

    RenderOutput render(const Scene& scene, const RenderSettings& settings,
                        const CameraMatrices& camera = identityCamera())
    {
        auto out = renderVulkanGraphics(scene, camera, settings, -1);
        EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
        return out.ok() ? std::move(*out) : RenderOutput{};
    }

    RenderOutput renderCompute(const Scene& scene, const RenderSettings& settings,
                               const CameraMatrices& camera = identityCamera())
    {
        auto device = makeVulkanDevice(-1);
        EXPECT_TRUE(device.ok()) << (device.ok() ? "" : device.error().message);
        if (!device.ok()) return RenderOutput{};
        auto out = renderScene(**device, scene, camera, settings);
        EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
        return out.ok() ? std::move(*out) : RenderOutput{};
    }

    size_t errorsBefore_ = 0;
};

TEST_F(VulkanGraphicsTest, QuadCoversExactlyTheLeftHalf)
{
    const uint32_t w = 64, h = 48;
    RenderSettings s = testSettings(w, h);
    RenderOutput out = render(clipSpaceScene(quad(-1, -1, 0, 1, 0.5f)), s);
    ASSERT_EQ(out.aov.id.size(), size_t(w) * h);
    ASSERT_EQ(out.color.pixels.size(), size_t(w) * h);
    EXPECT_EQ(out.aov.width, w);
    EXPECT_EQ(out.color.height, h);
    const uint32_t background = packRgba8(s.background);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            if (x < w / 2) {
                ASSERT_TRUE(out.aov.id[i] == 0 || out.aov.id[i] == 1) << x << "," << y;
                ASSERT_EQ(out.aov.depth[i], 0.5f) << x << "," << y;
                ASSERT_NE(out.color.pixels[i], background) << x << "," << y;
            } else {
                ASSERT_EQ(out.aov.id[i], EMPTY_ID) << x << "," << y;
                ASSERT_EQ(out.aov.depth[i], 1.0f) << x << "," << y;
                ASSERT_EQ(out.color.pixels[i], background) << x << "," << y;
            }
        }
}

TEST_F(VulkanGraphicsTest, NearerSurfaceWinsWhateverTheOrder)
{
    const uint32_t w = 40, h = 40;
    for (bool nearFirst : {true, false}) {
        auto nearQuad = quad(-1, -1, 1, 1, 0.3f), farQuad = quad(-0.5f, -1, 1, 0.5f, 0.7f);
        Scene scene = clipSpaceScene(nearFirst ? concat(nearQuad, farQuad) : concat(farQuad, nearQuad));
        RenderOutput out = render(scene, testSettings(w, h));
        ASSERT_EQ(out.aov.id.size(), size_t(w) * h);
        const uint32_t nearBase = nearFirst ? 0 : 2;
        for (size_t i = 0; i < out.aov.id.size(); ++i) {
            ASSERT_TRUE(out.aov.id[i] == nearBase || out.aov.id[i] == nearBase + 1) << i;
            ASSERT_EQ(out.aov.depth[i], 0.3f) << i;
        }
    }
}

TEST_F(VulkanGraphicsTest, EqualDepthsResolveToTheFirstTriangleDrawn)
{
    Scene scene = clipSpaceScene(concat(quad(-1, -1, 1, 1, 0.5f), quad(-1, -1, 1, 1, 0.5f)));
    RenderOutput out = render(scene, testSettings(32, 32));
    ASSERT_EQ(out.aov.id.size(), 32u * 32u);
    for (uint32_t id : out.aov.id) ASSERT_TRUE(id == 0 || id == 1) << id;
}

// The scene of render_test.cpp's FrontBackAndDoubleSidedCulling, with the same expectations, and the
// same id images as the compute backend.
TEST_F(VulkanGraphicsTest, FrontBackAndDoubleSidedCullingAsInTheComputeBackend)
{
    std::vector<glm::vec4> tris = cullingTriangles();  // 0: front-facing, 1: back-facing
    RenderSettings s = testSettings(64, 64);
    s.cullMode = CULL_BACK;
    RenderOutput back = render(clipSpaceScene(tris), s);
    EXPECT_GT(countId(back.aov, 0), 100u);
    EXPECT_EQ(countId(back.aov, 1), 0u);
    EXPECT_EQ(back.aov.id, renderCompute(clipSpaceScene(tris), s).aov.id);
    s.cullMode = CULL_FRONT;
    RenderOutput front = render(clipSpaceScene(tris), s);
    EXPECT_EQ(countId(front.aov, 0), 0u);
    EXPECT_EQ(countId(front.aov, 1), countId(back.aov, 0));  // mirror images: same pixel count
    EXPECT_EQ(front.aov.id, renderCompute(clipSpaceScene(tris), s).aov.id);
    const Scene twoSidedScene = clipSpaceScene(tris, {TRI_FLAG_DOUBLE_SIDED, TRI_FLAG_DOUBLE_SIDED});
    RenderOutput twoSided = render(twoSidedScene, s);
    EXPECT_EQ(countId(twoSided.aov, 0), countId(back.aov, 0));
    EXPECT_EQ(countId(twoSided.aov, 1), countId(front.aov, 1));
    EXPECT_EQ(twoSided.aov.id, renderCompute(twoSidedScene, s).aov.id);
}

// The reference check this backend exists for: the hardware (here Mesa's) rasterizer and the compute
// pipeline see the same scene through the same clip coordinates and shading code.
TEST_F(VulkanGraphicsTest, BuiltinSceneMatchesTheComputeBackend)
{
    const uint32_t w = 128, h = 96;
    const Scene scene = builtinScene();
    auto camera = resolveCamera(CameraSpec{}, scene, w, h);
    ASSERT_TRUE(camera.ok()) << camera.error().message;
    RenderSettings s;
    s.width = w;
    s.height = h;
    s.warmup = 0;
    s.repeat = 1;
    RenderOutput graphics = render(scene, s, *camera);
    RenderOutput compute = renderCompute(scene, s, *camera);
    const size_t pixels = size_t(w) * h;
    ASSERT_EQ(graphics.aov.id.size(), pixels);
    ASSERT_EQ(compute.aov.id.size(), pixels);

    size_t idsAgree = 0, covered = 0, colorsOff = 0;
    int worstColor = 0;
    float worstDepth = 0.0f;
    for (size_t i = 0; i < pixels; ++i) {
        covered += compute.aov.id[i] != EMPTY_ID;
        if (graphics.aov.id[i] != compute.aov.id[i]) continue;
        ++idsAgree;
        const int difference = channelDifference(graphics.color.pixels[i], compute.color.pixels[i]);
        worstColor = std::max(worstColor, difference);
        colorsOff += difference > 0;
        worstDepth = std::max(worstDepth, std::abs(graphics.aov.depth[i] - compute.aov.depth[i]));
    }
    std::printf(
        "built-in scene %ux%u: ids agree at %zu of %zu pixels (%zu covered by compute); where they "
        "agree, %zu colours differ, by at most %d LSB, and depths by at most %g\n",
        w, h, idsAgree, pixels, covered, colorsOff, worstColor, double(worstDepth));
    EXPECT_GT(covered, pixels / 10);  // the camera frames the scene: a real comparison
    EXPECT_GE(double(idsAgree), 0.999 * double(pixels));
    EXPECT_LE(worstColor, 1);
    // The compute pipeline interpolates depth between its vertices snapped to 1/256 pixel, Mesa's
    // rasterizer between the unsnapped ones: the two planes differ by the depth change over up to
    // half a subpixel, which stays far below this on the built-in scene.
    EXPECT_LT(worstDepth, 1e-3f);
}

TEST_F(VulkanGraphicsTest, ReportsTimingsStatsAndDevice)
{
    RenderSettings s = testSettings(16, 16);
    s.warmup = 1;
    s.repeat = 3;
    RenderOutput out = render(clipSpaceScene(quad(-1, -1, 1, 1, 0.5f)), s);
    ASSERT_EQ(out.stages.size(), 1u);
    EXPECT_EQ(out.stages[0].name, "draw");
    EXPECT_GE(out.stages[0].minMs, 0.0);
    EXPECT_LE(out.stages[0].minMs, out.stages[0].medianMs);
    EXPECT_LE(out.stages[0].medianMs, out.stages[0].maxMs);
    EXPECT_EQ(out.total.medianMs, out.stages[0].medianMs);
    EXPECT_EQ(out.stats.trianglesIn, 2u);
    EXPECT_GT(out.peakDeviceBytes, 3u * 16u * 16u * 4u);  // at least the three attachments
    EXPECT_EQ(out.device.backend, "vulkan-graphics");
    EXPECT_FALSE(out.device.name.empty());
    EXPECT_FALSE(out.device.driver.empty());
    EXPECT_EQ(out.device.isCpu, out.device.name.find("llvmpipe") != std::string::npos);
    EXPECT_EQ(out.params.width, 16u);
    EXPECT_EQ(out.params.triangleCount, 2u);
}

TEST_F(VulkanGraphicsTest, OutOfRangeDeviceIndexIsAnError)
{
    const Scene scene = clipSpaceScene(quad(-1, -1, 1, 1, 0.5f));
    for (int index : {1000, -2}) {
        auto out = renderVulkanGraphics(scene, identityCamera(), testSettings(8, 8), index);
        ASSERT_FALSE(out.ok()) << index;
        EXPECT_EQ(out.error().code, ExitCode::Usage);
        EXPECT_TRUE(isOneLine(out.error().message)) << out.error().message;
        EXPECT_NE(out.error().message.find("out of range"), std::string::npos) << out.error().message;
    }
}

TEST_F(VulkanGraphicsTest, RejectsWhatRenderSceneRejects)
{
    const Scene scene = clipSpaceScene(quad(-1, -1, 1, 1, 0.5f));
    RenderSettings noRepeat = testSettings(8, 8);
    noRepeat.repeat = 0;
    RenderSettings tooWide = testSettings(MAX_FRAMEBUFFER_DIM + 1, 8);
    for (const RenderSettings& s : {noRepeat, tooWide}) {
        auto out = renderVulkanGraphics(scene, identityCamera(), s, -1);
        ASSERT_FALSE(out.ok());
        EXPECT_EQ(out.error().code, ExitCode::Usage);
        EXPECT_TRUE(isOneLine(out.error().message)) << out.error().message;
    }
    auto empty = renderVulkanGraphics(Scene{}, identityCamera(), testSettings(8, 8), -1);
    ASSERT_FALSE(empty.ok());
    EXPECT_EQ(empty.error().code, ExitCode::Usage);
}

}  // namespace
}  // namespace sr::test
