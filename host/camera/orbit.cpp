// orbit.cpp - the viewer's orbit camera: drag, pan and zoom as changes of an OrbitPose.
#include "camera/orbit.h"

#include <algorithm>
#include <cmath>

namespace sr {

OrbitCamera::OrbitCamera(const Scene& scene, unsigned width, unsigned height) : sphere_(boundingSphere(scene))
{
    reset(width, height);
}

Result<OrbitCamera> OrbitCamera::fromSpec(const CameraSpec& spec, const Scene& scene, unsigned width,
                                          unsigned height)
{
    switch (spec.kind) {
    case CameraSpec::Kind::Auto: return OrbitCamera(scene, width, height);
    case CameraSpec::Kind::Orbit: {
        const BoundingSphere sphere = boundingSphere(scene);
        return OrbitCamera(sphere, orbitPoseOf(spec, sphere));
    }
    case CameraSpec::Kind::Gltf: break;
    }
    return makeError(ExitCode::Usage,
                     "--camera gltf:{} is not an orbit camera: use auto or orbit:AZ,EL,DIST[,TX,TY,TZ]",
                     spec.gltfIndex);
}

void OrbitCamera::orbit(float dxPixels, float dyPixels)
{
    if (!std::isfinite(dxPixels) || !std::isfinite(dyPixels)) return;
    // remainder() is exact, so an azimuth already in range keeps its bits.
    pose_.azimuthDeg = std::remainder(pose_.azimuthDeg - dxPixels * kOrbitDegreesPerPixel, 360.0f);
    pose_.elevationDeg = std::clamp(pose_.elevationDeg + dyPixels * kOrbitDegreesPerPixel, -kMaxElevationDeg,
                                    kMaxElevationDeg);
}

void OrbitCamera::pan(float dxPixels, float dyPixels, unsigned viewportHeight)
{
    if (!std::isfinite(dxPixels) || !std::isfinite(dyPixels) || viewportHeight == 0) return;
    // The view plane through the target is 2 d tan(fov / 2) world units tall; moving the target against
    // the cursor by that over the viewport's height per pixel keeps the point under it there.
    float worldPerPixel = 2.0f * pose_.distance * std::tan(0.5f * kOrbitYfov) / float(viewportHeight);
    OrbitBasis basis = orbitBasis(pose_);
    pose_.targetOffset += worldPerPixel * (dyPixels * basis.up - dxPixels * basis.right);
}

void OrbitCamera::zoom(float steps)
{
    if (!std::isfinite(steps) || steps == 0.0f) return;
    const float lo = sphere_.radius * kMinDistanceRadii;
    const float hi = sphere_.radius * kMaxDistanceRadii;
    const float d = pose_.distance;
    float next = float(double(d) * std::pow(double(kZoomFactorPerStep), double(steps)));
    pose_.distance = steps > 0.0f ? std::max(next, std::min(lo, d)) : std::min(next, std::max(hi, d));
}

void OrbitCamera::reset(unsigned width, unsigned height)
{
    pose_ = autoOrbitPose(sphere_, width, height);
}

CameraMatrices OrbitCamera::matrices(unsigned width, unsigned height, const ModelTransform& model) const
{
    return orbitCameraMatrices(pose_, sphere_, width, height, model);
}

}  // namespace sr
