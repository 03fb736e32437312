// api_test.cpp - the public API (include/raster/raster.h) on every backend: a scene from arrays against
// its analytic coverage, files and built-in scenes against the pipeline underneath, sessions that switch
// how the scene is drawn, settings by name, and one-line errors as values.
#include <cmath>
#include <cstdlib>
#include <set>

#include <gtest/gtest.h>

#include "raster/raster.h"

#include "render/renderer.h"
#include "camera/camera.h"
#include "settings/schema.h"
#include "test_util.h"

namespace {

constexpr uint32_t kEmpty = 0xffffffffu;

// The device of `backend`, or a skip when the backend is absent and SR_ALLOW_MISSING_BACKENDS lists it.
class ApiTest : public ::testing::TestWithParam<std::string> {
protected:
    void SetUp() override
    {
        auto backend = raster::parseBackend(GetParam());
        ASSERT_TRUE(backend.ok());
        auto device = raster::Device::open(*backend);
        if (!device) {
            const char* allowed = std::getenv("SR_ALLOW_MISSING_BACKENDS");
            if (allowed && std::string(allowed).find(GetParam()) != std::string::npos)
                GTEST_SKIP() << device.error().message;
            FAIL() << device.error().message;
        }
        device_.emplace(std::move(*device));
    }

