// camera.h - camera choice (`--camera auto|gltf:N|orbit:AZ,EL,DIST[,TX,TY,TZ]`), the model transform
// (`--model translate:X,Y,Z,rotate:AX,AY,AZ,scale:S`) and the matrices they yield, and the orbit camera
// model that the auto camera, `--camera orbit:...`, turntables and `raster view` share.
//
// All projections follow Vulkan's clip conventions: depth 0..1 (near -> 0), and NDC y = -1 is the
// top row of the image, so clipFromView flips y relative to OpenGL.
#ifndef RASTER_CAMERA_H
#define RASTER_CAMERA_H

#include <string>

#include <glm/glm.hpp>

#include "base/result.h"
#include "scene/scene.h"

namespace sr {

// The auto camera's angles: a three-quarter view from above.
constexpr float kAutoAzimuthDeg = 35.0f;
constexpr float kAutoElevationDeg = 25.0f;
// Vertical field of view of the auto and orbit cameras, radians (45 degrees).
constexpr float kOrbitYfov = 45.0f * 3.14159265358979f / 180.0f;

// Where an orbit camera stands. It looks at its target, the centre of the scene bounds plus
// targetOffset, from `distance` away, with no roll: its right vector stays horizontal.
struct OrbitPose {
    float azimuthDeg = kAutoAzimuthDeg;      // rotation about +y, 0 = looking along -z
    float elevationDeg = kAutoElevationDeg;  // angle above the horizontal plane
    float distance = 0.0f;                   // from the target, scene units
    glm::vec3 targetOffset{0.0f};            // the target's offset from the centre of the bounds, world units
};

struct CameraSpec {
    enum class Kind { Auto, Gltf, Orbit };
    Kind kind = Kind::Auto;
    int gltfIndex = 0;  // Kind::Gltf: index into Scene::cameras
    OrbitPose orbit;    // Kind::Orbit
    // Kind::Orbit with DIST written "Nr" ("orbit:30,20,2.5r"): orbit.distance is N bounding-sphere radii
    // of the scene, not scene units, so one spec frames models of any size (orbitPoseOf resolves it).
    bool distanceInRadii = false;
};

// Parses "auto", "gltf:N" or "orbit:AZ,EL,DIST[,TX,TY,TZ]" (DIST in scene units, or "Nr": N bounding
// radii; TX,TY,TZ: OrbitPose::targetOffset in scene units, zero when left out); a malformed spec is a
// one-line error.
Result<CameraSpec> parseCameraSpec(const std::string& text);

// The spec of `pose`, "orbit:AZ,EL,DIST" with ",TX,TY,TZ" when the offset is not zero, each number in
// the fewest digits that parseCameraSpec reads back as the same float, so the spec reproduces the
// camera bit for bit.
std::string orbitSpecString(const OrbitPose& pose);

// The model transform: the whole scene moved as one rigid body and scaled uniformly, before the camera
// looks at it. A point p of the scene (its world space as loaded) is drawn at
//
//     M p,   M = T(translate) * T(c) * Rz(AZ) * Ry(AY) * Rx(AX) * S(scale) * T(-c)
//
// where c is the centre of the scene's bounds (BoundingSphere::center, the orbit camera's target): the
// scene is scaled about its centre, turned about the world x, then y, then z axis through its centre
// (right-handed: counter-clockwise looking down the axis towards the centre), then moved by `translate`
// in world units. Turning and scaling about the centre keep the model where the camera looks; about the
// origin, a scene far from it would swing out of view. The scale is uniform and positive, so M keeps
// the winding (culling) and normals need only the inverse transpose the pipeline already takes.
//
// The cameras frame the scene as loaded: auto, orbit targets and the viewer's reset do not follow the
// model (moving the model never moves the camera); only the depth range encloses the moved scene.
struct ModelTransform {
    glm::vec3 translate{0.0f};  // world units
    glm::vec3 rotateDeg{0.0f};  // AX, AY, AZ: degrees about the world x, y and z axes through c
    float scale = 1.0f;         // > 0

