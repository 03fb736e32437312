// study_runner.cpp - see study_runner.h.
#include "study/study_runner.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>

#include <fmt/format.h>
#include <unistd.h>

#include "api/api_internal.h"
#include "study/quality.h"
#include "study/stress.h"

namespace sr {
namespace {

std::string backendOf(const raster::Device& device)
{
    return raster::backendName(device.info().backend);
}

// The study renders through the library as every front end does: `scene` handed to it (a copy, the
// study keeps its own for the measurements) in a session of its own, as `renderScene` would draw it on a
// fresh session, with the study's own matrices and the backend's whole output kept.
Result<RenderOutput> renderOnce(raster::Device& device, const Scene& scene, const CameraMatrices& camera,
                                const RenderSettings& settings)
{
    const raster::Scene handed = raster::Internal::makeScene(scene, "study", std::nullopt);
    auto session = raster::Session::create(device, handed);
    if (!session) return raster::fromPublic(session.error());
    return raster::Internal::renderOutput(*session, camera, settings);
}

std::string today()
{
    std::time_t now = std::time(nullptr);
    char text[16];
    std::strftime(text, sizeof text, "%Y-%m-%d", std::gmtime(&now));
    return text;
}

// JSON has no infinity: identical images get "inf" and the chart treats them as exact.
nlohmann::json psnrJson(double psnr)
{
    return std::isinf(psnr) ? nlohmann::json("inf") : nlohmann::json(psnr);
}

Status checkNames(const std::vector<std::string>& names, const std::vector<std::string>& known,
                  const char* what)
{
    for (const std::string& n : names)
        if (std::find(known.begin(), known.end(), n) == known.end())
            return makeError(ExitCode::Usage, "study: unknown {} '{}' (expected {})", what, n,
                             fmt::format("{}", fmt::join(known, ", ")));
    return okStatus();
}

// The conformant graphics pipeline's render of each stress case, drawn at first need and shared by
// every method and backend (it depends on the case alone). When vulkan-graphics cannot run at all, the
// first attempt says so on stderr and the study goes on without oracle mismatches; once it has run, a
// later failure is an error like any other.
class Oracle {
public:
    explicit Oracle(int device) : index_(device) {}

