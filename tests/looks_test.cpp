// looks_test.cpp - what a first render looks like (issue 26): the default material and light leave a
// lit surface unclipped, so that the lighting models differ; glTF emission is added to the shaded
// colour on both backends and on the vulkan-graphics reference; and the wireframe overlay and lines
// mode of a tessellated frame show the tessellated mesh.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "api/backend.h"
#include "io/image_io.h"
#include "render/tessellate.h"
#include "camera/camera.h"
#include "scene/primitive_mode.h"
#include "test_util.h"
#include "vulkan/vulkan_graphics.h"

namespace sr::test {
namespace {

// ci/setup installs glmark2-data, which ships this model (an OBJ without a material).
const std::string kBunny = glmark2Model("bunny.obj");

CameraMatrices cameraFor(const Scene& scene, const std::string& spec, uint32_t width, uint32_t height)
{
    auto parsed = parseCameraSpec(spec);
    EXPECT_TRUE(parsed.ok());
    auto camera = resolveCamera(*parsed, scene, width, height);
    EXPECT_TRUE(camera.ok()) << (camera.ok() ? "" : camera.error().message);
    return camera.ok() ? *camera : CameraMatrices{};
}

uint32_t channel(uint32_t rgba, int c)
{
    return (rgba >> (8 * c)) & 255u;
}

// The sRGB byte of a linear value, from the sRGB transfer function's definition (IEC 61966-2-1).
int srgbByte(double linear)
{
    double c = linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
    return int(std::lround(std::clamp(c, 0.0, 1.0) * 255.0));
}

using LooksTest = BackendTest;

// The glmark2 bunny with every default (OBJ without a material, the default light, 1x): no covered
// pixel reaches the display's white in any channel, and Lambert, Phong and Blinn-Phong are visibly
// different pictures. The old white material under light 1 + ambient 0.15 + specular 0.5 clipped 32%
// of the bunny to pure white.
TEST_P(LooksTest, DefaultBunnyIsShadedNotClipped)
{
    ASSERT_TRUE(std::filesystem::exists(kBunny)) << kBunny << " is missing: ci/setup installs glmark2-data";
    auto bunny = loadScene(kBunny);
    ASSERT_TRUE(bunny.ok()) << bunny.error().message;
    RenderSettings s = RenderOptions{}.resolved();
    s.warmup = 0;
    const CameraMatrices camera = cameraFor(*bunny, "auto", s.width, s.height);
    std::array<RenderOutput, 3> images;
    const uint32_t modes[3] = {SHADING_LAMBERT, SHADING_PHONG, SHADING_BLINN_PHONG};
    for (int m = 0; m < 3; ++m) {
        RenderSettings shaded = s;
        shaded.shadingMode = modes[m];
        images[size_t(m)] = render(*bunny, shaded, camera);
        ASSERT_EQ(images[size_t(m)].color.pixels.size(), size_t(s.width) * s.height);
    }
    const RenderOutput& blinn = images[2];
    size_t covered = 0, saturated = 0;
    for (size_t i = 0; i < blinn.color.pixels.size(); ++i) {
        if (blinn.aov.id[i] == EMPTY_ID) continue;
        ++covered;
        uint32_t p = blinn.color.pixels[i];
        if (channel(p, 0) == 255 || channel(p, 1) == 255 || channel(p, 2) == 255) ++saturated;
    }
    ASSERT_GT(covered, 20000u);
    std::printf("[ bunny ] %zu covered pixels, %zu saturated (%.2f%%)\n", covered, saturated,
                100.0 * double(saturated) / double(covered));
    EXPECT_EQ(saturated, 0u);
    // Every pair of lighting models differs by more than 4 levels on at least 2% of the covered pixels:
    // their highlights (Phong's, exponent 32, is the smallest).
    auto differing = [&](const RenderOutput& a, const RenderOutput& b) {
        size_t n = 0;
        for (size_t i = 0; i < a.color.pixels.size(); ++i)
            if (a.aov.id[i] != EMPTY_ID && channelDifference(a.color.pixels[i], b.color.pixels[i]) > 4) ++n;
        return double(n) / double(covered);
    };
    const double lambertPhong = differing(images[0], images[1]);
    const double lambertBlinn = differing(images[0], images[2]);
    const double phongBlinn = differing(images[1], images[2]);
    std::printf(
        "[ bunny ] pixels differing by > 4 levels: lambert/phong %.1f%%, lambert/blinn-phong "
        "%.1f%%, phong/blinn-phong %.1f%%\n",
        100.0 * lambertPhong, 100.0 * lambertBlinn, 100.0 * phongBlinn);
    EXPECT_GT(lambertPhong, 0.02);
    EXPECT_GT(lambertBlinn, 0.02);
    EXPECT_GT(phongBlinn, 0.02);
}

// A glTF file holding one quad facing +z (x, y in [-1, 1]) with TEXCOORD_0 and one material whose JSON
// is `material`; `images` is the glTF "images" array (empty: none) with one texture per image.
std::string quadGltf(const std::string& material, const std::string& images = "")
{
    // Positions (4 x vec3), texcoords (4 x vec2), indices (6 x ushort) in one base64 buffer.
    const float positions[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    const float uvs[8] = {0, 1, 1, 1, 1, 0, 0, 0};
    const uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
    std::string bytes(reinterpret_cast<const char*>(positions), sizeof positions);
    bytes.append(reinterpret_cast<const char*>(uvs), sizeof uvs);
    bytes.append(reinterpret_cast<const char*>(indices), sizeof indices);
    static const char* kBase64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string b64;
    for (size_t i = 0; i < bytes.size(); i += 3) {
        uint32_t v = uint32_t(uint8_t(bytes[i])) << 16;
        if (i + 1 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 1])) << 8;
        if (i + 2 < bytes.size()) v |= uint32_t(uint8_t(bytes[i + 2]));
        b64 += kBase64[(v >> 18) & 63];
        b64 += kBase64[(v >> 12) & 63];
        b64 += i + 1 < bytes.size() ? kBase64[(v >> 6) & 63] : '=';
        b64 += i + 2 < bytes.size() ? kBase64[v & 63] : '=';
    }
    std::string textures =
        images.empty() ? "" : R"(, "images": )" + images + R"(, "textures": [{"source": 0}])";
    return fmt::format(
        R"({{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}], "nodes": [{{"mesh": 0}}],
"meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "indices": 2, "material": 0}}]}}],
"materials": [{}]{},
"buffers": [{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{}"}}],
"bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 32}},
                {{"buffer": 0, "byteOffset": 80, "byteLength": 12}}],
"accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]}},
              {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"}},
              {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}}]}})",
        material, textures, bytes.size(), b64);
}

