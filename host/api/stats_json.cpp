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

namespace {

// A matrix as 16 numbers, column-major (glm's and Vulkan's order).
nlohmann::json matrixJson(const glm::mat4& m)
{
    nlohmann::json a = nlohmann::json::array();
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) a.push_back(m[c][r]);
    return a;
}

}  // namespace

nlohmann::json cameraJson(const CameraMatrices& camera, const std::string& spec, const std::string& resolved)
{
    const glm::vec3 eye(glm::inverse(camera.viewFromWorld)[3]);
    nlohmann::json json = {{"spec", spec},
                           {"view_from_world", matrixJson(camera.viewFromWorld)},
                           {"clip_from_view", matrixJson(camera.clipFromView)},
                           {"eye", {eye.x, eye.y, eye.z}},
                           {"znear", camera.znear},
                           {"zfar", camera.zfar}};
    if (!resolved.empty()) json["resolved_spec"] = resolved;
    return json;
}

nlohmann::json statsJson(const RenderOutput& out, const RenderOptions& options, const std::string& scene,
                         const std::string& resolvedCamera)
{
    const RenderSettings settings = options.resolved();
    const RenderStats& s = out.stats;
    // Counts the backend did not measure are null (vulkan-graphics: RenderStats::pipelineCounts).
    auto counted = [&](uint64_t v) { return s.pipelineCounts ? nlohmann::json(v) : nlohmann::json(nullptr); };
    nlohmann::json json = {
        {"backend", out.device.backend},
        {"device", out.device.name},
        {"driver", out.device.driver},
        {"scene", scene},
        {"resolution", {settings.width, settings.height}},
        {"msaa", settings.msaa},
        {"ssaa", settings.ssaa},
        {"clip_from_world", matrixJson(out.params.clipFromWorld)},
        {"camera", cameraJson(out.camera, options.camera, resolvedCamera)},
        {"triangles",
         {{"in", s.trianglesIn},
          {"culled", counted(s.culled)},
          {"clipped", counted(s.clipped)},
          {"invalid", counted(s.invalid)},
          {"lines_in", s.linesIn},
          {"lines", counted(s.lines)},
          {"points_in", s.pointsIn},
          {"points", counted(s.points)},
          {"rasterized", counted(s.rasterized)},
          {"small", counted(s.smallTris)},
          {"big", counted(s.bigTris)},
          {"records", counted(s.records)},
          {"pieces", counted(s.pieces)},
          {"bin_entries", counted(s.binEntries)}}},
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
    if (s.clusters > 0) json["clusters"] = {{"count", s.clusters}, {"culled", s.clustersCulled}};
    if (s.lodSceneTriangles > 0)
        json["lod"] = {{"triangles", s.lodTriangles},
                       {"scene_triangles", s.lodSceneTriangles},
                       {"build_ms", s.lodBuildMs}};
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
