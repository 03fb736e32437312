// main.cpp - the `raster` command line: it parses the arguments and calls one function per subcommand
// (cli/commands.h lists them: `raster commands`). The only place where errors become messages and exit
// codes.
#include <algorithm>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "bench/bench_runner.h"
#include "cli/batch.h"
#include "cli/commands.h"
#include "cli/options.h"
#include "cli/render.h"
#include "cli/usage_errors.h"
#include "io/compare.h"
#include "io/file_write.h"
#include "io/image_io.h"
#include "scene/scene.h"
#include "settings/schema.h"
#include "api/stats_json.h"
#include "study/study_runner.h"
#include "viewer/controls.h"
#include "viewer/view_loop.h"

namespace sr {
namespace {

struct CompareCommand {
    std::string a, b;
    std::string diffPath;
    CompareTolerance tolerance;  // the fields whose flag was given (CompareFlags)
};

// Which tolerance flags were given: each one replaces that part of the pair's documented tolerance.
struct CompareFlags {
    CLI::Option *colour = nullptr, *ids = nullptr, *depth = nullptr, *fraction = nullptr;
};

// Exit code 0 within tolerance, 1 outside it (ExitCode::CompareFailed), 2 for unreadable inputs.
Result<bool> runCompare(const CompareCommand& cmd, const CompareFlags& flags)
{
    SR_TRY(checkOutputNames({{"-o", cmd.diffPath, ".png"}}));
    // The default is what the project documents for the two backends that made the files.
    // A file whose origin cannot be read has none: reading its pixels below reports what is wrong.
    auto readOrigin = [](const std::string& path) {
        auto origin = fileOrigin(path);
        return origin ? *origin : FileOrigin{};
    };
    const FileOrigin originA = readOrigin(cmd.a), originB = readOrigin(cmd.b);
    PairTolerance pair = documentedTolerance(originA.origin, originB.origin, isExrPath(cmd.a));
    CompareTolerance tol = pair.tolerance;
    std::vector<std::string> given;
    if (flags.colour->count()) tol.colorLsb = cmd.tolerance.colorLsb, given.push_back("--tolerance");
    if (flags.ids->count())
        tol.maxIdMismatches = cmd.tolerance.maxIdMismatches, given.push_back("--max-id-mismatches");
    if (flags.depth->count())
        tol.depthTolerance = cmd.tolerance.depthTolerance, given.push_back("--depth-tolerance");
    if (flags.fraction->count())
        tol.maxFraction = cmd.tolerance.maxFraction, given.push_back("--max-fraction");
    auto report = compareFiles(cmd.a, cmd.b, tol);
    if (!report) return report.error();
    auto madeBy = [](const std::string& path, const FileOrigin& f) {
        if (f.origin.backend.empty()) return fmt::format("  {}: no backend recorded\n", path);
        return fmt::format("  {}: {}{} (from {})\n", path, f.origin.backend,
                           f.origin.device.empty() ? "" : " on " + f.origin.device, f.source);
    };
    std::string rule = "  Tolerance: " + pair.rule;
    if (!given.empty()) rule += fmt::format("; overridden by {}", fmt::join(given, ", "));
    fmt::print("Comparing \"{}\" and \"{}\" ({}x{})\n{}{}{}\n{}", cmd.a, cmd.b, report->width, report->height,
               madeBy(cmd.a, originA), madeBy(cmd.b, originB), rule, formatReport(*report, tol));
    if (!cmd.diffPath.empty()) SR_TRY(writePng(cmd.diffPath, report->heatmap));
    return report->pass;
}

struct BenchCommand {
    std::string backends = "cuda,vulkan,vulkan-graphics";
    std::string resolutions = "1920x1080";
    std::string scenes;
    std::string msaa;
    std::string clusters;
    std::string lod;
    std::string ao;
    std::string jsonPath;
    BenchOptions options;
};

std::vector<std::string> splitList(const std::string& text)
{
    std::vector<std::string> items;
    std::istringstream in(text);
    for (std::string item; std::getline(in, item, ',');)
        if (!item.empty()) items.push_back(item);
    return items;
}

Status runBenchCommand(BenchCommand& cmd)
{
    BenchOptions& o = cmd.options;
    o.backends = splitList(cmd.backends);
    o.scenes = splitList(cmd.scenes);
    o.resolutions.clear();
    for (const std::string& r : splitList(cmd.resolutions)) {
        unsigned w = 0, h = 0;
        char x = 0;
        std::istringstream in(r);
        if (!(in >> w >> x >> h) || x != 'x' || w < 1 || h < 1 || w > MAX_FRAMEBUFFER_DIM ||
            h > MAX_FRAMEBUFFER_DIM)
            return makeError(ExitCode::Usage, "invalid --resolutions entry '{}': expected WxH up to {}", r,
                             MAX_FRAMEBUFFER_DIM);
        o.resolutions.push_back({w, h});
    }
    if (!cmd.msaa.empty()) {
        o.msaa.clear();
        for (const std::string& m : splitList(cmd.msaa)) {
            auto samples = parseSettingText(setting("msaa"), m, "--msaa entry");
            if (!samples) return samples.error();
            o.msaa.push_back(samples->get<uint32_t>());
        }
    }
    if (!cmd.clusters.empty()) {
        o.clusters.clear();
        for (const std::string& c : splitList(cmd.clusters)) {
            auto mode = choiceValue(setting("clusters"), c, "--clusters entry");
            if (!mode) return mode.error();
            o.clusters.push_back(*mode);
        }
    }
    if (!cmd.lod.empty()) {
        o.lod.clear();
        for (const std::string& l : splitList(cmd.lod)) {
            if (l == "off") {
                o.lod.push_back(0.0f);
                continue;
            }
            auto error = parseSettingText(setting("lod-error-px"), l, "--lod entry");
            if (!error) return error.error();
            o.lod.push_back(error->get<float>());
        }
    }
    if (!cmd.ao.empty()) {
        o.ao.clear();
        for (const std::string& a : splitList(cmd.ao)) {
            auto mode = choiceValue(setting("ao"), a, "--ao entry");
            if (!mode) return mode.error();
            if (*mode == AO_REFERENCE)
                return makeError(ExitCode::Usage,
                                 "bench --ao: off or gtao (the reference is the host's, untimed)");
            o.ao.push_back(*mode);
        }
    }
    auto bench = runBench(o);
    if (!bench) return bench.error();
    if (!cmd.jsonPath.empty()) SR_TRY(writeJson(cmd.jsonPath, *bench));
    fmt::print("{}", benchMarkdown(*bench));
    return okStatus();
}

struct StudyCommand {
    std::string backends = "vulkan";
    std::string axes = "magnitude,slivers,near,coplanar";
    std::string methods = fmt::format("{}", fmt::join(rasterMethodNames(), ","));
    std::string scenes = fmt::format("{}", fmt::join(studySceneNames(), ","));
    std::string lodScenes = fmt::format("{}", fmt::join(StudyOptions{}.lodScenes, ","));
    std::string lodErrors = fmt::format("{:g}", fmt::join(StudyOptions{}.lodErrors, ","));
    std::string aoScenes = fmt::format("{}", fmt::join(StudyOptions{}.aoScenes, ","));
    std::string jsonPath;
    StudyOptions options;
};

Status runStudyCommand(StudyCommand& cmd)
{
    cmd.options.backends = splitList(cmd.backends);
    cmd.options.axes = splitList(cmd.axes);
    cmd.options.methods = splitList(cmd.methods);
    cmd.options.scenes = splitList(cmd.scenes);
    cmd.options.lodScenes = splitList(cmd.lodScenes);
    cmd.options.aoScenes = splitList(cmd.aoScenes);
    auto lodErrors = parseLodErrors(cmd.lodErrors);
    if (!lodErrors) return lodErrors.error();
    cmd.options.lodErrors = *lodErrors;
    auto study = runStudy(cmd.options);
    if (!study) return study.error();
    if (!cmd.jsonPath.empty()) SR_TRY(writeJson(cmd.jsonPath, *study));
    fmt::print("{}", studyMarkdown(*study));
    return okStatus();
}

}  // namespace
}  // namespace sr

