// delivery_test.cpp - what a frame hands back, as stage aovs computes it on the device: each pixel's id
// and depth equal to its AOV sample's key (read from every sample, which the host unpacks itself), the
// surface AOVs bit for bit those of the host's evaluation (fillSurfaceAovs, the form vulkan-graphics
// keeps, and the form every backend used before the stage), rasterize's output from them by its
// definition, only the images asked for, and positions replaced in place (Scene::updatePositions) against
// a scene made from the new positions. A missing backend fails these tests unless SR_ALLOW_MISSING_BACKENDS
// names it.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "raster/raster.h"

#include "render/aov.h"
#include "render/renderer.h"
#include "camera/camera.h"
#include "scene/scene.h"
#include "test_util.h"

namespace sr::test {
namespace {

// Bit-for-bit equality of two float planes, reporting the first difference.
void expectSameBits(const std::vector<float>& a, const std::vector<float>& b, const std::string& what)
{
    ASSERT_EQ(a.size(), b.size()) << what;
    for (size_t i = 0; i < a.size(); ++i) {
        uint32_t x = 0, y = 0;
        std::memcpy(&x, &a[i], 4);
        std::memcpy(&y, &b[i], 4);
        if (x != y) {
            ADD_FAILURE() << what << ": pixel " << i << " holds " << a[i] << ", the host's evaluation "
                          << b[i];
            return;
        }
    }
}

struct Case {
    std::string scene;
    uint32_t msaa = 1, ssaa = 1;
    uint32_t tessellate = TESS_OFF;
    uint32_t clusters = CLUSTERS_AUTO;
};

class DeliveryTest : public BackendTest {
protected:
    // `c` at 64 x 48 under the auto camera, with the surface AOVs and every sample's key.
    RenderOutput renderCase(const Case& c, Scene& scene, RenderSettings& s)
    {
        auto loaded = loadScene(c.scene);
        EXPECT_TRUE(loaded.ok()) << (loaded.ok() ? "" : loaded.error().message);
        if (!loaded.ok()) return {};
        scene = std::move(*loaded);
        s = testSettings(64, 48);
        s.cullMode = CULL_BACK;
        s.msaa = c.msaa;
        s.ssaa = c.ssaa;
        s.tessellate = c.tessellate;
        s.clusters = c.clusters;
        s.surfaceAovs = true;
        s.aovSamples = true;
        auto camera = resolveCamera(CameraSpec{}, scene, s.width, s.height);
        EXPECT_TRUE(camera.ok());
        return camera.ok() ? render(scene, s, *camera) : RenderOutput{};
    }
};

TEST_P(DeliveryTest, DeviceAovsEqualTheSampleKeysAndTheHostsSurfaces)
{
    for (const Case& c : {Case{"builtin"}, Case{"builtin:checker", 4, 1}, Case{"builtin:lowpoly", 1, 2},
                          Case{"builtin:cutout", 8, 1}, Case{"builtin:dense", 1, 1, TESS_OFF, CLUSTERS_ON},
                          Case{"builtin:lowpoly", 1, 1, TESS_PN}}) {
        SCOPED_TRACE(c.scene + " msaa " + std::to_string(c.msaa) + " ssaa " + std::to_string(c.ssaa) +
                     (c.tessellate != TESS_OFF ? " tessellated" : ""));
        Scene scene;
        RenderSettings s;
        RenderOutput out = renderCase(c, scene, s);
        ASSERT_EQ(out.aov.id.size(), size_t(64) * 48);
        ASSERT_EQ(out.aov.depth.size(), size_t(64) * 48);
        uint64_t covered = 0;
        for (uint32_t y = 0; y < 48; ++y)
            for (uint32_t x = 0; x < 64; ++x) {
                const uint64_t k = aovSampleIndex(x, y, out.samples.rasterWidth, c.ssaa);
                const size_t i = size_t(y) * 64 + x;
                ASSERT_EQ(out.aov.id[i], out.samples.id[k]) << "pixel " << x << "," << y;
                ASSERT_EQ(std::memcmp(&out.aov.depth[i], &out.samples.depth[k], 4), 0)
                    << "pixel " << x << "," << y;
                covered += out.aov.id[i] != EMPTY_ID;
            }
        EXPECT_GT(covered, 64u * 48u / 8u);
        if (c.tessellate != TESS_OFF) continue;  // the host's evaluation needs the generated mesh's ids
        AovImage host;
        host.width = 64;
        host.height = 48;
        host.id = out.aov.id;
        fillSurfaceAovs(scene, out.params, host);
        expectSameBits(out.aov.baryU, host.baryU, "bary.u");
        expectSameBits(out.aov.baryV, host.baryV, "bary.v");
        expectSameBits(out.aov.uvU, host.uvU, "uv.u");
        expectSameBits(out.aov.uvV, host.uvV, "uv.v");
        expectSameBits(out.aov.normalX, host.normalX, "N.x");
        expectSameBits(out.aov.normalY, host.normalY, "N.y");
        expectSameBits(out.aov.normalZ, host.normalZ, "N.z");
    }
}

// Names of the stages a frame ran.
std::vector<std::string> stageNames(const RenderOutput& out)
{
    std::vector<std::string> names;
    for (const StageTiming& t : out.stages) names.push_back(t.name);
    return names;
}

bool ran(const RenderOutput& out, const std::string& stage)
{
    const std::vector<std::string> names = stageNames(out);
    return std::find(names.begin(), names.end(), stage) != names.end();
}

TEST_P(DeliveryTest, OnlyTheImagesAskedForAreComputedAndCopied)
{
    FramedScene f = framedBuiltin(96, 64);
    const RenderOutput all = render(f.scene, f.settings, f.camera);
    ASSERT_EQ(all.color.pixels.size(), size_t(96) * 64);
    EXPECT_TRUE(ran(all, "shade") && ran(all, "aovs"));

    RenderSettings ids = f.settings;
    ids.outputs = OUTPUT_ID;
    const RenderOutput idsOnly = render(f.scene, ids, f.camera);
    EXPECT_TRUE(idsOnly.color.pixels.empty());
    EXPECT_TRUE(idsOnly.aov.depth.empty());
    EXPECT_EQ(idsOnly.aov.id, all.aov.id);
    EXPECT_FALSE(ran(idsOnly, "shade")) << "nobody reads the colour";

    RenderSettings colour = f.settings;
    colour.outputs = OUTPUT_COLOR;
    const RenderOutput colourOnly = render(f.scene, colour, f.camera);
    EXPECT_EQ(colourOnly.color.pixels, all.color.pixels);
    EXPECT_TRUE(colourOnly.aov.id.empty());
    EXPECT_TRUE(colourOnly.aov.depth.empty());
    EXPECT_FALSE(ran(colourOnly, "aovs")) << "no id or depth to unpack";

    RenderSettings depth = f.settings;
    depth.outputs = OUTPUT_DEPTH;
    EXPECT_EQ(render(f.scene, depth, f.camera).aov.depth, all.aov.depth);
}

TEST_P(DeliveryTest, RasterizeOutputFollowsItsDefinition)
{
    FramedScene f = framedBuiltin(80, 56);
    f.settings.cullMode = CULL_NONE;
    f.settings.surfaceAovs = true;
    f.settings.outputs = OUTPUT_ID | OUTPUT_DEPTH | OUTPUT_RAST;
    auto session = RenderSession::create(*device_, f.scene);
    ASSERT_TRUE(session.ok());
    auto out = session->render(f.camera, f.settings);
    ASSERT_TRUE(out.ok()) << out.error().message;
    std::vector<float> rast(size_t(4) * 80 * 56, -7.0f);
    ASSERT_TRUE(session->readImage(OUTPUT_RAST, rast.data(), rast.size() * 4, false).ok());
    for (size_t i = 0; i < out->aov.id.size(); ++i) {
        const uint32_t id = out->aov.id[i];
        // nvdiffrast's layout: the weights of vertices 0 and 1, OpenGL's z/w from Vulkan's window depth,
        // the id plus one; all zero where empty.
        const float b1 = out->aov.baryU[i], b2 = out->aov.baryV[i];
        const float expected[4] = {id == EMPTY_ID ? 0.0f : 1.0f - b1 - b2, id == EMPTY_ID ? 0.0f : b1,
                                   id == EMPTY_ID ? 0.0f : 2.0f * out->aov.depth[i] - 1.0f,
                                   id == EMPTY_ID ? 0.0f : float(id) + 1.0f};
        ASSERT_EQ(std::memcmp(expected, &rast[4 * i], sizeof(expected)), 0) << "pixel " << i;
    }
    // A frame without it has none to read, and a wrong size is refused.
    EXPECT_FALSE(session->readImage(OUTPUT_RAST, rast.data(), (rast.size() - 4) * 4, false).ok());
    RenderSettings plain = f.settings;
    plain.outputs = OUTPUT_IMAGES;
    ASSERT_TRUE(session->render(f.camera, plain).ok());
    EXPECT_FALSE(session->readImage(OUTPUT_RAST, rast.data(), rast.size() * 4, false).ok());
    // Not with generated or simplified triangles, whose ids the device does not know as the scene's.
    f.settings.tessellate = TESS_PN;
    EXPECT_FALSE(session->render(f.camera, f.settings).ok());
}

// The colour, ids and depth of `views` views of `pixels` each, as renderViews writes them.
struct ViewImages {
    ViewImages(size_t views, size_t pixels)
        : pixels(pixels), color(views * pixels), ids(views * pixels), depth(views * pixels)
    {
    }
    std::vector<RenderSession::ViewTarget> targets()
    {
        return {{OUTPUT_COLOR, color.data(), false},
                {OUTPUT_ID, ids.data(), false},
                {OUTPUT_DEPTH, depth.data(), false}};
    }
    // View b against a frame drawn alone, byte for byte.
    void expectView(size_t b, const RenderOutput& expected) const
    {
        ASSERT_EQ(expected.aov.id.size(), pixels);
        EXPECT_TRUE(std::equal(expected.color.pixels.begin(), expected.color.pixels.end(),
                               color.begin() + long(b * pixels)));
        EXPECT_TRUE(
            std::equal(expected.aov.id.begin(), expected.aov.id.end(), ids.begin() + long(b * pixels)));
        expectSameBits(expected.aov.depth,
                       {depth.begin() + long(b * pixels), depth.begin() + long((b + 1) * pixels)}, "depth");
    }
    size_t pixels;
    std::vector<uint32_t> color, ids;
    std::vector<float> depth;
};

// Views (RenderSession::renderViews): each view's colour, ids and depth equal a frame of the scene with
// that view's positions, drawn alone, also where the batch overflows its lists (tiny starting lists) and
// views are drawn again; the session's next render draws the scene's own positions again.
TEST_P(DeliveryTest, ViewsEqualFramesOfTheirPositionsDrawnAlone)
{
    auto loaded = loadScene("builtin:lowpoly");
    ASSERT_TRUE(loaded.ok());
    const Scene scene = std::move(*loaded);
    RenderSettings s = testSettings(56, 40);
    s.cullMode = CULL_NONE;
    s.msaa = 4;
    s.outputs = OUTPUT_COLOR | OUTPUT_ID | OUTPUT_DEPTH;
    auto camera = resolveCamera(CameraSpec{}, scene, s.width, s.height);
    ASSERT_TRUE(camera.ok());
    // A small view first, then views four and eight times its size and one turned about the centre.
    const glm::vec3 centre = 0.5f * (scene.boundsMin + scene.boundsMax);
    std::vector<glm::vec4> positions;
    for (float scale : {0.25f, 1.0f, 2.0f, -1.0f}) {
        for (const glm::vec4& p : scene.positions) {
            glm::vec3 q = glm::vec3(p) - centre;
            if (scale < 0.0f) q = glm::vec3(q.z, q.y, -q.x);
            positions.push_back(glm::vec4(centre + std::abs(scale) * q, 1.0f));
        }
    }
    const size_t views = 4, pixels = size_t(s.width) * s.height;
    for (uint32_t capacity : {0u, 16u}) {
        SCOPED_TRACE("initial list capacity " + std::to_string(capacity));
        s.initialListCapacity = capacity;
        auto session = RenderSession::create(*device_, scene);
        ASSERT_TRUE(session.ok());
        ViewImages images(views, pixels);
        ViewInputs inputs;
        inputs.positions = positions.data();
        inputs.bytes = scene.positions.size() * sizeof(glm::vec4);
        auto invalid = session->renderViews({*camera}, s, inputs, views, images.targets());
        ASSERT_TRUE(invalid.ok()) << invalid.error().message;
        EXPECT_EQ(*invalid, std::vector<uint32_t>(views, 0u));
        for (size_t b = 0; b < views; ++b) {
            SCOPED_TRACE("view " + std::to_string(b));
            Scene moved = scene;
            std::copy_n(positions.begin() + long(b * scene.positions.size()), scene.positions.size(),
                        moved.positions.begin());
            RenderSettings alone = s;
            alone.initialListCapacity = 0;
            const RenderOutput expected = render(moved, alone, *camera);
            images.expectView(b, expected);
        }
        auto own = session->render(*camera, s);
        ASSERT_TRUE(own.ok());
        EXPECT_EQ(own->aov.id, render(scene, s, *camera).aov.id) << "the scene's own positions again";
    }
}

// Frames of many cameras (views without positions, a camera each): each equal to a frame of its camera
// drawn alone, also where the batch overflows its lists and views are drawn again.
TEST_P(DeliveryTest, FramesOfManyCamerasEqualFramesDrawnAlone)
{
    auto loaded = loadScene("builtin:lowpoly");
    ASSERT_TRUE(loaded.ok());
    const Scene scene = std::move(*loaded);
    RenderSettings s = testSettings(48, 40);
    s.msaa = 4;
    s.outputs = OUTPUT_COLOR | OUTPUT_ID | OUTPUT_DEPTH;
    std::vector<CameraMatrices> cameras;
    for (const char* spec : {"orbit:0,10,6r", "orbit:70,20,2.5r", "orbit:150,-30,1.6r", "orbit:250,45,3r"}) {
        auto parsed = parseCameraSpec(spec);
        ASSERT_TRUE(parsed.ok());
        auto camera = resolveCamera(*parsed, scene, s.width, s.height);
        ASSERT_TRUE(camera.ok());
        cameras.push_back(*camera);
    }
    const size_t views = cameras.size(), pixels = size_t(s.width) * s.height;
    for (uint32_t capacity : {0u, 16u}) {
        SCOPED_TRACE("initial list capacity " + std::to_string(capacity));
        s.initialListCapacity = capacity;
        auto session = RenderSession::create(*device_, scene);
        ASSERT_TRUE(session.ok());
        ViewImages images(views, pixels);
        auto invalid = session->renderViews(cameras, s, ViewInputs{}, views, images.targets());
        ASSERT_TRUE(invalid.ok()) << invalid.error().message;
        for (size_t b = 0; b < views; ++b) {
            SCOPED_TRACE("camera " + std::to_string(b));
            RenderSettings alone = s;
            alone.initialListCapacity = 0;
            const RenderOutput expected = render(scene, alone, cameras[b]);
            images.expectView(b, expected);
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, DeliveryTest, ::testing::Values("vulkan", "cuda"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

// ---- positions replaced in place, through the public API ----------------------------------------------

// A small mesh with shared vertices: a 6 x 6 grid of quads over [-1, 1]^2 bent along z by `bend`.
struct Grid {
    std::vector<float> positions;
    std::vector<uint32_t> triangles;
};

Grid grid(float bend)
{
    Grid g;
    constexpr int n = 6;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const float x = -1.0f + 2.0f * float(i) / n, y = -1.0f + 2.0f * float(j) / n;
            g.positions.insert(g.positions.end(), {x, y, bend * (x * x - 0.5f * y)});
        }
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const auto v = uint32_t(j * (n + 1) + i);
            g.triangles.insert(g.triangles.end(), {v, v + 1, v + n + 2, v, v + n + 2, v + n + 1});
        }
    return g;
}

raster::Scene sceneOf(const Grid& g)
{
    raster::MeshArrays m;
    m.positions = g.positions.data();
    m.vertexCount = g.positions.size() / 3;
    m.triangles = g.triangles.data();
    m.triangleCount = g.triangles.size() / 3;
    m.doubleSided = true;
    auto scene = raster::Scene::fromArrays(m);
    EXPECT_TRUE(scene.ok());
    return std::move(*scene);
}

class UpdatePositionsTest : public ::testing::TestWithParam<std::string> {
protected:
    void SetUp() override
    {
        bool skip = false;
        if (!openBackend(GetParam(), skip)) {
            if (skip) GTEST_SKIP() << GetParam() << " absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
            FAIL() << "no " << GetParam() << " device";
        }
        auto device =
            raster::Device::open(GetParam() == "cuda" ? raster::Backend::Cuda : raster::Backend::Vulkan);
        ASSERT_TRUE(device.ok());
        device_.emplace(std::move(*device));
    }
    std::optional<raster::Device> device_;
};

TEST_P(UpdatePositionsTest, EqualsASceneMadeFromTheNewPositions)
{
    raster::Settings settings;
    ASSERT_TRUE(settings.set("width", 72).ok());
    ASSERT_TRUE(settings.set("height", 64).ok());
    ASSERT_TRUE(settings.set("camera", "orbit:20,30,3").ok());
    for (const char* clusters : {"off", "on"}) {
        SCOPED_TRACE(std::string("clusters ") + clusters);
        ASSERT_TRUE(settings.set("clusters", clusters).ok());
        raster::Scene moving = sceneOf(grid(0.0f));
        auto session = raster::Session::create(*device_, moving);
        ASSERT_TRUE(session.ok());
        const raster::Camera camera = raster::Camera::fromSpec("auto");
        ASSERT_TRUE(
            session->render(camera, settings).ok());  // uploads (and builds clusters of) the flat grid
        for (float bend : {0.8f, -0.5f}) {
            const Grid moved = grid(bend);
            ASSERT_TRUE(moving.updatePositions(moved.positions.data(), moved.positions.size() / 3, 3).ok());
            auto updated = session->render(camera, settings);
            ASSERT_TRUE(updated.ok()) << updated.error().message;
            const raster::Scene fresh = sceneOf(moved);
            auto expected = raster::render(*device_, fresh, camera, settings);
            ASSERT_TRUE(expected.ok());
            EXPECT_EQ(updated->color, expected->color) << "flat normals follow the positions";
            EXPECT_EQ(updated->id, expected->id);
            EXPECT_EQ(updated->depth, expected->depth);
            EXPECT_EQ(moving.boundsMin(), fresh.boundsMin());
            EXPECT_EQ(moving.boundsMax(), fresh.boundsMax());
        }
    }
}

TEST_P(UpdatePositionsTest, RefusesAnotherShapeOrNonFiniteValuesAndKeepsTheScene)
{
    Grid g = grid(0.3f);
    raster::Scene scene = sceneOf(g);
    const auto before = scene.boundsMax();
    EXPECT_FALSE(scene.updatePositions(g.positions.data(), g.positions.size() / 3 - 1, 3).ok());
    EXPECT_FALSE(scene.updatePositions(g.positions.data(), g.positions.size() / 4, 4).ok());
    g.positions[7] = NAN;
    const raster::Status nan = scene.updatePositions(g.positions.data(), g.positions.size() / 3, 3);
    ASSERT_FALSE(nan.ok());
    EXPECT_NE(nan.error().message.find("vertex 2 is not finite"), std::string::npos) << nan.error().message;
    EXPECT_EQ(scene.boundsMax(), before);
    auto loaded = raster::Scene::load("builtin");
    ASSERT_TRUE(loaded.ok());
    EXPECT_FALSE(loaded->updatePositions(g.positions.data(), 3, 3).ok()) << "only scenes made from arrays";
}

// Images written in place equal the frame's own arrays: straight from the device, and through the
// arrays where the host maps the ids (tessellation, level of detail); the arrays they replace stay empty.
TEST_P(UpdatePositionsTest, ImagesWrittenInPlaceEqualTheFramesArrays)
{
    auto scene = raster::Scene::load("builtin:lowpoly");
    ASSERT_TRUE(scene.ok());
    auto session = raster::Session::create(*device_, *scene);
    ASSERT_TRUE(session.ok());
    for (const char* mode : {"plain", "tessellate", "lod"}) {
        SCOPED_TRACE(mode);
        raster::Settings settings;
        ASSERT_TRUE(settings.set("width", 48).ok() && settings.set("height", 40).ok());
        if (std::string(mode) == "tessellate") {
            ASSERT_TRUE(settings.set("tessellate", "pn").ok());
        }
        if (std::string(mode) == "lod") {
            ASSERT_TRUE(settings.set("lod", "on").ok());
        }
        const raster::Camera camera = raster::Camera::fromSpec("auto");
        auto arrays = session->render(camera, settings);
        ASSERT_TRUE(arrays.ok()) << arrays.error().message;
        const size_t pixels = size_t(48) * 40;
        auto memory = raster::Memory::allocate(*device_, 12 * pixels);
        ASSERT_TRUE(memory.ok()) << memory.error().message;
        auto* base = static_cast<uint8_t*>(memory->data());
        raster::RenderRequest request;
        request.targets.color = base;
        request.targets.id = base + 4 * pixels;
        request.targets.depth = base + 8 * pixels;
        auto placed = session->render(camera, settings, request);
        ASSERT_TRUE(placed.ok()) << placed.error().message;
        EXPECT_TRUE(placed->color.empty() && placed->id.empty() && placed->depth.empty());
        EXPECT_EQ(std::memcmp(base, arrays->color.data(), 4 * pixels), 0);
        EXPECT_EQ(std::memcmp(base + 4 * pixels, arrays->id.data(), 4 * pixels), 0);
        EXPECT_EQ(std::memcmp(base + 8 * pixels, arrays->depth.data(), 4 * pixels), 0);
    }
}

// Session::renderMany through the public API: each camera's images equal its Frame's.
TEST_P(UpdatePositionsTest, ManyCamerasEqualTheirFrames)
{
    auto scene = raster::Scene::load("builtin");
    ASSERT_TRUE(scene.ok());
    auto session = raster::Session::create(*device_, *scene);
    ASSERT_TRUE(session.ok());
    raster::Settings settings;
    ASSERT_TRUE(settings.set("width", 40).ok() && settings.set("height", 32).ok() &&
                settings.set("msaa", 2).ok());
    std::vector<raster::Camera> cameras;
    for (const char* spec : {"orbit:10,20,3r", "orbit:100,5,2r", "auto"})
        cameras.push_back(raster::Camera::fromSpec(spec));
    const size_t pixels = size_t(40) * 32;
    std::vector<uint8_t> color(4 * pixels * cameras.size());
    std::vector<uint32_t> ids(pixels * cameras.size());
    raster::RenderRequest request;
    request.targets.color = color.data();
    request.targets.id = ids.data();
    auto report = session->renderMany(cameras, settings, request);
    ASSERT_TRUE(report.ok()) << report.error().message;
    for (size_t b = 0; b < cameras.size(); ++b) {
        SCOPED_TRACE("camera " + std::to_string(b));
        auto frame = session->render(cameras[b], settings);
        ASSERT_TRUE(frame.ok());
        EXPECT_EQ(std::memcmp(frame->color.data(), color.data() + 4 * pixels * b, 4 * pixels), 0);
        EXPECT_EQ(std::memcmp(frame->id.data(), ids.data() + pixels * b, 4 * pixels), 0);
    }
    ASSERT_TRUE(settings.set("primitive_mode", "lines").ok());
    EXPECT_FALSE(session->renderMany(cameras, settings, request).ok()) << "lines mode is refused";
}

// Session::renderViews through the public API: positions of 3 and 4 components, equal to frames of scenes
// made from each view's positions; a view with a NaN corner reported (and drawn without that triangle);
// what it does not take refused.
TEST_P(UpdatePositionsTest, ViewsEqualScenesMadeFromEachViewsPositions)
{
    raster::Settings settings;
    ASSERT_TRUE(settings.set("width", 40).ok() && settings.set("height", 36).ok());
    ASSERT_TRUE(settings.set("cull", "none").ok());
    // Fixed matrices (an orbit camera would follow each scene's bounds): the grid scaled into view, its
    // z into Vulkan's depth range, with a perspective divide by 1 + z / 4.
    const std::array<float, 16> view = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    const std::array<float, 16> projection = {0.8f, 0, 0, 0, 0, 0.8f, 0, 0, 0, 0, 0.2f, 0.25f, 0, 0, 0.5f, 1};
    const raster::Camera camera = raster::Camera::fromMatrices(view, projection);
    const size_t pixels = size_t(40) * 36;
    for (uint32_t components : {3u, 4u}) {
        SCOPED_TRACE(std::to_string(components) + " components");
        std::vector<float> all;
        for (float bend : {0.0f, 0.8f, -0.5f}) {
            const Grid g = grid(bend);
            for (size_t v = 0; v < g.positions.size() / 3; ++v) {
                all.insert(all.end(), g.positions.begin() + long(3 * v),
                           g.positions.begin() + long(3 * v + 3));
                if (components == 4) all.push_back(1.0f);
            }
        }
        const Grid flat = grid(0.0f);
        const size_t vertices = flat.positions.size() / 3;
        all[components * vertices + 1] = NAN;  // view 1, vertex 0: its triangles are dropped and counted
        const std::vector<float> normals(3 * vertices, 0.0f);
        auto sceneFrom = [&](const float* positions) {
            raster::MeshArrays m;
            m.positions = positions;
            m.positionComponents = components;
            m.normals = normals.data();
            m.vertexCount = vertices;
            m.triangles = flat.triangles.data();
            m.triangleCount = flat.triangles.size() / 3;
            auto scene = raster::Scene::fromArrays(m);
            EXPECT_TRUE(scene.ok());
            return std::move(*scene);
        };
        const raster::Scene scene = sceneFrom(all.data());
        auto session = raster::Session::create(*device_, scene);
        ASSERT_TRUE(session.ok());
        std::vector<uint32_t> ids(3 * pixels);
        std::vector<float> depth(3 * pixels);
        raster::RenderRequest request;
        request.targets.id = ids.data();
        request.targets.depth = depth.data();
        raster::ViewPositions positions;
        positions.data = all.data();
        positions.views = 3;
        auto report = session->renderViews(camera, settings, positions, request);
        ASSERT_TRUE(report.ok()) << report.error().message;
        ASSERT_EQ(report->invalidTriangles.size(), 3u);
        EXPECT_EQ(report->invalidTriangles[0], 0u);
        EXPECT_GT(report->invalidTriangles[1], 0u);
        EXPECT_EQ(report->invalidTriangles[2], 0u);
        for (size_t b : {0, 2}) {
            SCOPED_TRACE("view " + std::to_string(b));
            const raster::Scene fresh = sceneFrom(all.data() + b * components * vertices);
            auto expected = raster::render(*device_, fresh, camera, settings);
            ASSERT_TRUE(expected.ok());
            EXPECT_TRUE(std::equal(expected->id.begin(), expected->id.end(), ids.begin() + long(b * pixels)));
            EXPECT_EQ(std::memcmp(expected->depth.data(), depth.data() + b * pixels, 4 * pixels), 0);
        }
        auto own = session->render(camera, settings);
        ASSERT_TRUE(own.ok());
        auto first = raster::render(*device_, sceneFrom(all.data()), camera, settings);
        ASSERT_TRUE(first.ok());
        EXPECT_EQ(own->id, first->id) << "render() draws the scene's own positions after the views";
    }
    // Refused: a scene with flat normals (they would not follow), positions on the device elsewhere than
    // on CUDA.
    raster::Scene flatNormals = sceneOf(grid(0.2f));
    auto session = raster::Session::create(*device_, flatNormals);
    ASSERT_TRUE(session.ok());
    std::vector<uint32_t> ids(pixels);
    raster::RenderRequest request;
    request.targets.id = ids.data();
    const Grid g = grid(0.2f);
    raster::ViewPositions positions;
    positions.data = g.positions.data();
    positions.views = 1;
    auto refused = session->renderViews(camera, settings, positions, request);
    ASSERT_FALSE(refused.ok());
    EXPECT_NE(refused.error().message.find("normals"), std::string::npos) << refused.error().message;
}

// The command line asks for what its files hold: `raster render` and its turntable compute the ids and
// depth (stage aovs) only for an AOV EXR, and the PNG is the same either way.
TEST(DeliveryToolTest, IdsAndDepthAreComputedOnlyForAnAovFile)
{
    bool skip = false;
    if (!openBackend("vulkan", skip)) {
        if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
        FAIL() << "no Vulkan device";
    }
    ScratchDir dir("sr_delivery_tool");
    auto stagesRan = [&](const std::string& statsPath) {
        std::ifstream in(statsPath);
        nlohmann::json stats = nlohmann::json::parse(in);
        std::vector<std::string> names;
        for (const auto& [name, timing] : stats.at("stages_ms").items()) names.push_back(name);
        return names;
    };
    auto has = [](const std::vector<std::string>& names, const char* stage) {
        return std::find(names.begin(), names.end(), stage) != names.end();
    };
    const std::string common = "render builtin -q --backend vulkan --width 64 --height 48 ";
    ToolRun png = runTool(common + "-o " + dir.file("a.png") + " --stats " + dir.file("a.json"));
    ASSERT_EQ(png.exitCode, 0) << png.stderrText;
    ToolRun aov = runTool(common + "-o " + dir.file("b.png") + " --aov " + dir.file("b.exr") + " --stats " +
                          dir.file("b.json"));
    ASSERT_EQ(aov.exitCode, 0) << aov.stderrText;
    EXPECT_FALSE(has(stagesRan(dir.file("a.json")), "aovs"));
    EXPECT_TRUE(has(stagesRan(dir.file("b.json")), "aovs"));
    EXPECT_TRUE(has(stagesRan(dir.file("a.json")), "shade"));
    EXPECT_EQ(fileBytes(dir.file("a.png")), fileBytes(dir.file("b.png")));

    const std::string turntable = common + "--frames 2 --orbit 0:90 ";
    ToolRun frames = runTool(turntable + "-o " + dir.file("t%d.png") + " --stats " + dir.file("t%d.json"));
    ASSERT_EQ(frames.exitCode, 0) << frames.stderrText;
    ToolRun framesAov = runTool(turntable + "-o " + dir.file("u%d.png") + " --aov " + dir.file("u%d.exr") +
                                " --stats " + dir.file("u%d.json"));
    ASSERT_EQ(framesAov.exitCode, 0) << framesAov.stderrText;
    for (int k = 0; k < 2; ++k) {
        const std::string n = std::to_string(k);
        EXPECT_FALSE(has(stagesRan(dir.file("t" + n + ".json")), "aovs")) << k;
        EXPECT_TRUE(has(stagesRan(dir.file("u" + n + ".json")), "aovs")) << k;
        EXPECT_EQ(fileBytes(dir.file("t" + n + ".png")), fileBytes(dir.file("u" + n + ".png"))) << k;
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, UpdatePositionsTest, ::testing::Values("vulkan", "cuda"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace
}  // namespace sr::test
