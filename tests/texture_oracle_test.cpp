// texture_oracle_test.cpp - software texture sampling (common/shared/texture.h, through the Vulkan
// compute backend) against lavapipe's hardware sampler (`vulkan-graphics`: real VkImages and
// VkSamplers, textureGrad with the 2x2-quad derivatives of the interpolated coordinates).
//
// Criteria (derivations in docs/validation.md, "Textures against lavapipe's sampler"):
// - NEAREST magnification and alpha-MASK cut-outs: identical ids and colours, except at pixels whose
//   centre lies within eps of a texel border in our texture coordinate, eps covering half a subpixel of
//   position error (2^-9 px along x and y) times the coordinate's screen gradient, plus float rounding.
// - Bilinear magnification: colour within 2/255 (weights quantised to 1/256, sRGB encode rounding).
// - Trilinear minification: the oracle's colour within 2/255 of the range our filter spans over lambda
//   +- 0.5 (the spec's rho approximations, quad vs analytic derivatives), blend factors quantised to 1/16
//   (mipmapPrecisionBits 4) and coordinates +- 1/512 texel (subTexelPrecisionBits 8), as VK-GL-CTS's
//   TexLookupVerifier accepts a value that some admissible LOD, weight and coordinate produce.
// Each case prints a table row (pixels compared, outside the bound, PSNR, max error) for the docs.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "render/materials.h"
#include "camera/camera.h"
#include "scene/texture.h"
#include "test_util.h"
#include "vulkan/vulkan_graphics.h"

namespace sr::test {
namespace {

// Unlit, so the colour is the sRGB-encoded base colour; magenta background, a colour no texel here has.
RenderSettings unlitSettings(uint32_t w, uint32_t h, uint32_t uvInterpolation = UV_PERSPECTIVE)
{
    RenderSettings s = testSettings(w, h);
    s.shadingMode = SHADING_LAMBERT;
    s.lightColor = glm::vec3(0.0f);
    s.ambient = 1.0f;
    s.background = glm::vec3(1.0f, 0.0f, 1.0f);
    s.uvInterpolation = uvInterpolation;
    return s;
}

int channel(uint32_t word, int c)
{
    return int((word >> (8 * c)) & 255u);
}

// The byte packRgba8 writes for a linear value.
int encodeByte(float linear)
{
    return int(uint32_t(linearToSrgb(linear) * 255.0f + 0.5f));
}

// The scene's textures as the compute path reads them (gpuTextures' texel buffer, the sRGB decode
// table), and the sampling of compute_glsl/buffers.glsl (fetchTexel, sampleLevel) spelled out on the
// host with the same shared functions.
struct HostSampler {
    std::vector<GpuMaterial> materials;
    std::vector<GpuTexture> textures;
    std::vector<uint32_t> texels;
    std::vector<float> srgb = srgbDecodeTable();

    explicit HostSampler(const Scene& scene) : materials(gpuMaterials(scene))
    {
        auto t = gpuTextures(scene, texels);
        EXPECT_TRUE(t.ok());
        if (t.ok()) textures = *t;
    }

    vec4 fetch(const GpuTexture& t, uint32_t index) const
    {
        uint32_t texel = texels[index];
        vec4 c = textureUnorm(texel);
        if (t.srgb != 0u)
            c = vec4(srgb[texel & 255u], srgb[(texel >> 8) & 255u], srgb[(texel >> 16) & 255u], c.w);
        return c;
    }

    vec4 sampleLevel(const GpuTexture& t, uint32_t level, uint32_t filter, vec2 st) const
    {
        ivec2 size = textureLevelSize(t, level);
        uint32_t offset = textureLevelOffset(t, level);
        vec2 w;
        ivec2 ij = textureTexelCoords(st, size, filter, w);
        if (filter == FILTER_NEAREST) return fetch(t, textureTexelIndex(t, offset, size, ij.x, ij.y));
        return textureBilinear(fetch(t, textureTexelIndex(t, offset, size, ij.x, ij.y)),
                               fetch(t, textureTexelIndex(t, offset, size, ij.x + 1, ij.y)),
                               fetch(t, textureTexelIndex(t, offset, size, ij.x, ij.y + 1)),
                               fetch(t, textureTexelIndex(t, offset, size, ij.x + 1, ij.y + 1)), w);
    }

