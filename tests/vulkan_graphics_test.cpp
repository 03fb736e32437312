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

std::vector<glm::vec4> concat(std::vector<glm::vec4> a, const std::vector<glm::vec4>& b)
{
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

// A 4x4 black and white checkerboard (texel (i, j) white where i + j is even, row j = 0 on top) with its
// full mip chain, sampled NEAREST without mipmaps and wrapped by `wrap`. Its left half has alpha 0 when
// `transparentLeft` is set. The smaller levels are the box averages (sRGB 188 is linear 0.5); the
// tests never sample them, but a SceneTexture always carries its whole chain.
SceneTexture checkerboard(uint32_t wrap, bool transparentLeft = false)
{
    SceneTexture t;
    t.name = "checkerboard";
    t.width = t.height = 4;
    t.levels = 3;
    t.srgb = true;
    for (uint32_t j = 0; j < 4; ++j)
        for (uint32_t i = 0; i < 4; ++i) {
            const uint32_t rgb = (i + j) % 2 == 0 ? 0x00FFFFFFu : 0u;
            t.texels.push_back(rgb | (transparentLeft && i < 2 ? 0u : 0xFF000000u));
        }
    t.texels.insert(t.texels.end(), 4 + 1, 0xFFBCBCBCu);  // levels 1 (2x2) and 2 (1x1)
    t.sampler = TextureSampler{wrap, wrap, FILTER_NEAREST, FILTER_NEAREST, MIPMAP_NONE};
    return t;
}

// The checkerboard's colour at texel (i, j), wrapped by REPEAT (CLAMP_TO_EDGE callers stay inside).
uint32_t checkerWord(int i, int j)
{
    return ((i % 4) + (j % 4)) % 2 == 0 ? 0xFFFFFFFFu : 0xFF000000u;
}

// A screen-filling quad at depth 0.5 (two triangles) with one material textured by `texture`, and
// texture coordinates uvScale * (0..1) across it: at the centre of pixel (x, y) of a w x h image,
// u = uvScale * (x + 0.5) / w and v = uvScale * (y + 0.5) / h (NDC y = -1, the top row, is v = 0).
Scene texturedQuad(const SceneTexture& texture, float uvScale, uint32_t alphaMode = ALPHA_OPAQUE)
{
    Scene scene = clipSpaceScene(clipQuad(-1, -1, 1, 1, 0.5f));
    for (const glm::vec4& p : scene.positions)
        scene.texcoords.push_back(
            glm::vec4((p.x + 1.0f) * 0.5f * uvScale, (p.y + 1.0f) * 0.5f * uvScale, 0, 0));
    SceneMaterial material;
    material.baseColorTexture = 0;
    material.alphaMode = alphaMode;
    material.alphaCutoff = 0.5f;
    scene.materials = {material};
    scene.triMaterials.assign(scene.triangleCount(), 0);
    if (alphaMode == ALPHA_MASK)
        for (uint32_t& flags : scene.triFlags) flags |= TRI_FLAG_ALPHA_MASK;
    scene.textures = {texture};
    return scene;
}

// Whether coordinate `texels` (u or v times the texture size) lies within 1e-3 texel of a texel border,
// where the nearest texel is a matter of rounding.
bool nearTexelBorder(float texels)
{
    return std::abs(texels - std::round(texels)) < 1e-3f;
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
    RenderOutput out = render(clipSpaceScene(clipQuad(-1, -1, 0, 1, 0.5f)), s);
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
        auto nearQuad = clipQuad(-1, -1, 1, 1, 0.3f), farQuad = clipQuad(-0.5f, -1, 1, 0.5f, 0.7f);
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
    Scene scene = clipSpaceScene(concat(clipQuad(-1, -1, 1, 1, 0.5f), clipQuad(-1, -1, 1, 1, 0.5f)));
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

// Hardware texturing through a real image and sampler: NEAREST returns texel (floor(4u), floor(4v)).
TEST_F(VulkanGraphicsTest, NearestCheckerboardShowsTheTexelUnderEachPixelCentre)
{
    const uint32_t w = 64, h = 64;
    RenderOutput out = render(texturedQuad(checkerboard(WRAP_CLAMP_TO_EDGE), 1.0f), unlitSettings(w, h));
    ASSERT_EQ(out.color.pixels.size(), size_t(w) * h);
    size_t checked = 0;
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const float u = (float(x) + 0.5f) / float(w), v = (float(y) + 0.5f) / float(h);
            if (nearTexelBorder(4.0f * u) || nearTexelBorder(4.0f * v)) continue;
            const size_t i = size_t(y) * w + x;
            ASSERT_EQ(out.color.pixels[i], checkerWord(int(4.0f * u), int(4.0f * v))) << x << "," << y;
            ASSERT_NE(out.aov.id[i], EMPTY_ID) << x << "," << y;
            ++checked;
        }
    EXPECT_EQ(checked, size_t(w) * h);  // no pixel centre of this layout is near a texel border
}

// The texcoord debug view shows the interpolated (u, v) as red and green.
TEST_F(VulkanGraphicsTest, TexcoordViewShowsTheInterpolatedUv)
{
    const uint32_t w = 64, h = 64;
    RenderSettings s = unlitSettings(w, h);
    s.shadingMode = SHADING_TEXCOORD;
    RenderOutput out = render(texturedQuad(checkerboard(WRAP_CLAMP_TO_EDGE), 1.0f), s);
    ASSERT_EQ(out.color.pixels.size(), size_t(w) * h);
    int worst = 0;
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const glm::vec3 uv((float(x) + 0.5f) / float(w), (float(y) + 0.5f) / float(h), 0.0f);
            worst = std::max(worst, channelDifference(out.color.pixels[size_t(y) * w + x], packRgba8(uv)));
        }
    EXPECT_LE(worst, 1);  // 1/255 of the stored (sRGB-encoded) value
}

