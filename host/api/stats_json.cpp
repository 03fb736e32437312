// stats_json.cpp - JSON statistics through nlohmann::json.
#include "api/stats_json.h"

#include "io/file_write.h"
#include "settings/schema.h"

namespace sr {
nlohmann::json timingJson(const StageTiming& t)
{
    return {{"min", t.minMs}, {"median", t.medianMs}, {"max", t.maxMs}};
}

nlohmann::json stagesJson(const std::vector<StageTiming>& stages)
{
    nlohmann::json json = nlohmann::json::object();
    for (const StageTiming& t : stages) json[t.name] = timingJson(t);
    return json;
}

nlohmann::json statsJson(const RenderOutput& out, const RenderOptions& options, const std::string& scene)
{
    const RenderSettings settings = options.resolved();
    nlohmann::json clip = nlohmann::json::array();
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) clip.push_back(out.params.clipFromWorld[c][r]);
    const RenderStats& s = out.stats;
    nlohmann::json json = {
        {"backend", out.device.backend},
        {"device", out.device.name},
        {"driver", out.device.driver},
        {"scene", scene},
        {"resolution", {settings.width, settings.height}},
        {"msaa", settings.msaa},
        {"ssaa", settings.ssaa},
        {"clip_from_world", clip},
        {"triangles",
         {{"in", s.trianglesIn},
          {"culled", s.culled},
          {"clipped", s.clipped},
          {"invalid", s.invalid},
          {"points_in", s.pointsIn},
          {"points", s.points},
          {"rasterized", s.rasterized},
          {"small", s.smallTris},
          {"big", s.bigTris},
          {"records", s.records},
          {"pieces", s.pieces},
          {"bin_entries", s.binEntries}}},
        {"stages_ms", stagesJson(out.stages)},
        {"gpu_total_ms", timingJson(out.total)},
        {"peak_device_bytes", out.peakDeviceBytes},
        {"warmup", settings.warmup},
        {"repeat", settings.repeat},
        {"redraws", s.redraws},
        {"capacities",
         {{"records", s.capacities.records},
          {"pieces", s.capacities.pieces},
          {"bin_entries", s.capacities.binEntries}}},
    };
    json["settings"] = settingsJson(options);
    if (settings.tessellate != TESS_OFF) {
        json["tessellation"] = {{"mode", choiceName(setting("tessellate"), settings.tessellate)},
                                {"edge_px", settings.tessEdgePx},
                                {"max_level", settings.tessMaxLevel},
                                {"vertices", s.tessVertices},
                                {"triangles", s.tessTriangles},
                                {"culled", s.tessCulled}};
    }
    return json;
}

Status writeJson(const std::string& path, const nlohmann::json& json)
{
    const std::string text = json.dump(2) + "\n";
    return writeFileAtomically(path, text.data(), text.size());
}

}  // namespace sr
