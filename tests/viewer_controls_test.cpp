// viewer_controls_test.cpp - the interactive viewer's window-independent parts: the orbit camera against
// `--camera orbit:...` (bit for bit), every key's and mouse action's transition, and input scripts.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "camera/camera.h"
#include "scene/primitive_mode.h"
#include "scene/scene.h"
#include "test_util.h"
#include "settings/schema.h"
#include "viewer/controls.h"
#include "camera/orbit.h"
#include "viewer/script.h"

namespace sr::test {
namespace {

// A scene whose bounds are off the origin and not a cube, so centre, radius and aspect all matter.
Scene boundsScene()
{
    Scene scene;
    scene.boundsMin = glm::vec3(-3.0f, 0.5f, -1.0f);
    scene.boundsMax = glm::vec3(1.0f, 2.0f, 3.5f);
    return scene;
}

::testing::AssertionResult sameBits(const CameraMatrices& a, const CameraMatrices& b)
{
    const bool same = std::memcmp(&a.viewFromWorld, &b.viewFromWorld, sizeof(glm::mat4)) == 0 &&
                      std::memcmp(&a.clipFromView, &b.clipFromView, sizeof(glm::mat4)) == 0 &&
                      std::memcmp(&a.clipFromWorld, &b.clipFromWorld, sizeof(glm::mat4)) == 0 &&
                      std::memcmp(&a.znear, &b.znear, sizeof(float)) == 0 &&
                      std::memcmp(&a.zfar, &b.zfar, sizeof(float)) == 0;
    if (same) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "matrices differ (znear " << a.znear << " vs " << b.znear << ")";
}

::testing::AssertionResult samePose(const OrbitPose& a, const OrbitPose& b)
{
    if (std::memcmp(&a.azimuthDeg, &b.azimuthDeg, sizeof(float)) == 0 &&
        std::memcmp(&a.elevationDeg, &b.elevationDeg, sizeof(float)) == 0 &&
        std::memcmp(&a.distance, &b.distance, sizeof(float)) == 0 &&
        std::memcmp(&a.targetOffset, &b.targetOffset, sizeof(glm::vec3)) == 0)
        return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << orbitSpecString(a) << " vs " << orbitSpecString(b);
}

CameraMatrices resolved(const std::string& spec, const Scene& scene, unsigned w, unsigned h)
{
    auto parsed = parseCameraSpec(spec);
    EXPECT_TRUE(parsed.ok()) << spec << ": " << (parsed.ok() ? "" : parsed.error().message);
    if (!parsed) return {};
    auto m = resolveCamera(*parsed, scene, w, h);
    EXPECT_TRUE(m.ok());
    return m.ok() ? *m : CameraMatrices{};
}

OrbitCamera orbitAt(const Scene& scene, float az, float el, float dist, glm::vec3 offset = glm::vec3(0.0f))
{
    CameraSpec spec;
    spec.kind = CameraSpec::Kind::Orbit;
    spec.orbit = {az, el, dist, offset};
    auto camera = OrbitCamera::fromSpec(spec, scene, 64, 64);
    EXPECT_TRUE(camera.ok());
    return *camera;
}

// ---- the orbit camera -----------------------------------------------------------------------

TEST(OrbitCamera, ZeroPanIsBitIdenticalToTheOrbitSpec)
{
    const Scene scene = boundsScene();
    for (glm::vec3 p : {glm::vec3(35, 25, 7.5f), glm::vec3(-120.25f, 3, 0.37f), glm::vec3(179.9f, -89, 1e3f),
                        glm::vec3(0, 89, 12), glm::vec3(1e-3f, -0.5f, 4.2e-2f)})
        for (glm::uvec2 size : {glm::uvec2(64, 64), glm::uvec2(200, 90), glm::uvec2(33, 257)}) {
            OrbitCamera camera = orbitAt(scene, p.x, p.y, p.z);
            const std::string spec = fmt::format("orbit:{},{},{}", p.x, p.y, p.z);
            EXPECT_EQ(camera.specString(), spec);
            EXPECT_TRUE(sameBits(camera.matrices(size.x, size.y), resolved(spec, scene, size.x, size.y)))
                << spec << " at " << size.x << "x" << size.y;
        }
}

TEST(OrbitCamera, AnyPoseRoundTripsThroughItsSpecString)
{
    // Poses reached by dragging, panning and zooming have arbitrary float bits; their spec strings must
    // give back those bits and therefore the same matrices.
    const Scene scene = boundsScene();
    std::mt19937 rng(13);
    std::uniform_real_distribution<float> pixels(-300.0f, 300.0f);
    OrbitCamera camera(scene, 160, 120);
    for (int i = 0; i < 200; ++i) {
        camera.orbit(pixels(rng), pixels(rng));
        if (i % 3 == 0) camera.pan(pixels(rng), pixels(rng), 120);
        if (i % 5 == 0) camera.zoom(pixels(rng) / 100.0f);
        const std::string spec = camera.specString();
        auto parsed = parseCameraSpec(spec);
        ASSERT_TRUE(parsed.ok()) << spec;
        ASSERT_EQ(parsed->kind, CameraSpec::Kind::Orbit);
        ASSERT_TRUE(samePose(parsed->orbit, camera.pose())) << spec;
        ASSERT_TRUE(sameBits(camera.matrices(160, 120), resolved(spec, scene, 160, 120))) << spec;
    }
    EXPECT_NE(camera.pose().targetOffset, glm::vec3(0.0f));
    const std::string last = camera.specString();
    EXPECT_EQ(std::count(last.begin(), last.end(), ','), 5) << last;
}

TEST(OrbitCamera, SpecStringsAreShortAndExact)
{
    OrbitPose pose{30.0f, -12.5f, 4.0f, glm::vec3(0.0f)};
    EXPECT_EQ(orbitSpecString(pose), "orbit:30,-12.5,4");
    pose.targetOffset = glm::vec3(0.1f, 0.0f, -2.0f);
    EXPECT_EQ(orbitSpecString(pose), "orbit:30,-12.5,4,0.1,0,-2");
    std::mt19937 rng(7);
    std::uniform_int_distribution<uint32_t> bits;
    for (int i = 0; i < 2000; ++i) {
        OrbitPose random;
        float* fields[] = {&random.azimuthDeg,     &random.elevationDeg,   &random.distance,
                           &random.targetOffset.x, &random.targetOffset.y, &random.targetOffset.z};
        for (float* f : fields) {
            do {
                uint32_t b = bits(rng);
                std::memcpy(f, &b, sizeof b);
            } while (!std::isfinite(*f));
        }
        random.distance = std::fabs(random.distance) + 1e-30f;
        auto parsed = parseCameraSpec(orbitSpecString(random));
        ASSERT_TRUE(parsed.ok()) << orbitSpecString(random);
        ASSERT_TRUE(samePose(parsed->orbit, random));
    }
}

TEST(OrbitCamera, ResetAndTheDefaultAreTheAutoCamera)
{
    const Scene scene = boundsScene();
    for (glm::uvec2 size : {glm::uvec2(64, 64), glm::uvec2(300, 100), glm::uvec2(90, 250)}) {
        const CameraMatrices autoCamera = *resolveCamera(CameraSpec{}, scene, size.x, size.y);
        OrbitCamera camera(scene, size.x, size.y);
        EXPECT_TRUE(sameBits(camera.matrices(size.x, size.y), autoCamera));
        EXPECT_TRUE(
            sameBits(OrbitCamera::fromSpec(CameraSpec{}, scene, size.x, size.y)->matrices(size.x, size.y),
                     autoCamera));
        camera.orbit(120.0f, -45.0f);
        camera.pan(30.0f, 12.0f, size.y);
        camera.zoom(-3.0f);
        EXPECT_FALSE(sameBits(camera.matrices(size.x, size.y), autoCamera));
        camera.reset(size.x, size.y);
        EXPECT_TRUE(sameBits(camera.matrices(size.x, size.y), autoCamera));
        EXPECT_EQ(camera.pose().azimuthDeg, kAutoAzimuthDeg);
        EXPECT_EQ(camera.pose().elevationDeg, kAutoElevationDeg);
        EXPECT_EQ(camera.pose().targetOffset, glm::vec3(0.0f));
    }
}

TEST(OrbitCamera, OrbitTurnsWithTheCursorAndClampsElevation)
{
    const Scene scene = boundsScene();
    OrbitCamera camera = orbitAt(scene, 10.0f, 20.0f, 5.0f);
    camera.orbit(4.0f, 0.0f);  // right: the eye moves left, azimuth down by 4 px x 0.25 degrees
    EXPECT_FLOAT_EQ(camera.pose().azimuthDeg, 9.0f);
    EXPECT_FLOAT_EQ(camera.pose().elevationDeg, 20.0f);
    camera.orbit(0.0f, 8.0f);  // down: the eye rises
    EXPECT_FLOAT_EQ(camera.pose().elevationDeg, 22.0f);
    camera.orbit(0.0f, 1e6f);
    EXPECT_EQ(camera.pose().elevationDeg, kMaxElevationDeg);
    camera.orbit(0.0f, -1e6f);
    EXPECT_EQ(camera.pose().elevationDeg, -kMaxElevationDeg);
    // Still a proper view at the clamp: the right vector stays horizontal and the image upright.
    const CameraMatrices m = camera.matrices(64, 64);
    EXPECT_TRUE(std::isfinite(m.clipFromWorld[0][0]));
    EXPECT_GT(glm::vec3(glm::inverse(m.viewFromWorld)[1]).y, 0.0f);

    // The azimuth stays within [-180, 180] however far it turns, and whole turns change nothing.
    OrbitCamera turning = orbitAt(scene, 170.0f, 0.0f, 5.0f);
    turning.orbit(-80.0f, 0.0f);  // +20 degrees
    EXPECT_FLOAT_EQ(turning.pose().azimuthDeg, -170.0f);
    turning.orbit(1440.0f * 3, 0.0f);  // three turns
    EXPECT_NEAR(turning.pose().azimuthDeg, -170.0f, 1e-3f);
    // Non-finite input (a window system glitch) is ignored.
    turning.orbit(NAN, 1.0f);
    EXPECT_NEAR(turning.pose().azimuthDeg, -170.0f, 1e-3f);
}

TEST(OrbitCamera, ZoomIsMultiplicativeAndBounded)
{
    const Scene scene = boundsScene();
    const float radius = boundingSphere(scene).radius;
    OrbitCamera camera = orbitAt(scene, 0.0f, 0.0f, 10.0f);
    camera.zoom(1.0f);
    EXPECT_FLOAT_EQ(camera.pose().distance, 9.0f);
    camera.zoom(2.0f);
    EXPECT_FLOAT_EQ(camera.pose().distance, 10.0f * 0.9f * 0.9f * 0.9f);
    camera.zoom(-3.0f);
    EXPECT_FLOAT_EQ(camera.pose().distance, 10.0f);
    camera.zoom(0.5f);  // a trackpad's half step
    EXPECT_FLOAT_EQ(camera.pose().distance, 10.0f * std::sqrt(0.9f));
    // The same steps in any grouping land at the same distance (to float rounding).
    OrbitCamera a = orbitAt(scene, 0.0f, 0.0f, 3.0f), b = a;
    for (int i = 0; i < 7; ++i) a.zoom(1.0f);
    b.zoom(7.0f);
    EXPECT_NEAR(a.pose().distance, b.pose().distance, 1e-5f * b.pose().distance);

    camera.zoom(1e4f);
    EXPECT_FLOAT_EQ(camera.pose().distance, radius * kMinDistanceRadii);
    camera.zoom(-1e5f);
    EXPECT_FLOAT_EQ(camera.pose().distance, radius * kMaxDistanceRadii);
    // A distance outside the range (from a spec) is not pulled in, only kept from going further out.
    OrbitCamera far = orbitAt(scene, 0.0f, 0.0f, radius * 1e4f);
    far.zoom(-1.0f);
    EXPECT_EQ(far.pose().distance, radius * 1e4f);
    far.zoom(1.0f);
    EXPECT_FLOAT_EQ(far.pose().distance, radius * 1e4f * 0.9f);
}

TEST(OrbitCamera, PanKeepsThePointUnderTheCursor)
{
    const Scene scene = boundsScene();
    const unsigned w = 200, h = 100;
    for (glm::vec3 p : {glm::vec3(0, 0, 6), glm::vec3(35, 25, 9), glm::vec3(-100, -70, 3)}) {
        OrbitCamera camera = orbitAt(scene, p.x, p.y, p.z);
        const glm::vec3 target = boundingSphere(scene).center;
        camera.pan(20.0f, -10.0f, h);
        glm::vec4 clip = camera.matrices(w, h).clipFromWorld * glm::vec4(target, 1.0f);
        // Pixel position of the old target: the centre moved by the drag (NDC y = -1 at the top).
        float px = (clip.x / clip.w * 0.5f + 0.5f) * w, py = (clip.y / clip.w * 0.5f + 0.5f) * h;
        EXPECT_NEAR(px, w / 2.0f + 20.0f, 1e-3f);
        EXPECT_NEAR(py, h / 2.0f - 10.0f, 1e-3f);
        EXPECT_NEAR(glm::length(camera.pose().targetOffset),
                    std::hypot(20.0f, 10.0f) * 2.0f * p.z * std::tan(0.5f * kOrbitYfov) / h, 1e-4f);
    }
}

TEST(OrbitCamera, PannedCamerasStillEncloseTheScene)
{
    // The depth range follows the sphere's centre, not the target: a point of the bounds in front of
    // the camera keeps a depth inside (0, 1).
    const Scene scene = boundsScene();
    OrbitCamera camera = orbitAt(scene, 30.0f, 20.0f, 8.0f);
    camera.pan(-150.0f, 80.0f, 100);
    const CameraMatrices m = camera.matrices(100, 100);
    for (int i = 0; i < 8; ++i) {
        glm::vec3 corner((i & 1) ? scene.boundsMax.x : scene.boundsMin.x,
                         (i & 2) ? scene.boundsMax.y : scene.boundsMin.y,
                         (i & 4) ? scene.boundsMax.z : scene.boundsMin.z);
        glm::vec4 clip = m.clipFromWorld * glm::vec4(corner, 1.0f);
        EXPECT_GT(clip.z / clip.w, 0.0f) << i;
        EXPECT_LT(clip.z / clip.w, 1.0f) << i;
    }
}

TEST(OrbitCamera, GltfCamerasAreNoOrbit)
{
    Scene scene = boundsScene();
    scene.cameras.push_back(SceneCamera{});
    auto camera = OrbitCamera::fromSpec(*parseCameraSpec("gltf:0"), scene, 64, 64);
    ASSERT_FALSE(camera.ok());
    EXPECT_EQ(camera.error().code, ExitCode::Usage);
    EXPECT_TRUE(isOneLine(camera.error().message));
}

TEST(CameraSpec, OrbitTakesAnOptionalTargetOffset)
{
    auto spec = parseCameraSpec("orbit:10,20,3,0.5,-1,2e-3");
    ASSERT_TRUE(spec.ok());
    EXPECT_EQ(spec->orbit.targetOffset, glm::vec3(0.5f, -1.0f, 2e-3f));
    EXPECT_EQ(parseCameraSpec("orbit:10,20,3")->orbit.targetOffset, glm::vec3(0.0f));
    for (const char* bad : {"orbit:1,2,3,4,5", "orbit:1,2,3,4,5,6,7", "orbit:1,2,3,,5,6",
                            "orbit:1,2,3,4,5,nan", "orbit:1,2,3,4,5,6,", "orbit:1,2,0,4,5,6"}) {
        auto r = parseCameraSpec(bad);
        ASSERT_FALSE(r.ok()) << bad;
        EXPECT_TRUE(isOneLine(r.error().message));
    }
    // The offset moves the target: the bounds centre plus the offset projects to the image centre.
    const Scene scene = boundsScene();
    const CameraMatrices m = resolved("orbit:10,20,3,0.5,-1,0.25", scene, 64, 64);
    glm::vec4 clip =
        m.clipFromWorld * glm::vec4(boundingSphere(scene).center + glm::vec3(0.5f, -1.0f, 0.25f), 1.0f);
    EXPECT_NEAR(clip.x / clip.w, 0.0f, 1e-5f);
    EXPECT_NEAR(clip.y / clip.w, 0.0f, 1e-5f);
}

// ---- controls -------------------------------------------------------------------------------

ViewerState startState()
{
    RenderSettings settings = testSettings(160, 120);
    return makeViewerState(OrbitCamera(boundsScene(), 160, 120), settings, false, PrimitiveMode::Triangles,
                           2);
}

TEST(ViewerControls, StartStateFollowsTheCommandLine)
{
    RenderSettings settings = testSettings(160, 120);
    settings.msaa = 8;
    ViewerState s = makeViewerState(OrbitCamera(), settings, true, PrimitiveMode::Points);
    EXPECT_EQ(s.aaPreset, 2);
    EXPECT_TRUE(s.wireframe);
    EXPECT_EQ(s.settings.lineDepthBias, kWireframeDepthBias);
    EXPECT_EQ(s.primitiveMode, PrimitiveMode::Points);
    EXPECT_EQ(s.backendCount, 1u);
    settings.msaa = 2;
    ViewerState custom = makeViewerState(OrbitCamera(), settings, false, PrimitiveMode::Triangles);
    EXPECT_EQ(custom.aaPreset, -1);
    EXPECT_EQ(aaName(custom), "MSAA 2x SSAA 1x1");
    EXPECT_TRUE(onKey(custom, 'm'));
    EXPECT_EQ(custom.aaPreset, 0);
    EXPECT_EQ(custom.settings.msaa, 1u);
}

TEST(ViewerControls, DigitsPickTheShadingModes)
{
    ViewerState s = startState();
    for (char key = '1'; key <= '9'; ++key) {
        EXPECT_TRUE(onKey(s, key));
        EXPECT_EQ(s.settings.shadingMode, kShadingKeyModes[size_t(key - '1')]) << key;
    }
    EXPECT_EQ(kShadingKeyModes[0], SHADING_BLINN_PHONG);  // the default on 1
    EXPECT_FALSE(onKey(s, '0'));
    EXPECT_EQ(s.settings.shadingMode, SHADING_TEXCOORD);
}

TEST(ViewerControls, MCyclesTheAntiAliasingPresets)
{
    ViewerState s = startState();
    ASSERT_EQ(s.aaPreset, 0);
    const std::vector<std::pair<uint32_t, uint32_t>> expected = {{4, 1}, {8, 1}, {1, 2}, {1, 1}, {4, 1}};
    for (auto [msaa, ssaa] : expected) {
        EXPECT_TRUE(onKey(s, 'm'));
        EXPECT_EQ(s.settings.msaa, msaa);
        EXPECT_EQ(s.settings.ssaa, ssaa);
        EXPECT_EQ(aaName(s), kAaPresets[size_t(s.aaPreset)].name);
    }
    for (const AaPreset& p : kAaPresets) {
        RenderSettings settings = testSettings(64, 64);
        settings.msaa = p.msaa;
        settings.ssaa = p.ssaa;
        EXPECT_TRUE(checkRenderInputs(clipSpaceScene(clipQuad(-1, -1, 1, 1, 0.5f)), settings).ok()) << p.name;
    }
}

TEST(ViewerControls, ATogglesAmbientOcclusion)
{
    ViewerState s = startState();
    ASSERT_EQ(s.settings.ao, AO_OFF);
    EXPECT_TRUE(isBoundKey('a'));
    EXPECT_TRUE(onKey(s, 'a'));
    EXPECT_EQ(s.settings.ao, AO_GTAO);
    s.settings.shadingMode = SHADING_AO;
    EXPECT_TRUE(checkSettings(s.settings).ok());
    EXPECT_TRUE(onKey(s, 'a'));
    EXPECT_EQ(s.settings.ao, AO_OFF);
    // --shading ao without AO is refused: turning AO off leaves it for the first key's mode.
    EXPECT_EQ(s.settings.shadingMode, kShadingKeyModes[0]);
    EXPECT_TRUE(checkSettings(s.settings).ok());
}

TEST(ViewerControls, WTogglesTheWireframeAndPCyclesThePrimitiveMode)
{
    ViewerState s = startState();
    EXPECT_TRUE(onKey(s, 'w'));
    EXPECT_TRUE(s.wireframe);
    EXPECT_EQ(s.settings.lineDepthBias, kWireframeDepthBias);
    EXPECT_TRUE(s.sceneChanged);
    s.sceneChanged = false;
    EXPECT_TRUE(onKey(s, 'w'));
    EXPECT_FALSE(s.wireframe);
    EXPECT_EQ(s.settings.lineDepthBias, 0.0f);
    EXPECT_TRUE(s.sceneChanged);

    s.sceneChanged = false;
    for (PrimitiveMode mode : {PrimitiveMode::Lines, PrimitiveMode::Points, PrimitiveMode::Triangles}) {
        EXPECT_TRUE(onKey(s, 'p'));
        EXPECT_EQ(s.primitiveMode, mode);
        EXPECT_TRUE(s.sceneChanged);
        s.sceneChanged = false;
    }
}

TEST(ViewerControls, FrameSceneIsTheRenderCommandsScene)
{
    const Scene base = builtinScene();
    ViewerState s = startState();
    EXPECT_EQ(frameScene(base, s).triangleCount(), base.triangleCount());
    onKey(s, 'w');
    onKey(s, 'p');  // lines with the overlay
    const Scene viewed = frameScene(base, s);
    const Scene expected = meshAsLines(withWireframe(base));
    EXPECT_EQ(viewed.lines, expected.lines);
    EXPECT_EQ(viewed.triangleCount(), 0u);
    EXPECT_EQ(viewed.lineMaterials, expected.lineMaterials);
    onKey(s, 'p');  // points with the overlay's edges kept as lines
    EXPECT_EQ(frameScene(base, s).points, meshAsPoints(withWireframe(base)).points);
    EXPECT_EQ(frameScene(base, s).lines, meshAsPoints(withWireframe(base)).lines);
}

TEST(ViewerControls, BSwitchesBackendOnlyWhenThereAreSeveral)
{
    ViewerState s = startState();
    ASSERT_EQ(s.backendCount, 2u);
    EXPECT_TRUE(onKey(s, 'b'));
    EXPECT_EQ(s.backendIndex, 1u);
    EXPECT_TRUE(s.backendChanged);
    s.backendChanged = false;
    EXPECT_TRUE(onKey(s, 'b'));
    EXPECT_EQ(s.backendIndex, 0u);
    EXPECT_TRUE(s.backendChanged);

    ViewerState single = makeViewerState(OrbitCamera(), testSettings(8, 8), false, PrimitiveMode::Triangles);
    EXPECT_TRUE(onKey(single, 'b'));
    EXPECT_EQ(single.backendIndex, 0u);
    EXPECT_FALSE(single.backendChanged);
}

TEST(ViewerControls, RResetsSSavesQAndEscapeQuit)
{
    const Scene scene = boundsScene();
    ViewerState s = startState();
    onDrag(s, MouseButton::Left, 50.0f, 30.0f);
    onDrag(s, MouseButton::Right, 5.0f, 3.0f);
    onScroll(s, 4.0f);
    ASSERT_TRUE(onResize(s, 300, 100));
    EXPECT_TRUE(onKey(s, 'r'));
    // The auto camera for the size the window has now.
    EXPECT_TRUE(sameBits(s.camera.matrices(300, 100), *resolveCamera(CameraSpec{}, scene, 300, 100)));

    EXPECT_TRUE(onKey(s, 's'));
    EXPECT_TRUE(s.saveRequested);
    EXPECT_EQ(s.savePrefix, "");
    requestSave(s, "shots/a");
    EXPECT_EQ(s.savePrefix, "shots/a");

    EXPECT_FALSE(s.quit);
    EXPECT_TRUE(onKey(s, 'q'));
    EXPECT_TRUE(s.quit);
    ViewerState e = startState();
    EXPECT_TRUE(onKey(e, kKeyEscape));
    EXPECT_TRUE(e.quit);
}

TEST(ViewerControls, UnboundKeysChangeNothing)
{
    ViewerState s = startState();
    const ViewerState before = s;
    for (char key : {'v', 'M', 'W', ' ', '0', '\n', char(0)}) {
        EXPECT_FALSE(isBoundKey(key)) << int(key);
        EXPECT_FALSE(onKey(s, key)) << int(key);
    }
    EXPECT_TRUE(samePose(s.camera.pose(), before.camera.pose()));
    EXPECT_EQ(s.settings.shadingMode, before.settings.shadingMode);
    EXPECT_EQ(s.aaPreset, before.aaPreset);
    EXPECT_FALSE(s.quit || s.saveRequested || s.sceneChanged || s.backendChanged);
    EXPECT_TRUE(s.model.isIdentity());
    for (char key : std::string("123456789mwpbrsq\x1bjlikuoxXyYzZ+=-")) EXPECT_TRUE(isBoundKey(key)) << key;
}

TEST(ViewerControls, MouseDragsOrbitPanAndTheWheelZooms)
{
    ViewerState s = startState();
    OrbitCamera expected = s.camera;
    onDrag(s, MouseButton::Left, 12.0f, -7.0f);
    expected.orbit(12.0f, -7.0f);
    EXPECT_TRUE(samePose(s.camera.pose(), expected.pose()));
    onDrag(s, MouseButton::Right, 3.0f, 4.0f);
    expected.pan(3.0f, 4.0f, 120);
    EXPECT_TRUE(samePose(s.camera.pose(), expected.pose()));
    onDrag(s, MouseButton::Middle, -6.0f, 1.0f);
    expected.pan(-6.0f, 1.0f, 120);
    EXPECT_TRUE(samePose(s.camera.pose(), expected.pose()));
    onScroll(s, 2.0f);
    expected.zoom(2.0f);
    EXPECT_TRUE(samePose(s.camera.pose(), expected.pose()));

    EXPECT_FALSE(onResize(s, 0, 0));  // minimized
    EXPECT_FALSE(onResize(s, MAX_FRAMEBUFFER_DIM + 1, 10));
    EXPECT_EQ(s.settings.width, 160u);
    EXPECT_TRUE(onResize(s, 320, 200));
    EXPECT_EQ(s.settings.width, 320u);
    EXPECT_EQ(s.settings.height, 200u);
}

TEST(ViewerControls, HelpListsEveryControl)
{
    const std::string help = controlsHelp();
    for (const char* text : {"left drag", "right/middle drag", "wheel", "1-9", "Esc, q", "1 blinn-phong",
                             "9 texcoord", "MSAA 8x", "SSAA 2x2", "wireframe", "primitive mode", "backend",
                             "reset", "save", "j l, i k, u o", "x X, y Y, z Z", "+ -", "model"})
        EXPECT_NE(help.find(text), std::string::npos) << text;
    for (char key : std::string("mwpbrs"))
        EXPECT_NE(help.find(std::string("  ") + key + " "), std::string::npos);
    // docs/viewer.md lists the controls verbatim.
    std::ifstream readme(sourceDir() + "/docs/viewer.md");
    std::stringstream text;
    text << readme.rdbuf();
    EXPECT_NE(text.str().find("```\n" + help + "```\n"), std::string::npos) << "docs/viewer.md lacks:\n"
                                                                            << help;

    ViewerState s = startState();
    EXPECT_EQ(stateSummary(s), "blinn-phong, 1x, triangles");
    onKey(s, 'w');
    onKey(s, '5');
    EXPECT_EQ(stateSummary(s), "normals, 1x, triangles + wireframe");
    onKey(s, 'y');
    onKey(s, '+');
    EXPECT_EQ(stateSummary(s), "normals, 1x, triangles + wireframe, model rotate:0,15,0,scale:1.25");
}

// The model keys: j / l, i / k and u / o move the model a tenth of the bounding radius along the camera's
// right, up and back vectors (so it moves left / right, up / down and nearer / farther on screen); x, y,
// z and their capitals add or take 15 degrees to AX, AY, AZ; + (=) and - scale by 1.25. Each key and its
// opposite undo each other exactly, and r resets the model with the camera.
TEST(ViewerControls, ModelKeysMoveTurnAndScaleTheModel)
{
    ViewerState s = startState();
    onDrag(s, MouseButton::Left, 40.0f, -25.0f);  // any camera: the keys follow its basis
    const OrbitBasis basis = orbitBasis(s.camera.pose());
    const float step = 0.1f * s.camera.sphere().radius;
    const glm::vec3 center = s.camera.sphere().center;
    // Where the centre of the scene lands on screen (NDC x, y and view depth) with the state's model.
    auto centreOnScreen = [&]() {
        const CameraMatrices m = s.camera.matrices(160, 120, s.model);
        const glm::vec4 clip = m.clipFromWorld * glm::vec4(center, 1.0f);
        const glm::vec4 view = m.viewFromWorld * glm::vec4(center, 1.0f);
        return glm::vec3(clip.x / clip.w, clip.y / clip.w, -view.z);
    };
    const glm::vec3 still = centreOnScreen();
    EXPECT_NEAR(still.x, 0.0f, 1e-5f);  // the camera looks at the centre
    EXPECT_NEAR(still.y, 0.0f, 1e-5f);
    struct Move {
        char key, undo;
        glm::vec3 direction;
    };
    for (const Move& m :
         {Move{'l', 'j', basis.right}, Move{'j', 'l', -basis.right}, Move{'i', 'k', basis.up},
          Move{'k', 'i', -basis.up}, Move{'u', 'o', basis.back}, Move{'o', 'u', -basis.back}}) {
        SCOPED_TRACE(m.key);
        ASSERT_TRUE(onKey(s, m.key));
        EXPECT_EQ(s.model.translate, step * m.direction);
        const glm::vec3 now = centreOnScreen();
        // Right is +x in NDC, up is -y (Vulkan's y points down), towards the camera is less depth.
        const glm::vec3 expectedSign(glm::dot(m.direction, basis.right), -glm::dot(m.direction, basis.up),
                                     -glm::dot(m.direction, basis.back));
        for (int c = 0; c < 3; ++c) {
            const float moved = now[c] - still[c];
            if (expectedSign[c] == 0.0f)
                EXPECT_NEAR(moved, 0.0f, 1e-4f) << c;
            else
                EXPECT_GT(moved * expectedSign[c], 1e-3f) << c;
        }
        ASSERT_TRUE(onKey(s, m.undo));
        EXPECT_TRUE(s.model.isIdentity());
    }

    for (char key : {'x', 'y', 'z'}) {
        SCOPED_TRACE(key);
        const int axis = key - 'x';
        for (int i = 0; i < 6; ++i) onKey(s, key);
        EXPECT_EQ(s.model.rotateDeg[axis], 90.0f);
        for (int i = 0; i < 12; ++i) onKey(s, key);
        EXPECT_EQ(s.model.rotateDeg[axis], -90.0f) << "kept within (-180, 180]";
        for (int i = 0; i < 6; ++i) onKey(s, char(key - 'a' + 'A'));
        EXPECT_EQ(s.model.rotateDeg[axis], 180.0f);
        for (int i = 0; i < 12; ++i) onKey(s, char(key - 'a' + 'A'));
        EXPECT_EQ(s.model.rotateDeg[axis], 0.0f);
    }
    EXPECT_TRUE(s.model.isIdentity());

    onKey(s, '+');
    EXPECT_EQ(s.model.scale, 1.25f);
    onKey(s, '=');
    EXPECT_EQ(s.model.scale, 1.5625f);
    onKey(s, '-');
    onKey(s, '-');
    onKey(s, '-');
    EXPECT_EQ(s.model.scale, 0.8f);
    onKey(s, '+');
    EXPECT_EQ(s.model.scale, 1.0f);
    for (int i = 0; i < 100; ++i) onKey(s, '-');
    EXPECT_EQ(s.model.scale, float(std::pow(1.25, -31))) << "the range ends at 1.25^-31";
    for (int i = 0; i < 31; ++i) onKey(s, '+');
    EXPECT_EQ(s.model.scale, 1.0f) << "presses undo each other exactly";
    for (int i = 0; i < 100; ++i) onKey(s, '+');
    EXPECT_EQ(s.model.scale, float(std::pow(1.25, 31)));
    for (int i = 0; i < 31; ++i) onKey(s, '-');
    EXPECT_EQ(s.model.scale, 1.0f);

    onKey(s, 'l');
    onKey(s, 'y');
    EXPECT_TRUE(onKey(s, 'r'));
    EXPECT_TRUE(s.model.isIdentity()) << "r resets the model with the camera";
}

// What the viewer draws with a moved model is what `raster render --camera SPEC --model SPEC` draws: the
// state's two specs resolve to the matrices of its frame, bit for bit.
TEST(ViewerControls, TheMovedModelsSpecsGiveTheFramesMatrices)
{
    const Scene scene = boundsScene();
    ViewerState s = startState();
    onDrag(s, MouseButton::Left, 33.0f, 12.0f);
    onDrag(s, MouseButton::Right, -7.0f, 4.0f);
    for (char key : std::string("lliuyyyx+Z")) ASSERT_TRUE(onKey(s, key));
    const std::string model = modelSpecString(s.model);
    EXPECT_NE(model.find("translate:"), std::string::npos) << model;
    EXPECT_NE(model.find("rotate:15,45,-15"), std::string::npos) << model;
    EXPECT_NE(model.find("scale:1.25"), std::string::npos) << model;
    auto camera = parseCameraSpec(s.camera.specString());
    auto parsed = parseModelSpec(model);
    ASSERT_TRUE(camera.ok() && parsed.ok());
    auto resolvedCamera = resolveCamera(*camera, scene, 160, 120, *parsed);
    ASSERT_TRUE(resolvedCamera.ok());
    EXPECT_TRUE(sameBits(s.camera.matrices(160, 120, s.model), *resolvedCamera));
}

// ---- scripts --------------------------------------------------------------------------------

TEST(ViewerScript, ParsesEveryEvent)
{
    const std::string text =
        "# a tour\n"
        "\n"
        "drag left 40 -12.5   # orbit\n"
        "  drag right 3 4\n"
        "drag middle -1 0\n"
        "scroll 2\n"
        "scroll -0.5\n"
        "key 3\n"
        "key esc\n"
        "resize 200 150\n"
        "save out/shot one\n"
        "frame\n";
    auto events = parseScript(text, "tour.txt");
    ASSERT_TRUE(events.ok()) << events.error().message;
    ASSERT_EQ(events->size(), 10u);
    const auto& e = *events;
    EXPECT_EQ(e[0].kind, ScriptEvent::Kind::Drag);
    EXPECT_EQ(e[0].line, 3);
    EXPECT_EQ(e[0].button, MouseButton::Left);
    EXPECT_EQ(e[0].dx, 40.0f);
    EXPECT_EQ(e[0].dy, -12.5f);
    EXPECT_EQ(e[1].button, MouseButton::Right);
    EXPECT_EQ(e[1].line, 4);
    EXPECT_EQ(e[2].button, MouseButton::Middle);
    EXPECT_EQ(e[3].kind, ScriptEvent::Kind::Scroll);
    EXPECT_EQ(e[3].steps, 2.0f);
    EXPECT_EQ(e[4].steps, -0.5f);
    EXPECT_EQ(e[5].kind, ScriptEvent::Kind::Key);
    EXPECT_EQ(e[5].key, '3');
    EXPECT_EQ(e[6].key, kKeyEscape);
    EXPECT_EQ(e[7].kind, ScriptEvent::Kind::Resize);
    EXPECT_EQ(e[7].width, 200u);
    EXPECT_EQ(e[7].height, 150u);
    EXPECT_EQ(e[8].kind, ScriptEvent::Kind::Save);
    EXPECT_EQ(e[8].path, "out/shot one");
    EXPECT_EQ(e[9].kind, ScriptEvent::Kind::Frame);
    EXPECT_EQ(e[9].line, 12);
}

TEST(ViewerScript, BadLinesAreOneLineErrorsNamingFileAndLine)
{
    for (const char* line : {"drag",          "drag left 1",     "drag up 1 2",     "drag left 1 2 3",
                             "drag left a 2", "drag left 1 nan", "drag left 1 inf", "drag left +1 2",
                             "scroll",        "scroll x",        "scroll 1 2",      "key",
                             "key v",         "key ab",          "key esc esc",     "resize 0 10",
                             "resize 10",     "resize 10 -5",    "resize 99999 10", "resize 1.5 2",
                             "save",          "frame 1",         "click 1 2",       "Frame"}) {
        const std::string text = std::string("frame\n# ok\n") + line + "\nframe\n";
        auto events = parseScript(text, "dir/s.txt");
        ASSERT_FALSE(events.ok()) << "accepted '" << line << "'";
        const std::string& message = events.error().message;
        EXPECT_EQ(message.rfind("dir/s.txt:3: ", 0), 0u) << message;
        EXPECT_NE(message.find(line), std::string::npos) << message;
        EXPECT_TRUE(isOneLine(message)) << message;
        EXPECT_EQ(events.error().code, ExitCode::Usage);
    }
    auto missing = loadScript("/nonexistent/script.txt");
    ASSERT_FALSE(missing.ok());
    EXPECT_TRUE(isOneLine(missing.error().message));
}

TEST(ViewerScript, ReplayGoesThroughTheControls)
{
    ScratchDir dir("script");
    const std::string path = dir.file("tour.txt");
    std::ofstream(path) << "drag left 40 -12\ndrag right 3 4\nscroll 2\nkey 5\nkey m\nkey w\nkey p\n"
                           "resize 200 150\nframe\nsave shots/a\nkey b\nkey q\n";
    auto events = loadScript(path);
    ASSERT_TRUE(events.ok()) << events.error().message;

    ViewerState replayed = startState();
    std::vector<ScriptEffect> effects;
    for (const ScriptEvent& e : *events) effects.push_back(applyScriptEvent(replayed, e));

    // The same input through the controls, as the window's callbacks would send it.
    ViewerState live = startState();
    onDrag(live, MouseButton::Left, 40.0f, -12.0f);
    onDrag(live, MouseButton::Right, 3.0f, 4.0f);
    onScroll(live, 2.0f);
    for (char key : {'5', 'm', 'w', 'p'}) onKey(live, key);
    onResize(live, 200, 150);
    requestSave(live, "shots/a");
    onKey(live, 'b');
    onKey(live, 'q');

    EXPECT_TRUE(samePose(replayed.camera.pose(), live.camera.pose()));
    EXPECT_EQ(replayed.settings.shadingMode, SHADING_NORMALS);
    EXPECT_EQ(replayed.settings.shadingMode, live.settings.shadingMode);
    EXPECT_EQ(replayed.settings.msaa, 4u);
    EXPECT_EQ(replayed.aaPreset, live.aaPreset);
    EXPECT_TRUE(replayed.wireframe);
    EXPECT_EQ(replayed.primitiveMode, PrimitiveMode::Lines);
    EXPECT_EQ(replayed.settings.width, 200u);
    EXPECT_EQ(replayed.settings.height, 150u);
    EXPECT_TRUE(replayed.saveRequested);
    EXPECT_EQ(replayed.savePrefix, "shots/a");
    EXPECT_EQ(replayed.backendIndex, 1u);
    EXPECT_TRUE(replayed.quit);

    ASSERT_EQ(effects.size(), 12u);
    for (size_t i = 0; i < effects.size(); ++i) {
        EXPECT_EQ(effects[i].resizeWindow, i == 7) << i;
        EXPECT_EQ(effects[i].renderFrame, i == 8) << i;
    }
    // A resize the window cannot take changes nothing and asks for no window resize.
    ScriptEvent zero;
    zero.kind = ScriptEvent::Kind::Resize;
    EXPECT_FALSE(applyScriptEvent(replayed, zero).resizeWindow);
    EXPECT_EQ(replayed.settings.width, 200u);
}

}  // namespace
}  // namespace sr::test
