// front_end.h - what a frame's front ends share above the pipeline: the warnings a view earns before it is
// drawn, and the camera its statistics name. The library's Session uses them for every frame, and so
// does the batch runner. Not installed.
#ifndef RASTER_FRONT_END_H
#define RASTER_FRONT_END_H

#include <string>
#include <vector>

#include "camera/camera.h"
#include "scene/scene.h"
#include "settings/render_settings.h"

namespace sr {

// What would make a render of `scene` from `camera` with `settings` a plain image without the user
// knowing why, one line each (without the "warning: " prefix): a texture debug view (shading texcoord
// or mip) of a scene without textures, and an eye inside the scene's geometry (eyeInsideScene).
std::vector<std::string> viewWarnings(const Scene& scene, const CameraMatrices& camera,
                                      const RenderSettings& settings);

// The frame's camera spec in absolute scene units for its statistics (resolvedCameraSpec); "" for a
// study scene under the auto camera, which renders with the study's own camera (the matrices say which).
std::string absoluteCamera(const RenderOptions& options, const Scene& scene, const std::string& sceneName);

}  // namespace sr

#endif  // RASTER_FRONT_END_H
