// study.cpp - see study.h.
#include "cli/study.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <limits>
#include <map>

#include <fmt/format.h>
#include <unistd.h>

#include "cli/backend.h"
#include "scene/camera.h"
#include "scene/scene.h"
#include "study/stress.h"

namespace sr {
namespace {

struct StudyScene {
    std::string name;
    Scene scene;
    CameraMatrices camera;
    bool textured = false;
};

// One setting of a group: a label and what it changes from the 1x, trilinear, perspective baseline.
struct Setting {
    std::string group, label;
    uint32_t msaa = 1, ssaa = 1;
    uint32_t textureFilter = TEXTURE_FILTER_TRILINEAR;
    uint32_t uvInterpolation = UV_PERSPECTIVE;
};

std::vector<Setting> settingsFor(const StudyScene& s)
{
    std::vector<Setting> out;
    for (uint32_t m : {1u, 2u, 4u, 8u, 16u}) out.push_back({"aa", fmt::format("msaa{}", m), m, 1});
    out.push_back({"aa", "ssaa2", 1, 2});
    out.push_back({"aa", "ssaa3", 1, 3});
    out.push_back({"aa", "ssaa2+msaa4", 4, 2});
    if (s.textured) {
        out.push_back({"texture", "nearest", 1, 1, TEXTURE_FILTER_NEAREST});
        out.push_back({"texture", "bilinear", 1, 1, TEXTURE_FILTER_BILINEAR});
        out.push_back({"texture", "trilinear", 1, 1, TEXTURE_FILTER_TRILINEAR});
        out.push_back({"uv", "perspective", 1, 1, TEXTURE_FILTER_TRILINEAR, UV_PERSPECTIVE});
        out.push_back({"uv", "affine", 1, 1, TEXTURE_FILTER_TRILINEAR, UV_AFFINE});
    }
    return out;
}

Result<std::vector<StudyScene>> studyScenes(const StudyOptions& o)
{
    std::vector<StudyScene> scenes;
    auto add = [&](std::string name, Scene scene, const CameraSpec& spec, bool textured) -> Status {
        auto camera = resolveCamera(spec, scene, o.width, o.height);
        if (!camera) return camera.error();
        scenes.push_back({std::move(name), std::move(scene), *camera, textured});
        return okStatus();
    };
    SR_TRY(add("builtin", builtinScene(), CameraSpec{}, false));
    // The textured plane at a grazing angle, where texture filtering matters most.
    auto checker = builtinSceneNamed("builtin:checker");
    if (!checker) return checker.error();
    auto grazing = parseCameraSpec("orbit:0,6,12");
    if (!grazing) return grazing.error();
    SR_TRY(add("checker-grazing", std::move(*checker), *grazing, true));
    auto dense = builtinSceneNamed("builtin:dense");
    if (!dense) return dense.error();
    SR_TRY(add("dense", std::move(*dense), CameraSpec{}, false));
    if (!o.bunnyPath.empty() && std::filesystem::exists(o.bunnyPath)) {
        auto bunny = loadScene(o.bunnyPath);
        if (!bunny) return bunny.error();
        SR_TRY(add("bunny", std::move(*bunny), CameraSpec{}, false));
    }
    return scenes;
}

Result<std::unique_ptr<ComputeDevice>> openDevice(const std::string& backend, int device)
{
    return makeComputeDevice(backend == "cuda" ? BackendKind::Cuda : BackendKind::Vulkan, device);
}

std::string today()
{
    std::time_t now = std::time(nullptr);
    char text[16];
    std::strftime(text, sizeof text, "%Y-%m-%d", std::gmtime(&now));
    return text;
}

// JSON has no infinity: identical images get null and the chart treats them as exact.
nlohmann::json psnrJson(double psnr)
{
    return std::isinf(psnr) ? nlohmann::json("inf") : nlohmann::json(psnr);
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

Result<nlohmann::json> runStudy(const StudyOptions& o)
{
    for (const std::string& b : o.backends)
        if (b != "cuda" && b != "vulkan")
            return makeError(ExitCode::Usage, "study: unknown backend '{}' (cuda, vulkan)", b);
    const bool tty = isatty(fileno(stderr));
    auto progress = [&](const std::string& what) {
        if (tty) fmt::print(stderr, "\r\033[Kstudy: {}", what);
    };
    auto scenes = studyScenes(o);
    if (!scenes) return scenes.error();

    nlohmann::json accuracy = nlohmann::json::array(), stability = nlohmann::json::array();
    nlohmann::json devices = nlohmann::json::object();
    for (const std::string& backend : o.backends) {
        auto device = openDevice(backend, o.device);
        if (!device) return device.error();
        devices[backend] = (*device)->info().name;
        for (const StudyScene& s : *scenes) {
            RenderSettings base;
            base.width = o.width;
            base.height = o.height;
            base.warmup = o.warmup;
            base.repeat = o.repeat;
            base.shadingMode = SHADING_BLINN_PHONG;
            // The reference: 64 samples per pixel, the best filter, perspective-correct coordinates.
            RenderSettings ref = base;
            ref.msaa = 16;
            ref.ssaa = 4;
            ref.textureFilter = TEXTURE_FILTER_TRILINEAR;
            ref.warmup = 0;
            ref.repeat = 1;
            progress(fmt::format("{} reference on {}", s.name, backend));
            auto reference = renderScene(**device, s.scene, s.camera, ref);
            if (!reference) return reference.error();
            for (const Setting& setting : settingsFor(s)) {
                progress(fmt::format("{} {} on {}", s.name, setting.label, backend));
                RenderSettings r = base;
                r.msaa = setting.msaa;
                r.ssaa = setting.ssaa;
                r.textureFilter = setting.textureFilter;
                r.uvInterpolation = setting.uvInterpolation;
                auto out = renderScene(**device, s.scene, s.camera, r);
                if (!out) return out.error();
                ImageError e = imageError(out->color, reference->color);
                accuracy.push_back({{"scene", s.name},
                                    {"backend", backend},
                                    {"group", setting.group},
                                    {"setting", setting.label},
                                    {"ms", out->total.medianMs},
                                    {"psnr", psnrJson(e.psnr)},
                                    {"max_error", e.maxError},
                                    {"memory_mib", double(out->peakDeviceBytes) / (1 << 20)}});
            }
        }
        for (const std::string& axis : o.axes) {
            std::vector<StressCase> cases = stressCases(axis, o.stressSize);
            if (cases.empty()) return makeError(ExitCode::Usage, "study: unknown stress axis '{}'", axis);
            for (const StressCase& c : cases) {
                progress(fmt::format("{} {} on {}", axis, c.x, backend));
                auto out = renderScene(**device, c.scene, c.camera, c.settings);
                if (!out) return out.error();
                StressFailures f = countFailures(c, *out);
                stability.push_back({{"axis", axis},
                                     {"method", "fixed8"},
                                     {"backend", backend},
                                     {"x", c.x},
                                     {"cracks", f.cracks},
                                     {"double_hits", f.doubleHits},
                                     {"wrong_depth_order", f.wrongDepthOrder},
                                     {"oracle_mismatches", nullptr}});
            }
        }
    }
    if (tty) fmt::print(stderr, "\r\033[K");
    return nlohmann::json{{"date", today()},    {"devices", devices},   {"width", o.width},
                          {"height", o.height}, {"accuracy", accuracy}, {"stability", stability}};
}

std::string studyMarkdown(const nlohmann::json& study)
{
    std::string md =
        "| scene | backend | group | setting | ms | PSNR dB | max error |\n|---|---|---|---|---|---|---|\n";
    for (const auto& a : study["accuracy"]) {
        std::string psnr = a["psnr"].is_string() ? "exact" : fmt::format("{:.2f}", a["psnr"].get<double>());
        md += fmt::format("| {} | {} | {} | {} | {:.3f} | {} | {} |\n", a["scene"].get<std::string>(),
                          a["backend"].get<std::string>(), a["group"].get<std::string>(),
                          a["setting"].get<std::string>(), a["ms"].get<double>(), psnr,
                          a["max_error"].get<int>());
    }
    md +=
        "\n| axis | method | backend | x | cracks | double hits | wrong depth order "
        "|\n|---|---|---|---|---|---|---|\n";
    for (const auto& s : study["stability"])
        md += fmt::format("| {} | {} | {} | {:g} | {} | {} | {} |\n", s["axis"].get<std::string>(),
                          s["method"].get<std::string>(), s["backend"].get<std::string>(),
                          s["x"].get<double>(), s["cracks"].get<uint64_t>(), s["double_hits"].get<uint64_t>(),
                          s["wrong_depth_order"].get<uint64_t>());
    return md;
}

}  // namespace sr