int main(int argc, char** argv)
{
    using namespace sr;
    CLI::App app{"raster: a software rasterization pipeline on CUDA and Vulkan compute"};
    app.require_subcommand(1);

    RenderCommand cmd;
    CLI::App* render = app.add_subcommand("render", command("render").summary);
    render->add_option(
        "scene", cmd.scenePath,
        "glTF 2.0 (.gltf/.glb), OBJ, PLY or STL file, or builtin, builtin:dense, builtin:huge");
    render
        ->add_option(
            "--backend", cmd.backend,
            "auto (CUDA if present, else Vulkan), cuda, vulkan, or vulkan-graphics (the reference: the "
            "same scene through the real Vulkan graphics pipeline)")
        ->check(CLI::IsMember({"auto", "cuda", "vulkan", "vulkan-graphics"}));
    render->add_option("--device", cmd.device, "device index within the backend (default: first)");
    render->add_option(
        "-o,--output", cmd.output,
        "colour image, its extension choosing the format: .png (sRGB PNG) or .npy (the same RGBA8 pixels "
        "as a NumPy (H, W, 4) uint8 array); default render.png, none when only --aov is given; with "
        "--frames a pattern with one %d or %0Nd (frame_%04d.png)");
    render->add_option(
        "--aov", cmd.aovPath,
        "EXR with channels id (UINT), Z, bary.u, bary.v, uv.u, uv.v, N.x, N.y, N.z (FLOAT) and "
        "the linear colour R, G, B, A (HALF)");
    render->add_option("--stats", cmd.statsPath, "JSON statistics and per-stage GPU times");
    render->add_option("--png-compression", cmd.pngCompression, pngCompressionHelp());
    render->add_option("--exr-compression", cmd.exrCompression, exrCompressionHelp());
    CLI::Option* framesOption =
        render
            ->add_option("--frames", cmd.frames,
                         "a turntable of N frames in one process (the scene uploaded once): -o, --aov and "
                         "--stats are patterns with one %d or %0Nd, numbered from 0")
            ->check(CLI::Range(1, 1000000));
    CLI::Option* orbitOption =
        render
            ->add_option(
                "--orbit", cmd.orbitRange,
                "AZ0:AZ1: the turntable's azimuths, degrees, both ends rendered; AZ0:AZ1) leaves AZ1 out "
                "(a loop: '0:360)', quoted for the shell); elevation, distance and target from --camera "
                "orbit:... or the auto camera")
            ->needs(framesOption);
    framesOption->needs(orbitOption);
    // Every render setting, from the schema (settings/schema.h).
    addSettingOptions(*render, cmd.options);
    render->add_flag("-q,--quiet", cmd.quiet, "print nothing on success");
    // --quality chooses the anti-aliasing, filter, UV interpolation and raster method itself.
    CLI::Option* qualityOption =
        render
            ->add_option("--quality", cmd.quality,
                         "psnr:N: render with the cheapest setting whose image reaches N dB PSNR against the "
                         "study's reference for this scene on this backend, measured now (raster study's "
                         "accuracy procedure) or read from --study; prints what it chose")
            ->excludes(render->get_option("--msaa"))
            ->excludes(render->get_option("--ssaa"))
            ->excludes(render->get_option("--texture-filter"))
            ->excludes(render->get_option("--uv-interpolation"))
            ->excludes(render->get_option("--raster-method"));
    render
        ->add_option("--study", cmd.studyPath,
                     "with --quality: choose from this `raster study --json` file's rows for the scene "
                     "(builtin, dense, study:NAME as NAME, a file by its stem) and backend")
        ->needs(qualityOption);

    CompareCommand compare;
    CLI::App* cmp = app.add_subcommand("compare", command("compare").summary);
    cmp->add_option("a", compare.a, "reference (.png or .exr)")->required();
    cmp->add_option("b", compare.b, "test image of the same kind")->required();
    cmp->add_option("-o,--output", compare.diffPath, "difference heat map (PNG)");
    cmp->footer(
        "Without tolerance flags compare applies the tolerance the project documents for the pair of "
        "backends "
        "that made the files (their metadata, or a JSON of the same stem beside them): exact for one backend "
        "on "
        "one device, the goldens' criterion between cuda and vulkan, the oracle bounds against "
        "vulkan-graphics, "
        "exact when a file names no backend (docs/validation.md). Each flag replaces its part.");
    CompareFlags compareFlags;
    compareFlags.colour =
        cmp->add_option("--tolerance", compare.tolerance.colorLsb, "largest allowed 8-bit channel difference")
            ->check(CLI::Range(0, 255));
    compareFlags.ids = cmp->add_option("--max-id-mismatches", compare.tolerance.maxIdMismatches,
                                       "AOVs: pixels allowed to differ in id or coverage");
    compareFlags.depth = cmp->add_option("--depth-tolerance", compare.tolerance.depthTolerance,
                                         "AOVs: largest allowed depth difference")
                             ->check(CLI::Range(0.0, 1.0));
    compareFlags.fraction =
        cmp->add_option(
               "--max-fraction", compare.tolerance.maxFraction,
               "fraction of the pixels (of the samples, for sample channels) allowed over the colour, "
               "depth and surface tolerances")
            ->check(CLI::Range(0.0, 1.0));

    BenchCommand bench;
    CLI::App* benchApp = app.add_subcommand("bench", command("bench").summary);
    benchApp->add_option("--backends", bench.backends, "comma-separated: cuda, vulkan, vulkan-graphics");
    benchApp->add_option("--resolutions", bench.resolutions, "comma-separated WxH");
    benchApp->add_option(
        "--scenes", bench.scenes,
        "comma-separated subset of sweep-0.5px, sweep-2px, sweep-8px, sweep-32px, sweep-128px, "
        "points-1m, lines-1m, layers-16, fan-1m, copies-1m, bunny, dense, builtin, checker-*, sphere-* "
        "(default: all)");
    benchApp->add_option("--msaa", bench.msaa,
                         "comma-separated sample counts, each run on every scene (default 1)");
    benchApp->add_option("--clusters", bench.clusters,
                         "comma-separated --clusters modes (auto, on, off), each run on every scene (default "
                         "auto)");
    benchApp->add_option(
        "--lod", bench.lod,
        "comma-separated: off or a --lod-error-px value, each run on every scene (default off; "
        "the runs with level of detail share one session per scene and compute backend)");
    benchApp->add_option(
        "--ao", bench.ao,
        "comma-separated: off, gtao (default off), each run on every scene; a run reports its "
        "AO stages' time as ao_ms");
    benchApp
        ->add_option("--triangles", bench.options.sweepTriangles,
                     "primitives of each sweep, points, lines, fan and copies scene")
        ->check(CLI::Range(1, 1 << 26));
    benchApp->add_option("--dense-rings", bench.options.denseRings, "dense sphere: about 4 N^2 triangles")
        ->check(CLI::Range(4, kMaxSphereRings));
    benchApp->add_option("--bunny", bench.options.bunnyPath,
                         "the Stanford bunny OBJ (Debian's glmark2-data)");
    benchApp->add_option("--warmup", bench.options.warmup, "untimed runs first")->check(CLI::Range(0, 1000));
    benchApp
        ->add_option("--warmup-ms", bench.options.warmupMs,
                     "before each run, untimed frames until this many ms have passed, so that the GPU's "
                     "clock is up (default 0: none)")
        ->check(CLI::Range(0.0, 60000.0));
    benchApp->add_option("--repeat", bench.options.repeat, "timed runs")->check(CLI::Range(1, 100000));
    benchApp->add_option("--device", bench.options.device, "device index within each backend");
    benchApp->add_option("--json", bench.jsonPath, "all results as JSON");

    ViewOptions view;
    CLI::App* viewApp = app.add_subcommand("view", command("view").summary);
    viewApp->add_option("scene", view.scenePath, "as for render");
    viewApp->add_option("--backend", view.backend, "auto, cuda or vulkan")
        ->check(CLI::IsMember({"auto", "cuda", "vulkan"}));
    viewApp->add_option("--device", view.device, "device index within the backend");
    viewApp->add_option("--present-device", view.presentDevice, "Vulkan device that presents the window");
    viewApp->add_option("--width", view.settings.width, "initial window width")->check(CLI::Range(1, 16384));
    viewApp->add_option("--height", view.settings.height, "initial window height")
        ->check(CLI::Range(1, 16384));
    viewApp->add_option("--camera", view.camera,
                        "initial camera: auto, gltf:N or orbit:AZ,EL,DIST[,TX,TY,TZ] (DIST in scene units, "
                        "or Nr: N bounding radii)");
    viewApp->add_option("--model", view.model,
                        "initial model transform: identity or translate:X,Y,Z,rotate:AX,AY,AZ,scale:S");
    viewApp->add_option("--script", view.scriptPath, "replay an input script and quit (headless tests)");
    viewApp
        ->add_option("--present", view.present,
                     "device (frames stay on the GPU: the Vulkan backend presents its own framebuffer, CUDA "
                     "shares a buffer with the presenter, or goes through the host where it cannot), shared "
                     "(as device, but CUDA must share) or host (every frame through the host)")
        ->check(CLI::IsMember({"device", "shared", "host"}));
    viewApp->add_flag("--offscreen", view.offscreen,
                      "no window: present into an image instead of a swapchain (with --script; machines "
                      "without a display, timings)");
    viewApp->footer("Controls:\n" + controlsHelp());

    StudyCommand study;
    CLI::App* studyApp = app.add_subcommand("study", command("study").summary);
    studyApp->add_option("--backends", study.backends, "comma-separated: cuda, vulkan");
    studyApp->add_option("--width", study.options.width, "accuracy renders: width")
        ->check(CLI::Range(8, 4096));
    studyApp->add_option("--height", study.options.height, "accuracy renders: height")
        ->check(CLI::Range(8, 4096));
    studyApp->add_option("--stress-size", study.options.stressSize, "stress cases: side in pixels")
        ->check(CLI::Range(16, 1024));
    studyApp->add_option("--axes", study.axes,
                         "comma-separated stress axes: magnitude, slivers, near, coplanar");
    studyApp->add_option("--methods", study.methods,
                         "comma-separated raster methods: the accuracy group \"method\" and the stress "
                         "cases run with each of fixed8, fixed4, float, scanline");
    studyApp->add_option(
        "--scenes", study.scenes,
        "comma-separated accuracy scenes: builtin, checker-grazing, dense, bunny, sliver-fan, "
        "jittered-grid (\"\": none)");
    studyApp->add_option("--bunny", study.options.bunnyPath, "the Stanford bunny OBJ (skipped when absent)");
    studyApp->add_option("--lod-scenes", study.lodScenes,
                         "comma-separated level-of-detail scenes: sphere (builtin:dense:N, N = --lod-rings), "
                         "bunny, bunny-fine (the bunny split to 16x its triangles) (default sphere,bunny; "
                         "\"\": none)");
    studyApp->add_option("--ao-scenes", study.aoScenes,
                         "comma-separated ambient-occlusion scenes: builtin, bunny-plane, stress-grazing, "
                         "stress-near (default all; \"\": none), each drawn with --ao reference and the GTAO "
                         "sweep");
    studyApp->add_option("--lod-errors", study.lodErrors,
                         "comma-separated --lod-error-px values each LOD scene and camera is drawn with "
                         "besides --lod off (default 0.25,0.5,1,2,4)");
    studyApp
        ->add_option("--lod-rings", study.options.lodRings,
                     "the LOD sphere's rings: about 4 N^2 triangles (default 200; 5000: the 100M sphere)")
        ->check(CLI::Range(4, kMaxSphereRings));
    studyApp->add_option("--warmup", study.options.warmup, "untimed runs first")->check(CLI::Range(0, 1000));
    studyApp->add_option("--repeat", study.options.repeat, "timed runs")->check(CLI::Range(1, 100000));
    studyApp->add_option("--device", study.options.device, "device index within each backend");
    studyApp->add_option("--json", study.jsonPath, "all results as JSON (ci/study-chart draws them)");

    BatchOptions batch;
    CLI::App* batchApp = addBatchCommand(app, batch);

    std::string settingsFormat = "markdown";
    CLI::App* settingsApp = app.add_subcommand("settings", command("settings").summary);
    settingsApp->add_option("--format", settingsFormat, "markdown (docs/settings.md's reference) or json")
        ->check(CLI::IsMember({"markdown", "json"}));

    CLI::App* commandsApp = app.add_subcommand("commands", command("commands").summary);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);  // --help
        // Bounded as every message quoting input is (base/result.h): CLI11's own may quote an argument.
        fmt::print(stderr, "raster: error: {}\n",
                   clippedText(parseErrorMessage(app, std::vector<std::string>(argv + 1, argv + argc), e),
                               2 * kMaxQuotedBytes));
        return int(ExitCode::Usage);
    }

    Status status = okStatus();
    if (render->parsed()) status = runRender(cmd);
    if (benchApp->parsed()) status = runBenchCommand(bench);
    if (studyApp->parsed()) status = runStudyCommand(study);
    if (viewApp->parsed()) status = runView(view);
    if (commandsApp->parsed()) fmt::print("{}", commandsMarkdown());
    if (settingsApp->parsed())
        fmt::print("{}", settingsFormat == "json" ? schemaJson().dump(2) + "\n" : settingsMarkdown());
    if (batchApp->parsed()) {
        auto allRendered = runBatch(batch);
        if (allRendered.ok() && !*allRendered) return int(ExitCode::JobsFailed);
        if (!allRendered.ok()) status = allRendered.error();
    }
    if (cmp->parsed()) {
        auto pass = runCompare(compare, compareFlags);
        if (pass.ok() && !*pass) return int(ExitCode::CompareFailed);
        if (!pass.ok()) status = pass.error();
    }
    if (!status.ok()) {
        fmt::print(stderr, "raster: error: {}\n", status.error().message);
        return int(status.error().code);
    }
    return int(ExitCode::Ok);
}
