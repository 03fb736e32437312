// camera_test.cpp - `--camera` parsing and the Vulkan-convention matrices, checked on points whose
// NDC and depth are worked out by hand.
#include <algorithm>
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "camera/camera.h"
#include "camera/orbit.h"
#include "test_util.h"

namespace sr {
namespace {

constexpr float kPi = 3.14159265358979f;

// NDC x, y and depth of a view-space or world-space point under `m`.
glm::vec3 project(const glm::mat4& m, const glm::vec3& p)
{
    glm::vec4 c = m * glm::vec4(p, 1.0f);
    return glm::vec3(c) / c.w;
}

::testing::AssertionResult near(const glm::vec3& actual, const glm::vec3& expected, float eps = 1e-5f)
{
    glm::vec3 d = glm::abs(actual - expected);
    if (d.x <= eps && d.y <= eps && d.z <= eps) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure()
           << "got (" << actual.x << ", " << actual.y << ", " << actual.z << "), expected (" << expected.x
           << ", " << expected.y << ", " << expected.z << ")";
}

// A scene whose bounds are the cube [-1, 1]^3: bounding sphere at the origin, radius sqrt(3).
Scene cubeBoundsScene()
{
    Scene scene;
    scene.boundsMin = glm::vec3(-1.0f);
    scene.boundsMax = glm::vec3(1.0f);
    return scene;
}

glm::vec3 eyeOf(const CameraMatrices& m)
{
    return glm::vec3(glm::inverse(m.viewFromWorld)[3]);
}

// ---- parsing --------------------------------------------------------------------------------

TEST(CameraSpec, ParsesValidSpecs)
{
    Result<CameraSpec> autoSpec = parseCameraSpec("auto");
    ASSERT_TRUE(autoSpec.ok());
    EXPECT_EQ(autoSpec->kind, CameraSpec::Kind::Auto);

    Result<CameraSpec> gltf = parseCameraSpec("gltf:12");
    ASSERT_TRUE(gltf.ok());
    EXPECT_EQ(gltf->kind, CameraSpec::Kind::Gltf);
    EXPECT_EQ(gltf->gltfIndex, 12);

    Result<CameraSpec> orbit = parseCameraSpec("orbit:-30.5,12,4.25");
    ASSERT_TRUE(orbit.ok());
    EXPECT_EQ(orbit->kind, CameraSpec::Kind::Orbit);
    EXPECT_FLOAT_EQ(orbit->orbit.azimuthDeg, -30.5f);
    EXPECT_FLOAT_EQ(orbit->orbit.elevationDeg, 12.0f);
    EXPECT_FLOAT_EQ(orbit->orbit.distance, 4.25f);
}

TEST(CameraSpec, RejectsMalformedSpecs)
{
    for (const char* text : {"",
                             "Auto",
                             "auto ",
                             "gltf",
                             "gltf:",
                             "gltf:-1",
                             "gltf:1x",
                             "gltf: 1",
                             "gltf:99999999999",
                             "orbit:",
                             "orbit:1,2",
                             "orbit:1,2,0",
                             "orbit:1,2,-3",
                             "orbit:a,b,c",
                             "orbit:1,2,3,4",
                             "orbit:nan,1,1",
                             "orbit:1,inf,1",
                             "orbit:1,,2",
                             "orbit: 1,2,3",
                             "front"}) {
        Result<CameraSpec> spec = parseCameraSpec(text);
        ASSERT_FALSE(spec.ok()) << "accepted '" << text << "'";
        const std::string& message = spec.error().message;
        EXPECT_EQ(message.rfind("invalid --camera '" + std::string(text) +
                                    "': expected auto, gltf:N "
                                    "or orbit:AZ,EL,DIST",
                                0),
                  0u)
            << message;
        EXPECT_EQ(message.find('\n'), std::string::npos);
        EXPECT_EQ(spec.error().code, ExitCode::Usage);
    }
}

// ---- projections ----------------------------------------------------------------------------

TEST(Projection, PerspectiveVulkanConventions)
{
    // yfov 90 degrees: tan(45) = 1, so at distance d the visible half-height is d (and 2d across
    // for aspect 2). near 0.5, far 10.
    glm::mat4 p = perspectiveVulkan(kPi / 2.0f, 2.0f, 0.5f, 10.0f);
    EXPECT_TRUE(near(project(p, {0, 0, -0.5f}), {0, 0, 0}));
    EXPECT_TRUE(near(project(p, {0, 0, -10}), {0, 0, 1}));
    // Depth at view distance z: far (z - near) / (z (far - near)) = 10 * 0.5 / 9.5.
    EXPECT_TRUE(near(project(p, {0, 0, -1}), {0, 0, 5.0f / 9.5f}));
    // +y in view space is up, which is negative NDC y (the top row in Vulkan).
    // At view distance 2 the depth is 10 * 1.5 / (2 * 9.5) and the half extents are 2 (y), 4 (x).
    const float depth2 = 10.0f * 1.5f / (2.0f * 9.5f);
    EXPECT_TRUE(near(project(p, {0, 1, -2}), {0, -0.5f, depth2}));
    EXPECT_TRUE(near(project(p, {0, 2, -2}), {0, -1, depth2}));
    EXPECT_TRUE(near(project(p, {4, 0, -2}), {1, 0, depth2}));
    EXPECT_TRUE(near(project(p, {-4, -2, -2}), {-1, 1, depth2}));
    // w is the view distance (clip space is homogeneous, not pre-divided).
    EXPECT_FLOAT_EQ((p * glm::vec4(0, 0, -3, 1)).w, 3.0f);
}

TEST(Projection, OrthographicVulkanConventions)
{
    glm::mat4 o = orthographicVulkan(2.0f, 1.0f, 1.0f, 11.0f);
    EXPECT_TRUE(near(project(o, {2, 1, -1}), {1, -1, 0}));
    EXPECT_TRUE(near(project(o, {-2, -1, -11}), {-1, 1, 1}));
    EXPECT_TRUE(near(project(o, {1, 0.5f, -6}), {0.5f, -0.5f, 0.5f}));
    EXPECT_FLOAT_EQ((o * glm::vec4(1, 2, -3, 1)).w, 1.0f);
}

// ---- resolveCamera --------------------------------------------------------------------------

TEST(ResolveCamera, OrbitPlacement)
{
    Scene scene = cubeBoundsScene();
    CameraSpec spec = *parseCameraSpec("orbit:0,0,5");
    Result<CameraMatrices> m = resolveCamera(spec, scene, 100, 100);
    ASSERT_TRUE(m.ok());
    // Azimuth 0, elevation 0: the eye sits on +z looking towards -z, x right, y up.
    EXPECT_TRUE(near(eyeOf(*m), {0, 0, 5}));
    EXPECT_TRUE(near(glm::vec3(m->viewFromWorld * glm::vec4(0, 0, 0, 1)), {0, 0, -5}));
    EXPECT_TRUE(near(glm::vec3(m->viewFromWorld * glm::vec4(1, 2, 0, 1)), {1, 2, -5}));
    glm::vec3 centre = project(m->clipFromWorld, {0, 0, 0});
    EXPECT_NEAR(centre.x, 0.0f, 1e-6f);
    EXPECT_NEAR(centre.y, 0.0f, 1e-6f);
    EXPECT_LT(project(m->clipFromWorld, {0, 1, 0}).y, 0.0f);  // above the centre: top half
    EXPECT_GT(project(m->clipFromWorld, {1, 0, 0}).x, 0.0f);  // +x: right half
    // Near and far enclose the bounding sphere (radius sqrt(3)) with 1% padding.
    float r = std::sqrt(3.0f);
    EXPECT_NEAR(m->znear, (5.0f - r) * 0.99f, 1e-4f);
    EXPECT_NEAR(m->zfar, (5.0f + r) * 1.01f, 1e-4f);
    EXPECT_NEAR(project(m->clipFromWorld, {0, 0, 0}).z,
                m->zfar * (5.0f - m->znear) / (5.0f * (m->zfar - m->znear)), 1e-5f);

    // Azimuth 90 puts the eye on +x; elevation 90 straight above, with world -z at the top.
    Result<CameraMatrices> side = resolveCamera(*parseCameraSpec("orbit:90,0,5"), scene, 100, 100);
    ASSERT_TRUE(side.ok());
    EXPECT_TRUE(near(eyeOf(*side), {5, 0, 0}, 1e-4f));
    Result<CameraMatrices> top = resolveCamera(*parseCameraSpec("orbit:0,90,5"), scene, 100, 100);
    ASSERT_TRUE(top.ok());
    EXPECT_TRUE(near(eyeOf(*top), {0, 5, 0}, 1e-4f));
    glm::vec3 far = project(top->clipFromWorld, {0, 0, -1});
    EXPECT_TRUE(std::isfinite(far.x) && std::isfinite(far.y) && std::isfinite(far.z));
    EXPECT_LT(far.y, 0.0f);
    EXPECT_NEAR(far.x, 0.0f, 1e-5f);
}

TEST(ResolveCamera, AutoFramesTheBounds)
{
    Scene scene;
    scene.boundsMin = glm::vec3(-3.0f, 0.0f, -1.0f);
    scene.boundsMax = glm::vec3(1.0f, 2.0f, 3.0f);
    glm::vec3 centre(-1.0f, 1.0f, 1.0f);
    float r = 0.5f * glm::length(scene.boundsMax - scene.boundsMin);  // 3
    for (glm::uvec2 size : {glm::uvec2(100, 100), glm::uvec2(200, 100), glm::uvec2(100, 300)}) {
        Result<CameraMatrices> m = resolveCamera(CameraSpec{}, scene, size.x, size.y);
        ASSERT_TRUE(m.ok());
        // Default angles: azimuth 35, elevation 25 degrees around the centre.
        float az = 35.0f * kPi / 180.0f, el = 25.0f * kPi / 180.0f;
        glm::vec3 dir(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
        glm::vec3 offset = eyeOf(*m) - centre;
        float dist = glm::length(offset);
        EXPECT_TRUE(near(offset / dist, dir, 1e-4f));
        // The sphere fits the narrower half-angle of a 45-degree vertical fov exactly.
        float halfY = 22.5f * kPi / 180.0f;
        float halfX = std::atan(std::tan(halfY) * float(size.x) / float(size.y));
        EXPECT_NEAR(dist, r / std::sin(std::min(halfX, halfY)), 1e-3f);
        EXPECT_LE(m->znear, dist - r);
        EXPECT_GE(m->zfar, dist + r);
        for (int i = 0; i < 8; ++i) {
            glm::vec3 p((i & 1) ? scene.boundsMax.x : scene.boundsMin.x,
                        (i & 2) ? scene.boundsMax.y : scene.boundsMin.y,
                        (i & 4) ? scene.boundsMax.z : scene.boundsMin.z);
            glm::vec3 ndc = project(m->clipFromWorld, p);
            EXPECT_LE(std::fabs(ndc.x), 1.0f) << i;
            EXPECT_LE(std::fabs(ndc.y), 1.0f) << i;
            EXPECT_GT(ndc.z, 0.0f) << i;
            EXPECT_LT(ndc.z, 1.0f) << i;
        }
    }
}

// A 20 x 20 grid (800 triangles) scaled by 10^e, framed by the auto camera: every scale a camera in
// float can transform shows the grid as at scale 1 (the campaign's e <= -8 and e >= 19 drew the
// background alone, silently: an absolute floor on the radius and the near plane, and znear * zfar
// overflowing float); the scales beyond are one-line errors that say why.
Scene scaledGrid(int e)
{
    Scene scene;
    const double scale = std::pow(10.0, e);
    constexpr int n = 20;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            scene.positions.emplace_back(float(i * scale), float(j * scale), 0.0f, 1.0f);
            scene.normals.emplace_back(0.0f, 0.0f, 1.0f, 0.0f);
        }
    for (uint32_t j = 0; j < n; ++j)
        for (uint32_t i = 0; i < n; ++i) {
            const uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
            scene.indices.insert(scene.indices.end(), {a, b, d, a, d, c});
        }
    scene.triFlags.assign(scene.indices.size() / 3, TRI_FLAG_DOUBLE_SIDED);
    EXPECT_TRUE(finalizeScene(scene, "grid").ok());
    return scene;
}

TEST(ResolveCamera, AutoFramesEveryScaleAFloatCameraCanTransform)
{
    bool skip = false;
    auto device = test::openBackend("vulkan", skip);
    if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
    ASSERT_TRUE(device);
    RenderSettings s;
    s.width = s.height = 32;
    s.warmup = 0;
    auto covered = [&](int e) -> long {
        const Scene scene = scaledGrid(e);
        auto camera = resolveCamera(CameraSpec{}, scene, s.width, s.height);
        if (!camera) {
            ADD_FAILURE() << "10^" << e << ": " << camera.error().message;
            return -1;
        }
        auto out = renderScene(*device, scene, *camera, s);
        if (!out) {
            ADD_FAILURE() << "10^" << e << ": " << out.error().message;
            return -1;
        }
        return long(std::count_if(out->aov.id.begin(), out->aov.id.end(),
                                  [](uint32_t id) { return id != EMPTY_ID; }));
    };
    const long atOne = covered(0);
    ASSERT_GT(atOne, 300);
    for (int e = -30; e <= 36; e += e < -25 || e > 15 ? 1 : 5) {
        SCOPED_TRACE("scale 10^" + std::to_string(e));
        // Float's rounding of the scaled corners may move an edge across a pixel centre, no more.
        EXPECT_NEAR(covered(e), atOne, 4);
    }
    for (const auto& [e, message] : std::vector<std::pair<int, std::string>>{
             {-32, "the scene is 2.83e-31 units across, too small for a camera in float to frame"},
             {37, "the scene's bounds reach 2.83e+38 units, too far for a camera in float"}}) {
        auto camera = resolveCamera(CameraSpec{}, scaledGrid(e), s.width, s.height);
        ASSERT_FALSE(camera.ok()) << e;
        EXPECT_EQ(camera.error().message.rfind(message, 0), 0u) << camera.error().message;
        EXPECT_EQ(camera.error().message.find('\n'), std::string::npos);
    }
}

TEST(ResolveCamera, GltfCameras)
{
    Scene scene = cubeBoundsScene();
    SceneCamera persp;
    persp.worldFromView[3] = glm::vec4(0, 0, 10, 1);  // on +z looking at the origin
    persp.yfov = 0.8f;
    persp.aspectRatio = 0.0f;
    persp.znear = 0.1f;
    persp.zfar = 0.0f;  // infinite: the far plane comes from the bounds
    scene.cameras.push_back(persp);
    SceneCamera ortho;
    ortho.perspective = false;
    ortho.worldFromView[3] = glm::vec4(0, 0, 5, 1);
    ortho.xmag = 2.0f;
    ortho.ymag = 1.0f;
    ortho.znear = 0.5f;
    ortho.zfar = 20.0f;
    scene.cameras.push_back(ortho);

    Result<CameraMatrices> m = resolveCamera(*parseCameraSpec("gltf:0"), scene, 200, 100);
    ASSERT_TRUE(m.ok()) << m.error().message;
    EXPECT_TRUE(near(glm::vec3(m->viewFromWorld * glm::vec4(0, 0, 0, 1)), {0, 0, -10}));
    // Aspect 0 means the framebuffer's, 2 here.
    EXPECT_NEAR(m->clipFromView[0][0], 1.0f / std::tan(0.4f) / 2.0f, 1e-5f);
    EXPECT_NEAR(m->clipFromView[1][1], -1.0f / std::tan(0.4f), 1e-5f);
    EXPECT_FLOAT_EQ(m->znear, 0.1f);
    EXPECT_NEAR(m->zfar, (10.0f + std::sqrt(3.0f)) * 1.01f, 1e-3f);
    EXPECT_NEAR(project(m->clipFromWorld, {0, 0, 10.0f - 0.1f}).z, 0.0f, 1e-5f);

    Result<CameraMatrices> o = resolveCamera(*parseCameraSpec("gltf:1"), scene, 200, 100);
    ASSERT_TRUE(o.ok()) << o.error().message;
    EXPECT_TRUE(near(project(o->clipFromWorld, {2, 1, 4.5f}), {1, -1, 0}));
    EXPECT_TRUE(near(project(o->clipFromWorld, {0, 0, -15}), {0, 0, 1}));
    EXPECT_FLOAT_EQ(o->znear, 0.5f);
    EXPECT_FLOAT_EQ(o->zfar, 20.0f);

    Result<CameraMatrices> missing = resolveCamera(*parseCameraSpec("gltf:2"), scene, 200, 100);
    ASSERT_FALSE(missing.ok());
    EXPECT_EQ(missing.error().message, "--camera gltf:2: the scene has 2 camera(s)");
    EXPECT_EQ(missing.error().code, ExitCode::Usage);
}

// ---- distances in bounding radii ---------------------------------------------------------------

TEST(CameraSpec, DistanceInBoundingRadii)
{
    auto spec = parseCameraSpec("orbit:30,20,2.5r");
    ASSERT_TRUE(spec.ok()) << spec.error().message;
    EXPECT_EQ(spec->kind, CameraSpec::Kind::Orbit);
    EXPECT_TRUE(spec->distanceInRadii);
    EXPECT_EQ(spec->orbit.distance, 2.5f);
    auto offset = parseCameraSpec("orbit:0,0,1r,0.5,0,0");
    ASSERT_TRUE(offset.ok());
    EXPECT_TRUE(offset->distanceInRadii);
    EXPECT_FALSE(parseCameraSpec("orbit:30,20,2.5")->distanceInRadii);
    for (const char* bad : {"orbit:30,20,r", "orbit:30,20,2.5rr", "orbit:30,20,-1r", "orbit:30,20,0r",
                            "orbit:30r,20,2", "orbit:30,20,2,1r,0,0", "orbit:30,20,2.5 r"})
        EXPECT_FALSE(parseCameraSpec(bad).ok()) << bad;

    // Bounds [0, 4] x [-1, 1] x [2, 6]: centre (2, 0, 4), radius |(4, 2, 4)| / 2 = 3, so 2.5r puts the
    // eye 7.5 from the centre, the same camera as orbit:30,20,7.5.
    Scene scene;
    scene.boundsMin = glm::vec3(0, -1, 2);
    scene.boundsMax = glm::vec3(4, 1, 6);
    auto m = resolveCamera(*spec, scene, 64, 48);
    ASSERT_TRUE(m.ok());
    EXPECT_NEAR(glm::length(eyeOf(*m) - glm::vec3(2, 0, 4)), 7.5f, 1e-5f);
    auto absolute = resolveCamera(*parseCameraSpec("orbit:30,20,7.5"), scene, 64, 48);
    EXPECT_EQ(m->clipFromWorld, absolute->clipFromWorld);
    EXPECT_EQ(resolvedCameraSpec(*spec, scene, 64, 48), "orbit:30,20,7.5");
    EXPECT_EQ(resolvedCameraSpec(*offset, scene, 64, 48), "orbit:0,0,3,0.5,0,0");
    EXPECT_EQ(resolvedCameraSpec(*parseCameraSpec("gltf:2"), scene, 64, 48), "gltf:2");
    // The orbit camera of turntables and the viewer starts at the same place.
    auto orbit = OrbitCamera::fromSpec(*spec, scene, 64, 48);
    ASSERT_TRUE(orbit.ok());
    EXPECT_EQ(orbit->pose().distance, 7.5f);
    EXPECT_EQ(orbit->matrices(64, 48).clipFromWorld, m->clipFromWorld);
}

// ---- the eye inside the geometry -------------------------------------------------------------

// The cube [-1, 1]^3 as 12 triangles, counter-clockwise seen from outside (outward), or inward.
Scene closedCube(bool outward)
{
    Scene scene;
    for (int i = 0; i < 8; ++i)
        scene.positions.push_back(glm::vec4(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1, 1));
    const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                  {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& q : quads) {
        const uint32_t tri[6] = {q[0], q[1], q[2], q[0], q[2], q[3]};
        for (int k = 0; k < 6; ++k) scene.indices.push_back(tri[outward ? k : 5 - k]);
    }
    scene.boundsMin = glm::vec3(-1.0f);
    scene.boundsMax = glm::vec3(1.0f);
    return scene;
}

TEST(EyeInsideScene, WindingNumberOfAClosedCube)
{
    const Scene cube = closedCube(true);
    // Each face's normal points away from the centre (the fixture's own check).
    for (size_t t = 0; t < cube.indices.size(); t += 3) {
        glm::vec3 a(cube.positions[cube.indices[t]]), b(cube.positions[cube.indices[t + 1]]),
            c(cube.positions[cube.indices[t + 2]]);
        EXPECT_GT(glm::dot(glm::cross(b - a, c - a), (a + b + c) / 3.0f), 0.0f) << t;
    }
    EXPECT_NEAR(windingNumber(cube, glm::vec3(0.0f)), 1.0, 1e-9);
    EXPECT_NEAR(windingNumber(cube, glm::vec3(0.9f, -0.5f, 0.3f)), 1.0, 1e-9);
    EXPECT_NEAR(windingNumber(cube, glm::vec3(3.0f, 0.0f, 0.0f)), 0.0, 1e-9);
    EXPECT_NEAR(windingNumber(closedCube(false), glm::vec3(0.0f)), -1.0, 1e-9);

    // An orbit camera at 0.5 radii (inside) and at 2.5 radii (outside); inside a room whose walls face
    // in, nothing to warn about.
    auto inside = resolveCamera(*parseCameraSpec("orbit:30,20,0.5r"), cube, 32, 32);
    auto outside = resolveCamera(*parseCameraSpec("orbit:30,20,2.5r"), cube, 32, 32);
    EXPECT_TRUE(eyeInsideScene(cube, *inside));
    EXPECT_FALSE(eyeInsideScene(cube, *outside));
    EXPECT_FALSE(eyeInsideScene(closedCube(false), *inside));
}

}  // namespace
}  // namespace sr
