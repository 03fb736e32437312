// model_transform_test.cpp - `--model` (ModelTransform, scene/camera.h): the spec's parsing and exact
// text; M = T Rz Ry Rx S about the bounds centre on points worked out by hand; and renders that show
// moving the model is moving the camera the other way: a translation t is the orbit target moved by -t,
// a quarter turn about y the azimuth turned back 90 degrees, a scale S the camera S times as far. The
// identity is today's frame to the bit, through `raster render` too, and the vulkan-graphics reference
// draws the moved model with the compute backend's ids.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/image_io.h"
#include "camera/camera.h"
#include "test_util.h"
#include "vulkan/vulkan_graphics.h"

namespace sr::test {
namespace {

ModelTransform model(const std::string& spec)
{
    auto m = parseModelSpec(spec);
    EXPECT_TRUE(m.ok()) << spec << ": " << (m.ok() ? "" : m.error().message);
    return m.ok() ? *m : ModelTransform{};
}

bool sameFloats(const void* a, const void* b, size_t bytes)
{
    return std::memcmp(a, b, bytes) == 0;
}

// ---- the spec ---------------------------------------------------------------------------------

TEST(ModelSpec, ParsesEachPartInTheOrderOfTheProduct)
{
    ModelTransform m = model("translate:1,-2.5,0.125,rotate:90,-45,30,scale:1.5");
    EXPECT_EQ(m.translate, glm::vec3(1.0f, -2.5f, 0.125f));
    EXPECT_EQ(m.rotateDeg, glm::vec3(90.0f, -45.0f, 30.0f));
    EXPECT_EQ(m.scale, 1.5f);
    EXPECT_FALSE(m.isIdentity());

    // Each part is optional; what is left out is the identity.
    m = model("rotate:0,90,0");
    EXPECT_EQ(m.translate, glm::vec3(0.0f));
    EXPECT_EQ(m.scale, 1.0f);
    m = model("translate:0,0,2,scale:0.5");
    EXPECT_EQ(m.rotateDeg, glm::vec3(0.0f));
    EXPECT_EQ(m.scale, 0.5f);

    EXPECT_TRUE(model("identity").isIdentity());
    EXPECT_TRUE(model("translate:0,0,0,rotate:0,0,0,scale:1").isIdentity());
    EXPECT_TRUE(model("translate:-0,0,0").isIdentity()) << "-0 is no move";
}

TEST(ModelSpec, TextIsCanonicalAndRoundTripsExactly)
{
    for (const char* spec : {"identity", "translate:1,2,3", "rotate:0,90,0", "scale:0.1",
                             "translate:0.1,-0.2,1e-07,rotate:12.5,-180,179.9,scale:1.25"})
        EXPECT_EQ(modelSpecString(model(spec)), spec);
    EXPECT_EQ(modelSpecString(model("translate:0,0,0,rotate:0,0,0,scale:1")), "identity");
    EXPECT_EQ(modelSpecString(model("translate:0,0,0,scale:2")), "scale:2");

    // Arbitrary floats read back as the same bits (what a saved viewer frame relies on).
    std::mt19937 rng(26);
    std::uniform_real_distribution<float> any(-1000.0f, 1000.0f), positive(1e-3f, 100.0f);
    for (int i = 0; i < 2000; ++i) {
        ModelTransform m;
        m.translate = {any(rng), any(rng) * 1e-6f, any(rng) * 1e6f};
        m.rotateDeg = {any(rng), any(rng), any(rng) * 1e-3f};
        m.scale = positive(rng);
        const std::string text = modelSpecString(m);
        ModelTransform back = model(text);
        EXPECT_TRUE(sameFloats(&back, &m, sizeof(ModelTransform))) << text;
    }
}

TEST(ModelSpec, MalformedSpecsAreOneLineErrorsThatSayWhatIsWrong)
{
    const std::string expected =
        "expected identity or translate:X,Y,Z,rotate:AX,AY,AZ,scale:S (each part optional, in this order)";
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"", expected},
        {"1,2,3", expected},
        {"Identity", expected},
        {"foo:1", "unknown part 'foo': " + expected},
        {"Translate:1,2,3", "unknown part 'Translate': " + expected},
        {"translate:1,2", "translate takes three numbers X,Y,Z"},
        {"translate:1,2,3,4", "translate takes three numbers X,Y,Z"},
        {"translate:1,2,3,", "translate takes three numbers X,Y,Z"},
        {"translate: 1,2,3", "translate takes three numbers X,Y,Z, not ' 1'"},
        {"translate:nan,0,0", "translate takes three numbers X,Y,Z, not 'nan'"},
        {"rotate:0,x,0", "rotate takes three angles AX,AY,AZ in degrees, not 'x'"},
        {"rotate:", "rotate takes three angles AX,AY,AZ in degrees"},
        {"scale:1,2", "scale takes one number S above 0"},
        {"scale:0", "scale takes one number S above 0"},
        {"scale:-2", "scale takes one number S above 0"},
        {"scale:inf", "scale takes one number S above 0, not 'inf'"},
        {"scale:2,translate:1,0,0", "the parts go in the order translate, rotate, scale, each once"},
        {"scale:2,scale:3", "the parts go in the order translate, rotate, scale, each once"},
    };
    for (const auto& [spec, why] : cases) {
        SCOPED_TRACE(spec);
        auto m = parseModelSpec(spec);
        ASSERT_FALSE(m.ok());
        EXPECT_EQ(m.error().message, "invalid --model '" + spec + "': " + why);
        EXPECT_TRUE(isOneLine(m.error().message));
        EXPECT_EQ(m.error().code, ExitCode::Usage);
    }
}

