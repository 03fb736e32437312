// aov_test.cpp - the surface AOVs (bary.u/v, uv.u/v, N.x/y/z) against analytic values on clip-space
// quads, on each compute backend and on vulkan-graphics: with w = 1 the perspective-correct
// barycentrics are the screen-space ones and texture coordinates are an affine map of the pixel
// centre, so every pixel's expected value is known; with w != 1 the barycentrics must follow 1/w. Also
// the EXR round trip of every channel, files without them, and their comparison.
// A missing backend fails these tests unless SR_ALLOW_MISSING_BACKENDS names it.
#include <cmath>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "io/compare.h"
#include "render/aov.h"
#include "scene/texture.h"
#include "test_util.h"
#include "vulkan/vulkan_graphics.h"

namespace sr::test {
namespace {

constexpr float kEps = 2e-5f;

// A quad over the NDC rectangle [x0, x1] x [y0, y1] at depth 0.5 (w = 1) with vertex normal `normal`,
// set-1 texture coordinates (u, v) = ((x - x0) / (x1 - x0), (y - y0) / (y1 - y0)) (set 0 holds a decoy),
// drawn with material `material`.
void addQuad(Scene& scene, float x0, float y0, float x1, float y1, glm::vec3 normal, uint32_t material)
{
    const glm::vec2 corners[6] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y0}, {x1, y1}, {x0, y1}};
    for (const glm::vec2& c : corners) {
        scene.indices.push_back(uint32_t(scene.positions.size()));
        scene.positions.emplace_back(c.x, c.y, 0.5f, 1.0f);
        scene.normals.emplace_back(normal, 0.0f);
        scene.texcoords.emplace_back(7.0f, 7.0f, (c.x - x0) / (x1 - x0), (c.y - y0) / (y1 - y0));
    }
    scene.triFlags.insert(scene.triFlags.end(), {0u, 0u});
    scene.triMaterials.insert(scene.triMaterials.end(), {material, material});
    scene.boundsMin = glm::vec3(-1.0f);
    scene.boundsMax = glm::vec3(1.0f);
}

// The transform of the textured material: u' = 2u + 0.5v + 0.25, v' = 1 - v.
glm::mat3 uvTransform()
{
    glm::mat3 m(1.0f);  // column-major: m[column][row]
    m[0][0] = 2.0f;
    m[1][0] = 0.5f;
    m[2][0] = 0.25f;
    m[1][1] = -1.0f;
    m[2][1] = 1.0f;
    return m;
}

// Two quads side by side with a background border: the left one textured through texture coordinate
// set 1 and uvTransform(), with a normal tilted towards +x; the right one untextured, with the +z normal
// that the facing rule turns around (see expectedNormal).
constexpr float kLeft[4] = {-0.75f, -0.5f, 0.0f, 0.75f};  // x0, y0, x1, y1
constexpr float kRight[4] = {0.0f, -0.5f, 0.75f, 0.75f};
const glm::vec3 kTilted = glm::vec3(0.6f, 0.0f, -0.8f);

