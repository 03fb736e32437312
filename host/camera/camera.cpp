// camera.cpp - `--camera` parsing and the view and projection matrices (Vulkan conventions).
#include "camera/camera.h"

#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <vector>

namespace sr {
namespace {

constexpr float kPi = 3.14159265358979f;

float radians(float degrees)
{
    return degrees * kPi / 180.0f;
}

// Whole-string float parse: no trailing characters, finite. An underflow is the correctly rounded
// subnormal (or zero) strtof returns, so that every finite float orbitSpecString writes reads back.
bool parseFloat(const std::string& text, float& out)
{
    if (text.empty() || std::isspace(static_cast<unsigned char>(text.front()))) return false;
    errno = 0;
    char* end = nullptr;
    float value = std::strtof(text.c_str(), &end);
    const bool underflow = errno == ERANGE && std::fabs(value) <= FLT_MIN;
    if ((errno != 0 && !underflow) || end != text.c_str() + text.size() || !std::isfinite(value))
        return false;
    out = value;
    return true;
}

float aspectOf(unsigned width, unsigned height)
{
    return height > 0 && width > 0 ? float(width) / float(height) : 1.0f;
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

// Near and far planes for a bounding sphere whose centre lies `centerDepth` in front of the eye, enclosing
// it with 1% to spare. From inside the sphere the near plane cannot enclose it; it then sits at 1% of
// the distance to the target the camera looks at (at most 1/1000 of the radius), so nearby geometry
// stays visible in a scene much larger than the view.
void encloseSphere(float centerDepth, float lookDistance, float radius, float& znear, float& zfar)
{
    // Relative bounds only: a scene a billionth of a unit across is framed as one a unit across is.
    float minNear = std::min(radius * 1e-3f, lookDistance * 1e-2f);
    znear = std::max((centerDepth - radius) * 0.99f, minNear);
    zfar = std::max((centerDepth + radius) * 1.01f, znear * 2.0f);
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

// Splits at every comma (empty pieces kept, so "1,,2" has an empty middle piece).
std::vector<std::string> splitCommas(const std::string& text)
{
    std::vector<std::string> parts;
    size_t start = 0;
    for (size_t comma = text.find(','); comma != std::string::npos; comma = text.find(',', start)) {
        parts.push_back(text.substr(start, comma - start));
        start = comma + 1;
    }
    parts.push_back(text.substr(start));
    return parts;
}

// sin and cos of `degrees`, exact at quarter turns: the angle is reduced to the nearest multiple q of 90
// degrees and a remainder within +-45, whose sine and cosine (0 and 1 for a remainder of 0) are then
// turned by q quarters. sin(pi / 2) in floating point is 1 but cos(pi / 2) is 6e-17, not 0.
void sinCosDegrees(double degrees, double& s, double& c)
{
    const double turn = std::fmod(degrees, 360.0);  // exact
    const double quarters = std::nearbyint(turn / 90.0);
    const double r = (turn - 90.0 * quarters) * (3.14159265358979323846 / 180.0);
    const double s0 = std::sin(r), c0 = std::cos(r);
    switch ((int(quarters) % 4 + 4) % 4) {
    case 0: s = s0, c = c0; break;
    case 1: s = c0, c = -s0; break;  // sin(x + 90) = cos x, cos(x + 90) = -sin x
    case 2: s = -s0, c = -c0; break;
    default: s = -c0, c = s0; break;
    }
}

}  // namespace

Result<ModelTransform> parseModelSpec(const std::string& text)
{
    auto invalid = [&](const std::string& why) {
        return makeError(ExitCode::Usage, "invalid --model '{}': {}", text, why);
    };
    const std::string expected =
        "expected identity or translate:X,Y,Z,rotate:AX,AY,AZ,scale:S (each part optional, in this order)";
    ModelTransform model;
    if (text == "identity") return model;
    struct Part {
        const char* name;
        const char* takes;
        std::vector<float*> fields;
    };
    const Part parts[] = {
        {"translate", "three numbers X,Y,Z", {&model.translate.x, &model.translate.y, &model.translate.z}},
        {"rotate",
         "three angles AX,AY,AZ in degrees",
         {&model.rotateDeg.x, &model.rotateDeg.y, &model.rotateDeg.z}},
        {"scale", "one number S above 0", {&model.scale}}};
    // A part starts at a piece "NAME:NUMBER"; the pieces after it up to the next part are its numbers.
    const std::vector<std::string> pieces = splitCommas(text);
    size_t nextPart = 0;  // parts before this one are done: the order is T, R, S
    for (size_t i = 0; i < pieces.size();) {
        const size_t colon = pieces[i].find(':');
        if (colon == std::string::npos) return invalid(expected);
        const std::string name = pieces[i].substr(0, colon);
        size_t p = 0;
        while (p < 3 && name != parts[p].name) ++p;
        if (p == 3) return invalid("unknown part '" + name + "': " + expected);
        if (p < nextPart) return invalid("the parts go in the order translate, rotate, scale, each once");
        nextPart = p + 1;
        std::vector<std::string> numbers{pieces[i].substr(colon + 1)};
        for (++i; i < pieces.size() && pieces[i].find(':') == std::string::npos; ++i)
            numbers.push_back(pieces[i]);
        const Part& part = parts[p];
        if (numbers.size() != part.fields.size())
            return invalid(fmt::format("{} takes {}", part.name, part.takes));
        for (size_t k = 0; k < numbers.size(); ++k)
            if (!parseFloat(numbers[k], *part.fields[k]))
                return invalid(fmt::format("{} takes {}, not '{}'", part.name, part.takes, numbers[k]));
    }
    if (!(model.scale > 0.0f)) return invalid(fmt::format("scale takes {}", parts[2].takes));
    return model;
}

std::string modelSpecString(const ModelTransform& model)
{
    // fmt's shortest round-trip form, as orbitSpecString: parseModelSpec reads back the same floats.
    std::string text;
    auto add = [&](const std::string& part) { text += (text.empty() ? "" : ",") + part; };
    const glm::vec3& t = model.translate;
    const glm::vec3& r = model.rotateDeg;
    if (t != glm::vec3(0.0f)) add(fmt::format("translate:{},{},{}", t.x, t.y, t.z));
    if (r != glm::vec3(0.0f)) add(fmt::format("rotate:{},{},{}", r.x, r.y, r.z));
    if (model.scale != 1.0f) add(fmt::format("scale:{}", model.scale));
    return text.empty() ? "identity" : text;
}

glm::mat4 worldFromModel(const ModelTransform& model, const glm::vec3& center)
{
    // A = Rz Ry Rx S in double (glm: m[column][row]); each rotation turns counter-clockwise looking
    // down its axis, e.g. Ry maps +z to +x.
    double sx, cx, sy, cy, sz, cz;
    sinCosDegrees(model.rotateDeg.x, sx, cx);
    sinCosDegrees(model.rotateDeg.y, sy, cy);
    sinCosDegrees(model.rotateDeg.z, sz, cz);
    glm::dmat3 rx(1.0), ry(1.0), rz(1.0);
    rx[1][1] = cx, rx[2][1] = -sx, rx[1][2] = sx, rx[2][2] = cx;
    ry[0][0] = cy, ry[2][0] = sy, ry[0][2] = -sy, ry[2][2] = cy;
    rz[0][0] = cz, rz[1][0] = -sz, rz[0][1] = sz, rz[1][1] = cz;
    const glm::dmat3 a = rz * ry * rx * double(model.scale);
    // T(t) T(c) A T(-c) p = A p + (t + c - A c): for A = I the offset is t to the bit.
    const glm::dvec3 c(center);
    const glm::dvec3 offset = glm::dvec3(model.translate) + (c - a * c);
    glm::mat4 m(1.0f);
    for (int col = 0; col < 3; ++col) m[col] = glm::vec4(glm::vec3(a[col]), 0.0f);
    m[3] = glm::vec4(glm::vec3(offset), 1.0f);
    return m;
}

Result<CameraSpec> parseCameraSpec(const std::string& text)
{
    auto invalid = [&]() {
        return makeError(ExitCode::Usage,
                         "invalid --camera '{}': expected auto, gltf:N or orbit:AZ,EL,DIST[,TX,TY,TZ] "
                         "(DIST > 0: scene units, or Nr for N bounding radii)",
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
        std::vector<std::string> parts = splitCommas(text.substr(6));
        if (parts.size() != 3 && parts.size() != 6) return invalid();
        OrbitPose& pose = spec.orbit;
        float* fields[] = {&pose.azimuthDeg,     &pose.elevationDeg,   &pose.distance,
                           &pose.targetOffset.x, &pose.targetOffset.y, &pose.targetOffset.z};
        if (!parts[2].empty() && parts[2].back() == 'r') {
            spec.distanceInRadii = true;
            parts[2].pop_back();
        }
        for (size_t i = 0; i < parts.size(); ++i)
            if (!parseFloat(parts[i], *fields[i])) return invalid();
        if (!(pose.distance > 0.0f)) return invalid();
        return spec;
    }
    return invalid();
}

std::string orbitSpecString(const OrbitPose& pose)
{
    // fmt writes a float in the shortest form that reads back as the same float (strtof, as
    // parseCameraSpec reads it), so the spec round-trips exactly without trailing noise digits.
    std::string text = fmt::format("orbit:{},{},{}", pose.azimuthDeg, pose.elevationDeg, pose.distance);
    if (pose.targetOffset != glm::vec3(0.0f))
        text += fmt::format(",{},{},{}", pose.targetOffset.x, pose.targetOffset.y, pose.targetOffset.z);
    return text;
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
        // znear * zfar leaves float's normal range for depths past 1.8e19 or under 1.1e-19; the quotient
        // does not, in double.
        const float product = znear * zfar;
        m[3][2] = std::isnormal(product) ? product / (znear - zfar)
                                         : float(double(znear) * zfar / (double(znear) - zfar));
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

CameraMatrices withModel(const CameraMatrices& camera, const ModelTransform& model, const glm::vec3& center)
{
    if (model.isIdentity()) return camera;
    return finish(camera.viewFromWorld * worldFromModel(model, center), camera.clipFromView, camera.znear,
                  camera.zfar);
}

OrbitPose orbitPoseOf(const CameraSpec& spec, const BoundingSphere& sphere)
{
    OrbitPose pose = spec.orbit;
    if (spec.distanceInRadii) pose.distance *= sphere.radius;
    return pose;
}

std::string resolvedCameraSpec(const CameraSpec& spec, const Scene& scene, unsigned width, unsigned height)
{
    switch (spec.kind) {
    case CameraSpec::Kind::Gltf: return fmt::format("gltf:{}", spec.gltfIndex);
    case CameraSpec::Kind::Orbit: return orbitSpecString(orbitPoseOf(spec, boundingSphere(scene)));
    case CameraSpec::Kind::Auto: break;
    }
    return orbitSpecString(autoOrbitPose(boundingSphere(scene), width, height));
}

double windingNumber(const Scene& scene, const glm::vec3& point)
{
    // Van Oosterom and Strackee's solid angle of each triangle seen from the point, in double.
    double sum = 0.0;
    for (size_t t = 0; t + 2 < scene.indices.size(); t += 3) {
        const glm::dvec3 a = glm::dvec3(glm::vec3(scene.positions[scene.indices[t]])) - glm::dvec3(point);
        const glm::dvec3 b = glm::dvec3(glm::vec3(scene.positions[scene.indices[t + 1]])) - glm::dvec3(point);
        const glm::dvec3 c = glm::dvec3(glm::vec3(scene.positions[scene.indices[t + 2]])) - glm::dvec3(point);
        const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
        const double det = glm::dot(a, glm::cross(b, c));
        const double div = la * lb * lc + glm::dot(a, b) * lc + glm::dot(b, c) * la + glm::dot(c, a) * lb;
        sum += 2.0 * std::atan2(det, div);
    }
    return sum / (4.0 * 3.14159265358979323846);
}

bool eyeInsideScene(const Scene& scene, const CameraMatrices& camera)
{
    const glm::vec3 eye(glm::inverse(camera.viewFromWorld)[3]);
    if (glm::any(glm::lessThan(eye, scene.boundsMin)) || glm::any(glm::greaterThan(eye, scene.boundsMax)))
        return false;
    return windingNumber(scene, eye) > 0.5;
}

namespace {

// Scenes a camera in float can frame. The smallest: a thousand times float's smallest normal value
// (1.2e-38) is still far from the denormals a GPU may flush to zero in the products the transforms
// take; 1e-30 across leaves room for them. The largest: every corner of the bounds transformed to clip
// space within a quarter of float's range (the clip tests add up to twice w and x).
constexpr double kSmallestScene = 1e-30;

Status checkFramable(const CameraMatrices& m, const Scene& scene)
{
    const glm::dvec3 lo(scene.boundsMin), hi(scene.boundsMax);
    const double extent = glm::length(hi - lo);
    if (extent > 0.0 && extent < kSmallestScene)
        return makeError(ExitCode::Usage,
                         "the scene is {:.3g} units across, too small for a camera in float to frame (at "
                         "least {:.0g}): scale its coordinates up",
                         extent, kSmallestScene);
    bool finiteMatrix = true;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) finiteMatrix = finiteMatrix && std::isfinite(m.clipFromWorld[i][j]);
    const glm::dmat4 clip(m.clipFromWorld);
    for (int k = 0; k < 8; ++k) {
        const glm::dvec4 corner(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z, 1.0);
        const glm::dvec4 c = clip * corner;
        const double largest = std::max({std::abs(c.x), std::abs(c.y), std::abs(c.z), std::abs(c.w)});
        if (!finiteMatrix || !std::isfinite(largest) || largest > 0.25 * FLT_MAX)
            return makeError(ExitCode::Usage,
                             "the scene's bounds reach {:.3g} units, too far for a camera in float to "
                             "transform them (at most about 1e37 from the origin): scale its coordinates "
                             "down",
                             std::max(glm::length(lo), glm::length(hi)));
    }
    return okStatus();
}

Result<CameraMatrices> resolveCameraMatrices(const CameraSpec& spec, const Scene& scene, unsigned width,
                                             unsigned height, const ModelTransform& model)
{
    float aspect = aspectOf(width, height);
    BoundingSphere sphere = boundingSphere(scene);
    const BoundingSphere moved = movedSphere(sphere, model);

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
            // Infinite far plane: stop just behind the farthest point of the (moved) scene's sphere.
            glm::vec3 eye(cam.worldFromView[3]);
            float reach = (glm::length(moved.center - eye) + moved.radius) * 1.01f;
            zfar = std::max(reach, znear * 2.0f + 1e-6f);
        }
        const glm::mat4 clipFromView =
            cam.perspective
                ? perspectiveVulkan(cam.yfov, cam.aspectRatio > 0.0f ? cam.aspectRatio : aspect, znear, zfar)
                : orthographicVulkan(cam.xmag, cam.ymag, znear, zfar);
        return withModel(finish(viewFromWorld, clipFromView, znear, zfar), model, sphere.center);
    }

    if (spec.kind == CameraSpec::Kind::Orbit)
        return orbitCameraMatrices(orbitPoseOf(spec, sphere), sphere, width, height, model);
    return orbitCameraMatrices(autoOrbitPose(sphere, width, height), sphere, width, height, model);
}

}  // namespace

Result<CameraMatrices> resolveCamera(const CameraSpec& spec, const Scene& scene, unsigned width,
                                     unsigned height, const ModelTransform& model)
{
    auto m = resolveCameraMatrices(spec, scene, width, height, model);
    if (!m) return m;
    SR_TRY(checkFramable(*m, scene));
    return m;
}

BoundingSphere boundingSphere(const Scene& scene)
{
    glm::vec3 center = 0.5f * (scene.boundsMin + scene.boundsMax);
    float radius = 0.5f * glm::length(scene.boundsMax - scene.boundsMin);
    const float largest = std::max(glm::length(scene.boundsMin), glm::length(scene.boundsMax));
    if (!(radius > 1e-18f && radius < 1e18f && largest < 1e18f)) {
        // Past the range whose squares float holds (the length underflows to 0 or overflows): the
        // centre and the half-diagonal in double.
        const glm::dvec3 lo(scene.boundsMin), hi(scene.boundsMax);
        center = glm::vec3(0.5 * (lo + hi));
        radius = float(std::min(0.5 * glm::length(hi - lo), double(FLT_MAX)));
    }
    // No smaller than a few float steps at the centre, which no camera could resolve, and no absolute
    // floor (a scene a billionth of a unit across is framed as one a unit across is); a scene of one
    // point (radius 0) gets a millionth of its distance from the origin, or of a unit at the origin.
    const float distance = float(glm::length(glm::dvec3(center)));
    const float floor = radius > 0.0f ? distance * 1e-6f : std::max(distance, 1.0f) * 1e-6f;
    return {center, std::max(radius, floor)};
}

BoundingSphere movedSphere(const BoundingSphere& sphere, const ModelTransform& model)
{
    return {sphere.center + model.translate, sphere.radius * model.scale};
}

OrbitPose autoOrbitPose(const BoundingSphere& sphere, unsigned width, unsigned height)
{
    // The sphere touches the narrower of the two half-angles of the 45-degree frustum.
    float halfY = 0.5f * kOrbitYfov;
    float halfX = std::atan(std::tan(halfY) * aspectOf(width, height));
    OrbitPose pose;
    pose.distance = sphere.radius / std::sin(std::min(halfX, halfY));
    return pose;
}

OrbitBasis orbitBasis(const OrbitPose& pose)
{
    float azimuth = radians(pose.azimuthDeg);
    float elevation = radians(pose.elevationDeg);
    // From the angles directly (no lookAt), so straight up or down stays defined.
    float ca = std::cos(azimuth), sa = std::sin(azimuth);
    float ce = std::cos(elevation), se = std::sin(elevation);
    return {glm::vec3(ca, 0.0f, -sa), glm::vec3(-se * sa, ce, -se * ca), glm::vec3(ce * sa, se, ce * ca)};
}

CameraMatrices orbitCameraMatrices(const OrbitPose& pose, const BoundingSphere& sphere, unsigned width,
                                   unsigned height, const ModelTransform& model)
{
    const float dist = pose.distance;
    const auto [right, up, back] = orbitBasis(pose);
    glm::vec3 eye = (sphere.center + pose.targetOffset) + dist * back;
    glm::mat4 viewFromWorld(1.0f);
    for (int i = 0; i < 3; ++i) {
        viewFromWorld[i][0] = right[i];
        viewFromWorld[i][1] = up[i];
        viewFromWorld[i][2] = back[i];
    }
    viewFromWorld[3] = glm::vec4(-glm::dot(right, eye), -glm::dot(up, eye), -glm::dot(back, eye), 1.0f);
    // The moved sphere's centre c + translate lies dist + (offset - translate) . back in front of the eye
    // at c + offset + dist back (exactly dist without an offset or translation, so the depth range of an
    // unpanned camera does not depend on rounding); its radius is the scene's times the model's scale.
    const BoundingSphere moved = movedSphere(sphere, model);
    float centerDepth = dist + glm::dot(pose.targetOffset - model.translate, back);
    float znear, zfar;
    encloseSphere(centerDepth, dist, moved.radius, znear, zfar);
    return withModel(finish(viewFromWorld,
                            perspectiveVulkan(kOrbitYfov, aspectOf(width, height), znear, zfar), znear, zfar),
                     model, sphere.center);
}

}  // namespace sr
