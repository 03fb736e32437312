// manifest.cpp - JSON Lines job lists for `raster batch`.
#include "batch/manifest.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "io/file_write.h"
#include "loaders/safe_file.h"
#include "settings/schema.h"

namespace sr {
namespace {

using nlohmann::json;

enum class Kind { String, Integer };
// The keys of a job that are no render setting (those come from the settings schema, by their keys:
// width, shading, texture_filter, ...). png and exr are other names of output and aov. png_compression and
// exr_compression say how the job's files are encoded (io/image_io.h).
struct KeyInfo {
    const char* name;
    Kind kind;
    bool defaultable;  // may appear in the header's defaults and on the command line
};
const std::vector<KeyInfo> kJobKeys = {{"id", Kind::String, false},
                                       {"scene", Kind::String, true},
                                       {"orbit", Kind::String, true},
                                       {"frames", Kind::Integer, true},
                                       {"output", Kind::String, false},
                                       {"png", Kind::String, false},
                                       {"aov", Kind::String, false},
                                       {"exr", Kind::String, false},
                                       {"stats", Kind::String, false},
                                       {"png_compression", Kind::String, true},
                                       {"exr_compression", Kind::String, true}};

const KeyInfo* findJobKey(const std::string& name)
{
    for (const KeyInfo& k : kJobKeys)
        if (name == k.name) return &k;
    return nullptr;
}

const char* kindName(Kind kind)
{
    return kind == Kind::String ? "a string" : "a non-negative integer";
}

bool hasKind(const json& value, Kind kind)
{
    if (kind == Kind::String) return value.is_string();
    return value.is_number_integer() && value.get<int64_t>() >= 0 && value.get<int64_t>() <= 0xffffffffll;
}

// Every key of `object` known, of its kind, and allowed where it stands (`defaults`: the header or the
// command line).
Status checkKeys(const json& object, bool defaults, const std::string& where)
{
    for (auto it = object.begin(); it != object.end(); ++it) {
        // A render setting: its value is checked by the schema, under its key with underscores.
        const Setting* setting = findSetting(it.key());
        if (setting && setting->key() == it.key()) {
            auto checked = checkSettingValue(*setting, it.value(), it.key());
            if (!checked) return makeError(ExitCode::Usage, "{}: {}", where, checked.error().message);
            continue;
        }
        const KeyInfo* key = findJobKey(it.key());
        if (!key) return makeError(ExitCode::Usage, "{}: unknown key {}", where, quotedInput(it.key()));
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
std::string parseMessage(const json::exception& e)
{
    std::string message = e.what();
    const size_t bracket = message.find("] ");
    return bracket == std::string::npos ? message : message.substr(bracket + 2);
}

// Walks a JSON text as the parser reads it and keeps the path of the value it is in ('defaults',
// 'light_dir'[1]): where a parse fails, the path names the key the bad value belongs to.
class KeyPath : public nlohmann::json_sax<json> {
public:
    std::string path() const
    {
        std::string text;
        for (const Level& level : levels_) {
            if (level.object && !level.key.empty())
                text += (text.empty() ? "" : ".") + quotedInput(level.key);
            else if (!level.object)
                text += fmt::format("[{}]", level.index);
        }
        return text;
    }

    bool null() override { return value(); }
    bool boolean(bool) override { return value(); }
    bool number_integer(number_integer_t) override { return value(); }
    bool number_unsigned(number_unsigned_t) override { return value(); }
    bool number_float(number_float_t, const string_t&) override { return value(); }
    bool string(string_t&) override { return value(); }
    bool binary(binary_t&) override { return value(); }
    bool start_object(std::size_t) override
    {
        levels_.push_back({true, {}, 0});
        return true;
    }
    bool key(string_t& key) override
    {
        levels_.back().key = key;
        return true;
    }
    bool end_object() override { return close(); }
    bool start_array(std::size_t) override
    {
        levels_.push_back({false, {}, 0});
        return true;
    }
    bool end_array() override { return close(); }
    bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override
    {
        return false;
    }

private:
    struct Level {
        bool object;
        std::string key;  // objects: the key of the value being read
        size_t index;     // arrays: the index of the value being read
    };
    // A value ends: an array moves on to its next element.
    bool value()
    {
        if (!levels_.empty() && !levels_.back().object) ++levels_.back().index;
        return true;
    }
    bool close()
    {
        levels_.pop_back();
        return value();
    }
    std::vector<Level> levels_;
};

// A manifest line as JSON, or the one-line error: malformed JSON, or a number past the range of a double
// (1e400, or 10 MB of digits) named by its key.
Result<json> parseLine(const std::string& row, const std::string& where)
{
    try {
        return json::parse(row);
    } catch (const json::parse_error& e) {
        return makeError(ExitCode::Usage, "{}: malformed JSON: {}", where, clippedText(parseMessage(e), 200));
    } catch (const json::exception& e) {
        KeyPath keys;
        json::sax_parse(row, &keys);
        const std::string path = keys.path();
        if (e.id == 406)  // out_of_range.406: "number overflow parsing '<token>'"
            return makeError(ExitCode::Usage, "{}: {}a number outside the range of a double", where,
                             path.empty() ? std::string() : path + " is ");
        return makeError(ExitCode::Usage, "{}: {}{}", where, path.empty() ? "" : path + ": ",
                         clippedText(parseMessage(e), 200));
    }
}

}  // namespace

std::string joinPath(const std::string& baseDir, const std::string& path)
{
    if (baseDir.empty() || path.empty() || path.front() == '/') return path;
    return baseDir + "/" + path;
}

namespace {

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
    if (output.empty()) return makeError(ExitCode::Usage, "{}: no 'output' (the PNG or NPY to write)", where);
    // "output" is the colour image in either format, its extension choosing; "png" names a PNG.
    if (!merged.contains("png")) {
        auto extension = checkColorExtension("output", output);
        if (!extension) return makeError(ExitCode::Usage, "{}: {}", where, extension.error().message);
    }
    auto named = checkOutputNames(
        {{merged.contains("png") ? "png" : "output", output, merged.contains("png") ? ".png" : ""},
         {merged.contains("exr") ? "exr" : "aov", aov, ".exr"},
         {"stats", stats, ""}});
    if (!named) return makeError(ExitCode::Usage, "{}: {}", where, named.error().message);

    const std::string scene = merged["scene"].get<std::string>();
    if (scene.empty()) return makeError(ExitCode::Usage, "{}: empty 'scene'", where);
    job.scene = scene.compare(0, 7, "builtin") == 0 ? scene : joinPath(baseDir, scene);
    job.orbit = merged.value("orbit", std::string());
    if (merged.contains("frames")) {
        job.frames = merged["frames"].get<uint32_t>();
        if (job.frames < 1 || job.frames > 1000000)
            return makeError(ExitCode::Usage, "{}: 'frames' must be 1 to 1000000, not {}", where, job.frames);
    }
    // Every render setting the job (or its defaults) names, through the schema; the rest at their defaults.
    for (const Setting& setting : settingsSchema()) {
        if (!merged.contains(setting.key())) continue;
        auto set = setSetting(job.options, setting, merged[setting.key()], setting.key());
        if (!set) return makeError(ExitCode::Usage, "{}: {}", where, set.error().message);
    }
    auto combined = checkSettings(job.options.resolved());
    if (!combined) return makeError(ExitCode::Usage, "{}: {}", where, combined.error().message);
    auto samples = checkAovSamples(job.options.resolved(), !aov.empty(), "aov_samples", "an 'aov' file");
    if (!samples) return makeError(ExitCode::Usage, "{}: {}", where, samples.error().message);

    // An encoder setting is for a file the job writes: one without that file would change nothing.
    if (merged.contains("png_compression")) {
        auto png = parsePngCompression(merged["png_compression"].get<std::string>(), "'png_compression'");
        if (!png) return makeError(ExitCode::Usage, "{}: {}", where, png.error().message);
        if (isNpyPath(output))
            return makeError(ExitCode::Usage, "{}: 'png_compression' needs a PNG 'output', not {}", where,
                             quotedInput(output));
        job.encoding.png = *png;
    }
    if (merged.contains("exr_compression")) {
        auto exr = parseExrCompression(merged["exr_compression"].get<std::string>(), "'exr_compression'");
        if (!exr) return makeError(ExitCode::Usage, "{}: {}", where, exr.error().message);
        if (aov.empty())
            return makeError(ExitCode::Usage, "{}: 'exr_compression' needs an 'aov' file", where);
        job.encoding.exr = *exr;
    }

    job.outputPattern = output;
    job.aovPattern = aov;
    job.statsPattern = stats;
    job.output = joinPath(baseDir, output);
    job.aov = joinPath(baseDir, aov);
    job.stats = joinPath(baseDir, stats);
    job.id = merged.value("id", output);

    json& c = job.canonical;
    c = settingsJson(job.options);
    c["scene"] = scene;
    if (!job.orbit.empty()) c["orbit"] = job.orbit;
    if (job.frames) c["frames"] = job.frames;
    c["output"] = output;
    if (!aov.empty()) c["aov"] = aov;
    if (!stats.empty()) c["stats"] = stats;
    // The encoders change the files' bytes: a job asked for at other settings is written again. Recorded
    // only when not the default, so that the sidecars of jobs written before the setting existed still
    // vouch for their files.
    if (job.encoding.png != PngCompression::Default)
        c["png_compression"] = pngCompressionName(job.encoding.png);
    if (job.encoding.exr != ExrCompression::Zip) c["exr_compression"] = exrCompressionName(job.encoding.exr);
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
    probe["aov"] = "probe.exr";  // aov_samples in the defaults is for jobs that name an EXR
    auto job = makeJob(probe, 0, where, "");
    if (!job) return job.error();
    return okStatus();
}

}  // namespace

const std::vector<std::string>& manifestKeys()
{
    static const std::vector<std::string> names = [] {
        std::vector<std::string> n;
        for (const KeyInfo& k : kJobKeys) n.push_back(k.name);
        for (const Setting& s : settingsSchema()) n.push_back(s.key());
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
        auto parsed = parseLine(row, where);
        if (!parsed) return parsed.error();
        json& object = *parsed;
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
    auto text = readRegularFile(path, kMaxSceneFileBytes, "read manifest");
    if (!text) return text.error();
    return parseManifest(std::string(text->begin(), text->end()), path,
                         std::filesystem::path(path).parent_path().string(), commandLine);
}

}  // namespace sr
