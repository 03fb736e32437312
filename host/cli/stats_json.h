// stats_json.h - the JSON statistics written by `raster render --stats`.
#ifndef RASTER_STATS_JSON_H
#define RASTER_STATS_JSON_H

#include <string>

#include <nlohmann/json.hpp>

#include "render/renderer.h"

namespace sr {

// backend, device, driver, resolution, clip_from_world (column-major), triangle counts, per-stage GPU
// ms (min/median/max over the timed runs), total GPU ms, peak device memory and run settings.
// {"min", "median", "max"} of one stage, and an object of every stage by name.
nlohmann::json timingJson(const StageTiming& t);
nlohmann::json stagesJson(const std::vector<StageTiming>& stages);

nlohmann::json statsJson(const RenderOutput& out, const RenderSettings& settings, const std::string& scene);
Status writeJson(const std::string& path, const nlohmann::json& json);

}  // namespace sr

#endif  // RASTER_STATS_JSON_H