// ---- the matrix -------------------------------------------------------------------------------

// Where M (about the centre c) takes the point c + d.
glm::vec3 moved(const std::string& spec, const glm::vec3& c, const glm::vec3& d)
{
    return glm::vec3(worldFromModel(model(spec), c) * glm::vec4(c + d, 1.0f));
}

TEST(ModelMatrix, IsTRzRyRxSAboutTheCentreExactAtQuarterTurns)
{
    const glm::vec3 c(1.0f, 2.0f, -3.0f);
    const glm::vec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
    EXPECT_EQ(worldFromModel(ModelTransform{}, c), glm::mat4(1.0f));
    // A translation alone is T(t) to the bit, whatever the centre.
    const glm::mat4 t = worldFromModel(model("translate:0.1,-1,2"), c);
    glm::mat4 expected(1.0f);
    expected[3] = glm::vec4(0.1f, -1.0f, 2.0f, 1.0f);
    EXPECT_EQ(t, expected);

    // Right-handed quarter turns about axes through c: x takes y to z, y takes z to x, z takes x to y.
    EXPECT_EQ(moved("rotate:90,0,0", c, y), c + z);
    EXPECT_EQ(moved("rotate:0,90,0", c, z), c + x);
    EXPECT_EQ(moved("rotate:0,90,0", c, x), c - z);
    EXPECT_EQ(moved("rotate:0,0,90", c, x), c + y);
    EXPECT_EQ(moved("rotate:0,-90,0", c, z), c - x);
    EXPECT_EQ(moved("rotate:0,270,0", c, z), c - x);
    EXPECT_EQ(moved("rotate:0,450,0", c, z), c + x);
    EXPECT_EQ(moved("rotate:0,180,0", c, z), c - z);
    // The order: Rx first, then Ry (y -> z -> x; the other order would give y -> y -> z), and Rz last
    // (x -> x -> y; Rz first would give x -> y -> z).
    EXPECT_EQ(moved("rotate:90,90,0", c, y), c + x);
    EXPECT_EQ(moved("rotate:90,0,90", c, x), c + y);
    // The scale keeps the centre, scales distances from it, and comes before the turn and the move.
    EXPECT_EQ(moved("scale:2", c, glm::vec3(0.0f)), c);
    EXPECT_EQ(moved("scale:2", c, glm::vec3(1.0f, -1.0f, 0.5f)), c + glm::vec3(2.0f, -2.0f, 1.0f));
    EXPECT_EQ(moved("translate:0.5,0,0,rotate:0,90,0,scale:2", c, z), c + glm::vec3(2.5f, 0.0f, 0.0f));
    // Any other angle: sin and cos.
    const glm::vec3 p = moved("rotate:0,30,0", c, z) - c;
    EXPECT_NEAR(p.x, 0.5f, 1e-6f);
    EXPECT_NEAR(p.y, 0.0f, 1e-6f);
    EXPECT_NEAR(p.z, std::sqrt(3.0f) / 2.0f, 1e-6f);
}

// ---- the cameras ------------------------------------------------------------------------------

// A scene whose bounds are off the origin and not a cube.
Scene boundsScene()
{
    Scene scene;
    scene.boundsMin = glm::vec3(-3.0f, 0.5f, -1.0f);
    scene.boundsMax = glm::vec3(1.0f, 2.0f, 3.5f);
    return scene;
}