// The mip debug view shows the level of detail of the hardware's derivatives: 64 texture repeats across
// 64 pixels put 4 texels of level 0 under each pixel step, lambda = 2, green in mipColor's ramp. On
// llvmpipe this also covers the quads that the quad's diagonal crosses (see reference.frag).
TEST_F(VulkanGraphicsTest, MipViewShowsTheLevelOfDetailOfTheHardwareDerivatives)
{
    const uint32_t w = 64, h = 64;
    RenderSettings s = unlitSettings(w, h);
    s.shadingMode = SHADING_MIP;
    const SceneTexture texture = checkerboard(WRAP_REPEAT);
    RenderOutput out = render(texturedQuad(texture, 64.0f), s);
    ASSERT_EQ(out.color.pixels.size(), size_t(w) * h);
    int worst = 0;
    for (uint32_t pixel : out.color.pixels)
        worst = std::max(worst, channelDifference(pixel, packRgba8(mipColor(2.0f))));
    EXPECT_LE(worst, 1);
}

// alphaMode MASK: where the texture's alpha is below the cutoff the triangle covers nothing, so the
// background id, depth and colour show through on the left half.
TEST_F(VulkanGraphicsTest, AlphaMaskCutsOutTheTransparentHalf)
{
    const uint32_t w = 64, h = 64;
    RenderSettings s = unlitSettings(w, h);
    RenderOutput out = render(texturedQuad(checkerboard(WRAP_CLAMP_TO_EDGE, true), 1.0f, ALPHA_MASK), s);
    ASSERT_EQ(out.aov.id.size(), size_t(w) * h);
    const uint32_t background = packRgba8(s.background);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            if (x < w / 2) {
                ASSERT_EQ(out.aov.id[i], EMPTY_ID) << x << "," << y;
                ASSERT_EQ(out.aov.depth[i], 1.0f) << x << "," << y;
                ASSERT_EQ(out.color.pixels[i], background) << x << "," << y;
            } else {
                ASSERT_TRUE(out.aov.id[i] == 0 || out.aov.id[i] == 1) << x << "," << y;
                ASSERT_EQ(out.aov.depth[i], 0.5f) << x << "," << y;
            }
        }
    // The bench's visibility-only pass cannot test alpha, so it falls back to the full pass.
    s.visibilityOnly = true;
    RenderOutput visibility =
        render(texturedQuad(checkerboard(WRAP_CLAMP_TO_EDGE, true), 1.0f, ALPHA_MASK), s);
    EXPECT_EQ(visibility.aov.id, out.aov.id);
}

// REPEAT with texture coordinates 0..2 draws the checkerboard twice along each axis.
TEST_F(VulkanGraphicsTest, RepeatWrapTilesTheTexture)
{
    const uint32_t w = 64, h = 64;
    RenderOutput out = render(texturedQuad(checkerboard(WRAP_REPEAT), 2.0f), unlitSettings(w, h));
    ASSERT_EQ(out.color.pixels.size(), size_t(w) * h);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const float u = 2.0f * (float(x) + 0.5f) / float(w), v = 2.0f * (float(y) + 0.5f) / float(h);
            if (nearTexelBorder(4.0f * u) || nearTexelBorder(4.0f * v)) continue;
            ASSERT_EQ(out.color.pixels[size_t(y) * w + x], checkerWord(int(4.0f * u), int(4.0f * v)))
                << x << "," << y;
        }
    // The second copy repeats the first: the right half equals the left half.
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w / 2; ++x)
            ASSERT_EQ(out.color.pixels[size_t(y) * w + x], out.color.pixels[size_t(y) * w + x + w / 2])
                << x << "," << y;
}

// The compute pipeline samples in software what the reference samples in hardware; on these
// NEAREST textures both must give the same ids and colours.
TEST_F(VulkanGraphicsTest, TexturedQuadsMatchTheComputeBackend)
{
    const uint32_t w = 64, h = 64;
    const RenderSettings s = unlitSettings(w, h);
    for (const Scene& scene : {texturedQuad(checkerboard(WRAP_REPEAT), 2.0f),
                               texturedQuad(checkerboard(WRAP_CLAMP_TO_EDGE, true), 1.0f, ALPHA_MASK)}) {
        RenderOutput graphics = render(scene, s);
        RenderOutput compute = renderCompute(scene, s);
        ASSERT_EQ(graphics.aov.id.size(), size_t(w) * h);
        ASSERT_EQ(compute.aov.id.size(), size_t(w) * h);
        EXPECT_EQ(graphics.aov.id, compute.aov.id);
        int worst = 0;
        for (size_t i = 0; i < graphics.color.pixels.size(); ++i)
            worst = std::max(worst, channelDifference(graphics.color.pixels[i], compute.color.pixels[i]));
        EXPECT_EQ(worst, 0);
    }
}

TEST_F(VulkanGraphicsTest, ReportsTimingsStatsAndDevice)
{
    RenderSettings s = testSettings(16, 16);
    s.warmup = 1;
    s.repeat = 3;
    RenderOutput out = render(clipSpaceScene(clipQuad(-1, -1, 1, 1, 0.5f)), s);
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
    const Scene scene = clipSpaceScene(clipQuad(-1, -1, 1, 1, 0.5f));
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
    const Scene scene = clipSpaceScene(clipQuad(-1, -1, 1, 1, 0.5f));
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
