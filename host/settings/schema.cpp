// schema.cpp - the settings table (see schema.h) and the one place their values are checked.
#include "settings/schema.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include <fmt/format.h>

#include "camera/camera.h"

namespace sr {
namespace {

using nlohmann::json;

// Builders for the table's entries: each ties a name to one member of RenderOptions.
using Get = std::function<json(const RenderOptions&)>;
using Set = std::function<void(RenderOptions&, const json&)>;

Setting make(std::string group, std::string name, SettingType type, std::string help, Get get, Set set)
{
    Setting s;
    s.group = std::move(group);
    s.name = std::move(name);
    s.type = type;
    s.help = std::move(help);
    s.get = std::move(get);
    s.set = std::move(set);
    return s;
}

// A RenderSettings member of type uint32_t within [min, max].
Setting uintSetting(std::string group, std::string name, uint32_t RenderSettings::*member, double min,
                    double max, std::string help)
{
    Setting s = make(
        std::move(group), std::move(name), SettingType::Uint, std::move(help),
        [member](const RenderOptions& o) { return json(o.settings.*member); },
        [member](RenderOptions& o, const json& v) { o.settings.*member = v.get<uint32_t>(); });
    s.min = min;
    s.max = max;
    return s;
}

// A RenderSettings member of type float within [min, max], a multiple of `step` when step > 0.
Setting floatSetting(std::string group, std::string name, float RenderSettings::*member, double min,
                     double max, double step, std::string help)
{
    Setting s = make(
        std::move(group), std::move(name), SettingType::Float, std::move(help),
        [member](const RenderOptions& o) { return json(o.settings.*member); },
        [member](RenderOptions& o, const json& v) { o.settings.*member = v.get<float>(); });
    s.min = min;
    s.max = max;
    s.step = step;
    return s;
}

Setting boolSetting(std::string group, std::string name, bool RenderSettings::*member, std::string help)
{
    return make(
        std::move(group), std::move(name), SettingType::Bool, std::move(help),
        [member](const RenderOptions& o) { return json(o.settings.*member); },
        [member](RenderOptions& o, const json& v) { o.settings.*member = v.get<bool>(); });
}

Setting vec3Setting(std::string group, std::string name, glm::vec3 RenderSettings::*member, std::string help)
{
    return make(
        std::move(group), std::move(name), SettingType::Vec3, std::move(help),
        [member](const RenderOptions& o) {
            const glm::vec3& v = o.settings.*member;
            return json::array({v.x, v.y, v.z});
        },
        [member](RenderOptions& o, const json& v) {
            o.settings.*member = glm::vec3(v[0].get<float>(), v[1].get<float>(), v[2].get<float>());
        });
}

// A RenderSettings member holding one of the constants `choices` names; JSON holds the name.
Setting choiceSetting(std::string group, std::string name, uint32_t RenderSettings::*member,
                      std::vector<SettingChoice> choices, std::string help)
{
    Setting s =
        make(std::move(group), std::move(name), SettingType::Choice, std::move(help), nullptr, nullptr);
    s.choices = std::move(choices);
    const std::vector<SettingChoice> table = s.choices;
    s.get = [member, table](const RenderOptions& o) -> json {
        for (const SettingChoice& c : table)
            if (c.value == o.settings.*member) return c.name;
        return o.settings.*member;  // not a listed value: checkSettingValue reports the number
    };
    s.set = [member, table](RenderOptions& o, const json& v) {
        for (const SettingChoice& c : table)
            if (c.name == v.get<std::string>()) o.settings.*member = c.value;
    };
    return s;
}

std::vector<Setting> makeSchema()
{
    std::vector<Setting> t;
    // image
    t.push_back(uintSetting("image", "width", &RenderSettings::width, 1, MAX_FRAMEBUFFER_DIM,
                            "image width in pixels"));
    t.push_back(uintSetting("image", "height", &RenderSettings::height, 1, MAX_FRAMEBUFFER_DIM,
                            "image height in pixels"));
    t.push_back(make(
        "image", "camera", SettingType::Camera,
        "auto, gltf:N or orbit:AZ,EL,DIST[,TX,TY,TZ] (degrees; DIST in scene units, or Nr: N radii of the "
        "bounds' sphere, e.g. orbit:30,20,2.5r; TX,TY,TZ: the target's offset from the bounds centre, scene "
        "units)",
        [](const RenderOptions& o) { return json(o.camera); },
        [](RenderOptions& o, const json& v) { o.camera = v.get<std::string>(); }));
    t.push_back(make(
        "image", "model", SettingType::Model,
        "identity or translate:X,Y,Z,rotate:AX,AY,AZ,scale:S (parts optional, in this order): the scene "
        "drawn moved by T Rz Ry Rx S, turned and scaled about its bounds centre (degrees, world units, S > "
        "0); cameras frame the unmoved scene",
        [](const RenderOptions& o) { return json(o.model); },
        [](RenderOptions& o, const json& v) { o.model = v.get<std::string>(); }));
    // shading
    t.push_back(
        choiceSetting("shading", "shading", &RenderSettings::shadingMode,
                      {{"lambert", SHADING_LAMBERT},
                       {"phong", SHADING_PHONG},
                       {"blinn-phong", SHADING_BLINN_PHONG},
                       {"flat", SHADING_FLAT},
                       {"normals", SHADING_NORMALS},
                       {"depth", SHADING_DEPTH},
                       {"id", SHADING_PRIMITIVE_ID},
                       {"hits", SHADING_HIT_COUNT},
                       {"texcoord", SHADING_TEXCOORD},
                       {"mip", SHADING_MIP},
                       {"ao", SHADING_AO}},
                      "the shading model; hits (debug): triangles covering each pixel, green = 1, red = 2, "
                      "white = more; texcoord (debug): the base colour texture's (u, v) as red, green; mip "
                      "(debug): its level of detail, blue = 0 or magnified, cyan, green, yellow, red = 4+; "
                      "ao: the ambient occlusion alone (with --ao gtao or reference)"));
    t.push_back(choiceSetting("shading", "cull", &RenderSettings::cullMode,
                              {{"back", CULL_BACK}, {"front", CULL_FRONT}, {"none", CULL_NONE}},
                              "which faces are culled (glTF doubleSided materials never are)"));
    t.push_back(vec3Setting("shading", "light-dir", &RenderSettings::lightDirView,
                            "X,Y,Z towards the light, view space (+z to the eye)"));
    t.push_back(
        vec3Setting("shading", "light-color", &RenderSettings::lightColor, "R,G,B linear light colour"));
    t.push_back(
        floatSetting("shading", "ambient", &RenderSettings::ambient, 0.0, 100.0, 0.0, "ambient intensity"));
    t.push_back(floatSetting("shading", "specular", &RenderSettings::specular, 0.0, 100.0, 0.0,
                             "specular strength: the phong and blinn-phong highlight's peak as a fraction "
                             "of the light colour"));
    t.push_back(
        vec3Setting("shading", "background", &RenderSettings::background, "R,G,B linear background colour"));
    // ambient occlusion
    t.push_back(choiceSetting(
        "ambient occlusion", "ao", &RenderSettings::ao,
        {{"off", AO_OFF}, {"gtao", AO_GTAO}, {"reference", AO_REFERENCE}},
        "ambient occlusion, which scales the ambient term: gtao, screen-space GTAO over the visibility "
        "buffer on the device; reference, the ground truth, cosine-weighted rays against the scene's "
        "triangles on the host (slow)"));
    t.push_back(
        floatSetting("ambient occlusion", "ao-radius", &RenderSettings::aoRadius, 0.0, 1e20, 0.0,
                     "the occlusion radius in world units; 0: a tenth of the scene's bounding radius"));
    t.push_back(uintSetting("ambient occlusion", "ao-slices", &RenderSettings::aoSlices, 1, AO_MAX_SLICES,
                            "gtao: slice directions per pixel (cost is slices x steps)"));
    t.push_back(uintSetting("ambient occlusion", "ao-steps", &RenderSettings::aoSteps, 1, AO_MAX_STEPS,
                            "gtao: depth samples per side of a slice"));
    t.push_back(
        choiceSetting("ambient occlusion", "ao-denoise", &RenderSettings::aoDenoise,
                      {{"on", AO_DENOISE_ON}, {"off", AO_DENOISE_OFF}},
                      "gtao: average the 4x4 sampling pattern out with a depth-aware 5x5 filter (off: "
                      "the raw pattern)"));
    t.push_back(uintSetting("ambient occlusion", "ao-reference-rays", &RenderSettings::aoReferenceRays, 1, 64,
                            "reference: a stratified N x N grid of rays per pixel"));
    // textures
    t.push_back(
        choiceSetting("textures", "texture-filter", &RenderSettings::textureFilter,
                      {{"auto", TEXTURE_FILTER_AUTO},
                       {"nearest", TEXTURE_FILTER_NEAREST},
                       {"bilinear", TEXTURE_FILTER_BILINEAR},
                       {"trilinear", TEXTURE_FILTER_TRILINEAR}},
                      "auto follows each texture's glTF sampler; bilinear reads level 0, trilinear the two "
                      "nearest mip levels"));
    t.push_back(choiceSetting("textures", "uv-interpolation", &RenderSettings::uvInterpolation,
                              {{"perspective", UV_PERSPECTIVE}, {"affine", UV_AFFINE}},
                              "perspective-correct, or affine (screen-linear, to show the difference)"));
    // anti-aliasing and coverage
    Setting msaa = uintSetting("anti-aliasing", "msaa", &RenderSettings::msaa, 1, 16,
                               "samples per pixel at Vulkan's standard locations, shaded once per pixel and "
                               "triangle, resolved in linear space");
    msaa.numbers = {1, 2, 4, 8, 16};
    msaa.defaultNote =
        "raster render and batch: 4 (kImageMsaa); the library and Python module: 1, the exact path";
    t.push_back(msaa);
    t.push_back(
        uintSetting("anti-aliasing", "ssaa", &RenderSettings::ssaa, 1, MAX_SSAA,
                    "supersampling: N x N pixels per output pixel, each shaded, box-filtered; combines "
                    "with --msaa"));
    t.push_back(
        choiceSetting("anti-aliasing", "raster-method", &RenderSettings::rasterMethod,
                      {{"fixed8", RASTER_FIXED8},
                       {"fixed4", RASTER_FIXED4},
                       {"float", RASTER_FLOAT},
                       {"scanline", RASTER_SCANLINE}},
                      "fixed8: 1/256 px snapping, exact edge functions, top-left rule (conformant); fixed4: "
                      "the same at 1/16 px; float: float barycentrics with an epsilon; scanline: float "
                      "span ends per row; the last three are for comparison (raster study)"));
    // primitives
    t.push_back(make(
        "primitives", "primitive-mode", SettingType::Choice,
        "triangles as the file says, lines (a triangle mesh drawn as its edges, each once) or points (drawn "
        "as its "
        "vertices)",
        [](const RenderOptions& o) { return json(primitiveModeName(o.primitiveMode)); },
        [](RenderOptions& o, const json& v) {
            o.primitiveMode = *parsePrimitiveMode(v.get<std::string>());
        }));
    t.back().choices = {{"triangles", uint32_t(PrimitiveMode::Triangles)},
                        {"lines", uint32_t(PrimitiveMode::Lines)},
                        {"points", uint32_t(PrimitiveMode::Points)}};
    t.push_back(make(
        "primitives", "wireframe", SettingType::Bool,
        "overlay the mesh's edges (black lines, each edge once) on the shaded image, drawn 1/256 of their "
        "distance closer so edges on the surface win its depth test",
        [](const RenderOptions& o) { return json(o.wireframe); },
        [](RenderOptions& o, const json& v) { o.wireframe = v.get<bool>(); }));
    t.push_back(floatSetting("primitives", "point-size", &RenderSettings::pointSize, 1.0, MAX_POINT_SIZE,
                             0.125, "side of the square a point covers, in pixels"));
    t.push_back(floatSetting("primitives", "line-width", &RenderSettings::lineWidth, 1.0, MAX_LINE_WIDTH,
                             0.125, "width of the rectangle a line covers, in pixels"));
    // tessellation
    t.push_back(
        choiceSetting("tessellation", "tessellate", &RenderSettings::tessellate,
                      {{"off", TESS_OFF}, {"flat", TESS_FLAT}, {"pn", TESS_PN}, {"centroid", TESS_CENTROID}},
                      "flat: split triangles to the screen size --tess-edge-px asks, in their plane; pn: the "
                      "same, new vertices on Curved PN triangles (smooth silhouettes from vertex normals); "
                      "centroid: the course project's 1 -> 3 split, --tess-max-level times"));
    t.push_back(floatSetting("tessellation", "tess-edge-px", &RenderSettings::tessEdgePx, 0.25, 65536.0, 0.0,
                             "flat, pn: target projected edge length in output pixels"));
    Setting level = make(
        "tessellation", "tess-max-level", SettingType::Uint,
        "flat, pn: most pieces per edge (1..64); centroid: splits (0..8)",
        [](const RenderOptions& o) {
            return o.tessMaxLevel == kAutoTessLevel ? json("auto") : json(o.tessMaxLevel);
        },
        [](RenderOptions& o, const json& v) {
            o.tessMaxLevel = v.is_string() ? kAutoTessLevel : v.get<uint32_t>();
        });
    level.min = 0;
    level.max = TESS_MAX_LEVEL;
    level.allowAuto = true;
    level.defaultNote =
        fmt::format("{} for flat and pn, {} for centroid", kDefaultTessMaxLevel, kDefaultCentroidLevel);
    t.push_back(level);
    // geometry
    t.push_back(choiceSetting(
        "geometry", "clusters", &RenderSettings::clusters,
        {{"auto", CLUSTERS_AUTO}, {"on", CLUSTERS_ON}, {"off", CLUSTERS_OFF}},
        "set up triangles cluster by cluster (built at load time; whole clusters culled where every "
        "triangle would be) instead of one thread each; the same image either way. auto: on GPUs, for "
        "meshes whose clusters average at least 32 triangles, without tessellation"));
    t.push_back(choiceSetting(
        "geometry", "lod", &RenderSettings::lod, {{"off", LOD_OFF}, {"on", LOD_ON}},
        "level of detail: draw each part of a mesh at the coarsest level of its cluster hierarchy (built "
        "at load time with meshoptimizer, borders locked: no cracks) whose error projects within "
        "--lod-error-px; off draws every triangle. Not with --tessellate, --primitive-mode lines/points or "
        "--wireframe"));
    t.push_back(floatSetting("geometry", "lod-error-px", &RenderSettings::lodErrorPx, 0.015625, 1024.0, 0.0,
                             "with --lod on: the geometric error allowed on screen, in output pixels"));
    // outputs and timing
    t.push_back(
        boolSetting("output", "aov-samples", &RenderSettings::aovSamples,
                    "with an AOV file: also every sample's id and depth as channels id.s<k>, Z.s<k>"));
    t.push_back(uintSetting("timing", "repeat", &RenderSettings::repeat, 1, 100000,
                            "timed runs of the whole frame (the statistics give min, median and max)"));
    t.push_back(uintSetting("timing", "warmup", &RenderSettings::warmup, 0, 100000, "untimed runs first"));
    return t;
}

// A number as the messages and the reference write it: the fewest digits that read back the same.
std::string numberText(double v)
{
    return fmt::format("{}", v);
}

std::string joinNames(const std::vector<std::string>& names)
{
    std::string out;
    for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
    return out;
}

std::string numbersText(const std::vector<uint32_t>& numbers)
{
    std::vector<std::string> names;
    for (uint32_t n : numbers) names.push_back(std::to_string(n));
    return joinNames(names);
}

// Whole text as one decimal number (strtod accepts leading space and stops early; neither is wanted).
bool parseDouble(const std::string& text, double& out)
{
    // Decimal notation only: strtod would also read hexadecimal floats, "inf" and "nan".
    if (text.empty() || text.find_first_not_of("0123456789+-.eE") != std::string::npos) return false;
    char* end = nullptr;
    errno = 0;
    out = std::strtod(text.c_str(), &end);
    return end == text.c_str() + text.size() && errno != ERANGE;
}

}  // namespace

std::string Setting::key() const
{
    std::string k = name;
    std::replace(k.begin(), k.end(), '-', '_');
    return k;
}

const std::vector<Setting>& settingsSchema()
{
    static const std::vector<Setting> schema = makeSchema();
    return schema;
}

const Setting* findSetting(const std::string& name)
{
    std::string dashed = name;
    std::replace(dashed.begin(), dashed.end(), '_', '-');
    for (const Setting& s : settingsSchema())
        if (s.name == dashed) return &s;
    return nullptr;
}

const Setting& setting(const std::string& name)
{
    const Setting* s = findSetting(name);
    if (!s) throw std::logic_error("no setting '" + name + "' in the schema");
    return *s;
}

Error relabelled(Error error, const std::string& option, const std::string& label)
{
    for (size_t at = error.message.find(option); at != std::string::npos;
         at = error.message.find(option, at + label.size()))
        error.message.replace(at, option.size(), label);
    return error;
}

Result<json> checkSettingValue(const Setting& s, const json& value, const std::string& label)
{
    switch (s.type) {
    case SettingType::Uint: {
        if (s.allowAuto && value == json("auto")) return value;
        if (!value.is_number_integer() || (!value.is_number_unsigned() && value.get<int64_t>() < 0))
            return makeError(ExitCode::Usage, "{} must be a non-negative integer, not {}", label,
                             clippedText(value.dump()));
        if (value.get<uint64_t>() > s.max)
            return makeError(ExitCode::Usage, "{} {} is outside {}..{}", label, value.get<uint64_t>(),
                             numberText(s.min), numberText(s.max));
        const auto v = value.get<uint32_t>();
        if (!s.numbers.empty() && std::find(s.numbers.begin(), s.numbers.end(), v) == s.numbers.end())
            return makeError(ExitCode::Usage, "{} {} is not one of {}", label, v, numbersText(s.numbers));
        if (v < s.min || v > s.max)
            return makeError(ExitCode::Usage, "{} {} is outside {}..{}", label, v, numberText(s.min),
                             numberText(s.max));
        return json(v);
    }
    case SettingType::Float: {
        if (!value.is_number() || !std::isfinite(value.get<double>()))
            return makeError(ExitCode::Usage, "{} must be a number, not {}", label, value.dump());
        // Stored as float, so checked as float against the bounds as float hold them (the documented
        // maximum 1e20 is 1.00000002e20 in float); the value is shown as given.
        const double given = value.get<double>();
        const auto v = float(given);
        const bool inside = v >= float(s.min) && v <= float(s.max);
        if (s.step > 0.0 && (!inside || double(v) / s.step != std::floor(double(v) / s.step)))
            return makeError(ExitCode::Usage, "{} {} is not a multiple of {} between {} and {}", label, given,
                             s.step == 0.125 ? "1/8" : numberText(s.step), numberText(s.min),
                             numberText(s.max));
        if (!inside)
            return makeError(ExitCode::Usage, "{} {} is outside {}..{}", label, given, numberText(s.min),
                             numberText(s.max));
        return json(v);
    }
    case SettingType::Bool:
        if (!value.is_boolean())
            return makeError(ExitCode::Usage, "{} must be true or false, not {}", label, value.dump());
        return value;
    case SettingType::Choice: {
        if (!value.is_string())
            return makeError(ExitCode::Usage, "invalid {} {}: expected one of {}", label, value.dump(),
                             joinNames(choiceNames(s)));
        auto v = choiceValue(s, value.get<std::string>(), label);
        if (!v) return v.error();
        return value;
    }
    case SettingType::Vec3:
        if (!value.is_array() || value.size() != 3)
            return makeError(ExitCode::Usage, "{} must be an array of three numbers, not {}", label,
                             value.dump());
        for (const json& c : value)
            if (!c.is_number() || !std::isfinite(c.get<double>()))
                return makeError(ExitCode::Usage, "{} must be an array of three numbers, not {}", label,
                                 value.dump());
        return json::array({value[0].get<float>(), value[1].get<float>(), value[2].get<float>()});
    case SettingType::Camera: {
        if (!value.is_string())
            return makeError(ExitCode::Usage, "{} must be a string, not {}", label, value.dump());
        auto spec = parseCameraSpec(value.get<std::string>());
        if (!spec) return relabelled(spec.error(), "--camera", label);
        return value;
    }
    case SettingType::Model: {
        if (!value.is_string())
            return makeError(ExitCode::Usage, "{} must be a string, not {}", label, value.dump());
        auto spec = parseModelSpec(value.get<std::string>());
        if (!spec) return relabelled(spec.error(), "--model", label);
        return value;
    }
    }
    return makeError(ExitCode::Usage, "{}: unknown setting type", label);
}

Result<json> parseSettingText(const Setting& s, const std::string& text, const std::string& label)
{
    json value;
    double number = 0.0;
    switch (s.type) {
    case SettingType::Uint: {
        if (s.allowAuto && text == "auto") return checkSettingValue(s, json(text), label);
        const bool digits = !text.empty() && std::all_of(text.begin(), text.end(),
                                                         [](char c) { return c >= '0' && c <= '9'; });
        if (!digits)
            return makeError(ExitCode::Usage, "{} must be a non-negative integer, not {}", label,
                             quotedInput(text));
        const size_t first = std::min(text.find_first_not_of('0'), text.size() - 1);
        if (text.size() - first > 19)  // past uint64: outside any range
            return makeError(ExitCode::Usage, "{} {} is outside {}..{}", label,
                             clippedText(text.substr(first)), numberText(s.min), numberText(s.max));
        value = std::stoull(text.substr(first));
        break;
    }
    case SettingType::Float:
        if (!parseDouble(text, number) || !std::isfinite(number))
            return makeError(ExitCode::Usage, "{} must be a finite number, not {}", label, quotedInput(text));
        value = number;
        break;
    case SettingType::Bool:
        if (text == "true" || text == "1")
            value = true;
        else if (text == "false" || text == "0")
            value = false;
        else
            return makeError(ExitCode::Usage, "{} must be true or false, not '{}'", label, text);
        break;
    case SettingType::Vec3: {
        value = json::array();
        std::istringstream in(text);
        std::string part;
        while (std::getline(in, part, ',')) {
            if (!parseDouble(part, number) || !std::isfinite(number)) break;
            value.push_back(number);
        }
        if (value.size() != 3 || std::count(text.begin(), text.end(), ',') != 2)
            return makeError(ExitCode::Usage, "invalid {} {}: expected three numbers X,Y,Z", label,
                             quotedInput(text));
        break;
    }
    case SettingType::Choice:
    case SettingType::Camera:
    case SettingType::Model: value = text; break;
    }
    return checkSettingValue(s, value, label);
}

Status setSetting(RenderOptions& options, const Setting& s, const json& value, const std::string& label)
{
    auto checked = checkSettingValue(s, value, label);
    if (!checked) return checked.error();
    s.set(options, *checked);
    return okStatus();
}

json settingValue(const RenderOptions& options, const Setting& s)
{
    return s.get(options);
}

std::string settingText(const RenderOptions& options, const Setting& s)
{
    const json v = s.get(options);
    switch (s.type) {
    case SettingType::Float: return fmt::format("{}", v.get<float>());
    case SettingType::Vec3:
        return fmt::format("{},{},{}", v[0].get<float>(), v[1].get<float>(), v[2].get<float>());
    default: return v.is_string() ? v.get<std::string>() : v.dump();
    }
}

std::string settingDefaultText(const Setting& s)
{
    return settingText(RenderOptions{}, s);
}

json settingsJson(const RenderOptions& options)
{
    json out = json::object();
    for (const Setting& s : settingsSchema()) out[s.key()] = s.get(options);
    return out;
}

std::string renderArguments(const RenderOptions& options)
{
    // A `raster render` command line: what differs from that command's own defaults.
    const RenderOptions defaults = imageRenderOptions();
    std::string args;
    for (const Setting& s : settingsSchema()) {
        if (s.get(options) == s.get(defaults)) continue;
        if (s.type == SettingType::Bool) {
            if (s.get(options).get<bool>()) args += (args.empty() ? "--" : " --") + s.name;
            continue;
        }
        args += fmt::format("{}--{} {}", args.empty() ? "" : " ", s.name, settingText(options, s));
    }
    return args;
}

Status checkAovSamples(const RenderSettings& settings, bool hasAov, const std::string& samplesName,
                       const std::string& aovName)
{
    if (!settings.aovSamples) return okStatus();
    if (!hasAov) return makeError(ExitCode::Usage, "{} needs {}", samplesName, aovName);
    const uint32_t samples = settings.ssaa * settings.ssaa * settings.msaa;
    if (samples > kMaxAovSamples)
        return makeError(ExitCode::Usage, "{} writes at most {} samples per pixel, not {} (ssaa {}, msaa {})",
                         samplesName, kMaxAovSamples, samples, settings.ssaa, settings.msaa);
    return okStatus();
}

Status checkSettings(const RenderSettings& settings)
{
    RenderOptions options;
    options.settings = settings;
    options.tessMaxLevel = settings.tessMaxLevel;  // resolved: a number
    for (const Setting& s : settingsSchema()) {
        if (s.type == SettingType::Camera || s.type == SettingType::Model) continue;
        auto checked = checkSettingValue(s, s.get(options), "--" + s.name);
        if (!checked) return checked.error();
    }
    if (uint64_t(settings.width) * settings.ssaa > MAX_FRAMEBUFFER_DIM ||
        uint64_t(settings.height) * settings.ssaa > MAX_FRAMEBUFFER_DIM)
        return makeError(ExitCode::Usage,
                         "resolution {}x{} with --ssaa {} makes a raster grid over {} per side",
                         settings.width, settings.height, settings.ssaa, MAX_FRAMEBUFFER_DIM);
    // Sample indices (s * samplePlane + pixel) are 32-bit on the devices.
    if (uint64_t(settings.width) * settings.height * settings.ssaa * settings.ssaa * settings.msaa >=
        (uint64_t(1) << 31))
        return makeError(ExitCode::Usage, "{}x{} with --ssaa {} and --msaa {} is over 2^31 samples",
                         settings.width, settings.height, settings.ssaa, settings.msaa);
    if (settings.tessellate == TESS_CENTROID && settings.tessMaxLevel > TESS_MAX_CENTROID)
        return makeError(ExitCode::Usage, "--tess-max-level {} is outside 0..{} for centroid tessellation",
                         settings.tessMaxLevel, TESS_MAX_CENTROID);
    if ((settings.tessellate == TESS_FLAT || settings.tessellate == TESS_PN) && settings.tessMaxLevel < 1)
        return makeError(ExitCode::Usage, "--tess-max-level {} is outside 1..{}", settings.tessMaxLevel,
                         TESS_MAX_LEVEL);
    if (settings.lod == LOD_ON && settings.tessellate != TESS_OFF)
        return makeError(
            ExitCode::Usage,
            "--lod on simplifies the scene's triangles and --tessellate refines them; they do not "
            "combine (turn one of them off)");
    if (settings.ao == AO_REFERENCE && (settings.tessellate != TESS_OFF || settings.lod == LOD_ON))
        return makeError(ExitCode::Usage,
                         "--ao reference casts rays against the scene's own triangles; it does not combine "
                         "with --tessellate or --lod on (use --ao gtao)");
    if (settings.shadingMode == SHADING_AO && settings.ao == AO_OFF)
        return makeError(ExitCode::Usage,
                         "--shading ao shows the ambient occlusion: it needs --ao gtao or --ao reference");
    if (!(settings.lineDepthBias >= 0.0f && settings.lineDepthBias < 1.0f))
        return makeError(ExitCode::Usage, "line depth bias {} is outside [0, 1)", settings.lineDepthBias);
    return okStatus();
}

std::string choiceName(const Setting& s, uint32_t value)
{
    for (const SettingChoice& c : s.choices)
        if (c.value == value) return c.name;
    return "unknown";
}

Result<uint32_t> choiceValue(const Setting& s, const std::string& name, const std::string& label)
{
    for (const SettingChoice& c : s.choices)
        if (c.name == name) return c.value;
    return makeError(ExitCode::Usage, "invalid {} {}: expected one of {}", label, quotedInput(name),
                     joinNames(choiceNames(s)));
}

std::vector<std::string> choiceNames(const Setting& s)
{
    std::vector<std::string> names;
    for (const SettingChoice& c : s.choices) names.push_back(c.name);
    return names;
}

namespace {

// The "values" column of the reference: what a setting accepts.
std::string valuesText(const Setting& s)
{
    switch (s.type) {
    case SettingType::Uint:
        if (!s.numbers.empty()) return numbersText(s.numbers);
        return fmt::format("{}{}..{}", s.allowAuto ? "auto, " : "", numberText(s.min), numberText(s.max));
    case SettingType::Float:
        if (s.step > 0.0)
            return fmt::format("{}..{}, multiples of {}", numberText(s.min), numberText(s.max),
                               s.step == 0.125 ? "1/8" : numberText(s.step));
        return fmt::format("{}..{}", numberText(s.min), numberText(s.max));
    case SettingType::Bool: return "flag";
    case SettingType::Choice: return joinNames(choiceNames(s));
    case SettingType::Vec3: return "X,Y,Z";
    case SettingType::Camera: return "camera spec";
    case SettingType::Model: return "model spec";
    }
    return "";
}

const char* typeName(SettingType type)
{
    switch (type) {
    case SettingType::Uint: return "uint";
    case SettingType::Float: return "float";
    case SettingType::Bool: return "bool";
    case SettingType::Choice: return "choice";
    case SettingType::Vec3: return "vec3";
    case SettingType::Camera: return "camera";
    case SettingType::Model: return "model";
    }
    return "";
}

}  // namespace

std::string settingsMarkdown()
{
    std::string out;
    std::string group;
    for (const Setting& s : settingsSchema()) {
        if (s.group != group) {
            group = s.group;
            out += fmt::format(
                "{}**{}**\n\n| option | manifest key | values | default | meaning |\n"
                "|---|---|---|---|---|\n",
                out.empty() ? "" : "\n", group);
        }
        std::string def = s.type == SettingType::Bool ? "off" : settingDefaultText(s);
        if (!s.defaultNote.empty()) def += " (" + s.defaultNote + ")";
        std::string help = s.help;
        // A '|' would end the table cell.
        for (size_t at = help.find('|'); at != std::string::npos; at = help.find('|', at + 2))
            help.replace(at, 1, "\\|");
        out += fmt::format("| `--{}` | `{}` | {} | {} | {} |\n", s.name, s.key(), valuesText(s), def, help);
    }
    return out;
}

json schemaJson()
{
    json out = json::array();
    for (const Setting& s : settingsSchema()) {
        json e = {{"name", s.name},   {"key", s.key()}, {"type", typeName(s.type)},
                  {"group", s.group}, {"help", s.help}, {"default", s.get(RenderOptions{})}};
        if (!s.choices.empty()) e["choices"] = choiceNames(s);
        if (!s.numbers.empty()) e["values"] = s.numbers;
        if (s.type == SettingType::Uint || s.type == SettingType::Float) {
            e["min"] = s.min;
            e["max"] = s.max;
        }
        if (s.step > 0.0) e["step"] = s.step;
        if (!s.defaultNote.empty()) e["default_note"] = s.defaultNote;
        out.push_back(e);
    }
    return out;
}

}  // namespace sr