Scene loadWritten(const ScratchDir& dir, const std::string& name, const std::string& text)
{
    std::ofstream(dir.file(name)) << text;
    auto scene = loadScene(dir.file(name));
    EXPECT_TRUE(scene.ok()) << (scene.ok() ? "" : scene.error().message);
    return scene.ok() ? std::move(*scene) : Scene{};
}

// Every covered pixel of `out` (a 32 x 32 frame) has the sRGB colour `expected` to within one level;
// returns how many were covered.
size_t expectCoveredColour(const RenderOutput& out, const std::array<int, 3>& expected, const char* what)
{
    size_t covered = 0, wrong = 0;
    for (size_t i = 0; i < out.color.pixels.size(); ++i) {
        if (out.aov.id[i] == EMPTY_ID) continue;
        ++covered;
        bool ok = true;
        for (int c = 0; c < 3; ++c)
            ok = ok && std::abs(int(channel(out.color.pixels[i], c)) - expected[size_t(c)]) <= 1;
        if (!ok && wrong++ == 0)
            ADD_FAILURE() << what << ": pixel " << i << " is (" << channel(out.color.pixels[i], 0) << ", "
                          << channel(out.color.pixels[i], 1) << ", " << channel(out.color.pixels[i], 2)
                          << "), expected (" << expected[0] << ", " << expected[1] << ", " << expected[2]
                          << ")";
    }
    EXPECT_EQ(wrong, 0u) << what;
    return covered;
}