    // The oracle's render of case `index` of axis `axis`, nullptr when vulkan-graphics is unavailable.
    Result<const RenderOutput*> render(size_t axis, size_t index, const StressCase& c)
    {
        if (!available_) return static_cast<const RenderOutput*>(nullptr);
        auto it = outputs_.find({axis, index});
        if (it != outputs_.end()) return &it->second;
        if (!device_) {
            auto opened = raster::Device::open(raster::Backend::VulkanGraphics, index_);
            if (!opened) {
                fmt::print(stderr, "study: vulkan-graphics unavailable, oracle_mismatches left null: {}\n",
                           opened.error().message);
                available_ = false;
                return static_cast<const RenderOutput*>(nullptr);
            }
            device_.emplace(std::move(*opened));
        }
        auto out = renderOnce(*device_, c.scene, c.camera, c.settings);
        if (!out) {
            if (!outputs_.empty()) return out.error();
            fmt::print(stderr, "study: vulkan-graphics unavailable, oracle_mismatches left null: {}\n",
                       out.error().message);
            available_ = false;
            return static_cast<const RenderOutput*>(nullptr);
        }
        return &outputs_.emplace(std::make_pair(axis, index), std::move(*out)).first->second;
    }

private:
    int index_;
    std::optional<raster::Device> device_;
    bool available_ = true;
    std::map<std::pair<size_t, size_t>, RenderOutput> outputs_;
};

// Device memory of the frame just rendered: the sum of its buffers' sizes, as the renderer sized them
// for this scene and setting. Not peakAllocatedBytes: a device keeps its buffers at the largest size
// any frame needed (the reference's, rendered first), so its peak would give every setting that.
double frameMib(const raster::Device& device)
{
    const ComputeDevice& compute = *raster::Internal::of(device).compute;
    size_t bytes = 0;
    for (uint32_t buffer = BUF_PARAMS + 1; buffer < BUF_COUNT; ++buffer) bytes += compute.size(buffer);
    return double(bytes) / (1 << 20);
}

struct Axis {
    std::string name;
    std::vector<StressCase> cases;
};

uint64_t failures(const nlohmann::json& row)
{
    uint64_t n = 0;
    for (const char* key : {"cracks", "double_hits", "wrong_depth_order", "oracle_mismatches"})
        if (row.contains(key) && row[key].is_number()) n += row[key].get<uint64_t>();
    return n;
}

// The first failing x per (axis, backend) and method, in the order the rows come in (each method's
// cases in increasing stress): the x, or "none up to" the last x.
std::string firstFailureTable(const nlohmann::json& stability)
{
    struct Walk {
        std::optional<double> first;
        double last = 0.0;
    };
    std::vector<std::string> methods;
    std::vector<std::pair<std::string, std::string>> lines;  // (axis, backend) in order of appearance
    std::map<std::tuple<std::string, std::string, std::string>, Walk> walks;
    for (const auto& s : stability) {
        const std::string axis = s["axis"], backend = s["backend"], method = s["method"];
        if (std::find(methods.begin(), methods.end(), method) == methods.end()) methods.push_back(method);
        if (std::find(lines.begin(), lines.end(), std::make_pair(axis, backend)) == lines.end())
            lines.emplace_back(axis, backend);
        Walk& w = walks[{axis, backend, method}];
        w.last = s["x"].get<double>();
        if (!w.first && failures(s) > 0) w.first = w.last;
    }
    std::string md = "| axis | backend |";
    for (const std::string& m : methods) md += fmt::format(" {} |", m);
    md += "\n|---|---|";
    for (size_t i = 0; i < methods.size(); ++i) md += "---|";
    md += "\n";
    for (const auto& [axis, backend] : lines) {
        md += fmt::format("| {} | {} |", axis, backend);
        for (const std::string& m : methods) {
            auto it = walks.find({axis, backend, m});
            if (it == walks.end())
                md += " - |";
            else if (it->second.first)
                md += fmt::format(" {:g} |", *it->second.first);
            else
                md += fmt::format(" none up to {:g} |", it->second.last);
        }
        md += "\n";
    }
    return md;
}

// What the "lod" rows' depth errors measure (lodImageDiff), for the JSON and the table.
constexpr const char* kLodDepthMeaning =
    "the depth AOV's window depth z/w: 0 at the camera's near plane, 1 at its far plane (the planes "
    "enclose the scene's bounding sphere), non-linear in distance";

// A PSNR cell: "exact" for an identical image ("inf" in the JSON), else dB to 2 decimals.
std::string psnrCell(const nlohmann::json& psnr)
{
    return psnr.is_string() ? "exact" : fmt::format("{:.2f}", psnr.get<double>());
}

// The level-of-detail rows (measureLod) as a markdown table, under a heading that says what each
// column compares.
std::string lodTable(const nlohmann::json& lod)
{
    std::string md = fmt::format(
        "\n## Level of detail against --lod off (coverage px: covered in one frame only; beyond 1 px: of "
        "those, farther than 1 px from the --lod off silhouette; depth: |difference| over pixels both "
        "cover, of {}; PSNR vs ref: against SSAA 4 x MSAA 16 of --lod off)\n\n"
        "| scene | camera | backend | E px | triangles | visibility ms | coverage px | beyond 1 px | "
        "depth max | depth mean | PSNR vs off | PSNR vs ref |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        kLodDepthMeaning);
    for (const auto& r : lod) {
        const nlohmann::json& e = r["error_px"];
        md += fmt::format("| {} | {} | {} | {} | {} | {:.3f} | {} | {} | {:.2e} | {:.2e} | {} | {} |\n",
                          r["scene"].get<std::string>(), r["camera"].get<std::string>(),
                          r["backend"].get<std::string>(),
                          e.is_string() ? e.get<std::string>() : fmt::format("{:g}", e.get<double>()),
                          r["triangles"].get<uint64_t>(), r["visibility_ms"].get<double>(),
                          r["coverage_px"].get<uint64_t>(), r["beyond_silhouette_px"].get<uint64_t>(),
                          r["depth_max_error"].get<double>(), r["depth_mean_error"].get<double>(),
                          psnrCell(r["psnr_vs_off"]), psnrCell(r["psnr_vs_reference"]));
    }
    return md;
}

}  // namespace

ImageError imageError(const RgbaImage& image, const RgbaImage& reference)
{
    ImageError e;
    double sum = 0.0;
    size_t n = std::min(image.pixels.size(), reference.pixels.size());
    for (size_t i = 0; i < n; ++i)
        for (int shift = 0; shift < 24; shift += 8) {
            int d = int((image.pixels[i] >> shift) & 0xffu) - int((reference.pixels[i] >> shift) & 0xffu);
            sum += double(d) * d;
            e.maxError = std::max(e.maxError, std::abs(d));
        }
    double mse = n > 0 ? sum / (3.0 * double(n)) : 0.0;
    e.psnr = mse > 0.0 ? 10.0 * std::log10(255.0 * 255.0 / mse) : std::numeric_limits<double>::infinity();
    return e;
}

Result<nlohmann::json> measureAccuracy(raster::Device& device, const StudyScene& s,
                                       const RenderSettings& base, const std::vector<std::string>& methods,
                                       const std::function<void(const std::string&)>& progress)
{
    const std::string backend = backendOf(device);
    auto tell = [&](const std::string& what) {
        if (progress) progress(fmt::format("{} {} on {}", s.name, what, backend));
    };
    tell("reference");
    auto reference =
        renderOnce(device, s.referenceScene ? *s.referenceScene : s.scene, s.camera, referenceSettings(base));
    if (!reference) return reference.error();
    nlohmann::json rows = nlohmann::json::array();
    for (const StudySetting& setting : studySettings(s.textured, methods, s.tessellation)) {
        tell(setting.label);
        auto out = renderOnce(device, s.scene, s.camera, withSetting(base, setting));
        if (!out) return out.error();
        ImageError e = imageError(out->color, reference->color);
        // Silhouette error: pixels covered in one image and not in the other (ids at sample 0).
        size_t silhouette = 0;
        for (size_t i = 0; i < std::min(out->aov.id.size(), reference->aov.id.size()); ++i)
            silhouette += (out->aov.id[i] == EMPTY_ID) != (reference->aov.id[i] == EMPTY_ID);
        rows.push_back({{"scene", s.name},
                        {"backend", backend},
                        {"group", setting.group},
                        {"setting", setting.label},
                        {"method", rasterMethodName(setting.rasterMethod)},
                        {"msaa", setting.msaa},
                        {"ssaa", setting.ssaa},
                        {"texture_filter", textureFilterName(setting.textureFilter)},
                        {"uv", uvInterpolationName(setting.uvInterpolation)},
                        {"tessellate", setting.tessellate},
                        {"tess_edge_px", setting.tessEdgePx},
                        {"tess_max_level", setting.tessMaxLevel},
                        {"silhouette_px", silhouette},
                        {"ms", out->total.medianMs},
                        {"psnr", psnrJson(e.psnr)},
                        {"max_error", e.maxError},
                        {"memory_mib", frameMib(device)}});
    }
    return rows;
}

Result<nlohmann::json> measureLod(raster::Device& device, const std::string& name,
                                  const raster::Scene& handed, const RenderSettings& base,
                                  const std::vector<float>& errors,
                                  const std::function<void(const std::string&)>& progress)
{
    const std::string backend = backendOf(device);
    const Scene& scene = raster::Internal::of(handed).scene;
    auto tell = [&](const std::string& camera, const std::string& what) {
        if (progress) progress(fmt::format("lod {} {} {} on {}", name, camera, what, backend));
    };
    auto session = raster::Session::create(device, handed);
    if (!session) return raster::fromPublic(session.error());
    const std::vector<LodCamera> cameras = lodCameras(scene, base.width, base.height);
    RenderSettings off = base;
    off.lod = LOD_OFF;
    // Every camera's --lod off frame and reference first, then every error: the session's buffers hold
    // either the scene or the hierarchy's scene, and going from one to the other uploads it again (for
    // the 100M sphere, gigabytes), so the frames switch once.
    std::vector<RenderOutput> baselines;
    std::vector<RgbaImage> references;
    for (const LodCamera& c : cameras) {
        tell(c.name, "off");
        auto out = raster::Internal::renderOutput(*session, c.camera, off);
        if (!out) return out.error();
        tell(c.name, "reference");
        auto reference = raster::Internal::renderOutput(*session, c.camera, referenceSettings(off));
        if (!reference) return reference.error();
        baselines.push_back(std::move(*out));
        references.push_back(std::move(reference->color));
    }
    auto row = [&](size_t c, const RenderOutput& out, const nlohmann::json& errorPx) {
        const RenderOutput& baseline = baselines[c];
        const LodImageDiff d = lodImageDiff(out.aov, baseline.aov);
        // The visibility time, as `raster bench` reports it: the frame less deferred shading, which
        // costs the same whatever the triangles (one shading per pixel).
        double shadeMs = 0.0;
        for (const StageTiming& t : out.stages)
            if (t.name == "shade") shadeMs = t.medianMs;
        return nlohmann::json{{"scene", name},
                              {"camera", cameras[c].name},
                              {"camera_spec", orbitSpecString(cameras[c].pose)},
                              {"backend", backend},
                              {"error_px", errorPx},
                              {"triangles", out.stats.trianglesIn},
                              {"scene_triangles", scene.triangleCount()},
                              {"ms", out.total.medianMs},
                              {"visibility_ms", out.total.medianMs - shadeMs},
                              {"coverage_px", d.coveragePx},
                              {"beyond_silhouette_px", d.beyondSilhouettePx},
                              {"baseline_silhouette_px", d.silhouettePx},
                              {"depth_max_error", d.depthMaxError},
                              {"depth_mean_error", d.depthMeanError},
                              {"psnr_vs_off", psnrJson(imageError(out.color, baseline.color).psnr)},
                              {"psnr_vs_reference", psnrJson(imageError(out.color, references[c]).psnr)}};
    };
    std::vector<nlohmann::json> perCamera(cameras.size(), nlohmann::json::array());
    for (size_t c = 0; c < cameras.size(); ++c) perCamera[c].push_back(row(c, baselines[c], "off"));
    for (size_t c = 0; c < cameras.size(); ++c)
        for (float error : errors) {
            tell(cameras[c].name, fmt::format("{:g} px", error));
            RenderSettings on = off;
            on.lod = LOD_ON;
            on.lodErrorPx = error;
            auto out = raster::Internal::renderOutput(*session, cameras[c].camera, on);
            if (!out) return out.error();
            perCamera[c].push_back(row(c, *out, error));
        }
    nlohmann::json rows = nlohmann::json::array();
    for (nlohmann::json& camera : perCamera)
        for (nlohmann::json& r : camera) rows.push_back(std::move(r));
    return rows;
}

Result<nlohmann::json> measureAo(raster::Device& device, const AoStudyScene& scene,
                                 const RenderSettings& base,
                                 const std::function<void(const std::string&)>& progress)
{
    const std::string backend = backendOf(device);
    const raster::Scene handed = raster::Internal::makeScene(scene.scene, scene.name, std::nullopt);
    auto session = raster::Session::create(device, handed);
    if (!session) return raster::fromPublic(session.error());
    RenderSettings settings = base;
    settings.shadingMode = SHADING_AO;
    const double defaultRadius = aoWorldRadius(scene.scene, base);
    // The reference at each radius the sweep uses, once.
    std::map<float, RenderOutput> references;
    for (const AoSetting& a : aoStudySettings()) {
        if (references.count(a.radiusScale)) continue;
        if (progress)
            progress(fmt::format("ao {} reference x{:g} on {}", scene.name, a.radiusScale, backend));
        RenderSettings r = settings;
        r.ao = AO_REFERENCE;
        r.aoRadius = float(defaultRadius * a.radiusScale);
        r.warmup = 0;
        r.repeat = 1;
        auto out = raster::Internal::renderOutput(*session, scene.camera, r);
        if (!out) return out.error();
        references.emplace(a.radiusScale, std::move(*out));
    }
    nlohmann::json rows = nlohmann::json::array();
    for (const AoSetting& a : aoStudySettings()) {
        if (progress)
            progress(fmt::format("ao {} {}x{} x{:g}{} on {}", scene.name, a.slices, a.steps, a.radiusScale,
                                 a.denoise ? "" : " raw", backend));
        RenderSettings g = settings;
        g.ao = AO_GTAO;
        g.aoSlices = a.slices;
        g.aoSteps = a.steps;
        g.aoDenoise = a.denoise ? AO_DENOISE_ON : AO_DENOISE_OFF;
        g.aoRadius = float(defaultRadius * a.radiusScale);
        auto out = raster::Internal::renderOutput(*session, scene.camera, g);
        if (!out) return out.error();
        double shadeMs = 0.0;
        for (const StageTiming& t : out->stages)
            if (t.name == "shade") shadeMs = t.medianMs;
        const double aoMs = aoStagesMs(out->stages);
        const AoImageError e = aoImageError(out->aov, references.at(a.radiusScale).aov);
        rows.push_back({{"scene", scene.name},
                        {"camera_spec", scene.cameraSpec},
                        {"backend", backend},
                        {"slices", a.slices},
                        {"steps", a.steps},
                        {"radius_scale", a.radiusScale},
                        {"radius", g.aoRadius},
                        {"denoise", a.denoise},
                        {"ao_ms", aoMs},
                        {"shade_ms", shadeMs},
                        {"pixels", e.pixels},
                        {"mean_error", e.meanError},
                        {"max_error", e.maxError},
                        {"psnr", e.psnr}});
    }
    return rows;
}

// The ambient-occlusion rows as a markdown table; a row on its scene's Pareto front (no other row of the
// scene at the default radius both faster and closer to the reference) is marked.
std::string aoTable(const nlohmann::json& ao)
{
    std::string md =
        "\n## Ambient occlusion: GTAO against the ray-traced reference (AO image: mean and max |error|, PSNR "
        "with peak 1; ms: the AO stages' GPU time; * on the scene's error-time Pareto front)\n\n"
        "| scene | backend | slices | steps | radius | denoise | AO ms | shade ms | mean error | max error | "
        "PSNR dB | Pareto |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& r : ao) {
        bool front = r["radius_scale"].get<double>() == 1.0;
        for (const auto& o : ao)
            if (front && o["scene"] == r["scene"] && o["backend"] == r["backend"] &&
                o["radius_scale"].get<double>() == 1.0 &&
                o["ao_ms"].get<double>() < r["ao_ms"].get<double>() &&
                o["mean_error"].get<double>() < r["mean_error"].get<double>())
                front = false;
        md += fmt::format(
            "| {} | {} | {} | {} | x{:g} | {} | {:.3f} | {:.3f} | {:.4f} | {:.3f} | {:.1f} | {} |\n",
            r["scene"].get<std::string>(), r["backend"].get<std::string>(), r["slices"].get<int>(),
            r["steps"].get<int>(), r["radius_scale"].get<double>(), r["denoise"].get<bool>() ? "on" : "off",
            r["ao_ms"].get<double>(), r["shade_ms"].get<double>(), r["mean_error"].get<double>(),
            r["max_error"].get<double>(), r["psnr"].get<double>(), front ? "*" : "");
    }
    return md;
}

Result<QualityChoice> chooseQuality(const std::string& quality, const std::string& studyPath,
                                    raster::Device& device, const StudyScene& scene, RenderSettings base)
{
    auto target = parseQualityTarget(quality);
    if (!target) return target.error();
    Result<nlohmann::json> rows = nlohmann::json::array();
    if (!studyPath.empty()) {
        std::ifstream in(studyPath);
        if (!in) return makeError(ExitCode::Usage, "cannot read --study '{}'", studyPath);
        nlohmann::json study = nlohmann::json::parse(in, nullptr, false);
        if (study.is_discarded())
            return makeError(ExitCode::Usage, "--study '{}' is not valid JSON", studyPath);
        rows = accuracyRowsFor(study, scene.name, backendOf(device));
        if (!rows) return makeError(ExitCode::Usage, "--study '{}': {}", studyPath, rows.error().message);
    } else {
        // The measurement's own renders need no AOVs, and the reference's 256 samples per pixel would
        // exceed what --aov-samples may write.
        base.warmup = 1;
        base.repeat = kQualityRepeat;
        base.aovSamples = false;
        base.surfaceAovs = false;
        rows = measureAccuracy(device, scene, base, rasterMethodNames());
    }
    if (!rows) return rows.error();
    auto row = pickCheapest(*rows, *target);
    if (!row) return row.error();
    auto setting = settingFromRow(*row);
    if (!setting) return setting.error();
    return QualityChoice{*setting, describeChoice(*target, *row, *setting)};
}

Result<nlohmann::json> runStudy(const StudyOptions& o)
{
    SR_TRY(checkNames(o.backends, {"cuda", "vulkan"}, "backend"));
    SR_TRY(checkNames(o.methods, rasterMethodNames(), "raster method"));
    SR_TRY(checkNames(o.scenes, studySceneNames(), "scene"));
    SR_TRY(checkNames(o.lodScenes, lodSceneNames(), "LOD scene"));
    SR_TRY(checkNames(o.aoScenes, aoSceneNames(), "AO scene"));
    if (o.methods.empty()) return makeError(ExitCode::Usage, "study: no raster method to run (--methods)");
    const bool tty = isatty(fileno(stderr));
    auto progress = [&](const std::string& what) {
        if (tty) fmt::print(stderr, "\r\033[Kstudy: {}", what);
    };
    std::vector<StudyScene> scenes;
    for (const std::string& name : o.scenes) {
        if (name == "bunny" && !std::filesystem::exists(o.bunnyPath)) continue;
        auto scene = makeStudyScene(name, o.width, o.height, o.bunnyPath);
        if (!scene) return scene.error();
        scenes.push_back(std::move(*scene));
    }
    // The LOD scenes, built once for every backend (bunny-fine's subdivision, the 100M sphere).
    std::vector<std::pair<std::string, raster::Scene>> lodScenes;
    for (const std::string& name : o.lodScenes) {
        if (name != "sphere" && !std::filesystem::exists(o.bunnyPath)) continue;
        progress(fmt::format("lod {} (building)", name));
        auto scene = makeLodScene(name, o.lodRings, o.bunnyPath);
        if (!scene) return scene.error();
        lodScenes.emplace_back(name, raster::Internal::makeScene(std::move(*scene), name, std::nullopt));
    }
    std::vector<AoStudyScene> aoScenes;
    for (const std::string& name : o.aoScenes) {
        if (name == "bunny-plane" && !std::filesystem::exists(o.bunnyPath)) continue;
        auto scene = makeAoScene(name, o.width, o.height, o.bunnyPath);
        if (!scene) return scene.error();
        aoScenes.push_back(std::move(*scene));
    }
    // The cases depend on the axis and size alone: built once, drawn on every backend with every method.
    std::vector<Axis> axes;
    for (const std::string& axis : o.axes) {
        axes.push_back({axis, stressCases(axis, o.stressSize)});
        if (axes.back().cases.empty())
            return makeError(ExitCode::Usage, "study: unknown stress axis '{}'", axis);
    }
    // The graphics pipeline runs on the Vulkan device the study uses, else on the first one.
    const bool vulkanStudied = std::find(o.backends.begin(), o.backends.end(), "vulkan") != o.backends.end();
    Oracle oracle(vulkanStudied ? o.device : -1);

    // What the accuracy and level-of-detail renders share: the size, the timing and the shading.
    RenderSettings base;
    base.width = o.width;
    base.height = o.height;
    base.warmup = o.warmup;
    base.repeat = o.repeat;
    base.shadingMode = SHADING_BLINN_PHONG;
    nlohmann::json accuracy = nlohmann::json::array(), stability = nlohmann::json::array();
    nlohmann::json lod = nlohmann::json::array(), ao = nlohmann::json::array();
    nlohmann::json devices = nlohmann::json::object();
    for (const std::string& backend : o.backends) {
        auto device = raster::Internal::openNamed(backend, o.device);
        if (!device) return device.error();
        devices[backend] = device->info().name;
        for (const StudyScene& s : scenes) {
            auto rows = measureAccuracy(*device, s, base, o.methods, progress);
            if (!rows) return rows.error();
            for (auto& row : *rows) accuracy.push_back(std::move(row));
        }
        for (const auto& [name, scene] : lodScenes) {
            auto rows = measureLod(*device, name, scene, base, o.lodErrors, progress);
            if (!rows) return rows.error();
            for (auto& row : *rows) lod.push_back(std::move(row));
        }
        for (const AoStudyScene& scene : aoScenes) {
            auto rows = measureAo(*device, scene, base, progress);
            if (!rows) return rows.error();
            for (auto& row : *rows) ao.push_back(std::move(row));
        }
        for (size_t a = 0; a < axes.size(); ++a)
            for (size_t i = 0; i < axes[a].cases.size(); ++i) {
                const StressCase& c = axes[a].cases[i];
                progress(fmt::format("{} {:g} oracle", c.axis, c.x));
                auto reference = oracle.render(a, i, c);
                if (!reference) return reference.error();
                for (const std::string& method : o.methods) {
                    progress(fmt::format("{} {:g} {} on {}", c.axis, c.x, method, backend));
                    RenderSettings settings = c.settings;
                    settings.rasterMethod = *rasterMethodFromName(method);
                    auto out = renderOnce(*device, c.scene, c.camera, settings);
                    if (!out) return out.error();
                    StressFailures f = countFailures(c, *out);
                    stability.push_back({{"axis", c.axis},
                                         {"method", method},
                                         {"backend", backend},
                                         {"x", c.x},
                                         {"cracks", f.cracks},
                                         {"double_hits", f.doubleHits},
                                         {"wrong_depth_order", f.wrongDepthOrder},
                                         {"oracle_mismatches",
                                          *reference ? nlohmann::json(oracleMismatches(*out, **reference))
                                                     : nlohmann::json(nullptr)}});
                }
            }
    }
    if (tty) fmt::print(stderr, "\r\033[K");
    return nlohmann::json{{"date", today()},
                          {"devices", devices},
                          {"width", o.width},
                          {"height", o.height},
                          {"methods", o.methods},
                          {"stress_size", o.stressSize},
                          {"accuracy", accuracy},
                          {"stability", stability},
                          {"lod", lod},
                          {"lod_depth", kLodDepthMeaning},
                          {"ao", ao}};
}

std::string studyMarkdown(const nlohmann::json& study)
{
    std::string md =
        "| scene | backend | group | setting | method | ms | PSNR dB | max error | MiB |\n"
        "|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& a : study["accuracy"]) {
        std::string psnr = a["psnr"].is_string() ? "exact" : fmt::format("{:.2f}", a["psnr"].get<double>());
        md += fmt::format("| {} | {} | {} | {} | {} | {:.3f} | {} | {} | {:.1f} |\n",
                          a["scene"].get<std::string>(), a["backend"].get<std::string>(),
                          a["group"].get<std::string>(), a["setting"].get<std::string>(),
                          a.value("method", std::string("fixed8")), a["ms"].get<double>(), psnr,
                          a["max_error"].get<int>(), a.value("memory_mib", 0.0));
    }
    md +=
        "\n| axis | method | backend | x | cracks | double hits | wrong depth order | oracle mismatches "
        "|\n|---|---|---|---|---|---|---|---|\n";
    for (const auto& s : study["stability"]) {
        const nlohmann::json& oracle = s["oracle_mismatches"];
        md += fmt::format("| {} | {} | {} | {:g} | {} | {} | {} | {} |\n", s["axis"].get<std::string>(),
                          s["method"].get<std::string>(), s["backend"].get<std::string>(),
                          s["x"].get<double>(), s["cracks"].get<uint64_t>(), s["double_hits"].get<uint64_t>(),
                          s["wrong_depth_order"].get<uint64_t>(),
                          oracle.is_number() ? std::to_string(oracle.get<uint64_t>()) : "n/a");
    }
    if (!study["stability"].empty())
        md +=
            "\n## First failing value per axis and method (cracks + double hits + wrong depth order + oracle "
            "mismatches > 0)\n\n" +
            firstFailureTable(study["stability"]);
    if (study.contains("lod") && !study["lod"].empty()) md += lodTable(study["lod"]);
    if (study.contains("ao") && !study["ao"].empty()) md += aoTable(study["ao"]);
    return md;
}

}  // namespace sr