Scene twoQuads()
{
    Scene scene;
    addQuad(scene, kLeft[0], kLeft[1], kLeft[2], kLeft[3], kTilted, 0);
    addQuad(scene, kRight[0], kRight[1], kRight[2], kRight[3], glm::vec3(0.0f, 0.0f, 1.0f), 1);
    const uint8_t texels[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
    auto texture = makeTexture("aov", 2, 2, texels, false, TextureSampler{});
    EXPECT_TRUE(texture.ok()) << (texture.ok() ? "" : texture.error().message);
    if (texture.ok()) scene.textures.push_back(std::move(*texture));
    SceneMaterial textured;
    textured.baseColorTexture = 0;
    textured.texCoord = 1;
    textured.uvTransform = uvTransform();
    SceneMaterial plain;
    plain.baseColorFactor = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
    scene.materials = {textured, plain};
    return scene;
}

glm::vec2 pixelNdc(uint32_t px, uint32_t py, uint32_t w, uint32_t h)
{
    return {(float(px) + 0.5f) * 2.0f / float(w) - 1.0f, (float(py) + 0.5f) * 2.0f / float(h) - 1.0f};
}

float cross2(glm::vec2 a, glm::vec2 b)
{
    return a.x * b.y - a.y * b.x;
}

// Screen-space barycentrics of p in the 2D triangle (a, b, c).
glm::vec3 screenBary(glm::vec2 p, glm::vec2 a, glm::vec2 b, glm::vec2 c)
{
    float area = cross2(b - a, c - a);
    return glm::vec3(cross2(b - p, c - p), cross2(c - p, a - p), cross2(a - p, b - p)) / area;
}

// With the identity camera view space is clip space, so the eye sits at the origin looking down -z
// and the quads (z = 0.5) are seen from their -z side: shadePixel turns the face normal to -z and
// then any vertex normal on the other side of it, so +z comes out as -z and kTilted stays.
glm::vec3 expectedNormal(uint32_t id)
{
    return id < 2 ? kTilted : glm::vec3(0.0f, 0.0f, -1.0f);
}

// Checks every pixel of `aov` (rendered from twoQuads() at w x h) against the analytic values.
void expectTwoQuads(const Scene& scene, const AovImage& aov, uint32_t w, uint32_t h)
{
    ASSERT_EQ(aov.baryU.size(), size_t(w) * h);
    ASSERT_EQ(aov.baryV.size(), size_t(w) * h);
    ASSERT_EQ(aov.uvU.size(), size_t(w) * h);
    ASSERT_EQ(aov.uvV.size(), size_t(w) * h);
    ASSERT_EQ(aov.normalX.size(), size_t(w) * h);
    ASSERT_EQ(aov.normalY.size(), size_t(w) * h);
    ASSERT_EQ(aov.normalZ.size(), size_t(w) * h);
    size_t covered[2] = {0, 0};
    const glm::mat3 t = uvTransform();
    for (uint32_t py = 0; py < h; ++py) {
        for (uint32_t px = 0; px < w; ++px) {
            const size_t i = size_t(py) * w + px;
            const uint32_t id = aov.id[i];
            const std::string where = "pixel (" + std::to_string(px) + ", " + std::to_string(py) + ")";
            if (id == EMPTY_ID) {
                for (const std::vector<float>* plane :
                     {&aov.baryU, &aov.baryV, &aov.uvU, &aov.uvV, &aov.normalX, &aov.normalY, &aov.normalZ})
                    ASSERT_EQ((*plane)[i], 0.0f) << where;
                continue;
            }
            ASSERT_LT(id, 4u) << where;
            ++covered[id / 2];
            const glm::vec2 p = pixelNdc(px, py, w, h);
            glm::vec2 c[3];
            for (int k = 0; k < 3; ++k)
                c[k] = glm::vec2(scene.positions[scene.indices[3 * id + uint32_t(k)]]);
            const glm::vec3 b = screenBary(p, c[0], c[1], c[2]);
            EXPECT_NEAR(aov.baryU[i], b.y, kEps) << where;
            EXPECT_NEAR(aov.baryV[i], b.z, kEps) << where;

            if (id < 2) {
                const float u = (p.x - kLeft[0]) / (kLeft[2] - kLeft[0]);
                const float v = (p.y - kLeft[1]) / (kLeft[3] - kLeft[1]);
                const glm::vec3 uv = t * glm::vec3(u, v, 1.0f);
                EXPECT_NEAR(aov.uvU[i], uv.x, 4 * kEps) << where;
                EXPECT_NEAR(aov.uvV[i], uv.y, 4 * kEps) << where;
            } else {
                EXPECT_EQ(aov.uvU[i], 0.0f) << where << ": untextured material";
                EXPECT_EQ(aov.uvV[i], 0.0f) << where << ": untextured material";
            }

            const glm::vec3 n = expectedNormal(id);
            EXPECT_NEAR(aov.normalX[i], n.x, kEps) << where;
            EXPECT_NEAR(aov.normalY[i], n.y, kEps) << where;
            EXPECT_NEAR(aov.normalZ[i], n.z, kEps) << where;
        }
    }
    // Each quad covers 3/8 x 5/8 of the frame.
    EXPECT_EQ(covered[0], size_t(w) * 3 / 8 * (size_t(h) * 5 / 8));
    EXPECT_EQ(covered[1], size_t(w) * 3 / 8 * (size_t(h) * 5 / 8));
}

class AovTest : public BackendTest {
protected:
    RenderOutput render(const Scene& scene, uint32_t w, uint32_t h, bool surface = true)
    {
        RenderSettings s = testSettings(w, h);
        s.surfaceAovs = surface;
        auto out = renderScene(*device_, scene, identityCamera(), s);
        EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
        return out.ok() ? std::move(*out) : RenderOutput{};
    }
};

TEST_P(AovTest, SurfaceChannelsMatchAnalyticValues)
{
    const Scene scene = twoQuads();
    RenderOutput out = render(scene, 64, 32);
    expectTwoQuads(scene, out.aov, 64, 32);
}

TEST_P(AovTest, OffByDefault)
{
    RenderOutput out = render(twoQuads(), 16, 16, false);
    ASSERT_EQ(out.aov.id.size(), 256u);
    EXPECT_FALSE(out.aov.hasBary());
    EXPECT_FALSE(out.aov.hasUv());
    EXPECT_FALSE(out.aov.hasNormal());
}

// One triangle with a different w at each corner (kSlantedNdc, kSlantedW), at depth 0.5.
constexpr glm::vec2 kSlantedNdc[3] = {{-0.9f, -0.9f}, {0.9f, -0.6f}, {-0.3f, 0.9f}};
constexpr float kSlantedW[3] = {1.0f, 4.0f, 2.0f};

Scene perspectiveTriangle()
{
    std::vector<glm::vec4> corners;
    for (int k = 0; k < 3; ++k)
        corners.emplace_back(kSlantedNdc[k] * kSlantedW[k], 0.5f * kSlantedW[k], kSlantedW[k]);
    return clipSpaceScene(corners);
}

// One triangle with a different w at each corner: the barycentrics are the screen-space ones divided
// by each corner's w, renormalised (perspective-correct), not the screen-space ones.
TEST_P(AovTest, BarycentricsArePerspectiveCorrect)
{
    const Scene scene = perspectiveTriangle();
    const uint32_t size = 32;
    RenderOutput out = render(scene, size, size);
    ASSERT_TRUE(out.aov.hasBary());
    ASSERT_TRUE(out.aov.hasUv());
    size_t covered = 0;
    for (uint32_t py = 0; py < size; ++py) {
        for (uint32_t px = 0; px < size; ++px) {
            const size_t i = size_t(py) * size + px;
            if (out.aov.id[i] == EMPTY_ID) continue;
            ++covered;
            EXPECT_EQ(out.aov.uvU[i], 0.0f) << "a scene without materials has no texture coordinates";
            const glm::vec3 s =
                screenBary(pixelNdc(px, py, size, size), kSlantedNdc[0], kSlantedNdc[1], kSlantedNdc[2]);
            glm::vec3 b = s / glm::vec3(kSlantedW[0], kSlantedW[1], kSlantedW[2]);
            b /= b.x + b.y + b.z;
            EXPECT_NEAR(out.aov.baryU[i], b.y, kEps) << px << ", " << py;
            EXPECT_NEAR(out.aov.baryV[i], b.z, kEps) << px << ", " << py;
        }
    }
    EXPECT_GT(covered, size_t(size) * size / 4);
}

// Sample 0 of Vulkan's standard sample locations (the spec's table "Standard sample locations"), in
// pixels from the pixel's top-left corner: what the id and depth AOVs of an antialiased frame describe.
glm::vec2 standardSampleZero(uint32_t count)
{
    switch (count) {
    case 2: return {0.75f, 0.75f};
    case 4: return {0.375f, 0.125f};
    case 8: return {0.5625f, 0.3125f};
    case 16: return {0.5625f, 0.5625f};
    default: return {0.5f, 0.5f};
    }
}

// Under MSAA and SSAA the id and depth of an output pixel are those of sample 0 of its middle raster
// pixel (raster pixel (x ssaa + ssaa / 2, ...)); the barycentrics must be that sample's, so inside the
// triangle, not extrapolated to the output pixel's centre (which the triangle need not cover).
TEST_P(AovTest, BarycentricsDescribeTheSampleOfTheId)
{
    const Scene scene = perspectiveTriangle();
    const uint32_t size = 24;
    for (const auto& [msaa, ssaa] :
         std::vector<std::pair<uint32_t, uint32_t>>{{4, 1}, {8, 1}, {1, 2}, {4, 2}}) {
        RenderSettings s = testSettings(size, size);
        s.surfaceAovs = true;
        s.msaa = msaa;
        s.ssaa = ssaa;
        auto out = renderScene(*device_, scene, identityCamera(), s);
        ASSERT_TRUE(out.ok()) << out.error().message;
        const AovImage& aov = out->aov;
        ASSERT_TRUE(aov.hasBary());
        const std::string config = "msaa " + std::to_string(msaa) + " ssaa " + std::to_string(ssaa);
        const glm::vec2 sample = standardSampleZero(msaa);
        size_t covered = 0, outside = 0;
        for (uint32_t py = 0; py < size; ++py) {
            for (uint32_t px = 0; px < size; ++px) {
                const size_t i = size_t(py) * size + px;
                if (aov.id[i] == EMPTY_ID) continue;
                ++covered;
                // The sample in output pixels: raster pixel ssaa / 2 of the block, then the sample in it.
                const glm::vec2 at =
                    glm::vec2(float(px), float(py)) + (glm::vec2(float(ssaa / 2)) + sample) / float(ssaa);
                const glm::vec2 p = at * 2.0f / float(size) - 1.0f;
                glm::vec3 b = screenBary(p, kSlantedNdc[0], kSlantedNdc[1], kSlantedNdc[2]) /
                              glm::vec3(kSlantedW[0], kSlantedW[1], kSlantedW[2]);
                b /= b.x + b.y + b.z;
                const float u = aov.baryU[i], v = aov.baryV[i];
                if (u < 0.0f || v < 0.0f || u + v > 1.0f + 1e-6f) ++outside;
                EXPECT_NEAR(u, b.y, kEps) << config << ", pixel " << px << ", " << py;
                EXPECT_NEAR(v, b.z, kEps) << config << ", pixel " << px << ", " << py;
            }
        }
        EXPECT_GT(covered, size_t(size) * size / 4) << config;
        EXPECT_EQ(outside, 0u) << config << ": barycentrics outside the triangle whose id the pixel holds";
    }
}

// Every channel survives writeAovExr / readAovExr bit for bit, and the comparison of the file with the
// render reports no surface difference.
TEST_P(AovTest, ExrRoundTripOfEveryChannel)
{
    const Scene scene = twoQuads();
    RenderOutput out = render(scene, 32, 24);
    ScratchDir dir("sr_aov");
    const std::string path = dir.file("surface.exr");
    Status written = writeAovExr(path, out.aov);
    ASSERT_TRUE(written.ok()) << written.error().message;
    Result<AovImage> back = readAovExr(path);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->width, 32u);
    EXPECT_EQ(back->height, 24u);
    EXPECT_EQ(back->id, out.aov.id);
    auto bits = [](const std::vector<float>& v) {
        std::vector<uint32_t> b(v.size());
        if (!v.empty()) std::memcpy(b.data(), v.data(), v.size() * sizeof(float));
        return b;
    };
    EXPECT_EQ(bits(back->depth), bits(out.aov.depth));
    EXPECT_EQ(bits(back->baryU), bits(out.aov.baryU));
    EXPECT_EQ(bits(back->baryV), bits(out.aov.baryV));
    EXPECT_EQ(bits(back->uvU), bits(out.aov.uvU));
    EXPECT_EQ(bits(back->uvV), bits(out.aov.uvV));
    EXPECT_EQ(bits(back->normalX), bits(out.aov.normalX));
    EXPECT_EQ(bits(back->normalY), bits(out.aov.normalY));
    EXPECT_EQ(bits(back->normalZ), bits(out.aov.normalZ));

    CompareTolerance strict;
    strict.surfaceTolerance = 0.0;
    auto same = compareAov(out.aov, *back, strict);
    ASSERT_TRUE(same.ok()) << same.error().message;
    EXPECT_TRUE(same->pass);
    EXPECT_EQ(same->maxBaryDiff, 0.0);
    EXPECT_EQ(same->maxUvDiff, 0.0);
    EXPECT_EQ(same->maxNormalDiff, 0.0);

    // A render without the surface channels writes the old two-channel file, which still reads and
    // compares against the full one on id and Z alone.
    RenderOutput plain = render(scene, 32, 24, false);
    const std::string plainPath = dir.file("plain.exr");
    ASSERT_TRUE(writeAovExr(plainPath, plain.aov).ok());
    Result<AovImage> plainBack = readAovExr(plainPath);
    ASSERT_TRUE(plainBack.ok()) << plainBack.error().message;
    EXPECT_EQ(plainBack->id, out.aov.id);
    EXPECT_FALSE(plainBack->hasBary() || plainBack->hasUv() || plainBack->hasNormal());
    auto mixed = compareFiles(path, plainPath, strict);
    ASSERT_TRUE(mixed.ok()) << mixed.error().message;
    EXPECT_TRUE(mixed->pass);
    EXPECT_LT(mixed->maxBaryDiff, 0.0);  // not compared
    EXPECT_EQ(formatReport(*mixed, CompareTolerance{}).find("bary"), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(Backends, AovTest, ::testing::Values("vulkan", "cuda"),
                         [](const auto& info) { return info.param; });

// The reference backend fills the same channels from its own id attachment.
TEST(AovGraphics, SurfaceChannelsMatchAnalyticValues)
{
    const Scene scene = twoQuads();
    RenderSettings s = testSettings(64, 32);
    s.surfaceAovs = true;
    auto out = renderVulkanGraphics(scene, identityCamera(), s, -1);
    ASSERT_TRUE(out.ok()) << out.error().message;
    expectTwoQuads(scene, out->aov, 64, 32);
}

// Surface differences are reported per group and fail only under a surface tolerance.
TEST(AovCompare, SurfaceGroupsReportedAndToleranceOptIn)
{
    const Scene scene = twoQuads();
    AovImage a;
    a.width = 4;
    a.height = 1;
    a.id = {0, 1, 2, EMPTY_ID};
    a.depth = {0.5f, 0.5f, 0.5f, 1.0f};
    fillSurfaceAovs(scene, frameParams(scene, identityCamera(), testSettings(4, 1), {}, {}), a);
    ASSERT_TRUE(a.hasBary() && a.hasUv() && a.hasNormal());
    // Values whose differences are exact in float.
    a.baryU[0] = 0.25f;
    a.uvV[1] = 0.5f;
    a.normalZ[2] = -1.0f;
    AovImage b = a;
    b.baryU[0] = 0.375f;
    b.uvV[1] = 0.75f;
    b.normalZ[2] = -0.5f;
    b.normalX[3] = 9.0f;  // background: not compared

    auto r = compareAov(a, b, CompareTolerance{});
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_DOUBLE_EQ(r->maxBaryDiff, 0.125);
    EXPECT_DOUBLE_EQ(r->maxUvDiff, 0.25);
    EXPECT_DOUBLE_EQ(r->maxNormalDiff, 0.5);
    EXPECT_TRUE(r->pass);  // no surface tolerance set
    const std::string report = formatReport(*r, CompareTolerance{});
    EXPECT_NE(report.find("Max bary diff: 0.125"), std::string::npos) << report;
    EXPECT_NE(report.find("Max N diff: 0.5"), std::string::npos) << report;

    CompareTolerance tol;
    tol.surfaceTolerance = 0.2;
    r = compareAov(a, b, tol);
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r->surfaceOverTolerance, 2u);
    EXPECT_FALSE(r->pass);
    tol.surfaceTolerance = 0.5;
    EXPECT_TRUE(compareAov(a, b, tol)->pass);

    b.uvU.pop_back();  // a hand-made AOV with a short plane is an error, not a read past its end
    EXPECT_FALSE(compareAov(a, b, tol).ok());
}

}  // namespace
}  // namespace sr::test
