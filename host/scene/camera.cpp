// camera.cpp - `--camera` parsing and the view and projection matrices (Vulkan conventions).
#include "scene/camera.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace sr {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kDefaultYfov = 45.0f * kPi / 180.0f;

float radians(float degrees)
{
    return degrees * kPi / 180.0f;
}

// Whole-string float parse: no trailing characters, finite.
bool parseFloat(const std::string& text, float& out)
{
    if (text.empty() || std::isspace(static_cast<unsigned char>(text.front()))) return false;
    errno = 0;
    char* end = nullptr;
    float value = std::strtof(text.c_str(), &end);
    if (errno != 0 || end != text.c_str() + text.size() || !std::isfinite(value)) return false;
    out = value;
    return true;
}

bool parseIndex(const std::string& text, int& out)
{
    if (text.empty() || text.size() > 9) return false;
    int value = 0;
    for (char c : text) {
        if (c < '0' || c > '9') return false;
        value = value * 10 + (c - '0');
    }
    out = value;
    return true;
}

struct Sphere {
    glm::vec3 center;
    float radius;
};

// Bounding sphere of the scene bounds; a point-sized scene still gets a usable radius.
Sphere boundingSphere(const Scene& scene)
{
    glm::vec3 center = 0.5f * (scene.boundsMin + scene.boundsMax);
    float radius = 0.5f * glm::length(scene.boundsMax - scene.boundsMin);
    float scale = std::max(glm::length(center), 1.0f);
    return {center, std::max(radius, scale * 1e-6f)};
}

// Near and far planes at `dist` from the centre of the sphere, enclosing it with 1% to spare. From inside
// the sphere the near plane cannot enclose it; it then sits at 1% of the distance to the centre (at
// most 1/1000 of the radius), so nearby geometry stays visible in a scene much larger than the view.
void encloseSphere(float dist, float radius, float& znear, float& zfar)
{
    float minNear = std::max(std::min(radius * 1e-3f, dist * 1e-2f), 1e-6f);
    znear = std::max((dist - radius) * 0.99f, minNear);
    zfar = std::max((dist + radius) * 1.01f, znear * 2.0f);
}

CameraMatrices finish(const glm::mat4& viewFromWorld, const glm::mat4& clipFromView, float znear, float zfar)
{
    CameraMatrices m;
    m.viewFromWorld = viewFromWorld;
    m.clipFromView = clipFromView;
    m.clipFromWorld = clipFromView * viewFromWorld;
    m.znear = znear;
    m.zfar = zfar;
    return m;
}

}  // namespace

Result<CameraSpec> parseCameraSpec(const std::string& text)
{
    auto invalid = [&]() {
        return makeError(ExitCode::Usage,
                         "invalid --camera '{}': expected auto, gltf:N or orbit:AZ,EL,DIST "
                         "(DIST > 0)",
                         text);
    };
    CameraSpec spec;
    if (text == "auto") return spec;
    if (text.rfind("gltf:", 0) == 0) {
        spec.kind = CameraSpec::Kind::Gltf;
        if (!parseIndex(text.substr(5), spec.gltfIndex)) return invalid();
        return spec;
    }
    if (text.rfind("orbit:", 0) == 0) {
        spec.kind = CameraSpec::Kind::Orbit;
        std::string rest = text.substr(6);
        size_t c1 = rest.find(',');
        size_t c2 = c1 == std::string::npos ? c1 : rest.find(',', c1 + 1);
        if (c2 == std::string::npos) return invalid();
        bool ok = parseFloat(rest.substr(0, c1), spec.azimuthDeg) &&
                  parseFloat(rest.substr(c1 + 1, c2 - c1 - 1), spec.elevationDeg) &&
                  parseFloat(rest.substr(c2 + 1), spec.distance);
        if (!ok || !(spec.distance > 0.0f)) return invalid();
        return spec;
    }
    return invalid();
}