    // Per-channel range of one level's filter over the texel-space box st*size +- delta. The filter is
    // piecewise bilinear with kinks on the lines through texel centres, so its extremes over the box lie
    // at the box corners or where those lines cross the box: all of them are evaluated.
    void levelRange(const GpuTexture& t, uint32_t level, uint32_t filter, vec2 st, vec2 delta, vec4& lo,
                    vec4& hi) const
    {
        ivec2 size = textureLevelSize(t, level);
        double u = double(st.x) * size.x, v = double(st.y) * size.y;
        auto candidates = [](double c, double d) {
            std::vector<double> out = {c - d, c + d};
            for (double k = std::ceil(c - d - 0.5); k + 0.5 < c + d; ++k)
                if (k + 0.5 > c - d) out.push_back(k + 0.5);
            return out;
        };
        lo = vec4(1e30f);
        hi = vec4(-1e30f);
        for (double cu : candidates(u, delta.x))
            for (double cv : candidates(v, delta.y)) {
                vec4 c = sampleLevel(t, level, filter, vec2(float(cu / size.x), float(cv / size.y)));
                lo = min(lo, c);
                hi = max(hi, c);
            }
    }
};

// Texture coordinate of the base colour texture at a pixel, as materialBaseColor computes it.
struct PixelTexcoord {
    bool textured = false;
    GpuTexture texture{};
    vec2 st{0.0f}, dx{0.0f}, dy{0.0f};  // after the material's transform; derivatives per pixel
    float lambda = -128.0f;
};

PixelTexcoord texcoordAt(const Scene& scene, const HostSampler& host, const RasterParams& params, uint32_t id,
                         int px, int py)
{
    PixelTexcoord r;
    if (host.materials.empty() || id >= scene.triangleCount()) return r;
    const GpuMaterial& m =
        host.materials[std::min<size_t>(scene.triMaterials[id], host.materials.size() - 1)];
    if (m.baseColorTexture >= host.textures.size()) return r;
    uint32_t i0 = scene.indices[3 * id], i1 = scene.indices[3 * id + 1], i2 = scene.indices[3 * id + 2];
    SurfacePoint s = surfaceAt(params, px, py, scene.positions[i0], scene.positions[i1], scene.positions[i2],
                               scene.normals[i0], scene.normals[i1], scene.normals[i2]);
    auto set = [&](uint32_t v) {
        const glm::vec4& t = scene.texcoords[v];
        return m.texCoord != 0u ? vec2(t.z, t.w) : vec2(t.x, t.y);
    };
    vec2 dx, dy;
    vec2 uv = surfaceUv(s, set(i0), set(i1), set(i2), dx, dy);
    r.textured = true;
    r.texture = host.textures[m.baseColorTexture];
    r.st = materialTransformUv(m, uv);
    r.dx = materialTransformDerivative(m, dx);
    r.dy = materialTransformDerivative(m, dy);
    r.lambda = textureLambda(r.dx, r.dy, r.texture.width, r.texture.height);
    return r;
}

// Position uncertainty between the two pipelines, in pixels, along x and along y: half a subpixel of the
// 8-bit subpixel grid. lavapipe interpolates from unsnapped positions as we do, so float rounding alone
// separates them (~1e-5 px); half a subpixel also covers a device that sets up attribute planes from
// snapped vertices, as the D3D rule does.
constexpr double kPositionError = 1.0 / 512.0;
// Float rounding of a texel coordinate of magnitude <= 2^9 in either pipeline: a few ulps.
constexpr double kCoordinateRounding = 1e-5;

// Half-width, in level-0 texels, of the band around texel borders for a pixel: the coordinate's change
// over the position uncertainty along x and y, plus rounding.
vec2 borderEps(const PixelTexcoord& t)
{
    double ex = (std::abs(double(t.dx.x)) + std::abs(double(t.dy.x))) * t.texture.width * kPositionError;
    double ey = (std::abs(double(t.dx.y)) + std::abs(double(t.dy.y))) * t.texture.height * kPositionError;
    return vec2(float(ex + kCoordinateRounding), float(ey + kCoordinateRounding));
}

// Whether the pixel centre lies within eps of a level-0 texel border, along u or v.
bool nearTexelBorder(const PixelTexcoord& t, double* distance = nullptr)
{
    double u = double(t.st.x) * t.texture.width, v = double(t.st.y) * t.texture.height;
    double du = std::abs(u - std::round(u)), dv = std::abs(v - std::round(v));
    vec2 eps = borderEps(t);
    if (distance) *distance = std::min(du, dv);
    return du < eps.x || dv < eps.y;
}

// Bilinear magnification bound, /255 (derivation in the test below).
constexpr int kBilinearBound = 2;
// Slack around a trilinear acceptance range, /255: sRGB encode rounding on both sides and the device's
// sRGB decode and pow approximations.
constexpr int kColourSlack = 2;
// Trilinear: the LOD allowance either way, in levels. The spec lets rho_x be approximated by
// max(|du/dx|, |dv/dx|) (down to 1/sqrt(2) of the exact length, -0.5 level) and the derivatives are
// 2x2-quad differences where ours are analytic at the pixel centre.
constexpr float kLodAllowance = 0.5f;
// Hardware filter weights: subTexelPrecisionBits 8 means steps of 1/256 texel, rounding or truncating.
constexpr double kWeightStep = 1.0 / 256.0;
// Hardware blend factor between levels: mipmapPrecisionBits 4, steps of 1/16.
constexpr float kBlendStep = 1.0f / 16.0f;

// Per-channel range (linear) of our lookup over lambda +- allowance (every integer level crossed and the
// interval's ends rounded outwards to the blend step: the value is linear in lambda between integer
// levels, so these are its extremes), each level's filter over a coordinate box of one weight step plus
// the interpolation uncertainty (borderEps) scaled to that level.
void lookupRange(const HostSampler& host, const PixelTexcoord& t, uint32_t filterOverride, float allowance,
                 vec4& lo, vec4& hi)
{
    std::vector<float> lambdas = {t.lambda};
    if (allowance > 0.0f) {
        float a = t.lambda - allowance, b = t.lambda + allowance;
        lambdas = {a, b, std::floor(a / kBlendStep) * kBlendStep, std::ceil(b / kBlendStep) * kBlendStep};
        for (float k = std::floor(a) + 1.0f; k < b; k += 1.0f) lambdas.push_back(k);
    }
    vec2 eps0 = borderEps(t);
    lo = vec4(1e30f);
    hi = vec4(-1e30f);
    for (float lambda : lambdas) {
        TextureLookup look = textureSelect(t.texture, lambda, filterOverride);
        vec4 lo0, hi0, lo1, hi1;
        auto delta = [&](uint32_t level) {
            float scale = std::ldexp(1.0f, -int(level));
            return vec2(float(kWeightStep) + eps0.x * scale, float(kWeightStep) + eps0.y * scale);
        };
        host.levelRange(t.texture, look.level0, look.filterMode, t.st, delta(look.level0), lo0, hi0);
        if (look.blend > 0.0f) {
            host.levelRange(t.texture, look.level1, look.filterMode, t.st, delta(look.level1), lo1, hi1);
            lo0 = lo0 + (lo1 - lo0) * look.blend;
            hi0 = hi0 + (hi1 - hi0) * look.blend;
        }
        lo = min(lo, lo0);
        hi = max(hi, hi0);
    }
}

struct Row {
    std::string name;
    size_t compared = 0;        // pixels covered by the same triangle in both
    size_t idDiffers = 0;       // pixels whose ids differ (after any allowance: see each test)
    size_t inBand = 0;          // differing pixels excused by the border band (NEAREST, MASK)
    size_t bandPixels = 0;      // compared pixels whose centre lies in the band, differing or not
    double maxFootprint = 0.0;  // largest rho (level-0 texels per pixel) where compared, NEAREST/MASK
    int rangeExcess = 0;        // trilinear: largest distance, /255, of the oracle outside our bare range
    size_t outside = 0;         // pixels outside the bound
    double sumSq = 0.0;         // over compared pixels, RGB bytes
    int maxError = 0;           // largest channel difference, /255
    double maxBandEps = 0.0;    // largest eps used (texels)

