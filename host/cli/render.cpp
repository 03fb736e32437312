// render.cpp - `raster render`: the arguments checked before anything is loaded, then the library's own
// way through: a raster::Scene, a raster::Device, one raster::Session, raster::Frame and its files.
#include "cli/render.h"

#include <algorithm>
#include <cstdio>
#include <optional>

#include <unistd.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "raster/raster.h"

#include "api/api_internal.h"
#include "api/frame_files.h"
#include "base/warnings.h"
#include "batch/turntable.h"
#include "cli/usage_errors.h"
#include "io/file_write.h"
#include "io/image_io.h"
#include "camera/camera.h"
#include "scene/primitive_mode.h"
#include "study/ao_study.h"
#include "study/quality.h"
#include "study/study_runner.h"
#include "study/scenes.h"
#include "study/settings_study.h"

namespace sr {
namespace {

// The scene a path names, as the library holds it: a study scene ("study:NAME", framed by its own camera
// under the auto camera unless `orbits`), else what raster::Scene::load reads (the built-in scene for
// an empty path). The loader's warnings are printed.
Result<raster::Scene> loadScene(const std::string& path, const RenderSettings& s, bool orbits)
{
    const std::string prefix = kStudyScenePrefix;
    if (path.compare(0, prefix.size(), prefix) == 0) {
        const std::string name = path.substr(prefix.size());
        const std::vector<std::string>& aoScenes = aoSceneNames();
        std::optional<CameraMatrices> own;
        Scene scene;
        if (std::find(aoScenes.begin(), aoScenes.end(), name) != aoScenes.end() && name != "builtin") {
            // The ambient-occlusion group's scenes (study/ao_study.h): "study:bunny-plane",
            // "study:stress-grazing",
            // ...
            auto study = makeAoScene(name, s.width, s.height, StudyOptions{}.bunnyPath);
            if (!study) return study.error();
            scene = std::move(study->scene);
            own = study->camera;
        } else {
            auto study = makeStudyScene(name, s.width, s.height, StudyOptions{}.bunnyPath);
            if (!study) return study.error();
            scene = std::move(study->scene);
            own = study->camera;
        }
        return raster::Internal::makeScene(std::move(scene), path, orbits ? std::nullopt : own);
    }
    auto scene = raster::Scene::load(path.empty() ? "builtin" : path);
    if (!scene) return raster::fromPublic(scene.error());
    for (const std::string& warning : scene->warnings()) warnLine(warning);
    return std::move(*scene);
}

// The turntable: one session (the scene uploaded once, the device's buffers reused), a progress line on
// stderr when it is a terminal, one summary line.
Status runTurntable(const RenderCommand& cmd, raster::Session& session, const raster::Scene& scene,
                    const raster::Settings& settings, TurntableOptions frames)
{
    const bool progress = !cmd.quiet && isatty(STDERR_FILENO);
    if (progress)
        frames.progress = [](uint32_t done, uint32_t total) {
            fmt::print(stderr, "\rframe {}/{}{}", done, total, done == total ? "\n" : "");
            std::fflush(stderr);
        };
    auto result = renderTurntable(session, scene, settings, frames);
    if (!result) {
        // The error line must not continue the progress line.
        if (progress) fmt::print(stderr, "\n");
        return result.error();
    }
    if (!cmd.quiet) {
        // The first and last cameras as specs, so any frame can be rendered again on its own.
        const std::vector<double>& ms = result->frameGpuMs;
        fmt::print(
            "{}: {} frame{} from --camera {} to {}: {}x{} on {} ({}), {} triangles, GPU ms per frame min "
            "{:.4f} median {:.4f} max {:.4f}\n",
            cmd.output.empty() ? cmd.aovPath : cmd.output, frames.frames, frames.frames == 1 ? "" : "s",
            result->firstCamera, result->lastCamera, cmd.options.settings.width, cmd.options.settings.height,
            raster::backendName(result->device.backend), result->device.name, result->triangles,
            *std::min_element(ms.begin(), ms.end()), median(ms), *std::max_element(ms.begin(), ms.end()));
    }
    return okStatus();
}

// The summary `raster render` prints: the frame's counts (from its statistics) and its stage times.
void printSummary(const RenderCommand& cmd, const raster::Frame& frame)
{
    const nlohmann::json stats = nlohmann::json::parse(frame.statsJson);
    const nlohmann::json& t = stats.at("triangles");
    // The graphics pipeline's fixed-function stages count nothing we read back (null counts).
    const bool counted = !t.at("rasterized").is_null();
    const uint64_t linesIn = t.at("lines_in"), pointsIn = t.at("points_in");
    std::string lines, points, counts;
    if (counted) {
        lines = linesIn ? fmt::format(", {} line segments ({} drawn)", linesIn, t.at("lines").get<uint64_t>())
                        : "";
        points =
            pointsIn ? fmt::format(", {} points ({} drawn)", pointsIn, t.at("points").get<uint64_t>()) : "";
        counts = fmt::format("{} culled, {} clipped, {} triangles rasterized", t.at("culled").get<uint64_t>(),
                             t.at("clipped").get<uint64_t>(), t.at("rasterized").get<uint64_t>());
    } else {
        lines = linesIn ? fmt::format(", {} line segments", linesIn) : "";
        points = pointsIn ? fmt::format(", {} points", pointsIn) : "";
        counts = "culled, clipped and rasterized n/a (the graphics pipeline does not count them)";
    }
    fmt::print("{}: {}x{} on {} ({}), {} triangles{}{}: {}\n", cmd.output.empty() ? cmd.aovPath : cmd.output,
               frame.width, frame.height, stats.at("backend").get<std::string>(), frame.device.name,
               t.at("in").get<uint64_t>(), lines, points, counts);
    fmt::print("{:<14} {:>10} {:>10} {:>10}\n", "stage (ms)", "min", "median", "max");
    for (const raster::StageTime& st : frame.stages)
        fmt::print("{:<14} {:>10.4f} {:>10.4f} {:>10.4f}\n", st.name, st.minMs, st.medianMs, st.maxMs);
}

}  // namespace

Status runRender(RenderCommand& cmd)
{
    // An EXR asked for alone is the only output: no render.png appears beside it unasked.
    if (cmd.output.empty() && cmd.aovPath.empty()) cmd.output = "render.png";
    RenderSettings s = cmd.options.resolved();
    // Each output in its format and a file of its own, before anything is loaded or rendered.
    SR_TRY(checkColorExtension("-o", cmd.output));
    SR_TRY(checkOutputNames(
        {{"-o", cmd.output, ""}, {"--aov", cmd.aovPath, ".exr"}, {"--stats", cmd.statsPath, ""}}));
    // An encoder setting is for a file it encodes: one given without that file would change nothing.
    ImageEncoding encoding;
    if (!cmd.pngCompression.empty()) {
        auto png = parsePngCompression(cmd.pngCompression, "--png-compression");
        if (!png) return png.error();
        if (cmd.output.empty() || isNpyPath(cmd.output))
            return makeError(ExitCode::Usage, "--png-compression needs a PNG output (-o FILE.png){}",
                             cmd.output.empty() ? "" : ", not " + quotedInput(cmd.output));
        encoding.png = *png;
    }
    if (!cmd.exrCompression.empty()) {
        auto exr = parseExrCompression(cmd.exrCompression, "--exr-compression");
        if (!exr) return exr.error();
        if (cmd.aovPath.empty()) return makeError(ExitCode::Usage, "--exr-compression needs --aov FILE");
        encoding.exr = *exr;
    }
    if (!cmd.scenePath.empty() && cmd.scenePath.compare(0, 7, "builtin") != 0)
        for (const auto& [label, path] : {std::pair<const char*, const std::string&>{"-o", cmd.output},
                                          {"--aov", cmd.aovPath},
                                          {"--stats", cmd.statsPath}})
            if (!path.empty() && resolvedPath(path) == resolvedPath(cmd.scenePath))
                return makeError(ExitCode::Usage, "{} {} would overwrite the scene", label,
                                 quotedInput(path));
    SR_TRY(checkAovSamples(s, !cmd.aovPath.empty(), "--aov-samples", "--aov FILE"));

    // A malformed target, camera or frame pattern is reported before anything is loaded or rendered.
    if (!cmd.quality.empty()) SR_TRY(parseQualityTarget(cmd.quality));
    auto cameraSpec = parseCameraSpec(cmd.options.camera);
    if (!cameraSpec) return cameraSpec.error();
    auto model = parseModelSpec(cmd.options.model);
    if (!model) return model.error();
    const bool turntable = cmd.frames > 0;
    TurntableOptions frames;
    if (turntable) {
        if (cmd.backend == "vulkan-graphics")
            return makeError(ExitCode::Usage,
                             "--frames renders on one compute device: use --backend auto, cuda or vulkan");
        if (cameraSpec->kind == CameraSpec::Kind::Gltf)
            return makeError(ExitCode::Usage,
                             "--frames orbits the scene: use --camera auto or orbit:AZ,EL,DIST[,TX,TY,TZ]");
        auto range = parseAzimuthRange(cmd.orbitRange);
        if (!range) return range.error();
        frames.frames = cmd.frames;
        frames.azimuth = *range;
        frames.encoding = encoding;
        if ((frames.hasPng = !cmd.output.empty())) {
            auto png = parseFramePattern("-o", cmd.output);
            if (!png) return png.error();
            frames.png = *png;
        }
        if ((frames.hasAov = !cmd.aovPath.empty())) {
            auto aov = parseFramePattern("--aov", cmd.aovPath);
            if (!aov) return aov.error();
            frames.aov = *aov;
        }
        if ((frames.hasStats = !cmd.statsPath.empty())) {
            auto stats = parseFramePattern("--stats", cmd.statsPath);
            if (!stats) return stats.error();
            frames.stats = *stats;
        }
    }
    if (!cmd.quality.empty() && cmd.backend == "vulkan-graphics")
        return makeError(ExitCode::Usage,
                         "--quality picks among the compute backends' settings: use --backend auto, cuda or "
                         "vulkan");

    auto scene = loadScene(cmd.scenePath, s, turntable);
    if (!scene) return scene.error();
    auto device = raster::Device::open(*raster::parseBackend(cmd.backend), cmd.device);
    if (!device) return raster::fromPublic(device.error());
    if (!cmd.quality.empty()) {
        // --quality measures the study's settings on this device, scene (as drawn) and camera.
        auto view = raster::Internal::view(*scene, raster::Camera::fromSpec("auto"),
                                           raster::Internal::makeSettings(cmd.options));
        if (!view) return raster::fromPublic(view.error());
        StudyScene study;
        study.name = studySceneNameFor(cmd.scenePath);
        study.scene = std::move(view->first);
        study.camera = view->second;
        study.textured = !study.scene.textures.empty();
        auto choice = chooseQuality(cmd.quality, cmd.studyPath, *device, study, s);
        if (!choice) return choice.error();
        // What was chosen is what the frames and the statistics' echo use.
        cmd.options.settings = withSetting(cmd.options.settings, choice->setting);
        s = cmd.options.resolved();
        cmd.options.tessMaxLevel = s.tessMaxLevel;
        SR_TRY(checkAovSamples(s, true, "--aov-samples (with what --quality chose)", "--aov FILE"));
        if (!cmd.quiet) fmt::print("{}\n", choice->line);
    }
    const raster::Settings settings = raster::Internal::makeSettings(cmd.options);
    auto session = raster::Session::create(*device, *scene);
    if (!session) return raster::fromPublic(session.error());
    if (turntable) return runTurntable(cmd, *session, *scene, settings, frames);

    // The surface channels cost a host pass over the frame, and the ids and depth a pass on the device
    // (stage aovs): only for an EXR that will hold them.
    raster::RenderRequest request;
    request.surfaceAovs = !cmd.aovPath.empty();
    request.outputs = cmd.aovPath.empty() ? raster::OutputColor : raster::OutputImages;
    request.stats = !cmd.statsPath.empty() || !cmd.quiet;  // the file, or the summary's counts
    auto frame = session->render(raster::Camera::fromSpec("auto"), settings, request);
    if (!frame) return raster::fromPublic(frame.error());
    for (const std::string& warning : frame->warnings) warnLine(warning);
    FileGroup files;
    SR_TRY(stageFrame(files, *frame, OutputPaths{cmd.output, cmd.aovPath, cmd.statsPath}, encoding));
    SR_TRY(files.commit());
    if (!cmd.quiet) printSummary(cmd, *frame);
    return okStatus();
}

}  // namespace sr
