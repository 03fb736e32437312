// orbit.h - the orbit camera of the viewer, turntables and batch: the course projects' orbit camera, on
// exactly the model of `--camera orbit:AZ,EL,DIST[,TX,TY,TZ]` (scene/camera.h), so that any view the
// viewer shows is one `raster render --camera` spec away (specString) and renders bit-identically there.
#ifndef RASTER_ORBIT_H
#define RASTER_ORBIT_H

#include <string>

#include "base/result.h"
#include "camera/camera.h"
#include "scene/scene.h"

namespace sr {

// Degrees of azimuth and elevation per pixel of a left drag: a drag across a 1440-pixel window turns the
// scene once around.
constexpr float kOrbitDegreesPerPixel = 0.25f;
// Elevation stays within +-89 degrees: at +-90 the view direction is vertical and the next step across
// would turn the image upside down.
constexpr float kMaxElevationDeg = 89.0f;
// Distance factor per wheel step towards the target: multiplicative, so a step feels the same close up
// and far away.
constexpr float kZoomFactorPerStep = 0.9f;
// Zoom keeps the distance within these multiples of the bounding sphere's radius: closer, the near plane
// (1/1000 of the radius) clips what is looked at; farther, the scene is a few pixels.
constexpr float kMinDistanceRadii = 0.01f;
constexpr float kMaxDistanceRadii = 1000.0f;

class OrbitCamera {
public:
    // A camera on a unit sphere at the origin, looking from the auto angles; for default-constructed
    // holders (ViewerState) that are given a real one before use.
    OrbitCamera() = default;
    // The auto camera of `scene` for a width x height image (resolveCamera's Kind::Auto), which is also
    // where reset() returns.
    OrbitCamera(const Scene& scene, unsigned width, unsigned height);

    // The camera a `--camera` spec describes: auto or orbit (its pose, target offset included); gltf:N
    // is a usage error, since a glTF camera is no orbit.
    static Result<OrbitCamera> fromSpec(const CameraSpec& spec, const Scene& scene, unsigned width,
                                        unsigned height);

    // Left drag by (dx, dy) window pixels (y down): the scene turns with the cursor, so dragging right
    // decreases the azimuth (the eye moves left around the target) and dragging down raises the
    // elevation, clamped to +-kMaxElevationDeg; the azimuth is kept within [-180, 180].
    void orbit(float dxPixels, float dyPixels);
    // Right or middle drag by (dx, dy) window pixels in a view `viewportHeight` pixels tall: the target
    // moves in the view plane so that a point at the target's depth stays under the cursor.
    void pan(float dxPixels, float dyPixels, unsigned viewportHeight);
    // Wheel: `steps` towards the target (negative: away), the distance multiplied by
    // kZoomFactorPerStep^steps and kept within kMin/MaxDistanceRadii of the bounding sphere's radius (a
    // distance already outside that range, from a --camera spec, is not pulled in).
    void zoom(float steps);
    // Back to the auto camera for a width x height image: its angles and distance, no target offset.
    void reset(unsigned width, unsigned height);

    const OrbitPose& pose() const { return pose_; }
    void setPose(const OrbitPose& pose) { pose_ = pose; }
    const BoundingSphere& sphere() const { return sphere_; }

    // The matrices for a width x height image, looking at the scene moved by `model`:
    // orbitCameraMatrices, the very function resolveCamera uses for `--camera orbit:...` and `--model`,
    // so the same numbers give the same bits.
    CameraMatrices matrices(unsigned width, unsigned height, const ModelTransform& model = {}) const;
    // `--camera` spec of the current pose (orbitSpecString), exact: parsing it gives the same floats.
    std::string specString() const { return orbitSpecString(pose_); }

private:
    OrbitCamera(const BoundingSphere& sphere, const OrbitPose& pose) : sphere_(sphere), pose_(pose) {}

    BoundingSphere sphere_;
    OrbitPose pose_{kAutoAzimuthDeg, kAutoElevationDeg, 3.0f, glm::vec3(0.0f)};
};

}  // namespace sr

#endif  // RASTER_ORBIT_H
