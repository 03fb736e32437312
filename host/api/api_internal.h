// api_internal.h - what the public API's handles hold, and raster::Internal, the one way in to them: for
// the library's own files and the front ends inside this project (the command line's scenes of the study,
// --quality, the turntable). Not installed.
#ifndef RASTER_API_INTERNAL_H
#define RASTER_API_INTERNAL_H

#include <memory>
#include <optional>
#include <utility>

#include "raster/raster.h"

#include "base/result.h"
#include "render/compute_device.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "settings/render_settings.h"

struct raster::Device::Impl {
    DeviceInfo info;
    std::unique_ptr<sr::ComputeDevice> compute;  // null for Backend::VulkanGraphics
};

struct raster::Scene::Impl {
    sr::Scene scene;
    std::vector<std::string> warnings;  // of loading or making it
    // What the frames' statistics call the scene (the path it was loaded from; "arrays" for fromArrays),
    // and the camera it comes with, which the auto camera then means (a study scene's own framing).
    std::string name = "arrays";
    std::optional<sr::CameraMatrices> ownCamera;
    // Scene::fromArrays's record of the arrays, for updatePositions: the arrays' vertex each scene vertex
    // copies (flat normals give every triangle corners of its own), their count and width, whether
    // the normals are the triangles' own; positionsVersion counts updates, for the sessions.
    bool fromArrays = false;
    std::vector<uint32_t> sourceVertex;
    size_t sourceVertexCount = 0;
    uint32_t positionComponents = 3;
    bool flatNormals = false;
    uint64_t positionsVersion = 0;
};

struct raster::Settings::Impl {
    sr::RenderOptions options;
    // Settings the command line made (Internal::makeSettings): errors name the camera and the model as
    // its options do (--camera, --model); the API's own name them by their keys (camera, model).
    bool commandLine = false;
};

struct raster::Session::Impl {
    Device::Impl* device = nullptr;
    const Scene::Impl* scene = nullptr;
    // The scene as drawn: the scene itself, or its edges or vertices (primitive-mode lines or points)
    // or with its edges overlaid (wireframe); drawnMode/drawnWireframe say which. Changing how the scene
    // is drawn uploads the derived scene in a new session.
    sr::Scene derived;
    sr::PrimitiveMode drawnMode = sr::PrimitiveMode::Triangles;
    bool drawnWireframe = false;
    std::optional<sr::RenderSession> session;  // compute backends: the uploaded scene and its buffers
    uint64_t positionsVersion = 0;             // Scene::Impl::positionsVersion the session drew last
    std::string warnedView;                    // the camera, model, shading and size last warned about
};

namespace raster {

struct Internal {
    static Device::Impl& of(const Device& device) { return *device.impl_; }
    static Scene::Impl& of(const Scene& scene) { return *scene.impl_; }
    static Settings::Impl& of(const Settings& settings) { return *settings.impl_; }
    static Session::Impl& of(const Session& session) { return *session.impl_; }
    // A scene made below the API (the study's scenes), named `name`, framed by `ownCamera` under the auto
    // camera when it has one.
    static Scene makeScene(sr::Scene scene, std::string name, std::optional<sr::CameraMatrices> ownCamera);
    static Settings makeSettings(const sr::RenderOptions& options);
    // The device of backend `name` (auto, cuda, vulkan, vulkan-graphics; parseBackend) and `index`, its
    // errors as the command line's runners return them.
    static sr::Result<Device> openNamed(const std::string& name, int index);
    // A device the front end opened itself (the viewer's Vulkan device made on its window).
    static Device makeDevice(std::unique_ptr<sr::ComputeDevice> compute);
    // What the front ends inside the project ask of a render beyond the public request.
    struct RenderControl {
        // Which images come back to the host (the viewer presents from the device and downloads nothing,
        // or the colour alone; Session::render downloads all).
        sr::ImageDownload download = sr::ImageDownload::All;
        // vulkan-graphics: depth and ids with the cheapest fragment shader, rasterization and the depth
        // test alone (`raster bench`'s hardware baseline for the compute backends' visibility stages).
        bool visibilityOnly = false;
        // The view as the front end computed it (the bench's and the study's scenes come with theirs),
        // taken as it is in place of the camera's; the model setting is not applied to it.
        const sr::CameraMatrices* matrices = nullptr;
        // Receives the backend's output whole (images, counts, timings, peak memory; the bench and the
        // study measure those); the Frame then holds the statistics JSON, the stage times and the device
        // but no images.
        sr::RenderOutput* output = nullptr;
        // Receives the frame's AOVs as planes, the layout of the EXR (batch writes them): the Frame's
        // interleaved surface AOVs stay empty, so no frame is interleaved only to be split again.
        sr::AovImage* aovPlanes = nullptr;
    };
    // What Session::render is a face of (with the default control): the frame as `control` asks.
    static Result<Frame> render(Session& session, const Camera& camera, const Settings& settings,
                                const RenderRequest& request, const RenderControl& control);
    // The backend's whole output of a frame of `session` seen through `camera` with `settings` as they
    // are (visibilityOnly, outputs, surfaceAovs and download included): what `raster bench` and
    // `raster study` measure (times, counts, peak memory, the images). The frame's warnings go to stderr.
    static sr::Result<sr::RenderOutput> renderOutput(Session& session, const sr::CameraMatrices& camera,
                                                     const sr::RenderSettings& settings);
    // The scene as a frame with `settings` draws it (its lines, points or overlay) and the camera's
    // matrices there, as Session::render resolves them: for --quality, which measures that view.
    static Result<std::pair<sr::Scene, sr::CameraMatrices>> view(const Scene& scene, const Camera& camera,
                                                                 const Settings& settings);
};

// The public error of an internal one, and back.
Error toPublic(const sr::Error& error);
sr::Error fromPublic(const Error& error);

}  // namespace raster

#endif  // RASTER_API_INTERNAL_H