    double psnr() const
    {
        double mse = sumSq / std::max<double>(1.0, 3.0 * compared);
        return mse == 0.0 ? INFINITY : 10.0 * std::log10(255.0 * 255.0 / mse);
    }
    void add(uint32_t a, uint32_t b)
    {
        ++compared;
        for (int c = 0; c < 3; ++c) {
            int d = std::abs(channel(a, c) - channel(b, c));
            sumSq += double(d) * d;
            maxError = std::max(maxError, d);
        }
    }
    // One row of the table in docs/validation.md: | case | compared | differing ids | outside the bound |
    // pixels in the border band | PSNR (dB) | max error (/255) |.
    void print() const
    {
        std::printf("| %s | %zu | %zu | %zu | %zu | %.1f | %d |\n", name.c_str(), compared, idDiffers,
                    outside, bandPixels, psnr(), maxError);
    }
};

class TextureOracleTest : public ComputeOracleTest {
protected:
    // Both renders of one scene; false (with a failure) if either failed.
    bool renderBoth(const Scene& scene, const CameraMatrices& camera, const RenderSettings& s,
                    RenderOutput& ours, RenderOutput& oracle)
    {
        auto a = renderScene(*compute_, scene, camera, s);
        auto b = renderVulkanGraphics(scene, camera, s, -1);
        EXPECT_TRUE(a.ok()) << (a.ok() ? "" : a.error().message);
        EXPECT_TRUE(b.ok()) << (b.ok() ? "" : b.error().message);
        if (!a.ok() || !b.ok()) return false;
        ours = std::move(*a);
        oracle = std::move(*b);
        return true;
    }