CameraMatrices resolved(const std::string& camera, const Scene& scene, const std::string& modelSpec)
{
    auto spec = parseCameraSpec(camera);
    EXPECT_TRUE(spec.ok());
    if (!spec) return {};
    auto m = resolveCamera(*spec, scene, 160, 120, model(modelSpec));
    EXPECT_TRUE(m.ok()) << (m.ok() ? "" : m.error().message);
    return m.ok() ? *m : CameraMatrices{};
}

TEST(ModelCamera, AnIdentitySpecIsTheCameraToTheBit)
{
    Scene scene = boundsScene();
    SceneCamera gltf;
    gltf.worldFromView[3] = glm::vec4(0.0f, 1.0f, 12.0f, 1.0f);
    gltf.zfar = 0.0f;  // infinite: the far plane comes from the scene's sphere
    scene.cameras.push_back(gltf);
    for (const char* camera : {"auto", "orbit:30,20,9", "orbit:-120,-10,4,0.5,-0.25,1", "gltf:0"}) {
        SCOPED_TRACE(camera);
        const CameraMatrices plain = resolved(camera, scene, "identity");
        const CameraMatrices explicitIdentity =
            resolved(camera, scene, "translate:0,0,0,rotate:0,0,0,scale:1");
        auto spec = parseCameraSpec(camera);
        auto reference = resolveCamera(*spec, scene, 160, 120);
        ASSERT_TRUE(reference.ok());
        EXPECT_TRUE(sameFloats(&plain, &*reference, sizeof(CameraMatrices)));
        EXPECT_TRUE(sameFloats(&explicitIdentity, &*reference, sizeof(CameraMatrices)));
    }
}

// The camera stays where the spec puts it (viewFromWorld = V M), while its depth range follows the moved
// scene: a model brought most of the way to the eye and doubled still lies within depth 0..1 everywhere.
TEST(ModelCamera, TheCameraStaysAndTheDepthRangeEnclosesTheMovedScene)
{
    const Scene scene = boundsScene();
    const BoundingSphere sphere = boundingSphere(scene);
    const OrbitBasis basis = orbitBasis(OrbitPose{30.0f, 20.0f, 12.0f, glm::vec3(0.0f)});
    ModelTransform m;
    m.translate = 5.0f * basis.back;  // the centre 7 from the eye; the doubled radius is 6.2
    m.rotateDeg = glm::vec3(10.0f, 20.0f, 30.0f);
    m.scale = 2.0f;
    for (const char* camera : {"orbit:30,20,12", "gltf:0"}) {
        SCOPED_TRACE(camera);
        Scene withCamera = scene;
        SceneCamera gltf;
        gltf.worldFromView = glm::inverse(resolved("orbit:30,20,12", scene, "identity").viewFromWorld);
        gltf.zfar = 0.0f;
        withCamera.cameras.push_back(gltf);
        const CameraMatrices still = resolved(camera, withCamera, "identity");
        const CameraMatrices movedCamera = resolved(camera, withCamera, modelSpecString(m));
        const glm::mat4 expected = still.viewFromWorld * worldFromModel(m, sphere.center);
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) EXPECT_NEAR(movedCamera.viewFromWorld[c][r], expected[c][r], 1e-5f);
        if (std::string(camera) == "gltf:0") continue;  // its near plane is the file's
        // The 8 corners of the scene's bounds, moved, within the depth range; without the model the
        // nearest corners would be in front of the near plane.
        int inFrontOfTheOldRange = 0;
        for (int i = 0; i < 8; ++i) {
            const glm::vec3 corner((i & 1) ? scene.boundsMax.x : scene.boundsMin.x,
                                   (i & 2) ? scene.boundsMax.y : scene.boundsMin.y,
                                   (i & 4) ? scene.boundsMax.z : scene.boundsMin.z);
            const glm::vec4 clip = movedCamera.clipFromWorld * glm::vec4(corner, 1.0f);
            EXPECT_GT(clip.z / clip.w, 0.0f) << i;
            EXPECT_LT(clip.z / clip.w, 1.0f) << i;
            const glm::vec4 view = movedCamera.viewFromWorld * glm::vec4(corner, 1.0f);
            inFrontOfTheOldRange += -view.z < still.znear;
        }
        EXPECT_GT(inFrontOfTheOldRange, 0) << "the test moves the model in front of the unmoved range";
    }
}

// ---- renders ----------------------------------------------------------------------------------

