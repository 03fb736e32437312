// texture_test.cpp - textured rendering on each compute backend against analytic expectations: texel
// selection with NEAREST, the bilinear ramp, wrap modes, level selection from the analytic derivatives,
// and the alpha test of MASK materials in the visibility stages (ids and depth, not only colour).
// Screen-filling quads in clip space, so every pixel centre's texture coordinate is known exactly.
// A missing backend fails these tests unless SR_ALLOW_MISSING_BACKENDS names it.
#include <cmath>

#include <gtest/gtest.h>

#include "scene/texture.h"
#include "test_util.h"

namespace sr::test {
namespace {

class TextureTest : public BackendTest {
protected:
    // Unlit: ambient 1 and no light, so the colour is the base colour, sRGB-encoded.
    RenderOutput render(const Scene& scene, uint32_t w, uint32_t h)
    {
        RenderSettings s = testSettings(w, h);
        s.shadingMode = SHADING_LAMBERT;
        s.lightColor = glm::vec3(0.0f);
        s.ambient = 1.0f;
        auto out = renderScene(*device_, scene, identityCamera(), s);
        EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
        return out.ok() ? std::move(*out) : RenderOutput{};
    }
};

// A quad over the NDC square [x0, x1] x [y0, y1] at depth z, texture coordinates (0, 0) at its top-left
// corner (NDC -1, -1 is the top row) to (uvMax, uvMax) at the bottom-right, drawn with `material`.
void addQuad(Scene& scene, float x0, float y0, float x1, float y1, float z, float uvMax, uint32_t material)
{
    Scene quad = clipSpaceScene(
        {{x0, y0, z, 1}, {x1, y0, z, 1}, {x1, y1, z, 1}, {x0, y0, z, 1}, {x1, y1, z, 1}, {x0, y1, z, 1}});
    auto base = uint32_t(scene.positions.size());
    for (size_t i = 0; i < quad.positions.size(); ++i) {
        glm::vec4 p = quad.positions[i];
        scene.positions.push_back(p);
        scene.normals.push_back(quad.normals[i]);
        scene.texcoords.emplace_back((p.x - x0) / (x1 - x0) * uvMax, (p.y - y0) / (y1 - y0) * uvMax, 0.0f,
                                     0.0f);
        scene.indices.push_back(base + uint32_t(i));
    }
    scene.triFlags.insert(scene.triFlags.end(), {0u, 0u});
    scene.triMaterials.insert(scene.triMaterials.end(), {material, material});
    scene.boundsMin = glm::vec3(-1.0f);
    scene.boundsMax = glm::vec3(1.0f);
}

// A linear (not sRGB) texture from RGBA bytes, full mip chain, with `sampler`.
SceneTexture linearTexture(uint32_t w, uint32_t h, const std::vector<uint8_t>& rgba, TextureSampler sampler)
{
    auto t = makeTexture("test", w, h, rgba.data(), false, sampler);
    EXPECT_TRUE(t.ok()) << (t.ok() ? "" : t.error().message);
    return t.ok() ? std::move(*t) : SceneTexture{};
}

SceneMaterial texturedMaterial(int32_t texture)
{
    SceneMaterial m;
    m.baseColorTexture = texture;
    return m;
}

TextureSampler nearestSampler(uint32_t wrap)
{
    TextureSampler s;
    s.wrapS = s.wrapT = wrap;
    s.magFilter = s.minFilter = FILTER_NEAREST;
    s.mipmapMode = MIPMAP_NONE;
    return s;
}

// Largest difference of the R, G, B bytes of two packed RGBA8 words.
int byteDiff(uint32_t a, uint32_t b)
{
    int d = 0;
    for (int shift = 0; shift < 24; shift += 8)
        d = std::max(d, std::abs(int((a >> shift) & 255u) - int((b >> shift) & 255u)));
    return d;
}

// The colour the pipeline writes for a linear base colour: the shared sRGB encoding.
uint32_t encoded(float r, float g, float b)
{
    return packRgba8(vec3(r, g, b));
}

TEST_P(TextureTest, NearestMagnificationSelectsTheTexelUnderEachPixelCentre)
{
    // 4 x 4 texels, each a distinct colour; 64 x 64 pixels, so each texel covers 16 x 16 pixel centres
    // and no centre lies on a texel border.
    std::vector<uint8_t> rgba;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i)
            rgba.insert(rgba.end(), {uint8_t(40 + 60 * i), uint8_t(20 + 70 * j), 90, 255});
    Scene scene;
    addQuad(scene, -1, -1, 1, 1, 0.5f, 1.0f, 0);
    scene.textures.push_back(linearTexture(4, 4, rgba, nearestSampler(WRAP_CLAMP_TO_EDGE)));
    scene.materials.push_back(texturedMaterial(0));
    RenderOutput out = render(scene, 64, 64);
    ASSERT_EQ(out.color.pixels.size(), 64u * 64u);
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            int i = x / 16, j = y / 16;
            uint32_t want = encoded((40 + 60 * i) / 255.0f, (20 + 70 * j) / 255.0f, 90 / 255.0f);
            ASSERT_LE(byteDiff(out.color.pixels[size_t(y) * 64 + x], want), 1) << x << "," << y;
        }
}