    std::optional<raster::Device> device_;
};

// Identity view and projection: positions are clip coordinates (Vulkan's: y down, depth 0..1).
raster::Camera identityCamera()
{
    std::array<float, 16> identity{};
    for (int i = 0; i < 4; ++i) identity[size_t(5 * i)] = 1.0f;
    return raster::Camera::fromMatrices(identity, identity);
}

TEST_P(ApiTest, ArraysCoverWhatTheirGeometrySays)
{
    // A quad over the left half of the image at depth 0.5, two triangles.
    const float positions[] = {-1, -1, 0.5f, 0, -1, 0.5f, 0, 1, 0.5f, -1, 1, 0.5f};
    const uint32_t triangles[] = {0, 1, 2, 0, 2, 3};
    raster::MeshArrays mesh;
    mesh.positions = positions;
    mesh.vertexCount = 4;
    mesh.triangles = triangles;
    mesh.triangleCount = 2;
    auto scene = raster::Scene::fromArrays(mesh);
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    EXPECT_EQ(scene->triangleCount(), 2u);

    raster::Settings settings;
    ASSERT_TRUE(settings.set("width", 16).ok());
    ASSERT_TRUE(settings.set("height", 8).ok());
    ASSERT_TRUE(settings.set("cull", "none").ok());
    auto frame = raster::render(*device_, *scene, identityCamera(), settings);
    ASSERT_TRUE(frame.ok()) << frame.error().message;
    ASSERT_EQ(frame->width, 16u);
    ASSERT_EQ(frame->height, 8u);
    ASSERT_EQ(frame->id.size(), 16u * 8u);
    ASSERT_EQ(frame->color.size(), 16u * 8u * 4u);
    for (uint32_t y = 0; y < 8; ++y) {
        for (uint32_t x = 0; x < 16; ++x) {
            const size_t i = size_t(y) * 16 + x;
            SCOPED_TRACE(testing::Message() << "pixel " << x << "," << y);
            if (x < 8) {
                EXPECT_TRUE(frame->id[i] == 0u || frame->id[i] == 1u);
                EXPECT_EQ(frame->depth[i], 0.5f);
            } else {
                EXPECT_EQ(frame->id[i], kEmpty);
                EXPECT_EQ(frame->depth[i], 1.0f);
            }
        }
    }
    EXPECT_EQ(frame->device.backend, device_->info().backend);
    EXPECT_NE(frame->statsJson.find("\"settings\""), std::string::npos);
}

// A scene loaded through the API renders what the pipeline renders for it (same ids, same colours).
TEST_P(ApiTest, LoadedScenesRenderAsThePipelineDoes)
{
    auto scene = raster::Scene::load("builtin");
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    raster::Settings settings;
    ASSERT_TRUE(settings.set("width", 64).ok());
    ASSERT_TRUE(settings.set("height", 48).ok());
    ASSERT_TRUE(settings.set("msaa", 4).ok());
    auto frame = raster::render(*device_, *scene, raster::Camera::fromSpec("auto"), settings);
    ASSERT_TRUE(frame.ok()) << frame.error().message;

    bool skip = false;
    auto device = sr::test::openBackend(GetParam(), skip);
    ASSERT_TRUE(device);
    sr::RenderSettings s;  // the defaults, as a new raster::Settings holds them
    s.width = 64;
    s.height = 48;
    s.msaa = 4;
    const sr::Scene builtin = sr::builtinScene();
    auto camera = sr::resolveCamera(sr::CameraSpec{}, builtin, 64, 48);
    ASSERT_TRUE(camera.ok());
    auto out = sr::renderScene(*device, builtin, *camera, s);
    ASSERT_TRUE(out.ok()) << out.error().message;
    EXPECT_EQ(frame->id, out->aov.id);
    ASSERT_EQ(frame->color.size(), out->color.pixels.size() * 4);
    size_t differ = 0;
    for (size_t i = 0; i < out->color.pixels.size(); ++i)
        for (int c = 0; c < 4; ++c)
            differ += frame->color[4 * i + c] != uint8_t(out->color.pixels[i] >> (8 * c));
    EXPECT_EQ(differ, 0u);
}

// A session switches between the scene, its edges and its wireframe overlay and back, each frame equal
// to a fresh render of the same settings.
TEST_P(ApiTest, SessionsSwitchHowTheSceneIsDrawn)
{
    auto scene = raster::Scene::load("builtin");
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    auto session = raster::Session::create(*device_, *scene);
    ASSERT_TRUE(session.ok()) << session.error().message;
    raster::Settings plain;
    ASSERT_TRUE(plain.set("width", 48).ok());
    ASSERT_TRUE(plain.set("height", 32).ok());
    raster::Settings lines = plain, wire = plain;
    ASSERT_TRUE(lines.set("primitive-mode", "lines").ok());
    ASSERT_TRUE(wire.set("wireframe", true).ok());
    const raster::Camera camera = raster::Camera::fromSpec("orbit:20,30,9");
    std::vector<std::vector<uint32_t>> sessionIds;
    for (const raster::Settings* s : {&plain, &lines, &wire, &plain}) {
        auto frame = session->render(camera, *s);
        ASSERT_TRUE(frame.ok()) << frame.error().message;
        sessionIds.push_back(frame->id);
    }
    for (const auto& [k, s] :
         std::vector<std::pair<int, const raster::Settings*>>{{0, &plain}, {1, &lines}, {2, &wire}}) {
        auto fresh = raster::render(*device_, *scene, camera, *s);
        ASSERT_TRUE(fresh.ok()) << fresh.error().message;
        EXPECT_EQ(sessionIds[size_t(k)], fresh->id) << "frame " << k;
    }
    EXPECT_EQ(sessionIds[3], sessionIds[0]) << "back to the scene itself";
    EXPECT_NE(sessionIds[1], sessionIds[0]) << "lines draw the edges";
}

// Sessions of scenes that differ in everything a session keeps on its device (triangle count, textures
// and an alpha mask, clusters, level of detail, tessellation, lines mode) share one device in any order:
// every frame equals the same scene rendered alone on a device of its own. Before sessions claimed the
// device's buffers, every session but the last one made drew the last scene's data (the bad-input
// campaign's finding: builtin after builtin:dense covered 2 pixels instead of 357).
TEST_P(ApiTest, SessionsOfManyScenesShareOneDevice)
{
    struct Case {
        const char* scene;
        std::vector<std::pair<const char*, const char*>> settings;
    };
    const std::vector<Case> cases = {
        {"builtin", {}},
        {"builtin:dense", {}},
        {"builtin:checker", {{"texture-filter", "trilinear"}, {"camera", "orbit:0,30,14"}}},
        {"builtin:cutout", {}},
        {"builtin:lowpoly", {{"tessellate", "pn"}}},
        {"builtin", {{"clusters", "on"}}},
        {"builtin:lowpoly", {{"lod", "on"}, {"lod-error-px", "4"}}},
        {"builtin", {{"primitive-mode", "lines"}}},
    };
    std::vector<raster::Scene> scenes;
    std::vector<raster::Settings> settings(cases.size());
    for (size_t i = 0; i < cases.size(); ++i) {
        auto scene = raster::Scene::load(cases[i].scene);
        ASSERT_TRUE(scene.ok()) << scene.error().message;
        scenes.push_back(std::move(*scene));
        for (const char* key : {"width", "height"}) ASSERT_TRUE(settings[i].set(key, 48).ok());
        ASSERT_TRUE(settings[i].set("warmup", 0).ok());
        for (const auto& [key, value] : cases[i].settings) ASSERT_TRUE(settings[i].set(key, value).ok());
    }
    const raster::Camera camera = raster::Camera::fromSpec("auto");
    // Each case alone: a one-shot render uploads its scene just before it draws, on a second device.
    auto other = raster::Device::open(device_->info().backend);
    ASSERT_TRUE(other.ok()) << other.error().message;
    std::vector<raster::Frame> alone;
    for (size_t i = 0; i < cases.size(); ++i) {
        auto frame = raster::render(*other, scenes[i], camera, settings[i]);
        ASSERT_TRUE(frame.ok()) << cases[i].scene << ": " << frame.error().message;
        alone.push_back(std::move(*frame));
    }
    auto expectAlone = [&](size_t i, const raster::Frame& frame, const std::string& when) {
        SCOPED_TRACE(std::string(cases[i].scene) + " (case " + std::to_string(i) + ") " + when);
        auto differing = [](const auto& a, const auto& b) {
            if (a.size() != b.size()) return std::max(a.size(), b.size());
            size_t n = 0;
            for (size_t k = 0; k < a.size(); ++k) n += a[k] != b[k];
            return n;
        };
        EXPECT_EQ(differing(frame.id, alone[i].id), 0u) << "ids";
        EXPECT_EQ(differing(frame.depth, alone[i].depth), 0u) << "depths";
        EXPECT_EQ(differing(frame.color, alone[i].color), 0u) << "colour bytes";
    };
    // Every session made before any renders (making one uploads its scene), then drawn forwards and
    // backwards, with a one-shot render of the neighbouring case in between.
    std::vector<raster::Session> sessions;
    for (size_t i = 0; i < cases.size(); ++i) {
        auto session = raster::Session::create(*device_, scenes[i]);
        ASSERT_TRUE(session.ok()) << session.error().message;
        sessions.push_back(std::move(*session));
    }
    std::vector<size_t> order;
    for (size_t i = 0; i < cases.size(); ++i) order.push_back(i);
    for (size_t i = cases.size(); i-- > 0;) order.push_back(i);
    for (size_t k = 0; k < order.size(); ++k) {
        const size_t i = order[k];
        auto frame = sessions[i].render(camera, settings[i]);
        ASSERT_TRUE(frame.ok()) << frame.error().message;
        expectAlone(i, *frame, "in its session, step " + std::to_string(k));
        const size_t j = (i + 1) % cases.size();
        auto once = raster::render(*device_, scenes[j], camera, settings[j]);
        ASSERT_TRUE(once.ok()) << once.error().message;
        expectAlone(j, *once, "one-shot, step " + std::to_string(k));
    }
}

// A triangle, segment or point with an index out of range or a non-finite position is drawn by nothing
// and keeps its id: every other primitive's id still indexes the arrays (the campaign's ids shifted down
// past each dropped triangle). The same ids on this backend and on the graphics reference.
TEST_P(ApiTest, DroppedPrimitivesKeepTheirIds)
{
    // Vertices 0-3: the left half of the image, 4-7 the right half (depth 0.5), 8 NaN; 9-10 a
    // horizontal segment near the top, 11 a point near the bottom (clip space).
    const float positions[] = {
        -1,    -1,       0.5f,  0,    -1,       0.5f,  0, 1, 0.5f, -1, 1, 0.5f,  // left
        0,     -1,       0.5f,  1,    -1,       0.5f,  1, 1, 0.5f, 0,  1, 0.5f,  // right
        NAN,   0,        0,                                                      // 8
        -0.9f, -0.6875f, 0.25f, 0.9f, -0.6875f, 0.25f,                           // segment
        0.5f,  0.75f,    0.25f};                                                 // point
    const uint32_t triangles[] = {0, 1, 99,                                      // 0: out of range
                                  0, 1, 2,                                       // 1
                                  4, 5, 8,                                       // 2: NaN corner
                                  0, 2, 3,                                       // 3
                                  4, 5, 6,                                       // 4
                                  4, 6, 7};                                      // 5
    const uint32_t lines[] = {9, 8, 9, 10};  // segment 0 (id 6) reaches the NaN vertex; 1 (id 7) draws
    const uint32_t points[] = {50, 11};      // point 0 (id 8) out of range; point 1 (id 9) draws
    raster::MeshArrays mesh;
    mesh.positions = positions;
    mesh.vertexCount = 12;
    mesh.triangles = triangles;
    mesh.triangleCount = 6;
    mesh.lines = lines;
    mesh.lineCount = 2;
    mesh.points = points;
    mesh.pointCount = 2;
    mesh.doubleSided = true;
    auto scene = raster::Scene::fromArrays(mesh);
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    EXPECT_EQ(scene->warnings().size(), 3u);  // triangles, segments, points
    raster::Settings settings;
    ASSERT_TRUE(settings.set("width", 16).ok());
    ASSERT_TRUE(settings.set("height", 16).ok());
    ASSERT_TRUE(settings.set("point-size", 3).ok());
    auto graphics = raster::Device::open(raster::Backend::VulkanGraphics);
    ASSERT_TRUE(graphics.ok()) << graphics.error().message;
    for (raster::Device* device : {&*device_, &*graphics}) {
        SCOPED_TRACE(raster::backendName(device->info().backend));
        auto frame = raster::render(*device, *scene, identityCamera(), settings);
        ASSERT_TRUE(frame.ok()) << frame.error().message;
        std::set<uint32_t> seen(frame->id.begin(), frame->id.end());
        EXPECT_EQ(seen, (std::set<uint32_t>{1, 3, 4, 5, 7, 9})) << "the drawn primitives, by their array ids";
        // Pixel centres: (4, 8) in the left half, (12, 8) in the right one; the segment's row 2, the
        // point at (12, 14).
        auto id = [&](uint32_t x, uint32_t y) { return frame->id[size_t(y) * 16 + x]; };
        EXPECT_TRUE(id(4, 8) == 1u || id(4, 8) == 3u) << id(4, 8);
        EXPECT_TRUE(id(12, 8) == 4u || id(12, 8) == 5u) << id(12, 8);
        EXPECT_EQ(id(8, 2), 7u);
        EXPECT_EQ(id(12, 14), 9u);
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, ApiTest, ::testing::Values("vulkan", "cuda"));

// The reference backend through the same API: the conformant graphics pipeline gives the compute
// pipeline's ids exactly (fixed8 coverage is the graphics rule).
TEST(Api, GraphicsReferenceAgreesWithComputeIds)
{
    auto compute = raster::Device::open(raster::Backend::Vulkan);
    ASSERT_TRUE(compute.ok()) << compute.error().message;
    auto graphics = raster::Device::open(raster::Backend::VulkanGraphics);
    ASSERT_TRUE(graphics.ok()) << graphics.error().message;
    EXPECT_EQ(graphics->info().backend, raster::Backend::VulkanGraphics);
    auto scene = raster::Scene::load(sr::test::sourceDir() + "/assets/hierarchy.gltf");
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    raster::Settings settings;
    ASSERT_TRUE(settings.set("width", 80).ok());
    ASSERT_TRUE(settings.set("height", 60).ok());
    auto a = raster::render(*compute, *scene, raster::Camera::fromSpec("auto"), settings);
    auto b = raster::render(*graphics, *scene, raster::Camera::fromSpec("auto"), settings);
    ASSERT_TRUE(a.ok() && b.ok());
    size_t covered = 0;
    for (uint32_t id : a->id) covered += id != kEmpty;
    EXPECT_GT(covered, 100u);
    EXPECT_EQ(a->id, b->id);
}

TEST(Api, SettingsByNameFollowTheSchema)
{
    raster::Settings s;
    EXPECT_EQ(*s.get("shading"), "blinn-phong");
    EXPECT_EQ(*s.get("texture_filter"), "auto") << "underscores name the same setting";
    ASSERT_TRUE(s.set("light_dir", std::array<double, 3>{1, 0, 0}).ok());
    EXPECT_EQ(*s.get("light-dir"), "1,0,0");
    ASSERT_TRUE(s.set("msaa", 8).ok());
    ASSERT_TRUE(s.set("wireframe", true).ok());
    EXPECT_EQ(s.commandLine(), "--light-dir 1,0,0 --msaa 8 --wireframe");
    ASSERT_TRUE(s.set("msaa", 4).ok());
    EXPECT_EQ(s.commandLine(), "--light-dir 1,0,0 --wireframe") << "MSAA 4x is raster render's default";
    ASSERT_TRUE(s.set("msaa", 1).ok());
    EXPECT_EQ(s.commandLine(), "--light-dir 1,0,0 --msaa 1 --wireframe") << "the library's is spelled out";
    EXPECT_EQ(raster::Settings::names().size(), sr::settingsSchema().size());

    auto unknown = s.set("msaaa", 4);
    ASSERT_FALSE(unknown.ok());
    EXPECT_EQ(unknown.error().message, "unknown setting 'msaaa' (raster settings lists them)");
    EXPECT_FALSE(s.set("msaa", 4.5).ok());
    EXPECT_FALSE(s.set("shading", 3).ok()) << "a choice is a name";
    EXPECT_FALSE(s.set("wireframe", "maybe").ok());
    EXPECT_FALSE(s.set("light-dir", std::array<double, 3>{1, NAN, 0}).ok());
    EXPECT_FALSE(s.get("nothing").ok());
    EXPECT_EQ(*s.get("msaa"), "1") << "a refused value leaves the setting as it was";
}

TEST(Api, BadInputIsOneLineErrors)
{
    auto missing = raster::Scene::load("/nonexistent/scene.gltf");
    ASSERT_FALSE(missing.ok());
    EXPECT_EQ(missing.error().message.find('\n'), std::string::npos);
    EXPECT_NE(missing.error().message.find("/nonexistent/scene.gltf"), std::string::npos);

    const float positions[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, NAN, 0, 0};
    const uint32_t triangles[] = {0, 1, 2, 0, 1, 7, 0, 1, 3};
    raster::MeshArrays mesh;
    mesh.positions = positions;
    mesh.vertexCount = 4;
    mesh.triangles = triangles;
    mesh.triangleCount = 3;
    // An index out of range and a NaN corner drop their triangles, with a warning the scene returns
    // (nothing is printed); they keep their ids, so triangle 0 is still the arrays' triangle 0.
    ::testing::internal::CaptureStderr();
    auto scene = raster::Scene::fromArrays(mesh);
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    EXPECT_EQ(scene->triangleCount(), 3u);
    ASSERT_EQ(scene->warnings().size(), 1u);
    EXPECT_EQ(
        scene->warnings()[0],
        "fromArrays: dropped 2 triangle(s) with out-of-range indices or non-finite positions (their ids "
        "stay reserved)");
    // Nothing left to draw is an error.
    mesh.triangles = triangles + 3;
    mesh.triangleCount = 2;
    auto empty = raster::Scene::fromArrays(mesh);
    ASSERT_FALSE(empty.ok());
    EXPECT_EQ(empty.error().message.find('\n'), std::string::npos);
    // A texture needs coordinates.
    const uint8_t texel[4] = {255, 0, 0, 255};
    mesh.triangles = triangles;
    mesh.texture = raster::TextureView{texel, 1, 1, true};
    auto untextured = raster::Scene::fromArrays(mesh);
    ASSERT_FALSE(untextured.ok());
    EXPECT_EQ(untextured.error().message, "fromArrays: a texture needs texture coordinates");

    EXPECT_FALSE(raster::parseBackend("metal").ok());
    EXPECT_EQ(raster::Camera::fromSpec("orbit:1").spec, "orbit:1");
    auto device = raster::Device::open(raster::Backend::Vulkan);
    ASSERT_TRUE(device.ok()) << device.error().message;
    auto builtin = raster::Scene::load("builtin");
    ASSERT_TRUE(builtin.ok());
    auto bad = raster::render(*device, *builtin, raster::Camera::fromSpec("orbit:1"), raster::Settings());
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.error().kind, raster::ErrorKind::Usage);
    EXPECT_EQ(bad.error().message.rfind("invalid camera 'orbit:1'", 0), 0u) << bad.error().message;
}

}  // namespace