    // Exact agreement up to the texel-border band: ids and colours identical wherever the pixel centre is
    // farther than eps from a texel border in our coordinate (of the front textured triangle involved).
    Row exactOutsideBand(const std::string& name, const Scene& scene, const CameraMatrices& camera,
                         const RenderSettings& s)
    {
        Row row{name};
        RenderOutput ours, oracle;
        if (!renderBoth(scene, camera, s, ours, oracle)) return row;
        HostSampler host(scene);
        for (size_t i = 0; i < ours.aov.id.size(); ++i) {
            uint32_t a = ours.aov.id[i], b = oracle.aov.id[i];
            int px = int(i % s.width), py = int(i / s.width);
            bool same = a == b && ours.color.pixels[i] == oracle.color.pixels[i];
            if (a == b && a != EMPTY_ID) {
                row.add(ours.color.pixels[i], oracle.color.pixels[i]);
                PixelTexcoord t = texcoordAt(scene, host, ours.params, a, px, py);
                row.bandPixels += t.textured && nearTexelBorder(t);
                if (t.textured) row.maxFootprint = std::max(row.maxFootprint, double(std::exp2(t.lambda)));
            }
            if (a != b) ++row.idDiffers;
            if (same) continue;
            // The textured triangle at this pixel in either image (ours first).
            PixelTexcoord t;
            for (uint32_t id : {a, b})
                if (!t.textured && id != EMPTY_ID) t = texcoordAt(scene, host, ours.params, id, px, py);
            double distance = 0.0;
            if (t.textured && nearTexelBorder(t, &distance)) {
                ++row.inBand;
                row.maxBandEps = std::max(row.maxBandEps, double(std::max(borderEps(t).x, borderEps(t).y)));
                continue;
            }
            ++row.outside;
            if (row.outside <= 5)
                ADD_FAILURE() << name << ": pixel " << px << "," << py << " ids " << a << "/" << b
                              << " colour " << std::hex << ours.color.pixels[i] << " vs oracle "
                              << oracle.color.pixels[i] << std::dec << ", texel coordinate "
                              << t.st.x * t.texture.width << "," << t.st.y * t.texture.height
                              << " (border distance " << distance << ")";
        }
        row.print();
        return row;
    }

