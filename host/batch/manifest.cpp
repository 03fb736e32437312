// manifest.cpp - JSON Lines job lists for `raster batch`.
#include "batch/manifest.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "render/option_names.h"
#include "scene/camera.h"
#include "scene/primitive_mode.h"

namespace sr {
namespace {

using nlohmann::json;

enum class Kind { String, Integer, Number, Bool, Vec3 };
struct KeyInfo {
    const char* name;
    Kind kind;
    bool defaultable;  // may appear in the header's defaults and on the command line
};
// Each key mirrors the `raster render` option of that name (dashes as underscores); png and exr are
// other names of output and aov.
const std::vector<KeyInfo> kKeys = {{"id", Kind::String, false},
                                    {"scene", Kind::String, true},
                                    {"camera", Kind::String, true},
                                    {"orbit", Kind::String, true},
                                    {"frames", Kind::Integer, true},
                                    {"width", Kind::Integer, true},
                                    {"height", Kind::Integer, true},
                                    {"shading", Kind::String, true},
                                    {"cull", Kind::String, true},
                                    {"msaa", Kind::Integer, true},
                                    {"ssaa", Kind::Integer, true},
                                    {"texture_filter", Kind::String, true},
                                    {"uv_interpolation", Kind::String, true},
                                    {"raster_method", Kind::String, true},
                                    {"primitive_mode", Kind::String, true},
                                    {"wireframe", Kind::Bool, true},
                                    {"ambient", Kind::Number, true},
                                    {"light_dir", Kind::Vec3, true},
                                    {"light_color", Kind::Vec3, true},
                                    {"background", Kind::Vec3, true},
                                    {"point_size", Kind::Number, true},
                                    {"line_width", Kind::Number, true},
                                    {"output", Kind::String, false},
                                    {"png", Kind::String, false},
                                    {"aov", Kind::String, false},
                                    {"exr", Kind::String, false},
                                    {"stats", Kind::String, false}};

const std::map<std::string, uint32_t>& kCullModes = cullModesByName();
const std::map<std::string, uint32_t>& kTextureFilters = textureFiltersByName();
const std::map<std::string, uint32_t>& kUvInterpolations = uvInterpolationsByName();
const std::map<std::string, uint32_t>& kRasterMethods = rasterMethodsByName();

const KeyInfo* findKey(const std::string& name)
{
    for (const KeyInfo& k : kKeys)
        if (name == k.name) return &k;
    return nullptr;
}

const char* kindName(Kind kind)
{
    switch (kind) {
    case Kind::String: return "a string";
    case Kind::Integer: return "a non-negative integer";
    case Kind::Number: return "a number";
    case Kind::Bool: return "true or false";
    case Kind::Vec3: return "an array of three numbers";
    }
    return "";
}

bool hasKind(const json& value, Kind kind)
{
    switch (kind) {
    case Kind::String: return value.is_string();
    case Kind::Integer:
        return value.is_number_integer() && value.get<int64_t>() >= 0 && value.get<int64_t>() <= 0xffffffffll;
    case Kind::Number: return value.is_number() && std::isfinite(value.get<double>());
    case Kind::Bool: return value.is_boolean();
    case Kind::Vec3:
        if (!value.is_array() || value.size() != 3) return false;
        for (const json& v : value)
            if (!v.is_number() || !std::isfinite(v.get<double>())) return false;
        return true;
    }
    return false;
}

// Every key of `object` known, of its kind, and allowed where it stands (`defaults`: the header or the
// command line).
Status checkKeys(const json& object, bool defaults, const std::string& where)
{
    for (auto it = object.begin(); it != object.end(); ++it) {
        const KeyInfo* key = findKey(it.key());
        if (!key) return makeError(ExitCode::Usage, "{}: unknown key '{}'", where, it.key());
        if (defaults && !key->defaultable)
            return makeError(ExitCode::Usage, "{}: '{}' belongs to one job, not to the defaults", where,
                             it.key());
        if (!hasKind(it.value(), key->kind))
            return makeError(ExitCode::Usage, "{}: '{}' must be {}, not {}", where, it.key(),
                             kindName(key->kind), it.value().dump());
    }
    return okStatus();
}

// The message of a parse error without nlohmann's "[json.exception.parse_error.101] " prefix.
std::string parseMessage(const json::parse_error& e)
{
    std::string message = e.what();
    const size_t bracket = message.find("] ");
    return bracket == std::string::npos ? message : message.substr(bracket + 2);
}

}  // namespace

std::string joinPath(const std::string& baseDir, const std::string& path)
{
    if (baseDir.empty() || path.empty() || path.front() == '/') return path;
    return baseDir + "/" + path;
}

namespace {

// NAME -> value in `table`, or a one-line error listing the names.
Result<uint32_t> lookup(const std::map<std::string, uint32_t>& table, const json& job, const char* key,
                        const std::string& fallback, const std::string& where)
{
    const std::string name = job.value(key, fallback);
    auto it = table.find(name);
    if (it != table.end()) return it->second;
    std::string names;
    for (const auto& [n, v] : table) names += (names.empty() ? "" : ", ") + n;
    return makeError(ExitCode::Usage, "{}: invalid {} '{}': expected one of {}", where, key, name, names);
}

glm::vec3 vec3Of(const json& job, const char* key, glm::vec3 fallback)
{
    if (!job.contains(key)) return fallback;
    const json& v = job[key];
    return {v[0].get<float>(), v[1].get<float>(), v[2].get<float>()};
}

json vec3Json(glm::vec3 v)
{
    return json::array({v.x, v.y, v.z});
}

// The job that `merged` (job over header over command line) describes, checked.
Result<ManifestJob> makeJob(const json& merged, int line, const std::string& where,
                            const std::string& baseDir)
{
    ManifestJob job;
    job.line = line;
    if (!merged.contains("scene")) return makeError(ExitCode::Usage, "{}: no 'scene'", where);
    if (merged.contains("output") && merged.contains("png"))
        return makeError(ExitCode::Usage, "{}: 'output' and 'png' name the same file: give one", where);
    if (merged.contains("aov") && merged.contains("exr"))
        return makeError(ExitCode::Usage, "{}: 'aov' and 'exr' name the same file: give one", where);
    const std::string output = merged.value("output", merged.value("png", std::string()));
    const std::string aov = merged.value("aov", merged.value("exr", std::string()));
    const std::string stats = merged.value("stats", std::string());
    if (output.empty()) return makeError(ExitCode::Usage, "{}: no 'output' (the PNG to write)", where);

    const std::string scene = merged["scene"].get<std::string>();
    if (scene.empty()) return makeError(ExitCode::Usage, "{}: empty 'scene'", where);
    job.scene = scene.compare(0, 7, "builtin") == 0 ? scene : joinPath(baseDir, scene);
    job.camera = merged.value("camera", std::string("auto"));
    auto camera = parseCameraSpec(job.camera);
    if (!camera) return makeError(ExitCode::Usage, "{}: {}", where, camera.error().message);
    job.orbit = merged.value("orbit", std::string());
    if (merged.contains("frames")) {
        job.frames = merged["frames"].get<uint32_t>();
        if (job.frames < 1 || job.frames > 1000000)
            return makeError(ExitCode::Usage, "{}: 'frames' must be 1 to 1000000, not {}", where, job.frames);
    }
    job.primitiveMode = merged.value("primitive_mode", std::string("triangles"));
    auto mode = parsePrimitiveMode(job.primitiveMode);
    if (!mode) return makeError(ExitCode::Usage, "{}: {}", where, mode.error().message);
    job.wireframe = merged.value("wireframe", false);

    RenderSettings& s = job.settings;
    s.width = merged.value("width", s.width);
    s.height = merged.value("height", s.height);
    if (s.width < 1 || s.height < 1 || s.width > MAX_FRAMEBUFFER_DIM || s.height > MAX_FRAMEBUFFER_DIM)
        return makeError(ExitCode::Usage, "{}: width and height must be 1 to {}, not {}x{}", where,
                         MAX_FRAMEBUFFER_DIM, s.width, s.height);
    std::map<std::string, uint32_t> shadings;
    for (uint32_t m = 0; m < kShadingModeCount; ++m) shadings[shadingModeName(m)] = m;
    auto shading = lookup(shadings, merged, "shading", "blinn-phong", where);
    if (!shading) return shading.error();
    s.shadingMode = *shading;
    auto cull = lookup(kCullModes, merged, "cull", "back", where);
    if (!cull) return cull.error();
    s.cullMode = *cull;
    auto filter = lookup(kTextureFilters, merged, "texture_filter", "auto", where);
    if (!filter) return filter.error();
    s.textureFilter = *filter;
    auto uv = lookup(kUvInterpolations, merged, "uv_interpolation", "perspective", where);
    if (!uv) return uv.error();
    s.uvInterpolation = *uv;
    auto method = lookup(kRasterMethods, merged, "raster_method", "fixed8", where);
    if (!method) return method.error();
    s.rasterMethod = *method;
    s.msaa = merged.value("msaa", s.msaa);
    if (s.msaa != 1 && s.msaa != 2 && s.msaa != 4 && s.msaa != 8 && s.msaa != 16)
        return makeError(ExitCode::Usage, "{}: 'msaa' must be 1, 2, 4, 8 or 16, not {}", where, s.msaa);
    s.ssaa = merged.value("ssaa", s.ssaa);
    if (s.ssaa < 1 || s.ssaa > MAX_SSAA)
        return makeError(ExitCode::Usage, "{}: 'ssaa' must be 1 to {}, not {}", where, MAX_SSAA, s.ssaa);
    s.ambient = merged.value("ambient", s.ambient);
    if (s.ambient < 0.0f || s.ambient > 100.0f)
        return makeError(ExitCode::Usage, "{}: 'ambient' must be 0 to 100, not {}", where, s.ambient);
    s.pointSize = merged.value("point_size", s.pointSize);
    s.lineWidth = merged.value("line_width", s.lineWidth);
    s.lightDirView = vec3Of(merged, "light_dir", s.lightDirView);
    s.lightColor = vec3Of(merged, "light_color", s.lightColor);
    s.background = vec3Of(merged, "background", s.background);

    job.outputPattern = output;
    job.aovPattern = aov;
    job.statsPattern = stats;
    job.output = joinPath(baseDir, output);
    job.aov = joinPath(baseDir, aov);
    job.stats = joinPath(baseDir, stats);
    job.id = merged.value("id", output);

    json& c = job.canonical;
    c["scene"] = scene;
    c["camera"] = job.camera;
    if (!job.orbit.empty()) c["orbit"] = job.orbit;
    if (job.frames) c["frames"] = job.frames;
    c["width"] = s.width;
    c["height"] = s.height;
    c["shading"] = shadingModeName(s.shadingMode);
    c["cull"] = merged.value("cull", std::string("back"));
    c["msaa"] = s.msaa;
    c["ssaa"] = s.ssaa;
    c["texture_filter"] = merged.value("texture_filter", std::string("auto"));
    c["uv_interpolation"] = merged.value("uv_interpolation", std::string("perspective"));
    c["raster_method"] = merged.value("raster_method", std::string("fixed8"));
    c["primitive_mode"] = job.primitiveMode;
    c["wireframe"] = job.wireframe;
    c["ambient"] = s.ambient;
    c["point_size"] = s.pointSize;
    c["line_width"] = s.lineWidth;
    c["light_dir"] = vec3Json(s.lightDirView);
    c["light_color"] = vec3Json(s.lightColor);
    c["background"] = vec3Json(s.background);
    c["output"] = output;
    if (!aov.empty()) c["aov"] = aov;
    if (!stats.empty()) c["stats"] = stats;
    return job;
}

// Defaults are checked where they are written, so that a bad value is reported there and not at the
// first job that inherits it.
Status checkDefaults(const json& defaults, const std::string& where)
{
    SR_TRY(checkKeys(defaults, true, where));
    json probe = defaults;
    if (!probe.contains("scene")) probe["scene"] = "builtin";
    probe["output"] = "probe.png";
    auto job = makeJob(probe, 0, where, "");
    if (!job) return job.error();
    return okStatus();
}

}  // namespace

const std::vector<std::string>& manifestKeys()
{
    static const std::vector<std::string> names = [] {
        std::vector<std::string> n;
        for (const KeyInfo& k : kKeys) n.push_back(k.name);
        return n;
    }();
    return names;
}

Result<Manifest> parseManifest(const std::string& text, const std::string& name, const std::string& baseDir,
                               const nlohmann::json& commandLine)
{
    SR_TRY(checkDefaults(commandLine, "command line"));
    Manifest manifest;
    manifest.path = name;
    manifest.baseDir = baseDir;
    json defaults = commandLine;
    bool sawLine = false;
    std::istringstream in(text);
    int line = 0;
    for (std::string row; std::getline(in, row);) {
        ++line;
        if (!row.empty() && row.back() == '\r') row.pop_back();
        if (row.find_first_not_of(" \t") == std::string::npos) continue;
        const std::string where = fmt::format("{}:{}", name, line);
        json object;
        try {
            object = json::parse(row);
        } catch (const json::parse_error& e) {
            return makeError(ExitCode::Usage, "{}: malformed JSON: {}", where, parseMessage(e));
        }
        if (!object.is_object())
            return makeError(ExitCode::Usage, "{}: expected a JSON object (one job), not {}", where,
                             object.dump());
        if (object.contains("defaults")) {
            if (sawLine)
                return makeError(ExitCode::Usage, "{}: the defaults line must be the first line", where);
            if (object.size() != 1 || !object["defaults"].is_object())
                return makeError(ExitCode::Usage,
                                 "{}: the header is {{\"defaults\": {{...}}}} and nothing else", where);
            SR_TRY(checkDefaults(object["defaults"], where));
            defaults.update(object["defaults"]);
            sawLine = true;
            continue;
        }
        sawLine = true;
        SR_TRY(checkKeys(object, false, where));
        json merged = defaults;
        merged.update(object);
        auto job = makeJob(merged, line, where, baseDir);
        if (!job) return job.error();
        manifest.jobs.push_back(std::move(*job));
    }
    if (manifest.jobs.empty()) return makeError(ExitCode::Usage, "{}: no jobs", name);
    return manifest;
}

Result<Manifest> loadManifest(const std::string& path, const nlohmann::json& commandLine)
{
    std::ifstream file(path, std::ios::binary);
    if (!file) return makeError(ExitCode::Usage, "cannot read manifest '{}': {}", path, std::strerror(errno));
    std::ostringstream text;
    text << file.rdbuf();
    return parseManifest(text.str(), path, std::filesystem::path(path).parent_path().string(), commandLine);
}

}  // namespace sr