    bool isIdentity() const
    {
        return translate == glm::vec3(0.0f) && rotateDeg == glm::vec3(0.0f) && scale == 1.0f;
    }
};

// Parses "identity" or "translate:X,Y,Z,rotate:AX,AY,AZ,scale:S", each part optional but in this order
// (the order of the product T * R * S) and the numbers finite, S > 0; a malformed spec is a one-line
// error naming what is wrong.
Result<ModelTransform> parseModelSpec(const std::string& text);
// The spec of `model`: "identity", or its parts that are not the identity, each number in the fewest
// digits that parseModelSpec reads back as the same float (exact, as orbitSpecString).
std::string modelSpecString(const ModelTransform& model);
// M of the comment above for the centre `center`. Exact for what is exact in the maths: quarter turns
// have sines and cosines of exactly 0 and +-1, a translation alone is T(translate) to the bit.
glm::mat4 worldFromModel(const ModelTransform& model, const glm::vec3& center);

struct CameraMatrices {
    glm::mat4 viewFromWorld{1.0f};
    glm::mat4 clipFromView{1.0f};
    glm::mat4 clipFromWorld{1.0f};
    float znear = 0.0f;  // view-space distances of the depth range actually used
    float zfar = 0.0f;
};

// Vulkan-convention projections (right-handed view space looking down -z).
glm::mat4 perspectiveVulkan(float yfov, float aspect, float znear, float zfar);
glm::mat4 orthographicVulkan(float xmag, float ymag, float znear, float zfar);

// The sphere around the scene bounds that the orbit cameras frame and their depth range encloses; a
// point-sized scene still gets a usable radius.
struct BoundingSphere {
    glm::vec3 center{0.0f};
    float radius = 1.0f;
};
BoundingSphere boundingSphere(const Scene& scene);
// The bounding sphere of the scene moved by `model` (`sphere` is the scene's): rotation about the centre
// keeps it, the scale scales its radius and the translation moves its centre.
BoundingSphere movedSphere(const BoundingSphere& sphere, const ModelTransform& model);

// The auto camera: kAuto* angles, no offset, and the distance at which the bounding sphere touches the
// narrower half-angle of the 45-degree frustum of a width x height image.
OrbitPose autoOrbitPose(const BoundingSphere& sphere, unsigned width, unsigned height);

// An orbit camera's orthonormal basis in world space: back points from the target to the eye, right is
// horizontal (the derivative of back by the azimuth), up = back x right.
struct OrbitBasis {
    glm::vec3 right, up, back;
};
OrbitBasis orbitBasis(const OrbitPose& pose);

// The matrices of an orbit camera for a width x height image: 45-degree vertical field of view, near
// and far planes enclosing the bounding sphere. With a model transform, the camera still stands where
// `pose` and the scene's `sphere` put it; viewFromWorld is V * worldFromModel(model, sphere.center) and
// the depth range encloses the moved sphere (movedSphere). The identity gives V itself, bit for bit.
CameraMatrices orbitCameraMatrices(const OrbitPose& pose, const BoundingSphere& sphere, unsigned width,
                                   unsigned height, const ModelTransform& model = {});

// `camera` looking at the scene moved by `model` about `center`: viewFromWorld and clipFromWorld times
// worldFromModel, the projection and depth range the camera's own (a glTF camera's planes, explicit
// matrices). The identity returns `camera` unchanged.
CameraMatrices withModel(const CameraMatrices& camera, const ModelTransform& model, const glm::vec3& center);

// The pose of an orbit spec around `sphere`: its own, with a distance in radii multiplied by the radius.
OrbitPose orbitPoseOf(const CameraSpec& spec, const BoundingSphere& sphere);

// The spec that gives the same camera in absolute terms: auto and orbit specs as the exact
// orbitSpecString of their pose in scene units (the auto pose for a width x height image, a distance in
// radii resolved), gltf:N unchanged.
std::string resolvedCameraSpec(const CameraSpec& spec, const Scene& scene, unsigned width, unsigned height);

// The generalized winding number of the scene's triangles around `point` (Jacobson, Kavan and
// Sorkine-Hornung 2013: the signed solid angle they subtend, over 4 pi): 1 inside a closed mesh whose
// triangles face outwards, 0 outside it, in between near holes; -1 inside a room whose walls face in.
double windingNumber(const Scene& scene, const glm::vec3& point);

// Whether the camera's eye is inside the scene's geometry, where every view direction meets the inside
// of a surface (back faces: culled, or an image of the wrong side): the eye inside the bounds and the
// winding number around it above 1/2. The box test first, so a camera outside costs nothing; inside
// it, one pass over the triangles.
bool eyeInsideScene(const Scene& scene, const CameraMatrices& camera);

// Resolves the spec against the scene moved by `model`: auto is autoOrbitPose, orbit its pose (both
// through orbitCameraMatrices; auto frames the scene as loaded), gltf:N the scene's camera N (error if
// it does not exist) through withModel. Near and far planes enclose the (moved) scene bounds, except a
// glTF camera's finite ones.
Result<CameraMatrices> resolveCamera(const CameraSpec& spec, const Scene& scene, unsigned width,
                                     unsigned height, const ModelTransform& model = {});

}  // namespace sr

#endif  // RASTER_CAMERA_H
