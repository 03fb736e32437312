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

// backend, device, driver, resolution, clip_from_world (column-major), triangle counts, per-stage GPU
// ms (min/median/max over the timed runs), total GPU ms, peak device memory, and under "settings" every
// setting of the schema as the render was asked for (settingsJson).
nlohmann::json statsJson(const RenderOutput& out, const RenderOptions& options, const std::string& scene);
Status writeJson(const std::string& path, const nlohmann::json& json);

}  // namespace sr

#endif  // RASTER_STATS_JSON_H