// The frame of `scene` on the vulkan-graphics reference agrees with `out` to one level per channel.
void expectReferenceAgrees(const Scene& scene, const CameraMatrices& camera, const RenderSettings& s,
                           const RenderOutput& out)
{
    auto reference = renderVulkanGraphics(scene, camera, s, -1);
    ASSERT_TRUE(reference.ok()) << reference.error().message;
    ASSERT_EQ(reference->color.pixels.size(), out.color.pixels.size());
    EXPECT_EQ(reference->aov.id, out.aov.id);
    int worst = 0;
    for (size_t i = 0; i < out.color.pixels.size(); ++i)
        worst = std::max(worst, channelDifference(reference->color.pixels[i], out.color.pixels[i]));
    EXPECT_LE(worst, 1);
}

// An emissive-only quad (black base colour, Lambert so that no highlight is added) shows its emitted
// colour: emissiveFactor x KHR_materials_emissive_strength, encoded as sRGB. With an emissive texture
// of one colour and factor 1, it shows the texture's own sRGB bytes.
TEST_P(LooksTest, GltfEmissionIsAddedToTheShadedColour)
{
    ScratchDir dir("emissive");
    const CameraMatrices camera = identityCamera();
    RenderSettings s = testSettings(32, 32);
    s.shadingMode = SHADING_LAMBERT;

    Scene factor = loadWritten(dir, "factor.gltf",
                               quadGltf(R"({"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]},
                                 "emissiveFactor": [0.9, 0.4, 0.1],
                                 "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 0.5}}})"));
    RenderOutput out = render(factor, s, camera);
    EXPECT_GT(expectCoveredColour(out, {srgbByte(0.45), srgbByte(0.2), srgbByte(0.05)}, "emissive factor"),
              500u);
    if (GetParam() == "vulkan") expectReferenceAgrees(factor, camera, s, out);

    // A 4 x 4 emissive texture of sRGB (250, 128, 30).
    RgbaImage image{4, 4, std::vector<uint32_t>(16, 250u | 128u << 8 | 30u << 16 | 255u << 24)};
    ASSERT_TRUE(writePng(dir.file("glow.png"), image).ok());
    Scene textured = loadWritten(dir, "texture.gltf",
                                 quadGltf(R"({"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]},
                                   "emissiveFactor": [1, 1, 1], "emissiveTexture": {"index": 0}})",
                                          R"([{"uri": "glow.png"}])"));
    out = render(textured, s, camera);
    EXPECT_GT(expectCoveredColour(out, {250, 128, 30}, "emissive texture"), 500u);
    if (GetParam() == "vulkan") expectReferenceAgrees(textured, camera, s, out);

    // Emission adds to the lit colour: the same quad with a grey base is brighter by it.
    Scene lit = loadWritten(dir, "lit.gltf",
                            quadGltf(R"({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]},
                                  "emissiveFactor": [0.2, 0, 0]})"));
    RenderSettings ambientOnly = unlitSettings(32, 32);
    ambientOnly.ambient = 0.4f;
    out = render(lit, ambientOnly, camera);
    expectCoveredColour(out, {srgbByte(0.5 * 0.4 + 0.2), srgbByte(0.5 * 0.4), srgbByte(0.5 * 0.4)},
                        "lit + emissive");
}