// Two equal views computed through different float products put a vertex an ulp apart, which may snap
// it to the neighbouring 1/256 pixel; the depth interpolated at a pixel centre then moves by the
// surface's depth gradient over 1/256 pixel, largest on the ground plane seen at a grazing 20 degrees
// (5e-5 measured for the quarter turn below). A wrong transform is off by orders more (7.6e-3 between
// the translated model and the unmoved one, besides the ids).
constexpr float kSnapDepthTolerance = 1e-4f;

constexpr uint32_t kWidth = 128, kHeight = 96;

RenderSettings modelSettings()
{
    RenderSettings s = testSettings(kWidth, kHeight);
    s.cullMode = CULL_BACK;
    s.msaa = 1;
    return s;
}

// How two frames of the same scene agree: pixels with different ids, and the largest depth difference
// where both cover the pixel with the same triangle.
struct Agreement {
    size_t idMismatches = 0;
    size_t covered = 0;
    float maxDepthDifference = 0.0f;
};

Agreement agreement(const AovImage& a, const AovImage& b)
{
    Agreement g;
    EXPECT_EQ(a.id.size(), b.id.size());
    for (size_t i = 0; i < std::min(a.id.size(), b.id.size()); ++i) {
        g.covered += a.id[i] != EMPTY_ID;
        if (a.id[i] != b.id[i]) {
            g.idMismatches++;
        } else if (a.id[i] != EMPTY_ID) {
            g.maxDepthDifference = std::max(g.maxDepthDifference, std::fabs(a.depth[i] - b.depth[i]));
        }
    }
    return g;
}

class ModelRenderTest : public BackendTest {
protected:
    RenderOutput draw(const std::string& camera, const std::string& modelSpec)
    {
        return render(scene_, modelSettings(), resolved(camera, scene_, modelSpec));
    }

    const Scene scene_ = builtinScene();
};

// Moving the model by t is moving the camera's target (and so its eye) by -t: the same picture.
TEST_P(ModelRenderTest, ATranslationIsTheCameraMovedTheOtherWay)
{
    const RenderOutput still = draw("orbit:30,20,6", "identity");
    const RenderOutput a = draw("orbit:30,20,6", "translate:0.5,-0.25,0.75");
    const RenderOutput b = draw("orbit:30,20,6,-0.5,0.25,-0.75", "identity");
    const Agreement g = agreement(a.aov, b.aov);
    EXPECT_GT(g.covered, size_t(kWidth) * kHeight / 4);
    EXPECT_EQ(g.idMismatches, 0u);
    EXPECT_LE(g.maxDepthDifference, 1e-6f);
    EXPECT_GT(agreement(a.aov, still.aov).idMismatches, size_t(kWidth) * kHeight / 20) << "the model moved";
}

// A quarter turn of the model about y (through the centre, the orbit target) is the camera's azimuth
// turned back by 90 degrees: Ry(90) back(az) = back(az + 90), so V(az) Ry(90) = V(az - 90). Equal up to
// the rounding of the two orbit bases (sin and cos of different angles): a few edge pixels at most.
TEST_P(ModelRenderTest, AQuarterTurnIsTheAzimuthTurnedBack)
{
    const RenderOutput a = draw("orbit:30,20,6", "rotate:0,90,0");
    const RenderOutput b = draw("orbit:-60,20,6", "identity");
    const Agreement g = agreement(a.aov, b.aov);
    EXPECT_GT(g.covered, size_t(kWidth) * kHeight / 4);
    EXPECT_LE(g.idMismatches, g.covered / 500) << "of " << g.covered;
    EXPECT_LE(g.maxDepthDifference, kSnapDepthTolerance);
}

// The model scaled by S about its centre, seen from S times as far, is the same picture: every view-space
// position and the depth range scale by S, and perspective divides it out.
TEST_P(ModelRenderTest, AScaleIsTheCameraThatManyTimesAsFar)
{
    const RenderOutput a = draw("orbit:30,20,12", "scale:2");
    const RenderOutput b = draw("orbit:30,20,6", "identity");
    const Agreement g = agreement(a.aov, b.aov);
    EXPECT_GT(g.covered, size_t(kWidth) * kHeight / 4);
    // A factor of two scales floats exactly: the same ids, depth to a few ulps.
    EXPECT_EQ(g.idMismatches, 0u);
    EXPECT_LE(g.maxDepthDifference, 1e-6f);
    const RenderOutput c = draw("orbit:30,20,9", "scale:1.5");
    const Agreement h = agreement(c.aov, b.aov);
    EXPECT_LE(h.idMismatches, h.covered / 500) << "of " << h.covered;
    EXPECT_LE(h.maxDepthDifference, kSnapDepthTolerance);
}