    // Bilinear (no mips): identical ids, colour within kBilinearBound everywhere both cover.
    Row bilinear(const std::string& name, const Scene& scene, const CameraMatrices& camera,
                 const RenderSettings& s)
    {
        Row row{name};
        RenderOutput ours, oracle;
        if (!renderBoth(scene, camera, s, ours, oracle)) return row;
        for (size_t i = 0; i < ours.aov.id.size(); ++i) {
            uint32_t a = ours.aov.id[i], b = oracle.aov.id[i];
            if (a != b) ++row.idDiffers;
            if (a != b || a == EMPTY_ID) continue;
            row.add(ours.color.pixels[i], oracle.color.pixels[i]);
            int d = 0;
            for (int c = 0; c < 3; ++c)
                d = std::max(d,
                             std::abs(channel(ours.color.pixels[i], c) - channel(oracle.color.pixels[i], c)));
            if (d > kBilinearBound) ++row.outside;
        }
        row.print();
        return row;
    }

    // Trilinear: per pixel the range our filter spans over the admissible LODs, blend factors and
    // coordinates (see lookupRange), widened by kColourSlack; the oracle's colour must lie inside. Also
    // counts (in `atLambda`) the pixels that would fall outside with our own lambda alone, to show what
    // the LOD allowance is needed for.
    Row trilinear(const std::string& name, const Scene& scene, const CameraMatrices& camera,
                  const RenderSettings& s, size_t& atLambda)
    {
        Row row{name};
        atLambda = 0;
        RenderOutput ours, oracle;
        if (!renderBoth(scene, camera, s, ours, oracle)) return row;
        HostSampler host(scene);
        for (size_t i = 0; i < ours.aov.id.size(); ++i) {
            uint32_t a = ours.aov.id[i], b = oracle.aov.id[i];
            if (a != b) ++row.idDiffers;
            if (a != b || a == EMPTY_ID) continue;
            row.add(ours.color.pixels[i], oracle.color.pixels[i]);
            int px = int(i % s.width), py = int(i / s.width);
            PixelTexcoord t = texcoordAt(scene, host, ours.params, a, px, py);
            if (!t.textured) continue;
            vec4 lo, hi;
            lookupRange(host, t, s.textureFilter, kLodAllowance, lo, hi);
            vec4 lo0, hi0;
            lookupRange(host, t, s.textureFilter, 0.0f, lo0, hi0);
            bool inside = true, inside0 = true;
            for (int c = 0; c < 3; ++c) {
                int o = channel(oracle.color.pixels[i], c);
                row.rangeExcess = std::max({row.rangeExcess, encodeByte(lo[c]) - o, o - encodeByte(hi[c])});
                inside =
                    inside && o >= encodeByte(lo[c]) - kColourSlack && o <= encodeByte(hi[c]) + kColourSlack;
                inside0 = inside0 && o >= encodeByte(lo0[c]) - kColourSlack &&
                          o <= encodeByte(hi0[c]) + kColourSlack;
            }
            atLambda += !inside0;
            if (inside) continue;
            ++row.outside;
            if (row.outside <= 5)
                ADD_FAILURE() << name << ": pixel " << px << "," << py << " oracle " << std::hex
                              << oracle.color.pixels[i] << " ours " << ours.color.pixels[i] << std::dec
                              << " accepted R " << encodeByte(lo.x) - kColourSlack << ".."
                              << encodeByte(hi.x) + kColourSlack << ", our lambda " << t.lambda << ", st "
                              << t.st.x << "," << t.st.y;
        }
        row.print();
        return row;
    }
};

// A world-space quad (corners counter-clockwise, texture coordinates (0, 0) at corner 0 to (uvMax,
// uvMax) at corner 2) with one material using `texture`, finalised like a loaded scene.
Scene texturedQuad(const glm::vec3 (&corner)[4], float uvMax, SceneTexture texture)
{
    Scene scene;
    const glm::vec2 uv[4] = {{0.0f, 0.0f}, {uvMax, 0.0f}, {uvMax, uvMax}, {0.0f, uvMax}};
    glm::vec3 n = glm::normalize(glm::cross(corner[1] - corner[0], corner[3] - corner[0]));
    for (int k = 0; k < 4; ++k) {
        scene.positions.emplace_back(corner[k], 1.0f);
        scene.normals.emplace_back(n, 0.0f);
        scene.texcoords.emplace_back(uv[k].x, uv[k].y, 0.0f, 0.0f);
    }
    scene.indices = {0, 1, 2, 0, 2, 3};
    scene.triMaterials = {0, 0};
    scene.textures.push_back(std::move(texture));
    SceneMaterial m;
    m.baseColorTexture = 0;
    scene.materials.push_back(m);
    Status status = finalizeScene(scene, "texture oracle quad");
    EXPECT_TRUE(status.ok());
    return scene;
}

// 8 x 8 texels of distinct colours, every channel >= minValue (so green is never the magenta
// background's 0), sampled by `filter` without mipmaps, REPEAT.
SceneTexture colourGrid(bool srgb, uint32_t filter, uint8_t minValue)
{
    std::vector<uint8_t> rgba;
    for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i) {
            int span = 255 - minValue;
            rgba.insert(rgba.end(),
                        {uint8_t(minValue + span * i / 7), uint8_t(minValue + span * ((i + 3 * j) % 8) / 7),
                         uint8_t(minValue + span * (7 - j) / 7), 255});
        }
    TextureSampler sampler{WRAP_REPEAT, WRAP_REPEAT, filter, filter, MIPMAP_NONE};
    auto t = makeTexture("grid", 8, 8, rgba.data(), srgb, sampler);
    EXPECT_TRUE(t.ok());
    return t.ok() ? std::move(*t) : SceneTexture{};
}

CameraMatrices orbit(const Scene& scene, float az, float el, float dist, uint32_t w, uint32_t h)
{
    CameraSpec spec;
    spec.kind = CameraSpec::Kind::Orbit;
    spec.orbit.azimuthDeg = az;
    spec.orbit.elevationDeg = el;
    spec.orbit.distance = dist;
    auto c = resolveCamera(spec, scene, w, h);
    EXPECT_TRUE(c.ok());
    return c.ok() ? *c : identityCamera();
}

// The two views of the magnification cases: screen-aligned (a clip-space quad whose texel borders fall
// at arbitrary pixel positions, 14.6 px per texel) and a perspective, rotated view of a unit-square quad.
struct View {
    std::string name;
    Scene scene;
    CameraMatrices camera;
    uint32_t size;
};

std::vector<View> magnificationViews(const SceneTexture& texture)
{
    const glm::vec3 clipQuad[4] = {
        {-0.91f, -0.87f, 0.5f}, {0.93f, -0.87f, 0.5f}, {0.93f, 0.95f, 0.5f}, {-0.91f, 0.95f, 0.5f}};
    const glm::vec3 worldQuad[4] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    std::vector<View> views;
    views.push_back({"screen-aligned", texturedQuad(clipQuad, 1.0f, texture), identityCamera(), 128});
    Scene world = texturedQuad(worldQuad, 1.0f, texture);
    CameraMatrices camera = orbit(world, 30.0f, 35.0f, 3.2f, 256, 256);
    views.push_back({"perspective", std::move(world), camera, 256});
    return views;
}

TEST_F(TextureOracleTest, NearestMagnificationIsExactAwayFromTexelBorders)
{
    SceneTexture texture = colourGrid(true, FILTER_NEAREST, 40);
    for (View& v : magnificationViews(texture)) {
        Row row = exactOutsideBand("nearest " + v.name, v.scene, v.camera, unlitSettings(v.size, v.size));
        EXPECT_EQ(row.idDiffers, 0u) << v.name;
        EXPECT_EQ(row.outside, 0u) << v.name;
        EXPECT_GT(row.compared, v.size * v.size / 3) << v.name;
        // Magnified by at least 8: the premise of the band's size (<= 2.6e-4 texel) in the docs.
        EXPECT_LE(row.maxFootprint, 0.125) << v.name;
        std::printf("  %s: at most %.3f texels per pixel\n", v.name.c_str(), row.maxFootprint);
    }
}

// Bilinear magnification: weights quantised to 1/256 move the value by at most 1/256 of the texel
// contrast (0.75 here: channels 64..255, UNORM); over that range the sRGB encode's slope is below 1, so
// that is < 0.75/255 after encoding, plus the rounding of each side's encode: within 2/255. Texels darker
// than 64 would multiply the weight error by the encode's slope near black (12.92).
TEST_F(TextureOracleTest, BilinearMagnificationWithinTwoLevels)
{
    SceneTexture texture = colourGrid(false, FILTER_LINEAR, 64);
    for (View& v : magnificationViews(texture)) {
        Row row = bilinear("bilinear " + v.name, v.scene, v.camera, unlitSettings(v.size, v.size));
        EXPECT_EQ(row.idDiffers, 0u) << v.name;
        EXPECT_EQ(row.outside, 0u) << v.name;
        EXPECT_GT(row.compared, v.size * v.size / 3) << v.name;
    }
}

// Trilinear minification on builtin:checker, grazing and mid angles, perspective-correct and affine UVs.
TEST_F(TextureOracleTest, TrilinearMinificationWithinTheLodAndWeightAllowances)
{
    auto checker = builtinSceneNamed("builtin:checker");
    ASSERT_TRUE(checker.ok());
    struct Case {
        const char* name;
        float el;
        uint32_t uv;
    };
    for (Case c : {Case{"trilinear grazing (orbit:0,6,12)", 6.0f, UV_PERSPECTIVE},
                   Case{"trilinear mid (orbit:0,35,12)", 35.0f, UV_PERSPECTIVE},
                   Case{"trilinear grazing, affine UV", 6.0f, UV_AFFINE}}) {
        const uint32_t size = 256;
        CameraMatrices camera = orbit(*checker, 0.0f, c.el, 12.0f, size, size);
        size_t atLambda = 0;
        Row row = trilinear(c.name, *checker, camera, unlitSettings(size, size, c.uv), atLambda);
        std::printf(
            "  %s: %zu pixels outside with our lambda alone; the oracle at most %d/255 outside the "
            "bare range\n",
            c.name, atLambda, row.rangeExcess);
        EXPECT_EQ(row.outside, 0u) << c.name;
        // The plane reaches far outside the viewport and is clipped by lavapipe: its ids may differ where a
        // clip-generated vertex rounds to the neighbouring subpixel, as oracle_test.cpp allows (64 pixels).
        EXPECT_LE(row.idDiffers, 64u) << c.name;
        EXPECT_GT(row.compared, size * size / 4) << c.name;
    }
}

// builtin:cutout (alphaMode MASK, NEAREST): ids and colours identical except in the border band.
TEST_F(TextureOracleTest, AlphaMaskCutoutIsExactAwayFromTexelBorders)
{
    auto cutout = builtinSceneNamed("builtin:cutout");
    ASSERT_TRUE(cutout.ok());
    const uint32_t size = 256;
    CameraMatrices camera = orbit(*cutout, 25.0f, 20.0f, 4.5f, size, size);
    Row row = exactOutsideBand("cutout (orbit:25,20,4.5)", *cutout, camera, unlitSettings(size, size));
    EXPECT_EQ(row.outside, 0u);
    EXPECT_GT(row.compared, size * size / 4);
    EXPECT_GT(row.bandPixels, 0u);  // the view does put pixel centres near the cut-out borders
    std::printf("  cutout: at most %.3f texels per pixel\n", row.maxFootprint);
}

}  // namespace
}  // namespace sr::test
