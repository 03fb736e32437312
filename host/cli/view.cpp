// view.cpp - see view.h.
#include "cli/view.h"

#include <chrono>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "cli/backend.h"
#include "io/image_io.h"
#include "scene/camera.h"
#include "scene/scene.h"
#include "viewer/present.h"
#include "viewer/window.h"

namespace sr {

Status runView(const ViewOptions& o)
{
    Result<Scene> scene = o.scenePath.empty() ? Result<Scene>(builtinScene()) : loadScene(o.scenePath);
    if (!scene) return scene.error();
    auto spec = parseCameraSpec(o.camera);
    if (!spec) return spec.error();
    auto window = Window::open(o.settings.width, o.settings.height, "raster view");
    if (!window) return window.error();
    auto presenter = Presenter::create((*window)->presentTarget(), o.presentDevice);
    if (!presenter) return presenter.error();
    BackendKind kind = o.backend == "cuda"     ? BackendKind::Cuda
                       : o.backend == "vulkan" ? BackendKind::Vulkan
                                               : BackendKind::Auto;
    auto device = makeComputeDevice(kind, o.device);
    if (!device) return device.error();

    std::vector<std::string> script;
    if (!o.scriptPath.empty()) {
        std::ifstream in(o.scriptPath);
        if (!in) return makeError(ExitCode::Usage, "view: cannot read script '{}'", o.scriptPath);
        for (std::string line; std::getline(in, line);) script.push_back(line);
    }
    size_t next = 0;
    RenderSettings s = o.settings;
    while (!(*window)->closeRequested()) {
        bool quit = false;
        for (const InputEvent& e : (*window)->poll())
            if (e.kind == InputEvent::Kind::Key && (e.key == kKeyEscape || e.key == 'q')) quit = true;
        if (quit) break;
        uint32_t w = 0, h = 0;
        (*window)->framebufferSize(w, h);
        if (w == 0 || h == 0) continue;
        s.width = w;
        s.height = h;
        auto camera = resolveCamera(*spec, *scene, w, h);
        if (!camera) return camera.error();
        auto out = renderScene(**device, *scene, *camera, s);
        if (!out) return out.error();
        std::string savePrefix;
        if (!o.scriptPath.empty()) {
            if (next >= script.size()) break;
            std::istringstream line(script[next++]);
            std::string verb;
            line >> verb >> savePrefix;
            if (verb != "save") savePrefix.clear();
        }
        RgbaImage shown;
        SR_TRY((*presenter)->present(out->color, w, h, savePrefix.empty() ? nullptr : &shown));
        if (!savePrefix.empty()) {
            SR_TRY(writePng(savePrefix + ".png", out->color));
            SR_TRY(writePng(savePrefix + ".window.png", shown));
        }
        (*window)->setTitle(fmt::format("raster view - {} ({}) - {:.2f} ms GPU - {} triangles",
                                        out->device.backend, out->device.name, out->total.medianMs,
                                        out->stats.trianglesIn));
    }
    return okStatus();
}

}  // namespace sr