TEST_P(TextureTest, BilinearMagnificationIsTheLinearRampBetweenTexelCentres)
{
    // Two texels, black and white, clamped: along u the value is clamp(2u - 0.5, 0, 1), whatever v.
    Scene scene;
    addQuad(scene, -1, -1, 1, 1, 0.5f, 1.0f, 0);
    TextureSampler linear;
    linear.wrapS = linear.wrapT = WRAP_CLAMP_TO_EDGE;
    linear.mipmapMode = MIPMAP_NONE;
    scene.textures.push_back(linearTexture(2, 1, {0, 0, 0, 255, 255, 255, 255, 255}, linear));
    scene.materials.push_back(texturedMaterial(0));
    RenderOutput out = render(scene, 64, 8);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 64; ++x) {
            float u = (float(x) + 0.5f) / 64.0f;
            float value = std::clamp(2.0f * u - 0.5f, 0.0f, 1.0f);
            ASSERT_LE(byteDiff(out.color.pixels[size_t(y) * 64 + x], encoded(value, value, value)), 1)
                << x << "," << y;
        }
}

TEST_P(TextureTest, WrapModesRepeatMirrorAndClamp)
{
    // A 4 x 1 ramp of distinct texels over texture coordinates -1.5 .. 2.5 along u (offset quad).
    std::vector<uint8_t> rgba = {10, 0, 0, 255, 80, 0, 0, 255, 150, 0, 0, 255, 220, 0, 0, 255};
    for (uint32_t wrap : {WRAP_REPEAT, WRAP_MIRRORED_REPEAT, WRAP_CLAMP_TO_EDGE}) {
        Scene scene;
        addQuad(scene, -1, -1, 1, 1, 0.5f, 4.0f, 0);
        scene.textures.push_back(linearTexture(4, 1, rgba, nearestSampler(wrap)));
        SceneMaterial m = texturedMaterial(0);
        m.uvTransform[2] = glm::vec3(-1.5f, 0.0f, 1.0f);  // u' = u - 1.5
        scene.materials.push_back(m);
        RenderOutput out = render(scene, 64, 4);
        for (int x = 0; x < 64; ++x) {
            float u = (float(x) + 0.5f) / 64.0f * 4.0f - 1.5f;
            int i = int(std::floor(u * 4.0f));
            int texel = i;
            if (wrap == WRAP_REPEAT) texel = ((i % 4) + 4) % 4;
            if (wrap == WRAP_CLAMP_TO_EDGE) texel = std::clamp(i, 0, 3);
            if (wrap == WRAP_MIRRORED_REPEAT) {
                int m8 = ((i % 8) + 8) % 8;
                texel = m8 < 4 ? m8 : 7 - m8;
            }
            uint32_t want = encoded(rgba[size_t(4 * texel)] / 255.0f, 0.0f, 0.0f);
            ASSERT_LE(byteDiff(out.color.pixels[size_t(x)], want), 1) << "wrap " << wrap << " x " << x;
        }
    }
}

TEST_P(TextureTest, TrilinearLevelFollowsTheScreenDerivative)
{
    // An 8 x 8 texture whose levels are flat colours (red, green, blue, white for levels 0..3), built by
    // hand so that the level read shows in the colour. The quad maps `repeats` copies of it onto 64
    // pixels: rho = 8 * repeats / 64 texels per pixel, so repeats 32 gives lambda = 2 exactly (level 2,
    // blue) and repeats 16 * sqrt(2) gives lambda = 1.5 (half green, half blue).
    SceneTexture t;
    t.width = t.height = 8;
    t.levels = 4;
    t.srgb = false;
    t.sampler.wrapS = t.sampler.wrapT = WRAP_REPEAT;
    const uint32_t colours[4] = {0xff0000ffu, 0xff00ff00u, 0xffff0000u, 0xffffffffu};
    for (uint32_t level = 0, size = 8; level < 4; ++level, size /= 2)
        t.texels.insert(t.texels.end(), size * size, colours[level]);
    struct Case {
        float repeats;
        glm::vec3 want;
    };
    for (Case c :
         {Case{32.0f, {0, 0, 1}}, Case{16.0f * std::sqrt(2.0f), {0, 0.5f, 0.5f}}, Case{4.0f, {1, 0, 0}}}) {
        Scene scene;
        addQuad(scene, -1, -1, 1, 1, 0.5f, c.repeats, 0);
        scene.textures.push_back(t);
        scene.materials.push_back(texturedMaterial(0));
        RenderOutput out = render(scene, 64, 64);
        for (size_t p = 0; p < out.color.pixels.size(); p += 97)
            ASSERT_LE(byteDiff(out.color.pixels[p], encoded(c.want.x, c.want.y, c.want.z)), 2)
                << "repeats " << c.repeats << " pixel " << p;
    }
}