glm::mat4 perspectiveVulkan(float yfov, float aspect, float znear, float zfar)
{
    // View space looks down -z, so clip w = -z. Depth z_clip / w maps -znear -> 0 and -zfar -> 1;
    // y is negated because Vulkan's NDC y = -1 is the top row.
    float f = 1.0f / std::tan(0.5f * yfov);
    glm::mat4 m(0.0f);
    m[0][0] = f / aspect;
    m[1][1] = -f;
    m[2][3] = -1.0f;
    if (std::isinf(zfar)) {
        m[2][2] = -1.0f;
        m[3][2] = -znear;
    } else {
        m[2][2] = zfar / (znear - zfar);
        m[3][2] = znear * zfar / (znear - zfar);
    }
    return m;
}

glm::mat4 orthographicVulkan(float xmag, float ymag, float znear, float zfar)
{
    glm::mat4 m(0.0f);
    m[0][0] = 1.0f / xmag;
    m[1][1] = -1.0f / ymag;
    m[2][2] = -1.0f / (zfar - znear);
    m[3][2] = -znear / (zfar - znear);
    m[3][3] = 1.0f;
    return m;
}

Result<CameraMatrices> resolveCamera(const CameraSpec& spec, const Scene& scene, unsigned width,
                                     unsigned height)
{
    float aspect = height > 0 && width > 0 ? float(width) / float(height) : 1.0f;
    Sphere sphere = boundingSphere(scene);

    if (spec.kind == CameraSpec::Kind::Gltf) {
        if (spec.gltfIndex < 0 || size_t(spec.gltfIndex) >= scene.cameras.size()) {
            return makeError(ExitCode::Usage, "--camera gltf:{}: the scene has {} camera(s)", spec.gltfIndex,
                             scene.cameras.size());
        }
        const SceneCamera& cam = scene.cameras[size_t(spec.gltfIndex)];
        glm::mat4 viewFromWorld = glm::inverse(cam.worldFromView);
        float znear = cam.znear;
        float zfar = cam.zfar;
        if (!(zfar > znear)) {
            // Infinite far plane: stop just behind the farthest point of the scene's sphere.
            glm::vec3 eye(cam.worldFromView[3]);
            float reach = (glm::length(sphere.center - eye) + sphere.radius) * 1.01f;
            zfar = std::max(reach, znear * 2.0f + 1e-6f);
        }
        if (cam.perspective) {
            float camAspect = cam.aspectRatio > 0.0f ? cam.aspectRatio : aspect;
            return finish(viewFromWorld, perspectiveVulkan(cam.yfov, camAspect, znear, zfar), znear, zfar);
        }
        return finish(viewFromWorld, orthographicVulkan(cam.xmag, cam.ymag, znear, zfar), znear, zfar);
    }

    float azimuth = radians(spec.kind == CameraSpec::Kind::Orbit ? spec.azimuthDeg : 35.0f);
    float elevation = radians(spec.kind == CameraSpec::Kind::Orbit ? spec.elevationDeg : 25.0f);
    float dist = spec.distance;
    if (spec.kind == CameraSpec::Kind::Auto) {
        // The sphere touches the narrower of the two half-angles of the 45-degree frustum.
        float halfY = 0.5f * kDefaultYfov;
        float halfX = std::atan(std::tan(halfY) * aspect);
        dist = sphere.radius / std::sin(std::min(halfX, halfY));
    }

    // Camera basis from the angles directly (no lookAt), so straight up or down stays defined:
    // back = direction from the target to the eye, right = d(back)/d(azimuth), up = back x right.
    float ca = std::cos(azimuth), sa = std::sin(azimuth);
    float ce = std::cos(elevation), se = std::sin(elevation);
    glm::vec3 back(ce * sa, se, ce * ca);
    glm::vec3 right(ca, 0.0f, -sa);
    glm::vec3 up(-se * sa, ce, -se * ca);
    glm::vec3 eye = sphere.center + dist * back;
    glm::mat4 viewFromWorld(1.0f);
    for (int i = 0; i < 3; ++i) {
        viewFromWorld[i][0] = right[i];
        viewFromWorld[i][1] = up[i];
        viewFromWorld[i][2] = back[i];
    }
    viewFromWorld[3] = glm::vec4(-glm::dot(right, eye), -glm::dot(up, eye), -glm::dot(back, eye), 1.0f);
    float znear, zfar;
    encloseSphere(dist, sphere.radius, znear, zfar);
    return finish(viewFromWorld, perspectiveVulkan(kDefaultYfov, aspect, znear, zfar), znear, zfar);
}

}  // namespace sr
