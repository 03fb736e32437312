// bench_runner.cpp - see bench_runner.h.
#include "bench/bench_runner.h"

#include <optional>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <unistd.h>

#include <fmt/format.h>

#include "api/api_internal.h"
#include "api/stats_json.h"
#include "camera/camera.h"
#include "scene/texture.h"
#include "settings/schema.h"

namespace sr {
namespace {

struct BenchScene {
    std::string name;
    Scene scene;
    CameraMatrices camera;
    double triangleArea = 0.0;                     // pixels, for the sweep scenes
    uint32_t textureFilter = TEXTURE_FILTER_AUTO;  // TEXTURE_FILTER_* for the textured scenes
};

// Clip space is world space for the synthetic scenes: identity matrices, depth range 0..1.
CameraMatrices identityMatrices()
{
    CameraMatrices camera;
    camera.znear = 0.0f;
    camera.zfar = 1.0f;
    return camera;
}

void addClipTriangle(Scene& scene, glm::vec4 a, glm::vec4 b, glm::vec4 c)
{
    auto base = uint32_t(scene.positions.size());
    for (glm::vec4 p : {a, b, c}) {
        scene.positions.push_back(p);
        scene.normals.push_back(glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
    }
    scene.indices.insert(scene.indices.end(), {base, base + 1, base + 2});
}

// `count` right isosceles triangles of `area` pixels scattered over a w x h screen at random depths,
// counter-clockwise on screen (front-facing).
Scene sweepScene(double area, uint32_t count, uint32_t w, uint32_t h)
{
    std::mt19937 rng(uint32_t(area * 1000.0) + w);
    double leg = std::sqrt(2.0 * area);
    std::uniform_real_distribution<double> px(0.0, std::max(1.0, w - leg)), py(0.0, std::max(1.0, h - leg));
    std::uniform_real_distribution<float> depth(0.05f, 0.95f);
    Scene scene;
    scene.positions.reserve(size_t(count) * 3);
    scene.normals.reserve(size_t(count) * 3);
    scene.indices.reserve(size_t(count) * 3);
    auto ndc = [&](double x, double y, float z) {
        return glm::vec4(float(x * 2.0 / w - 1.0), float(y * 2.0 / h - 1.0), z, 1.0f);
    };
    for (uint32_t i = 0; i < count; ++i) {
        double x = px(rng), y = py(rng);
        float z = depth(rng);
        addClipTriangle(scene, ndc(x, y, z), ndc(x, y + leg, z), ndc(x + leg, y, z));
    }
    (void)finalizeScene(scene, "sweep scene");
    return scene;
}

// `count` points scattered over the screen at random depths (1 px each at the default point size): the
// point-cloud twin of the smallest triangles of the sweep.
Scene pointCloudScene(uint32_t count)
{
    std::mt19937 rng(count);
    std::uniform_real_distribution<float> ndc(-0.999f, 0.999f), depth(0.05f, 0.95f);
    Scene scene;
    scene.positions.reserve(count);
    scene.normals.assign(count, glm::vec4(0.0f));
    scene.points.reserve(count);
    for (uint32_t i = 0; i < count; ++i) {
        scene.points.push_back(uint32_t(scene.positions.size()));
        scene.positions.push_back(glm::vec4(ndc(rng), ndc(rng), depth(rng), 1.0f));
    }
    (void)finalizeScene(scene, "point cloud");
    return scene;
}

// `count` line segments of `length` pixels (1 px wide) in random directions, scattered over the screen at
// random depths, each with its own two vertices: the line twin of the sweep.
Scene lineSegmentsScene(uint32_t count, double length, uint32_t w, uint32_t h)
{
    std::mt19937 rng(count + 1);
    std::uniform_real_distribution<double> px(2.0 + length, w - 2.0 - length),
        py(2.0 + length, h - 2.0 - length), angle(0.0, 6.283185307179586);
    std::uniform_real_distribution<float> depth(0.05f, 0.95f);
    auto ndc = [&](double x, double y, float z) {
        return glm::vec4(float(x * 2.0 / w - 1.0), float(y * 2.0 / h - 1.0), z, 1.0f);
    };
    Scene scene;
    scene.positions.reserve(size_t(count) * 2);
    scene.normals.assign(size_t(count) * 2, glm::vec4(0.0f));
    scene.lines.reserve(size_t(count) * 2);
    for (uint32_t i = 0; i < count; ++i) {
        double x = px(rng), y = py(rng), a = angle(rng);
        float z = depth(rng);
        scene.lines.push_back(uint32_t(scene.positions.size()));
        scene.positions.push_back(ndc(x, y, z));
        scene.lines.push_back(uint32_t(scene.positions.size()));
        scene.positions.push_back(ndc(x + length * std::cos(a), y + length * std::sin(a), z));
    }
    (void)finalizeScene(scene, "line segments");
    return scene;
}

// `layers` full-screen quads at distinct depths, drawn in random depth order.
Scene layerScene(int layers)
{
    std::mt19937 rng(16);
    std::vector<float> depths;
    for (int i = 0; i < layers; ++i) depths.push_back(0.05f + 0.9f * float(i) / float(layers));
    std::shuffle(depths.begin(), depths.end(), rng);
    Scene scene;
    for (float z : depths) {
        glm::vec4 a(-1, -1, z, 1), b(-1, 1, z, 1), c(1, 1, z, 1), d(1, -1, z, 1);
        addClipTriangle(scene, a, b, c);
        addClipTriangle(scene, a, c, d);
    }
    (void)finalizeScene(scene, "layer scene");
    return scene;
}

// A window position (pixels, y down) of a w x h screen as a clip-space vertex at depth 0.5.
glm::vec4 windowPoint(double x, double y, uint32_t w, uint32_t h)
{
    return glm::vec4(float(2.0 * x / w - 1.0), float(2.0 * y / h - 1.0), 0.5f, 1.0f);
}

// `count` triangles around one vertex at the screen's centre: a disc of 32 pixels' radius.
Scene fanScene(uint32_t count, uint32_t w, uint32_t h)
{
    Scene scene;
    scene.positions.push_back(windowPoint(0.5 * w, 0.5 * h, w, h));
    for (uint32_t k = 0; k <= count; ++k) {
        // Clockwise in y-up terms: counter-clockwise on the screen, front-facing.
        const double angle = -6.283185307179586 * double(k) / count;
        scene.positions.push_back(
            windowPoint(0.5 * w + 32.0 * std::cos(angle), 0.5 * h + 32.0 * std::sin(angle), w, h));
    }
    scene.normals.assign(scene.positions.size(), glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
    for (uint32_t k = 0; k < count; ++k) scene.indices.insert(scene.indices.end(), {0u, 1 + k, 2 + k});
    (void)finalizeScene(scene, "fan scene");
    return scene;
}

// `count` copies of one 8-pixel triangle at the screen's centre, over one set of three vertices.
Scene copiesScene(uint32_t count, uint32_t w, uint32_t h)
{
    Scene scene;
    const double x = 0.5 * w, y = 0.5 * h;
    scene.positions = {windowPoint(x, y, w, h), windowPoint(x, y + 4.0, w, h), windowPoint(x + 4.0, y, w, h)};
    scene.normals.assign(3, glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
    for (uint32_t k = 0; k < count; ++k) scene.indices.insert(scene.indices.end(), {0u, 1u, 2u});
    (void)finalizeScene(scene, "copies scene");
    return scene;
}

// A texture-free copy of a textured scene: the same geometry, so the pair shows what texturing costs.
Scene untextured(Scene scene)
{
    scene.materials.clear();
    scene.triMaterials.clear();
    scene.texcoords.clear();
    scene.textures.clear();
    return scene;
}

// The dense sphere with texture coordinates from its normals (u around the axis, v from pole to pole)
// and a 1024 x 1024 checkerboard of 16 x 16 squares, glTF's default sampler.
Scene texturedSphere(int rings)
{
    Scene scene = tessellatedSphere(rings);
    constexpr float kPi = 3.14159265358979f;
    for (const glm::vec4& n : scene.normals)
        scene.texcoords.emplace_back(0.5f + std::atan2(n.z, n.x) / (2.0f * kPi),
                                     std::acos(std::clamp(n.y, -1.0f, 1.0f)) / kPi, 0.0f, 0.0f);
    std::vector<uint8_t> texels;
    for (int y = 0; y < 1024; ++y)
        for (int x = 0; x < 1024; ++x) {
            uint8_t c = ((x / 64) + (y / 64)) % 2 ? 230 : 30;
            texels.insert(texels.end(), {c, uint8_t(c / 2 + 60), 90, 255});
        }
    auto texture = makeTexture("sphere checkerboard", 1024, 1024, texels.data(), true, TextureSampler{});
    scene.textures.push_back(std::move(*texture));
    SceneMaterial m;
    m.baseColorTexture = 0;
    scene.materials.push_back(m);
    scene.triMaterials.assign(scene.triangleCount(), 0u);
    return scene;
}

Result<std::vector<BenchScene>> buildScenes(const BenchOptions& o, uint32_t w, uint32_t h)
{
    auto wanted = [&](const std::string& name) {
        return o.scenes.empty() || std::find(o.scenes.begin(), o.scenes.end(), name) != o.scenes.end();
    };
    std::vector<BenchScene> scenes;
    for (double area : {0.5, 2.0, 8.0, 32.0, 128.0}) {
        std::string name = fmt::format("sweep-{}px", area);
        if (wanted(name))
            scenes.push_back({name, sweepScene(area, o.sweepTriangles, w, h), identityMatrices(), area});
    }
    if (wanted("layers-16")) scenes.push_back({"layers-16", layerScene(16), identityMatrices(), 0.0});
    if (wanted("points-1m"))
        scenes.push_back({"points-1m", pointCloudScene(o.sweepTriangles), identityMatrices(), 0.0});
    if (wanted("lines-1m"))
        scenes.push_back(
            {"lines-1m", lineSegmentsScene(o.sweepTriangles, 8.0, w, h), identityMatrices(), 0.0});
    auto framed = [&](std::string name, Scene scene) -> Result<BenchScene> {
        auto camera = resolveCamera(CameraSpec{}, scene, w, h);
        if (!camera) return camera.error();
        return BenchScene{std::move(name), std::move(scene), *camera, 0.0};
    };
    // Meshes that defeat a clusterizer walking shared vertices and centroids (meshoptimizer's took
    // O(n^2) on both; cluster_build_ms shows the build): a fan of triangles around one vertex, and copies
    // of one triangle.
    if (wanted("fan-1m"))
        scenes.push_back({"fan-1m", fanScene(o.sweepTriangles, w, h), identityMatrices(), 0.0});
    if (wanted("copies-1m"))
        scenes.push_back({"copies-1m", copiesScene(o.sweepTriangles, w, h), identityMatrices(), 0.0});
    if (wanted("bunny")) {
        auto bunny = loadScene(o.bunnyPath);
        if (!bunny) return bunny.error();
        auto s = framed("bunny", std::move(*bunny));
        if (!s) return s.error();
        scenes.push_back(std::move(*s));
    }
    if (wanted("dense")) {
        auto s = framed("dense", tessellatedSphere(o.denseRings));
        if (!s) return s.error();
        scenes.push_back(std::move(*s));
    }
    if (wanted("builtin")) {
        auto s = framed("builtin", builtinScene());
        if (!s) return s.error();
        scenes.push_back(std::move(*s));
    }
    // Textured scenes, each next to its untextured twin: builtin:checker seen from 30 degrees above so
    // that the plane fills the screen and grazes towards the top (minification up to the last level),
    // once per filter; and a textured sphere of about 1M triangles.
    const std::pair<const char*, uint32_t> filters[] = {{"checker-nearest", TEXTURE_FILTER_NEAREST},
                                                        {"checker-bilinear", TEXTURE_FILTER_BILINEAR},
                                                        {"checker-trilinear", TEXTURE_FILTER_TRILINEAR}};
    bool anyChecker = wanted("checker-untextured");
    for (auto [name, filter] : filters) anyChecker = anyChecker || wanted(name);
    if (anyChecker) {
        auto checker = builtinSceneNamed("builtin:checker");
        if (!checker) return checker.error();
        auto spec = parseCameraSpec("orbit:0,30,2.5");
        if (!spec) return spec.error();
        auto camera = resolveCamera(*spec, *checker, w, h);
        if (!camera) return camera.error();
        if (wanted("checker-untextured"))
            scenes.push_back({"checker-untextured", untextured(*checker), *camera, 0.0});
        for (auto [name, filter] : filters)
            if (wanted(name)) scenes.push_back({name, *checker, *camera, 0.0, filter});
    }
    if (wanted("sphere-untextured") || wanted("sphere-textured")) {
        Scene sphere = texturedSphere(512);  // 1,046,528 triangles
        auto camera = resolveCamera(CameraSpec{}, sphere, w, h);
        if (!camera) return camera.error();
        if (wanted("sphere-untextured"))
            scenes.push_back({"sphere-untextured", untextured(sphere), *camera, 0.0});
        if (wanted("sphere-textured"))
            scenes.push_back({"sphere-textured", std::move(sphere), *camera, 0.0, TEXTURE_FILTER_AUTO});
    }
    if (scenes.empty()) return makeError(ExitCode::Usage, "bench: no scene matches --scenes");
    return scenes;
}

size_t sceneBytes(const Scene& s)
{
    size_t texels = 0;
    for (const SceneTexture& t : s.textures) texels += t.texels.size();
    return (s.positions.size() + s.normals.size() + s.colors.size() + s.texcoords.size()) *
               sizeof(glm::vec4) +
           (s.indices.size() + s.triFlags.size() + s.triMaterials.size() + s.lines.size() +
            s.lineMaterials.size() + s.points.size() + s.pointMaterials.size() + texels) *
               sizeof(uint32_t) +
           s.materials.size() * sizeof(GpuMaterial);
}

// What a run's warm-up by time (BenchOptions::warmupMs) drew before its frames: `frames` in all, the
// first of them in `firstMs`, the others in `ms`.
struct Prewarm {
    uint32_t frames = 0;
    double firstMs = 0.0;
    double ms = 0.0;
};

// Untimed frames of `session` with `settings` (one each, no warm-up of their own): a first one, then more
// until `ms` of wall time have passed after it. The first frame uploads the scene and builds what the
// device keeps of it (seconds for a million-triangle scene) while the GPU idles; counted in the time, it
// ended the warm-up of the big scenes after that one frame, their timed frames ran at a GPU clock that had
// dropped (the H200's Vulkan sweeps, up to 5.6x slow: docs/benchmark.md), so the time starts after it.
Result<Prewarm> prewarm(raster::Session& session, const CameraMatrices& camera,
                        const RenderSettings& settings, double ms)
{
    using Clock = std::chrono::steady_clock;
    Prewarm done;
    if (ms <= 0.0) return done;
    RenderSettings once = settings;
    once.warmup = 0;
    once.repeat = 1;
    once.download = ImageDownload::None;  // only the GPU's work is wanted of them
    const auto since = [](Clock::time_point t) {
        return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
    };
    auto draw = [&]() -> Status {
        auto out = raster::Internal::renderOutput(session, camera, once);
        if (!out) return out.error();
        ++done.frames;
        return okStatus();
    };
    const auto first = Clock::now();
    SR_TRY(draw());
    done.firstMs = since(first);
    const auto start = Clock::now();
    do {
        SR_TRY(draw());
        done.ms = since(start);
    } while (done.ms < ms);
    return done;
}

// The run's frames of `session` (settings.warmup and settings.repeat), after its warm-up by time
// (`warmupMs`, what it drew in `warmed`).
Result<RenderOutput> warmedRender(raster::Session& session, const CameraMatrices& camera,
                                  const RenderSettings& settings, double warmupMs, Prewarm& warmed)
{
    auto warm = prewarm(session, camera, settings, warmupMs);
    if (!warm) return warm.error();
    warmed = *warm;
    return raster::Internal::renderOutput(session, camera, settings);
}

// One run of scene s on `backend` through the library, as every front end renders, on a device opened for it
// alone, so that its peak memory is this run's. For vulkan-graphics `shaded` picks the whole shaded frame
// (the same shading as the compute backends' shade stage) over the visibility pass: the hardware baseline,
// depth + id with the cheapest fragment shader, i.e. rasterization and the depth test, which is what the
// compute pipeline's stages before `shade` do.
Result<RenderOutput> renderOn(const std::string& backend, int device, const BenchScene& s,
                              const raster::Scene& scene, const RenderSettings& r, double warmupMs,
                              Prewarm& warmed, bool shaded = false)
{
    auto dev = raster::Internal::openNamed(backend, device);
    if (!dev) return dev.error();
    auto session = raster::Session::create(*dev, scene);
    if (!session) return raster::fromPublic(session.error());
    RenderSettings settings = r;
    settings.visibilityOnly = backend == "vulkan-graphics" && !shaded;
    return warmedRender(*session, s.camera, settings, warmupMs, warmed);
}

}  // namespace

Result<nlohmann::json> runBench(const BenchOptions& o)
{
    for (const std::string& b : o.backends)
        if (b != "cuda" && b != "vulkan" && b != "vulkan-graphics")
            return makeError(ExitCode::Usage, "bench: unknown backend '{}' (cuda, vulkan, vulkan-graphics)",
                             b);
    bool tty = isatty(fileno(stderr));
    nlohmann::json runs = nlohmann::json::array();
    for (auto [w, h] : o.resolutions) {
        auto scenes = buildScenes(o, w, h);
        if (!scenes) return scenes.error();
        for (BenchScene& s : *scenes) {
            const size_t bytes = sceneBytes(s.scene);
            const uint64_t primitives = s.scene.primitiveCount();
            // The library's scene takes the bench's (a 100M-triangle sphere is not copied).
            const raster::Scene scene = raster::Internal::makeScene(std::move(s.scene), s.name, s.camera);
            for (uint32_t msaa : o.msaa) {
                for (const std::string& backend : o.backends) {
                    // The session the level-of-detail runs of this scene and backend share.
                    std::optional<raster::Device> lodDevice;
                    std::optional<raster::Session> lodSession;
                    for (uint32_t clusters : o.clusters)
                        for (float lodError : o.lod)
                            for (uint32_t aoMode : o.ao) {
                                if ((lodError > 0.0f || aoMode != AO_OFF) && backend == "vulkan-graphics")
                                    continue;
                                const std::string clusterMode = choiceName(setting("clusters"), clusters);
                                if (tty)
                                    fmt::print(
                                        stderr,
                                        "\r\033[Kbench: {} {}x{} {}x MSAA on {}, clusters {}, lod {} ({} "
                                        "triangles)",
                                        s.name, w, h, msaa, backend, clusterMode,
                                        lodError > 0.0f ? fmt::format("{} px", lodError) : std::string("off"),
                                        primitives);
                                RenderSettings r;
                                r.msaa = msaa;
                                r.width = w;
                                r.height = h;
                                r.warmup = o.warmup;
                                r.repeat = o.repeat;
                                r.cullMode = CULL_BACK;
                                r.shadingMode = SHADING_LAMBERT;
                                r.textureFilter = s.textureFilter;
                                r.clusters = clusters;
                                r.ao = aoMode;
                                // The colour alone comes back, as before stage aovs: no ids or depths
                                // unpacked for the host in the timed frame.
                                r.outputs = OUTPUT_COLOR;
                                Result<RenderOutput> out = makeError(ExitCode::Runtime, "not rendered");
                                Prewarm warmed;
                                if (lodError > 0.0f) {
                                    r.lod = LOD_ON;
                                    r.lodErrorPx = lodError;
                                    if (!lodSession) {
                                        auto dev = raster::Internal::openNamed(backend, o.device);
                                        if (!dev) return dev.error();
                                        lodDevice.emplace(std::move(*dev));
                                        auto session = raster::Session::create(*lodDevice, scene);
                                        if (!session) return raster::fromPublic(session.error());
                                        lodSession.emplace(std::move(*session));
                                    }
                                    out = warmedRender(*lodSession, s.camera, r, o.warmupMs, warmed);
                                } else {
                                    out = renderOn(backend, o.device, s, scene, r, o.warmupMs, warmed);
                                }
                                if (!out) return out.error();
                                double ms = out->total.medianMs;
                                // Visibility time: the whole frame less deferred shading (the graphics
                                // baseline has none).
                                double shadeMs = 0.0;
                                for (const StageTiming& t : out->stages)
                                    if (t.name == "shade") shadeMs = t.medianMs;
                                const double aoMs = aoStagesMs(out->stages);
                                // The whole shaded frame: the compute backends' total; the graphics pipeline
                                // draws it once more with its fragment shader shading (what a user of either
                                // gets).
                                double frameMs = ms;
                                if (backend == "vulkan-graphics") {
                                    // Right after the visibility run: the GPU is warm already.
                                    Prewarm none;
                                    auto frame = renderOn(backend, o.device, s, scene, r, 0.0, none, true);
                                    if (!frame) return frame.error();
                                    frameMs = frame->total.medianMs;
                                }
                                double pixels = double(w) * h;
                                size_t working =
                                    out->peakDeviceBytes > bytes ? out->peakDeviceBytes - bytes : 0;
                                runs.push_back(
                                    {{"scene", s.name},
                                     {"resolution", {w, h}},
                                     {"msaa", msaa},
                                     {"backend", backend},
                                     {"device", out->device.name},
                                     {"driver", out->device.driver},
                                     {"triangles", primitives},
                                     {"triangle_area_px", s.triangleArea},
                                     // null where the backend does not count it (vulkan-graphics)
                                     {"rasterized", out->stats.pipelineCounts
                                                        ? nlohmann::json(out->stats.rasterized)
                                                        : nlohmann::json(nullptr)},
                                     {"stages_ms", stagesJson(out->stages)},
                                     {"gpu_total_ms", timingJson(out->total)},
                                     {"visibility_ms", ms - shadeMs},
                                     {"frame_ms", frameMs},
                                     {"triangles_per_s", ms > 0 ? double(primitives) / (ms * 1e-3) : 0.0},
                                     {"pixels_per_s", ms > 0 ? pixels / (ms * 1e-3) : 0.0},
                                     {"peak_device_bytes", out->peakDeviceBytes},
                                     {"scene_bytes", bytes},
                                     {"working_bytes", working},
                                     {"working_budget_bytes",
                                      40.0 * double(primitives) + 8.0 * pixels + 8.0 * pixels * msaa},
                                     {"redraws", out->stats.redraws},
                                     {"clusters", clusterMode},
                                     {"cluster_count", out->stats.clusters},
                                     {"clusters_culled", out->stats.clustersCulled},
                                     {"lod_error_px",
                                      lodError > 0.0f ? nlohmann::json(lodError) : nlohmann::json(nullptr)},
                                     {"lod_triangles", out->stats.trianglesIn},
                                     {"lod_build_ms", out->stats.lodBuildMs},
                                     {"cluster_build_ms", out->stats.clusterBuildMs},
                                     {"ao", choiceName(setting("ao"), aoMode)},
                                     {"ao_ms", aoMs},
                                     {"prewarm_frames", warmed.frames},
                                     {"prewarm_first_ms", warmed.firstMs},
                                     {"prewarm_ms", warmed.ms}});
                            }
                }
            }
        }
    }
    if (tty) fmt::print(stderr, "\r\033[K");
    return nlohmann::json{
        {"runs", runs}, {"warmup", o.warmup}, {"repeat", o.repeat}, {"warmup_ms", o.warmupMs}};
}

std::string benchMarkdown(const nlohmann::json& bench)
{
    // Hardware visibility and whole-frame time per (scene, resolution), for the ratio columns.
    std::map<std::string, double> hardware, hardwareFrame;
    auto key = [](const nlohmann::json& r) {
        return fmt::format("{} {}x{} {}", r["scene"].get<std::string>(), r["resolution"][0].get<int>(),
                           r["resolution"][1].get<int>(), r.value("msaa", 1));
    };
    for (const auto& r : bench["runs"])
        if (r["backend"] == "vulkan-graphics") {
            hardware[key(r)] = r["visibility_ms"].get<double>();
            hardwareFrame[key(r)] = r.value("frame_ms", 0.0);
        }
    auto ratio = [](const std::map<std::string, double>& base, const std::string& k, double ms) {
        auto it = base.find(k);
        return it != base.end() && it->second > 0 ? fmt::format("{:.2f}", ms / it->second) : std::string("-");
    };
    std::string md =
        "| scene | resolution | msaa | backend | triangles | median ms | min ms | max ms | visibility ms | x "
        "hardware | frame ms | x hardware frame | "
        "Mtri/s | Gpix/s | peak MiB | working B/tri | budget B/tri |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& r : bench["runs"]) {
        double ms = r["gpu_total_ms"]["median"].get<double>();
        double visibilityMs = r["visibility_ms"].get<double>();
        double tris = r["triangles"].get<double>();
        double frameMs = r.value("frame_ms", ms);
        md += fmt::format(
            "| {} | {}x{} | {} | {} | {} | {:.4f} | {:.4f} | {:.4f} | {:.4f} | {} | {:.4f} | {} | {:.1f} | "
            "{:.2f} | {:.1f} | {:.1f} | {:.1f} |\n",
            r["scene"].get<std::string>(), r["resolution"][0].get<int>(), r["resolution"][1].get<int>(),
            r.value("msaa", 1), r["backend"].get<std::string>(), r["triangles"].get<uint64_t>(), ms,
            r["gpu_total_ms"]["min"].get<double>(), r["gpu_total_ms"]["max"].get<double>(), visibilityMs,
            ratio(hardware, key(r), visibilityMs), frameMs, ratio(hardwareFrame, key(r), frameMs),
            r["triangles_per_s"].get<double>() * 1e-6, r["pixels_per_s"].get<double>() * 1e-9,
            r["peak_device_bytes"].get<double>() / (1 << 20), r["working_bytes"].get<double>() / tris,
            r["working_budget_bytes"].get<double>() / tris);
    }
    return md;
}

}  // namespace sr