TEST_P(TextureTest, AlphaMaskCutsCoverageIdsAndDepth)
{
    // Front quad (ids 0, 1, depth 0.3): a 2 x 1 NEAREST texture, left texel alpha 0, right opaque, MASK.
    // Behind it a quad at depth 0.7 (ids 2, 3). The left half must show the back quad in every AOV.
    Scene scene;
    addQuad(scene, -1, -1, 1, 1, 0.3f, 1.0f, 0);
    addQuad(scene, -1, -1, 1, 1, 0.7f, 1.0f, 1);
    scene.textures.push_back(
        linearTexture(2, 1, {255, 0, 0, 0, 0, 255, 0, 255}, nearestSampler(WRAP_CLAMP_TO_EDGE)));
    SceneMaterial cut = texturedMaterial(0);
    cut.alphaMode = ALPHA_MASK;
    scene.materials.push_back(cut);
    scene.materials.push_back(SceneMaterial{});
    scene.triFlags[0] = scene.triFlags[1] = TRI_FLAG_ALPHA_MASK;
    for (uint32_t w : {32u, 200u}) {  // 200 px: the quads are big triangles, resolved in raster_tiles
        RenderOutput out = render(scene, w, 16);
        for (uint32_t y = 0; y < 16; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                size_t p = size_t(y) * w + x;
                bool left = x < w / 2;
                uint32_t id = out.aov.id[p];
                ASSERT_TRUE(left ? (id == 2 || id == 3) : (id == 0 || id == 1)) << w << ": " << x << "," << y;
                ASSERT_EQ(out.aov.depth[p], left ? 0.7f : 0.3f) << x << "," << y;
            }
    }
}

// The loop bound of a CPU device (docs/benchmark.md, "Loops on a CPU device"): 1,999 alpha-masked
// quads cut out everywhere, in front of one opaque quad drawn last, over every tile, with a mipmapped
// texture seen minified (level 4 and 5 blended), so that each pixel of each bin entry runs the alpha
// test's trilinear lookup. Every pixel must show the opaque quad. On llvmpipe 22.3, whose loop limiter
// ends a shader invocation's loops after 65,535 turns in all, a chunk of bin entries whose lookups each
// walked the mip levels in a loop lost the rest of its entries, and every pixel showed nothing.
TEST_P(TextureTest, ThousandsOfAlphaMaskedLayersOverATileAreEachTested)
{
    Scene scene;
    const uint32_t layers = 1000;  // 2,000 bin entries per tile: two full chunks on a CPU device
    for (uint32_t k = 0; k + 1 < layers; ++k) addQuad(scene, -1, -1, 1, 1, 0.1f + 0.7f * k / layers, 1.0f, 0);
    addQuad(scene, -1, -1, 1, 1, 0.9f, 1.0f, 1);
    // 1024^2 texels of alpha 0 over 64 pixels: 16 texels a pixel, levels 4 and 5 (default sampler:
    // trilinear).
    scene.textures.push_back(linearTexture(1024, 1024, std::vector<uint8_t>(1024 * 1024 * 4, 0), {}));
    SceneMaterial cut = texturedMaterial(0);
    cut.alphaMode = ALPHA_MASK;
    scene.materials.push_back(cut);
    scene.materials.push_back(SceneMaterial{});
    for (uint32_t t = 0; t + 2 < scene.triangleCount(); ++t) scene.triFlags[t] = TRI_FLAG_ALPHA_MASK;
    const uint32_t size = 64;
    RenderOutput out = render(scene, size, size);
    ASSERT_EQ(out.aov.id.size(), size_t(size) * size);
    const uint32_t back = 2 * (layers - 1);
    size_t wrong = 0;
    for (size_t p = 0; p < out.aov.id.size(); ++p)
        wrong += (out.aov.id[p] != back && out.aov.id[p] != back + 1) || out.aov.depth[p] != 0.9f;
    EXPECT_EQ(wrong, 0u) << "of " << out.aov.id.size() << " pixels on " << out.device.driver;
}

TEST_P(TextureTest, TexturesCostMemoryOnlyWhenTheSceneHasThem)
{
    Scene plain;
    addQuad(plain, -1, -1, 1, 1, 0.5f, 1.0f, 0);
    plain.triMaterials.clear();
    plain.texcoords.clear();
    render(plain, 32, 32);
    EXPECT_LE(device_->size(BUF_TEXELS), 16u);  // at most the placeholder every Vulkan binding needs
    EXPECT_LE(device_->size(BUF_TEXCOORDS), 16u);

    Scene textured;
    addQuad(textured, -1, -1, 1, 1, 0.5f, 1.0f, 0);
    textured.textures.push_back(
        linearTexture(256, 256, std::vector<uint8_t>(256 * 256 * 4, 128), nearestSampler(WRAP_REPEAT)));
    textured.materials.push_back(texturedMaterial(0));
    render(textured, 32, 32);
    // 256^2 texels at level 0 and the chain below it: 87,381 texels of 4 bytes.
    EXPECT_GE(device_->size(BUF_TEXELS), 87381u * 4u);
    EXPECT_GE(device_->size(BUF_TEXCOORDS), textured.vertexCount() * sizeof(glm::vec4));
}

INSTANTIATE_TEST_SUITE_P(Backends, TextureTest, ::testing::Values("vulkan", "cuda"));

}  // namespace
}  // namespace sr::test
