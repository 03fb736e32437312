// stats_json.h - the JSON statistics written by `raster render --stats`.
#ifndef RASTER_STATS_JSON_H
#define RASTER_STATS_JSON_H

#include <string>

#include <nlohmann/json.hpp>

#include "render/renderer.h"
#include "settings/render_settings.h"

namespace sr {

// {"min", "median", "max"} of one stage, and an object of every stage by name.
nlohmann::json timingJson(const StageTiming& t);
nlohmann::json stagesJson(const std::vector<StageTiming>& stages);

// The camera a frame was drawn with: its spec as given, the view and projection matrices (column-major),
// the eye's world position, the depth range, and `resolved` (the spec in absolute scene units,
// resolvedCameraSpec) where not empty.
nlohmann::json cameraJson(const CameraMatrices& camera, const std::string& spec, const std::string& resolved);

// backend, device, driver, resolution, clip_from_world (column-major), the camera (cameraJson),
// triangle counts (null where the backend does not count them: RenderStats::pipelineCounts), per-stage
// GPU ms (min/median/max over the timed runs), total GPU ms, peak device memory, and under "settings"
// every setting of the schema as the render was asked for (settingsJson): the scene and "settings" are a
// `raster render` that reproduces the frame (renderArguments).
nlohmann::json statsJson(const RenderOutput& out, const RenderOptions& options, const std::string& scene,
                         const std::string& resolvedCamera = "");
Status writeJson(const std::string& path, const nlohmann::json& json);

}  // namespace sr

#endif  // RASTER_STATS_JSON_H