// The identity, spelled out, draws today's frame to the bit.
TEST_P(ModelRenderTest, AnIdentitySpecIsTodaysFrame)
{
    const RenderOutput a = draw("auto", "identity");
    const RenderOutput b = draw("auto", "translate:0,0,0,rotate:0,0,0,scale:1");
    auto camera = resolveCamera(CameraSpec{}, scene_, kWidth, kHeight);
    ASSERT_TRUE(camera.ok());
    const RenderOutput today = render(scene_, modelSettings(), *camera);
    for (const RenderOutput* o : {&a, &b}) {
        EXPECT_EQ(o->aov.id, today.aov.id);
        EXPECT_TRUE(sameFloats(o->aov.depth.data(), today.aov.depth.data(), today.aov.depth.size() * 4));
        EXPECT_EQ(o->color.pixels, today.color.pixels);
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, ModelRenderTest, ::testing::Values("vulkan", "cuda"),
                         [](const auto& info) { return info.param; });

// The vulkan-graphics reference takes the same matrices: the moved model has the compute backend's ids.
TEST(ModelGraphics, TheReferenceDrawsTheMovedModelWithTheSameIds)
{
    bool skip = false;
    auto device = openBackend("vulkan", skip);
    if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
    ASSERT_TRUE(device);
    const Scene scene = builtinScene();
    const CameraMatrices camera =
        resolved("orbit:30,20,6", scene, "translate:0.5,-0.25,0.75,rotate:0,40,10,scale:1.2");
    auto compute = renderScene(*device, scene, camera, modelSettings());
    auto graphics = renderVulkanGraphics(scene, camera, modelSettings(), -1);
    ASSERT_TRUE(compute.ok() && graphics.ok());
    const Agreement g = agreement(compute->aov, graphics->aov);
    EXPECT_GT(g.covered, size_t(kWidth) * kHeight / 4);
    EXPECT_EQ(g.idMismatches, 0u);
}

// ---- raster render ------------------------------------------------------------------------------

// `raster render` takes --model: the default and the identity spelled out give the same files, a
// translation the files of the camera moved the other way, and --stats echoes the spec.
TEST(ModelTool, RenderTakesTheModelAndItsIdentityIsTheDefault)
{
    ScratchDir dir("model_tool");
    const std::string common = "render --backend vulkan --msaa 1 --width 96 --height 72 -q ";
    auto run = [&](const std::string& name, const std::string& args) {
        ToolRun r = runTool(common + args + " -o " + dir.file(name + ".png") + " --aov " +
                            dir.file(name + ".exr") + " --stats " + dir.file(name + ".json"));
        EXPECT_EQ(r.exitCode, 0) << r.stderrText;
        auto png = readPng(dir.file(name + ".png"));
        auto aov = readAovExr(dir.file(name + ".exr"));
        EXPECT_TRUE(png.ok() && aov.ok());
        return std::make_pair(png.ok() ? *png : RgbaImage{}, aov.ok() ? *aov : AovImage{});
    };
    const auto plain = run("plain", "");
    for (const char* identity : {"identity", "translate:0,0,0,rotate:0,0,0,scale:1"}) {
        SCOPED_TRACE(identity);
        const auto same = run("identity", std::string("--model ") + identity);
        EXPECT_EQ(same.first.pixels, plain.first.pixels);
        EXPECT_EQ(same.second.id, plain.second.id);
        EXPECT_TRUE(sameFloats(same.second.depth.data(), plain.second.depth.data(),
                               plain.second.depth.size() * sizeof(float)));
    }
    const auto movedModel = run("moved", "--camera orbit:30,20,6 --model translate:0.5,-0.25,0.75");
    const auto movedCamera = run("camera", "--camera orbit:30,20,6,-0.5,0.25,-0.75");
    EXPECT_EQ(movedModel.second.id, movedCamera.second.id);
    EXPECT_NE(movedModel.second.id, plain.second.id);
    std::ifstream stats(dir.file("moved.json"));
    const nlohmann::json j = nlohmann::json::parse(stats);
    EXPECT_EQ(j["settings"]["model"], "translate:0.5,-0.25,0.75") << j.dump();

    ToolRun bad = runTool(common + "--model scale:0 -o " + dir.file("never.png"));
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.stderrText.find("invalid --model 'scale:0': scale takes one number S above 0"),
              std::string::npos)
        << bad.stderrText;
    EXPECT_EQ(std::count(bad.stderrText.begin(), bad.stderrText.end(), '\n'), 1) << bad.stderrText;
}

}  // namespace
}  // namespace sr::test