// assimp-testmodels' ClearCoatTest: its labels are black with an emissive texture of white text. They
// show that text, and the compute backend agrees with the reference.
TEST_P(LooksTest, ClearCoatLabelsAreEmissive)
{
    // SR_ASSIMP_MODELS: the folder ci/gpu-bundle carries to the GPU machine.
    const char* root = std::getenv("SR_ASSIMP_MODELS");
    const std::string path =
        std::string(root ? root : "/usr/share/assimp/models") + "/glTF2/ClearCoat-glTF/ClearCoatTest.gltf";
    ASSERT_TRUE(std::filesystem::exists(path)) << path << " is missing: ci/setup installs assimp-testmodels";
    auto scene = loadScene(path);
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    uint32_t label = UINT32_MAX;
    for (size_t m = 0; m < scene->materials.size(); ++m)
        if (scene->materials[m].name == "LabelMaterial") label = uint32_t(m);
    ASSERT_NE(label, UINT32_MAX);
    ASSERT_GE(scene->materials[label].emissiveTexture, 0);
    RenderSettings s = testSettings(256, 256);
    const CameraMatrices camera = cameraFor(*scene, "auto", 256, 256);
    RenderOutput out = render(*scene, s, camera);
    size_t labelPixels = 0, bright = 0;
    for (size_t i = 0; i < out.color.pixels.size(); ++i) {
        uint32_t id = out.aov.id[i];
        if (id == EMPTY_ID || scene->triMaterials[id] != label) continue;
        ++labelPixels;
        if (channel(out.color.pixels[i], 0) > 128) ++bright;
    }
    ASSERT_GT(labelPixels, 500u);
    // The text covers a good part of the labels; without emission every label pixel is black.
    EXPECT_GT(double(bright) / double(labelPixels), 0.05) << bright << " of " << labelPixels;
    if (GetParam() != "vulkan") return;
    // Against the reference, whose hardware derivatives may pick another mip level at texel edges of
    // the text: most pixels agree to one level.
    auto reference = renderVulkanGraphics(*scene, camera, s, -1);
    ASSERT_TRUE(reference.ok()) << reference.error().message;
    size_t close = 0;
    for (size_t i = 0; i < out.color.pixels.size(); ++i)
        close += channelDifference(reference->color.pixels[i], out.color.pixels[i]) <= 1 ? 1 : 0;
    EXPECT_GT(double(close) / double(out.color.pixels.size()), 0.99);
}

// The unique edges of a triangle mesh, by their endpoints' positions (the count lines mode must draw).
size_t uniqueEdgeCount(const Scene& mesh)
{
    std::set<std::array<float, 6>> edges;
    for (size_t t = 0; t < mesh.triangleCount(); ++t)
        for (size_t c = 0; c < 3; ++c) {
            glm::vec4 a = mesh.positions[mesh.indices[3 * t + c]];
            glm::vec4 b = mesh.positions[mesh.indices[3 * t + (c + 1) % 3]];
            std::array<float, 3> pa{a.x, a.y, a.z}, pb{b.x, b.y, b.z};
            if (pb < pa) std::swap(pa, pb);
            edges.insert({pa[0], pa[1], pa[2], pb[0], pb[1], pb[2]});
        }
    return edges.size();
}

RenderSettings pnSettings(uint32_t size)
{
    RenderOptions o;
    o.settings = testSettings(size, size);
    o.settings.cullMode = CULL_BACK;
    o.settings.tessellate = TESS_PN;
    o.settings.tessEdgePx = 8.0f;
    return o.resolved();
}

// `--tessellate pn --primitive-mode lines` draws the edges of the tessellated mesh (with culling off,
// as lines mode shows the back of a mesh), not the scene's own.
TEST_P(LooksTest, TessellatedLinesModeDrawsTheGeneratedEdges)
{
    const Scene sphere = tessellatedSphere(4);
    const uint32_t size = 128;
    const CameraMatrices camera = cameraFor(sphere, "orbit:30,20,3", size, size);
    RenderSettings s = pnSettings(size);
    RenderSettings unculled = s;
    unculled.cullMode = CULL_NONE;
    const Scene generated =
        tessellateOnHost(sphere, tessSources(sphere), frameParams(sphere, camera, unculled, {}, {})).scene;
    const size_t expected = uniqueEdgeCount(generated);
    ASSERT_GT(expected, 4 * uniqueEdgeCount(sphere));
    RenderOutput out = render(displayScene(sphere, PrimitiveMode::Lines, false), s, camera);
    EXPECT_EQ(out.stats.linesIn, expected);
    EXPECT_EQ(out.stats.tessTriangles, generated.triangleCount());
    if (GetParam() != "vulkan") return;
    auto reference = renderGraphics(displayScene(sphere, PrimitiveMode::Lines, false), camera, s, -1);
    ASSERT_TRUE(reference.ok()) << reference.error().message;
    EXPECT_EQ(reference->stats.linesIn, expected);
}

