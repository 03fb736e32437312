// view_loop.cpp - see view_loop.h.
#include "viewer/view_loop.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "api/api_internal.h"
#include "api/backend.h"
#include "api/frame_files.h"
#include "base/warnings.h"
#include "io/image_io.h"
#include "render/frame_share.h"
#include "camera/camera.h"
#include "settings/schema.h"
#include "viewer/controls.h"
#include "viewer/present.h"
#include "viewer/script.h"
#include "viewer/window.h"
#include "vulkan/vulkan_present_source.h"

namespace sr {
namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// The compute backends the window can switch between (`b`), chosen where every backend is
// (makeSwitchableDevices): the one asked for first, then the other where it opens; with `auto`, CUDA
// first as `raster render` does. Each is a raster::Device, as the library's sessions take them.
Result<std::vector<raster::Device>> openBackends(const std::string& backend, int device,
                                                 const PresentTarget* window)
{
    const BackendKind preferred = backend == "vulkan" ? BackendKind::Vulkan
                                  : backend == "cuda" ? BackendKind::Cuda
                                                      : BackendKind::Auto;
    auto devices = makeSwitchableDevices(preferred, device, window);
    if (!devices) return devices.error();
    std::vector<raster::Device> opened;
    for (auto& d : *devices) opened.push_back(raster::Internal::makeDevice(std::move(d)));
    return opened;
}

// Live input, through the same controls a script uses.
void applyInput(ViewerState& state, const InputEvent& e)
{
    switch (e.kind) {
    case InputEvent::Kind::Drag: onDrag(state, e.button, float(e.dx), float(e.dy)); break;
    case InputEvent::Kind::Scroll: onScroll(state, float(e.dy)); break;
    case InputEvent::Kind::Key: onKey(state, char(e.key)); break;
    case InputEvent::Kind::Resize: onResize(state, uint32_t(e.dx), uint32_t(e.dy)); break;
    }
}

// What a saved frame needs beside its PNG, EXR and JSON to be reproduced: the `raster render`
// arguments of the same view (PREFIX.view.json), which the viewer test runs.
//
// The view as the options of `raster render`: the state's settings, camera, model and primitive mode.
RenderOptions viewOptions(const ViewerState& state)
{
    RenderOptions options;
    options.settings = state.settings;
    options.camera = state.camera.specString();
    options.model = modelSpecString(state.model);
    options.primitiveMode = state.primitiveMode;
    options.wireframe = state.wireframe;
    options.tessMaxLevel =
        state.settings.tessellate == TESS_OFF ? kAutoTessLevel : state.settings.tessMaxLevel;
    return options;
}

nlohmann::json viewJson(const ViewerState& state, const std::string& scenePath,
                        const raster::DeviceInfo& info)
{
    const std::pair<std::string, std::string> device{raster::backendName(info.backend), info.name};
    const std::string args =
        fmt::format("{} {}", scenePath.empty() ? "builtin" : scenePath, renderArguments(viewOptions(state)));
    return {{"camera", state.camera.specString()},
            {"model", modelSpecString(state.model)},
            {"backend", device.first},
            {"device", device.second},
            {"state", stateSummary(state)},
            {"render_args", args}};
}

}  // namespace

