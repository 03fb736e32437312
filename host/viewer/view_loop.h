// view_loop.h - `raster view`: the interactive window (issue 13). The scene is rendered by a compute
// backend at the window's size whenever the view changes and presented through a Vulkan swapchain
// (host/viewer/present.h); input comes from the window or, with --script, from a replayed file that
// goes through the same handlers (host/viewer/script.h), so a test under Xvfb drives the real window.
#ifndef RASTER_VIEW_LOOP_H
#define RASTER_VIEW_LOOP_H

#include <cstdint>
#include <string>

#include "base/result.h"
#include "render/renderer.h"

namespace sr {

struct ViewOptions {
    std::string scenePath;           // as `raster render`: a file, builtin, builtin:NAME
    std::string backend = "auto";    // auto, cuda or vulkan (the compute backends; `b` switches live)
    int device = -1;                 // device index within the backend
    int presentDevice = -1;          // Vulkan device that presents (-1: the first that can)
    std::string camera = "auto";     // initial camera, as --camera of `raster render`
    std::string model = "identity";  // initial model transform, as --model of `raster render`
    std::string scriptPath;          // replay this input script instead of waiting for the user
    // device: frames stay on the GPU: the Vulkan backend presents from its own framebuffer, the CUDA
    // backend shares a buffer with the presenter (render/frame_share.h) or, where it cannot (no Vulkan
    // device is its GPU, no export), goes through the host with a one-line notice; shared: the same, but
    // CUDA failing to share is an error; host: every frame through the host.
    std::string present = "device";
    // No window (machines without a display): the frames go through the same copies into an image of
    // the presenter's instead of a swapchain; needs scriptPath.
    bool offscreen = false;
    RenderSettings settings;  // width x height is the initial window size
};

Status runView(const ViewOptions& options);

}  // namespace sr

#endif  // RASTER_VIEW_LOOP_H