// `--tessellate pn --wireframe`: the overlay's edges are the tessellated triangles' and lie on the
// curved surface. Its line pixels sit at the surface's depth (within the wireframe bias) and cover a
// good share of the sphere; the scene's straight edges sink inside the surface, so that only crosses at
// the vertices showed.
TEST_P(LooksTest, TessellatedWireframeLiesOnTheSurface)
{
    const Scene sphere = tessellatedSphere(4);
    const uint32_t size = 128;
    const CameraMatrices camera = cameraFor(sphere, "orbit:30,20,3", size, size);
    RenderSettings surfaceOnly = pnSettings(size);
    RenderOutput surface = render(sphere, surfaceOnly, camera);
    RenderOptions o;
    o.settings = surfaceOnly;
    o.wireframe = true;
    RenderSettings s = o.resolved();
    RenderOutput wire = render(displayScene(sphere, PrimitiveMode::Triangles, true), s, camera);
    ASSERT_EQ(wire.aov.id.size(), surface.aov.id.size());
    const auto triangles = uint32_t(sphere.triangleCount());
    size_t covered = 0, linePixels = 0, offSurface = 0;
    for (size_t i = 0; i < wire.aov.id.size(); ++i) {
        if (surface.aov.id[i] == EMPTY_ID) continue;
        ++covered;
        if (wire.aov.id[i] == EMPTY_ID || wire.aov.id[i] < triangles) continue;
        ++linePixels;
        // A line on the surface is drawn at z_l = z - b (1 - z) where the surface has depth z, but the
        // line's depth at this pixel is its own (the segment's point nearest the pixel centre) and the
        // surface's is the triangle's at the centre: they may differ by the surface's depth change
        // across a pixel, steep near the silhouette.
        const float z = surface.aov.depth[i], zl = wire.aov.depth[i];
        float slope = 0.0f;
        const int x = int(i % size), y = int(i / size);
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int nx = x + dx, ny = y + dy;
                if (nx < 0 || ny < 0 || nx >= int(size) || ny >= int(size)) continue;
                const size_t n = size_t(ny) * size + size_t(nx);
                if (surface.aov.id[n] != EMPTY_ID)
                    slope = std::max(slope, std::abs(surface.aov.depth[n] - z));
            }
        if (zl > z + slope || z - zl > kWireframeDepthBias * (1.0f - z) + slope) ++offSurface;
    }
    std::printf("[ pn wireframe ] %zu of %zu sphere pixels are edges, %zu off the surface\n", linePixels,
                covered, offSurface);
    EXPECT_GT(double(linePixels) / double(covered), 0.15);
    EXPECT_LE(double(offSurface), 0.02 * double(linePixels));
    // The triangles under the overlay are the plain pn frame's, with the same scene ids.
    size_t sameTriangle = 0, surfacePixels = 0;
    for (size_t i = 0; i < wire.aov.id.size(); ++i) {
        if (wire.aov.id[i] >= triangles) continue;
        ++surfacePixels;
        sameTriangle += wire.aov.id[i] == surface.aov.id[i] ? 1 : 0;
    }
    EXPECT_EQ(sameTriangle, surfacePixels);
}

INSTANTIATE_TEST_SUITE_P(Backends, LooksTest, ::testing::Values("vulkan", "cuda"));

}  // namespace
}  // namespace sr::test