Status runView(const ViewOptions& o)
{
    auto base = raster::Scene::load(o.scenePath.empty() ? "builtin" : o.scenePath);
    if (!base) return raster::fromPublic(base.error());
    for (const std::string& warning : base->warnings()) warnLine(warning);
    auto spec = parseCameraSpec(o.camera);
    if (!spec) return spec.error();
    auto model = parseModelSpec(o.model);
    if (!model) return model.error();
    std::vector<ScriptEvent> script;
    if (!o.scriptPath.empty()) {
        auto loaded = loadScript(o.scriptPath);
        if (!loaded) return loaded.error();
        script = std::move(*loaded);
    }
    // Offscreen: no window; the frames go through the same copies into an image of the presenter's.
    if (o.offscreen && o.scriptPath.empty())
        return makeError(ExitCode::Usage,
                         "view: --offscreen needs --script (there is no window to take input)");
    std::unique_ptr<Window> window;
    PresentTarget target;
    if (!o.offscreen) {
        auto opened = Window::open(o.settings.width, o.settings.height, "raster view");
        if (!opened) return opened.error();
        window = std::move(*opened);
        target = window->presentTarget();
    }
    auto devices = openBackends(o.backend, o.device, o.present != "host" && window ? &target : nullptr);
    if (!devices) return devices.error();
    // One presenter per path, made when first needed; a window has one swapchain at a time, so a
    // switch of path releases the other's. devicePresenters[k]: backend k's frames from the GPU (the
    // Vulkan device's own buffer, or the buffer CUDA shares).
    std::unique_ptr<Presenter> hostPresenter;
    std::vector<std::unique_ptr<Presenter>> devicePresenters(devices->size());
    std::vector<bool> shareFailed(devices->size(), false);  // CUDA could not share: through the host
    std::vector<std::string> paths;                         // "BACKEND PATH" of the frames, in order

    uint32_t width = o.settings.width, height = o.settings.height;
    if (window) window->framebufferSize(width, height);
    RenderSettings settings = o.settings;
    settings.width = std::max(width, 1u);
    settings.height = std::max(height, 1u);
    settings.warmup = 0;
    settings.repeat = 1;
    auto camera =
        OrbitCamera::fromSpec(*spec, raster::Internal::of(*base).scene, settings.width, settings.height);
    if (!camera) return camera.error();
    ViewerState state =
        makeViewerState(*camera, settings, false, PrimitiveMode::Triangles, uint32_t(devices->size()));
    state.model = *model;
    // The library's session draws the scene as the state's primitive mode and overlay ask.
    std::optional<raster::Session> session;
    std::set<std::string> warned;  // each warning once

    size_t next = 0;  // the script's next event
    bool dirty = true;
    double fps = 0.0;
    std::vector<double> gpuMs, presentMs, wallMs;  // per frame: GPU time, presentation, the whole frame
    while (!state.quit) {
        bool draw = false;
        if (!o.scriptPath.empty()) {
            if (window) window->poll();  // keeps the window system served; live input is ignored
            if (next == script.size()) break;
            ScriptEffect effect = applyScriptEvent(state, script[next++]);
            if (effect.resizeWindow && window)
                SR_TRY(window->resize(state.settings.width, state.settings.height));
            draw = effect.renderFrame || state.saveRequested;
        } else {
            std::vector<InputEvent> events = window->poll();
            for (const InputEvent& e : events) applyInput(state, e);
            dirty = dirty || !events.empty();
            if (window->closeRequested()) break;
            draw = dirty || state.sceneChanged || state.backendChanged || state.saveRequested;
        }
        if (state.quit) break;
        if (state.backendChanged) session.reset();  // a new device: the uploads belong to the old one
        state.sceneChanged = state.backendChanged = false;
        if (!draw) {
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
            continue;
        }
        Clock::time_point start = Clock::now();
        raster::Device& opened = (*devices)[state.backendIndex % devices->size()];
        ComputeDevice& device = *raster::Internal::of(opened).compute;
        if (!session) {
            auto created = raster::Session::create(opened, *base);
            if (!created) return raster::fromPublic(created.error());
            session.emplace(std::move(*created));
        }
        const size_t backend = state.backendIndex % devices->size();
        // The path of this frame, decided here and nowhere else. Device: a Vulkan device made on the
        // window, or any Vulkan device offscreen. Shared: the CUDA device writes into a buffer it shares
        // with a presenter on its GPU (render/frame_share.h); where that presenter cannot be made
        // (no Vulkan device is CUDA's GPU, it cannot export), CUDA goes through the host with a notice,
        // unless --present shared asked for it. Host: everything else, and --present host.
        std::optional<VulkanPresentSource> deviceSource;
        if (o.present != "host") deviceSource = vulkanPresentSource(device);
        const bool fromDevice =
            deviceSource && (o.offscreen || deviceSource->context->surface() != VK_NULL_HANDLE);
        std::optional<FrameShareSource> shareSource;
        if (o.present != "host" && !fromDevice && !shareFailed[backend])
            shareSource = cudaFrameShareSource(device);
        if (shareSource && !devicePresenters[backend]) {
            auto created =
                Presenter::createShared(o.offscreen ? nullptr : &target, o.presentDevice, *shareSource,
                                        size_t(state.settings.width) * state.settings.height * 4);
            if (created) {
                devicePresenters[backend] = std::move(*created);
            } else if (o.present == "shared") {
                return created.error();
            } else {
                shareFailed[backend] = true;
                shareSource.reset();
                fmt::print(stderr, "view: CUDA frames go through the host: {}\n", created.error().message);
            }
        }
        const bool shared = shareSource.has_value();
        const std::string path = fmt::format("{} {}", device.info().backend,
                                             fromDevice ? "device"
                                             : shared   ? "shared"
                                                        : "host");
        if (std::find(paths.begin(), paths.end(), path) == paths.end()) paths.push_back(path);
        const RenderSettings& s = state.settings;
        // From the GPU nothing comes back, through the host only the colour image, unless the frame
        // is saved. The camera and model go as the specs `raster render` takes (viewOptions), so that a
        // saved frame's render_args draw it again bit for bit.
        const ImageDownload download = state.saveRequested    ? ImageDownload::All
                                       : fromDevice || shared ? ImageDownload::None
                                                              : ImageDownload::Colour;
        raster::RenderRequest request;
        request.surfaceAovs = state.saveRequested;
        request.outputs = state.saveRequested ? raster::OutputImages : raster::OutputColor;
        request.stats = state.saveRequested;
        auto out = raster::Internal::render(*session, raster::Camera::fromSpec("auto"),
                                            raster::Internal::makeSettings(viewOptions(state)), request,
                                            raster::Internal::RenderControl{download});
        if (!out) return raster::fromPublic(out.error());
        for (const std::string& warning : out->warnings)
            if (warned.insert(warning).second) warnLine(warning);
        // Read after the frame: a new size replaces the buffer.
        std::optional<VulkanPresentSource> source;
        if (fromDevice) source = vulkanPresentSource(device);
        Clock::time_point presentStart = Clock::now();
        uint32_t windowWidth = s.width, windowHeight = s.height;
        if (window) window->framebufferSize(windowWidth, windowHeight);
        RgbaImage shown;
        RgbaImage* readback = state.saveRequested ? &shown : nullptr;
        if (source || shared) {
            if (hostPresenter) hostPresenter->releaseSwapchain();
            for (size_t k = 0; k < devicePresenters.size(); ++k)
                if (k != backend && devicePresenters[k]) devicePresenters[k]->releaseSwapchain();
            if (!devicePresenters[backend]) {
                auto created = o.offscreen ? Presenter::createOffscreen(source->context, -1)
                                           : Presenter::createOn(*source->context);
                if (!created) return created.error();
                devicePresenters[backend] = std::move(*created);
            }
            if (shared)
                SR_TRY(devicePresenters[backend]->presentShared(s.width, s.height, windowWidth, windowHeight,
                                                                readback));
            else
                SR_TRY(devicePresenters[backend]->presentBuffer(source->framebuffer, s.width, s.height,
                                                                windowWidth, windowHeight, readback));
        } else {
            for (auto& p : devicePresenters)
                if (p) p->releaseSwapchain();
            if (!hostPresenter) {
                auto created = o.offscreen ? Presenter::createOffscreen(nullptr, o.presentDevice)
                                           : Presenter::create(target, o.presentDevice);
                if (!created) return created.error();
                hostPresenter = std::move(*created);
            }
            SR_TRY(hostPresenter->present(colorImage(*out), windowWidth, windowHeight, readback));
        }
        presentMs.push_back(msSince(presentStart));
        gpuMs.push_back(out->gpuMs);
        if (state.saveRequested) {
            std::string prefix =
                state.savePrefix.empty() ? fmt::format("view_{:04d}", gpuMs.size()) : state.savePrefix;
            // The save's five files appear together or not at all.
            FileGroup files;
            SR_TRY(stageFrame(files, *out, OutputPaths{prefix + ".png", prefix + ".exr", prefix + ".json"},
                              ImageEncoding{}));
            auto shownPng = encodePng(shown);
            if (!shownPng) return shownPng.error();
            SR_TRY(files.stage(prefix + ".window.png", shownPng->data(), shownPng->size()));
            const std::string view = viewJson(state, o.scenePath, out->device).dump(2) + "\n";
            SR_TRY(files.stage(prefix + ".view.json", view.data(), view.size()));
            SR_TRY(files.commit());
            state.saveRequested = false;
        }
        double frameMs = msSince(start);
        wallMs.push_back(frameMs);
        fps = frameMs > 0.0 ? 1000.0 / frameMs : 0.0;
        if (window)
            window->setTitle(fmt::format(
                "raster view - {} ({}), {} - GPU {:.2f} ms, present {:.2f} ms, {:.0f} fps - "
                "{} triangles - {}",
                raster::backendName(out->device.backend), out->device.name, path.substr(path.find(' ') + 1),
                out->gpuMs, presentMs.back(), fps, base->triangleCount(), stateSummary(state)));
        dirty = false;
    }
    if (!gpuMs.empty() && !o.scriptPath.empty()) {
        auto median = [](std::vector<double> v) {
            std::sort(v.begin(), v.end());
            return v[v.size() / 2];
        };
        std::string via;
        for (const std::string& p : paths) via += (via.empty() ? "" : ", ") + p;
        fmt::print(
            "view: {} frames at {}x{} ({}), median GPU {:.3f} ms, median present {:.3f} ms, median frame "
            "{:.3f} ms (render, downloads, presentation)\n",
            gpuMs.size(), state.settings.width, state.settings.height, via, median(gpuMs), median(presentMs),
            median(wallMs));
    }
    return okStatus();
}

}  // namespace sr
