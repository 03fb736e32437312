// camera.h - camera choice (`--camera auto|gltf:N|orbit:AZ,EL,DIST`) and the matrices it yields.
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

struct CameraSpec {
    enum class Kind { Auto, Gltf, Orbit };
    Kind kind = Kind::Auto;
    int gltfIndex = 0;           // Kind::Gltf: index into Scene::cameras
    float azimuthDeg = 35.0f;    // Kind::Orbit: rotation about +y, 0 = looking along -z
    float elevationDeg = 25.0f;  // Kind::Orbit: angle above the horizontal plane
    float distance = 0.0f;       // Kind::Orbit: from the centre of the scene bounds, scene units
};

// Parses "auto", "gltf:N" or "orbit:AZ,EL,DIST"; a malformed spec is a one-line error.
Result<CameraSpec> parseCameraSpec(const std::string& text);

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

// Resolves the spec against the scene: auto frames the bounds from the default orbit angles, orbit
// looks at the bounds centre, gltf:N uses the scene's camera N (error if it does not exist). Near and
// far planes enclose the scene bounds.
Result<CameraMatrices> resolveCamera(const CameraSpec& spec, const Scene& scene, unsigned width,
                                     unsigned height);

}  // namespace sr

#endif  // RASTER_CAMERA_H
