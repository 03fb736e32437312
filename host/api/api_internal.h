// api_internal.h - what the public API's handles hold, for the front ends inside this project (the
// command line, batch, the viewer) that also reach the pipeline below the API. Not installed.
#ifndef RASTER_API_INTERNAL_H
#define RASTER_API_INTERNAL_H

#include <memory>
#include <optional>

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
};

namespace raster {

// The public error of an internal one, and back.
Error toPublic(const sr::Error& error);
sr::Error fromPublic(const Error& error);

}  // namespace raster

#endif  // RASTER_API_INTERNAL_H
