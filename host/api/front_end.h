// front_end.h - the warnings a view earns before it is drawn (a texture view of an untextured scene, an
// eye inside the geometry), which the library's Session gives with every frame. Not installed.
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

}  // namespace sr

#endif  // RASTER_FRONT_END_H
