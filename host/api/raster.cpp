// raster.cpp - the public API (include/raster/raster.h) over the pipeline: devices through the one
// backend choice (api/backend.h), scenes through the loaders' checks, settings through the schema,
// frames through RenderSession.
#include "raster/raster.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <new>
#include <tuple>

#include <fmt/format.h>

#include "api/api_internal.h"
#include "api/backend.h"
#include "api/frame_files.h"
#include "api/front_end.h"
#include "api/stats_json.h"
#include "base/warnings.h"
#include "io/compare.h"
#include "raster_shared.h"
#include "render/aov.h"
#include "camera/camera.h"
#include "scene/primitive_mode.h"
#include "scene/texture.h"
#include "settings/schema.h"
#include "shared/interpolate.h"

namespace raster {

Error toPublic(const sr::Error& error)
{
    return Error{error.code == sr::ExitCode::Runtime ? ErrorKind::Runtime : ErrorKind::Usage, error.message};
}

sr::Error fromPublic(const Error& error)
{
    return sr::Error{error.message,
                     error.kind == ErrorKind::Runtime ? sr::ExitCode::Runtime : sr::ExitCode::Usage};
}

namespace {

Error usage(std::string message)
{
    return Error{ErrorKind::Usage, std::move(message)};
}

}  // namespace

const char* version()
{
    return RASTER_VERSION;
}

// ---- devices ------------------------------------------------------------------------------------

const char* backendName(Backend backend)
{
    switch (backend) {
    case Backend::Auto: return "auto";
    case Backend::Cuda: return "cuda";
    case Backend::Vulkan: return "vulkan";
    case Backend::VulkanGraphics: return "vulkan-graphics";
    }
    return "unknown";
}

Result<Backend> parseBackend(const std::string& name)
{
    for (Backend b : {Backend::Auto, Backend::Cuda, Backend::Vulkan, Backend::VulkanGraphics})
        if (name == backendName(b)) return b;
    return usage(
        fmt::format("invalid backend '{}': expected one of auto, cuda, vulkan, vulkan-graphics", name));
}

std::vector<DeviceInfo> devices()
{
    // Each backend's devices are opened in index order until one does not open: a backend has no
    // count query that also says whether the pipeline can use the device (Vulkan's list is filtered).
    constexpr int kMaxDevicesPerBackend = 64;
    std::vector<DeviceInfo> list;
    for (Backend backend : {Backend::Cuda, Backend::Vulkan}) {
        for (int index = 0; index < kMaxDevicesPerBackend; ++index) {
            auto device = Device::open(backend, index);
            if (!device) break;
            list.push_back(device->info());
        }
    }
    return list;
}

Device::Device(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Device::Device(Device&&) noexcept = default;
Device& Device::operator=(Device&&) noexcept = default;
Device::~Device() = default;

const DeviceInfo& Device::info() const
{
    return impl_->info;
}

Result<Device> Device::open(Backend backend, int index)
{
    auto impl = std::make_unique<Impl>();
    impl->info.index = index;
    if (backend == Backend::VulkanGraphics) {
        // The graphics pipeline opens its own device per frame; opening the compute device of the same
        // index here checks that it exists and names it.
        auto probe = sr::makeComputeDevice(sr::BackendKind::Vulkan, index);
        if (!probe) return toPublic(probe.error());
        impl->info.backend = Backend::VulkanGraphics;
        impl->info.name = (*probe)->info().name;
        impl->info.driver = (*probe)->info().driver;
        impl->info.cpu = (*probe)->info().isCpu;
        return Device(std::move(impl));
    }
    const sr::BackendKind kind = backend == Backend::Cuda     ? sr::BackendKind::Cuda
                                 : backend == Backend::Vulkan ? sr::BackendKind::Vulkan
                                                              : sr::BackendKind::Auto;
    auto device = sr::makeComputeDevice(kind, index);
    if (!device) return toPublic(device.error());
    impl->compute = std::move(*device);
    const sr::DeviceInfo& info = impl->compute->info();
    impl->info.backend = info.backend == "cuda" ? Backend::Cuda : Backend::Vulkan;
    impl->info.name = info.name;
    impl->info.driver = info.driver;
    impl->info.cpu = info.isCpu;
    return Device(std::move(impl));
}

// ---- scenes -------------------------------------------------------------------------------------

Scene::Scene(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Scene::Scene(const Scene& other) : impl_(std::make_unique<Impl>(*other.impl_)) {}
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;
Scene::~Scene() = default;

size_t Scene::vertexCount() const
{
    return impl_->scene.vertexCount();
}
size_t Scene::triangleCount() const
{
    return impl_->scene.triangleCount();
}
size_t Scene::lineCount() const
{
    return impl_->scene.lineCount();
}
size_t Scene::pointCount() const
{
    return impl_->scene.pointCount();
}
std::array<float, 3> Scene::boundsMin() const
{
    const glm::vec3& b = impl_->scene.boundsMin;
    return {b.x, b.y, b.z};
}
std::array<float, 3> Scene::boundsMax() const
{
    const glm::vec3& b = impl_->scene.boundsMax;
    return {b.x, b.y, b.z};
}

const std::vector<std::string>& Scene::warnings() const
{
    return impl_->warnings;
}

Result<Scene> Scene::load(const std::string& path)
{
    sr::WarningCapture capture;
    auto scene = sr::loadScene(path);
    if (!scene) return toPublic(scene.error());
    auto impl = std::make_unique<Impl>();
    impl->scene = std::move(*scene);
    impl->warnings = capture.take();
    impl->name = path;
    return Scene(std::move(impl));
}

Scene Internal::makeScene(sr::Scene scene, std::string name, std::optional<sr::CameraMatrices> ownCamera)
{
    auto impl = std::make_unique<Scene::Impl>();
    impl->scene = std::move(scene);
    impl->name = std::move(name);
    impl->ownCamera = ownCamera;
    return Scene(std::move(impl));
}

Settings Internal::makeSettings(const sr::RenderOptions& options)
{
    Settings settings;
    settings.impl_->options = options;
    settings.impl_->commandLine = true;
    return settings;
}

namespace {

glm::vec3 vec3At(const float* data, size_t i)
{
    return {data[3 * i], data[3 * i + 1], data[3 * i + 2]};
}

// Vertex i of positions with `components` (3 or 4) floats each, as a homogeneous point.
glm::vec4 positionAt(const float* data, uint32_t components, size_t i)
{
    const float* p = data + size_t(components) * i;
    return {p[0], p[1], p[2], components == 4 ? p[3] : 1.0f};
}

// The point a homogeneous position stands for (x/w, y/w, z/w), for face normals.
glm::vec3 euclidean(glm::vec4 p)
{
    return glm::vec3(p) / p.w;
}

// A triangle's unit normal from its corners, zero for a degenerate one (as the glTF loader gives a
// primitive without normals: the shading of such a triangle is its ambient term).
glm::vec3 faceNormal(glm::vec3 a, glm::vec3 b, glm::vec3 c)
{
    const glm::vec3 n = glm::cross(b - a, c - a);
    const float length = glm::length(n);
    return length > 0.0f && std::isfinite(length) ? n / length : glm::vec3(0.0f);
}

}  // namespace

Result<Scene> Scene::fromArrays(const MeshArrays& m)
{
    sr::WarningCapture capture;
    if (m.vertexCount > 0 && m.positions == nullptr) return usage("fromArrays: vertices without positions");
    if (m.triangleCount > 0 && m.triangles == nullptr)
        return usage("fromArrays: a triangle count without indices");
    if (m.lineCount > 0 && m.lines == nullptr) return usage("fromArrays: a line count without indices");
    if (m.pointCount > 0 && m.points == nullptr) return usage("fromArrays: a point count without indices");
    if (m.texture.rgba8 != nullptr && m.texcoords == nullptr)
        return usage("fromArrays: a texture needs texture coordinates");
    if (m.positionComponents != 3 && m.positionComponents != 4)
        return usage(fmt::format("fromArrays: positions have {} components (3 or 4)", m.positionComponents));
    for (size_t i = 0; i < 4; ++i)
        if (!std::isfinite(m.baseColor[i])) return usage("fromArrays: the base colour must be finite");
    // Attributes must be finite: a NaN colour, normal or texture coordinate has no shade to give (a
    // position may not be: its primitives are dropped with a warning, as the loaders drop them).
    for (const auto& [data, count, what] :
         {std::tuple<const float*, size_t, const char*>{m.normals, 3, "normal"},
          {m.texcoords, 2, "texture coordinate"},
          {m.colors, 4, "colour"}}) {
        if (!data) continue;
        for (size_t i = 0; i < count * m.vertexCount; ++i)
            if (!std::isfinite(data[i]))
                return usage(fmt::format("fromArrays: the {} of vertex {} is not finite ({})", what,
                                         i / count, data[i]));
    }

    sr::Scene s;
    const uint32_t flags = m.doubleSided ? TRI_FLAG_DOUBLE_SIDED : 0u;
    // Vertex v of the arrays as scene vertex, with normal n (the arrays' own when given).
    std::vector<uint32_t> sourceVertex;  // per scene vertex, the arrays' vertex it copies
    auto pushVertex = [&](size_t v, glm::vec3 n) {
        sourceVertex.push_back(uint32_t(v));
        s.positions.push_back(positionAt(m.positions, m.positionComponents, v));
        s.normals.emplace_back(m.normals ? vec3At(m.normals, v) : n, 0.0f);
        if (m.colors)
            s.colors.emplace_back(m.colors[4 * v], m.colors[4 * v + 1], m.colors[4 * v + 2],
                                  m.colors[4 * v + 3]);
        if (m.texcoords) s.texcoords.emplace_back(m.texcoords[2 * v], m.texcoords[2 * v + 1], 0.0f, 0.0f);
    };
    // Out-of-range indices are left for finalizeScene, which drops those primitives with a warning.
    auto inRange = [&](uint32_t v) { return v < m.vertexCount; };
    if (m.normals) {
        for (size_t v = 0; v < m.vertexCount; ++v) pushVertex(v, glm::vec3(0.0f));
        s.indices.assign(m.triangles, m.triangles + 3 * m.triangleCount);
    } else {
        // Flat normals: every triangle gets three vertices of its own (lines and points keep the shared
        // vertices, appended after them, with zero normals: they are shaded unlit).
        for (size_t t = 0; t < m.triangleCount; ++t) {
            const uint32_t* c = m.triangles + 3 * t;
            const bool valid = inRange(c[0]) && inRange(c[1]) && inRange(c[2]);
            auto corner = [&](int k) {
                return euclidean(positionAt(m.positions, m.positionComponents, c[k]));
            };
            const glm::vec3 n = valid ? faceNormal(corner(0), corner(1), corner(2)) : glm::vec3(0.0f);
            for (int k = 0; k < 3; ++k) {
                if (!valid) {
                    s.indices.push_back(uint32_t(-1));
                    continue;
                }
                s.indices.push_back(uint32_t(s.positions.size()));
                pushVertex(c[k], n);
            }
        }
    }
    const auto base = uint32_t(m.normals ? 0 : s.positions.size());
    if (!m.normals && (m.lineCount || m.pointCount))
        for (size_t v = 0; v < m.vertexCount; ++v) pushVertex(v, glm::vec3(0.0f));
    auto shift = [&](uint32_t v) { return inRange(v) ? base + v : uint32_t(-1); };
    for (size_t i = 0; i < 2 * m.lineCount; ++i) s.lines.push_back(shift(m.lines[i]));
    for (size_t i = 0; i < m.pointCount; ++i) s.points.push_back(shift(m.points[i]));
    s.triFlags.assign(s.indices.size() / 3, flags);

    sr::SceneMaterial material;
    material.name = "arrays";
    material.baseColorFactor = glm::vec4(m.baseColor[0], m.baseColor[1], m.baseColor[2], m.baseColor[3]);
    if (m.texture.rgba8 != nullptr) {
        auto texture = sr::makeTexture("arrays texture", m.texture.width, m.texture.height, m.texture.rgba8,
                                       m.texture.srgb, sr::TextureSampler{});
        if (!texture) return toPublic(texture.error());
        s.textures.push_back(std::move(*texture));
        material.baseColorTexture = 0;
    } else {
        s.texcoords.clear();
    }
    s.materials.push_back(material);
    s.triMaterials.assign(s.triangleCount(), 0u);
    s.lineMaterials.assign(s.lineCount(), 0u);
    s.pointMaterials.assign(s.pointCount(), 0u);
    auto finalized = sr::finalizeScene(s, "fromArrays");
    if (!finalized) return toPublic(finalized.error());
    auto impl = std::make_unique<Impl>();
    impl->scene = std::move(s);
    impl->warnings = capture.take();
    impl->fromArrays = true;
    impl->sourceVertex = std::move(sourceVertex);
    impl->sourceVertexCount = m.vertexCount;
    impl->positionComponents = m.positionComponents;
    impl->flatNormals = m.normals == nullptr;
    return Scene(std::move(impl));
}

Memory::Memory(std::shared_ptr<void> data, size_t size, Where where)
    : data_(std::move(data)), size_(size), where_(where)
{
}

Result<Memory> Memory::allocate(Device& device, size_t bytes, Where where)
{
    const bool onDevice = where == Where::Device;
    if (!Internal::of(device).compute) {
        if (onDevice) return usage("memory on the device needs a CUDA device, not vulkan-graphics");
        auto data = std::shared_ptr<void>(::operator new(bytes == 0 ? 1 : bytes, std::nothrow),
                                          [](void* p) { ::operator delete(p); });
        if (!data)
            return Error{ErrorKind::Runtime, fmt::format("cannot allocate {} bytes of host memory", bytes)};
        return Memory(std::move(data), bytes, where);
    }
    auto data = Internal::of(device).compute->allocateMemory(onDevice, bytes);
    if (!data) return toPublic(data.error());
    return Memory(std::move(*data), bytes, where);
}

Status Scene::updatePositions(const float* positions, size_t vertexCount, uint32_t components)
{
    Impl& self = *impl_;
    if (!self.fromArrays)
        return usage("updatePositions: only a scene made from arrays can move its vertices");
    if (vertexCount != self.sourceVertexCount || components != self.positionComponents)
        return usage(
            fmt::format("updatePositions: {} positions of {} components for a scene made from {} of {}",
                        vertexCount, components, self.sourceVertexCount, self.positionComponents));
    if (vertexCount > 0 && positions == nullptr) return usage("updatePositions: no positions");
    for (size_t i = 0; i < vertexCount * components; ++i)
        if (!std::isfinite(positions[i]))
            return usage(fmt::format("updatePositions: the position of vertex {} is not finite ({})",
                                     i / components, positions[i]));
    sr::Scene& s = self.scene;
    for (size_t v = 0; v < self.sourceVertex.size(); ++v)
        s.positions[v] = positionAt(positions, components, self.sourceVertex[v]);
    if (self.flatNormals) {
        // Each triangle's corners are its own vertices (a dropped one's all one anchor vertex, which keeps
        // the normal of the primitive it belongs to).
        for (size_t t = 0; t < s.triangleCount(); ++t) {
            const uint32_t* c = &s.indices[3 * t];
            if (c[0] == c[1] && c[1] == c[2]) continue;
            const glm::vec3 n = faceNormal(euclidean(s.positions[c[0]]), euclidean(s.positions[c[1]]),
                                           euclidean(s.positions[c[2]]));
            for (int k = 0; k < 3; ++k) s.normals[c[k]] = glm::vec4(n, 0.0f);
        }
    }
    sr::updateBounds(s);
    ++self.positionsVersion;
    return Status();
}

// ---- settings and cameras -----------------------------------------------------------------------

Settings::Settings() : impl_(std::make_unique<Impl>()) {}
Settings::Settings(const Settings& other) : impl_(std::make_unique<Impl>(*other.impl_)) {}
Settings& Settings::operator=(const Settings& other)
{
    *impl_ = *other.impl_;
    return *this;
}
Settings::~Settings() = default;

namespace {

Result<const sr::Setting*> lookUp(const std::string& name)
{
    const sr::Setting* s = sr::findSetting(name);
    if (!s)
        return usage(fmt::format("unknown setting {} (raster settings lists them)", sr::quotedInput(name)));
    return s;
}

Status store(sr::RenderOptions& options, const std::string& name, const nlohmann::json& value)
{
    auto s = lookUp(name);
    if (!s) return s.error();
    auto stored = sr::setSetting(options, **s, value, (*s)->key());
    if (!stored) return toPublic(stored.error());
    return Status();
}

}  // namespace

Status Settings::set(const std::string& name, const std::string& text)
{
    auto s = lookUp(name);
    if (!s) return s.error();
    auto value = sr::parseSettingText(**s, text, (*s)->key());
    if (!value) return toPublic(value.error());
    (*s)->set(impl_->options, *value);
    return Status();
}

Status Settings::set(const std::string& name, double number)
{
    auto s = lookUp(name);
    if (!s) return s.error();
    // JSON has no NaN or infinity (nlohmann writes them as null): refused here, by value.
    if (!std::isfinite(number))
        return usage(fmt::format("{} {} is not a finite number", (*s)->key(), number));
    // A whole number goes to uint settings as an integer; anything else is checked as given.
    if ((*s)->type == sr::SettingType::Uint && number == std::floor(number) && number >= 0.0 &&
        number < 4294967296.0)
        return store(impl_->options, name, nlohmann::json(uint64_t(number)));
    return store(impl_->options, name, nlohmann::json(number));
}

Status Settings::set(const std::string& name, bool flag)
{
    return store(impl_->options, name, nlohmann::json(flag));
}

Status Settings::set(const std::string& name, const std::array<double, 3>& v)
{
    for (double x : v)
        if (!std::isfinite(x)) {
            auto s = lookUp(name);
            if (!s) return s.error();
            return usage(
                fmt::format("{} {},{},{} is not three finite numbers", (*s)->key(), v[0], v[1], v[2]));
        }
    return store(impl_->options, name, nlohmann::json::array({v[0], v[1], v[2]}));
}

Result<std::string> Settings::get(const std::string& name) const
{
    auto s = lookUp(name);
    if (!s) return s.error();
    return sr::settingText(impl_->options, **s);
}

std::string Settings::json() const
{
    return sr::settingsJson(impl_->options).dump();
}

std::string Settings::commandLine() const
{
    return sr::renderArguments(impl_->options);
}

std::vector<std::string> Settings::names()
{
    std::vector<std::string> names;
    for (const sr::Setting& s : sr::settingsSchema()) names.push_back(s.name);
    return names;
}

std::string Settings::schemaJson()
{
    return sr::schemaJson().dump();
}

Camera Camera::fromSpec(std::string spec)
{
    Camera c;
    c.spec = std::move(spec);
    return c;
}

Camera Camera::fromMatrices(const std::array<float, 16>& view, const std::array<float, 16>& projection)
{
    Camera c;
    c.explicitMatrices = true;
    c.view = view;
    c.projection = projection;
    return c;
}

namespace {

glm::mat4 toMat4(const std::array<float, 16>& m)
{
    glm::mat4 out;
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) out[c][r] = m[size_t(4 * c + r)];
    return out;
}

// The spec a camera asks for: its own, or the settings' under "auto" ("" for explicit matrices).
std::string cameraSpecText(const Camera& camera, const sr::RenderOptions& options)
{
    if (camera.explicitMatrices) return "";
    return camera.spec == "auto" ? options.camera : camera.spec;
}

// Whether the frame is framed by the scene's own camera: the auto camera of a scene that has one.
bool usesOwnCamera(const Camera& camera, const sr::RenderOptions& options, const Scene::Impl& scene)
{
    if (!scene.ownCamera || camera.explicitMatrices) return false;
    auto spec = sr::parseCameraSpec(cameraSpecText(camera, options));
    return spec && spec->kind == sr::CameraSpec::Kind::Auto;
}

// The matrices of `camera` for this scene and image, looking at the scene moved by the model setting: a
// spec resolved as `raster render --camera --model` does, or explicit matrices with the depth range they
// encode (perspective: the last column is (0, 0, -1, 0); otherwise orthographic) times the model matrix.
Result<sr::CameraMatrices> resolvedMatrices(const Camera& camera, const sr::RenderOptions& options,
                                            const sr::Scene& scene, const Scene::Impl& record)
{
    const sr::RenderSettings& s = options.settings;
    auto model = sr::parseModelSpec(options.model);
    if (!model) return toPublic(model.error());
    if (usesOwnCamera(camera, options, record))
        return sr::withModel(*record.ownCamera, *model, sr::boundingSphere(scene).center);
    if (!camera.explicitMatrices) {
        auto spec = sr::parseCameraSpec(cameraSpecText(camera, options));
        if (!spec) return toPublic(spec.error());
        auto m = sr::resolveCamera(*spec, scene, s.width, s.height, *model);
        if (!m) return toPublic(m.error());
        return *m;
    }
    sr::CameraMatrices m;
    m.viewFromWorld = toMat4(camera.view);
    m.clipFromView = toMat4(camera.projection);
    for (float v : camera.view)
        if (!std::isfinite(v)) return usage("the camera's view matrix is not finite");
    for (float v : camera.projection)
        if (!std::isfinite(v)) return usage("the camera's projection matrix is not finite");
    m.clipFromWorld = m.clipFromView * m.viewFromWorld;
    const glm::mat4& p = m.clipFromView;
    if (p[2][3] != 0.0f) {
        // Vulkan perspective: z_clip = A z + B, w = -z with A = f / (n - f), B = n f / (n - f).
        m.znear = p[3][2] / p[2][2];
        m.zfar = p[2][2] + 1.0f == 0.0f ? INFINITY : p[3][2] / (p[2][2] + 1.0f);
    } else {
        // Orthographic: z_clip = A z + B with A = 1 / (n - f), B = n / (n - f).
        m.znear = p[3][2] / p[2][2];
        m.zfar = m.znear - 1.0f / p[2][2];
    }
    return sr::withModel(m, *model, sr::boundingSphere(scene).center);
}

// resolvedMatrices, its errors naming the camera and the model as the caller does: by the settings' keys
// for the API (and Python), by the options for the command line's own settings.
Result<sr::CameraMatrices> cameraMatrices(const Camera& camera, const Settings::Impl& settings,
                                          const sr::Scene& scene, const Scene::Impl& record)
{
    auto m = resolvedMatrices(camera, settings.options, scene, record);
    if (m || settings.commandLine) return m;
    sr::Error error = fromPublic(m.error());
    for (const char* name : {"camera", "model"})
        error = sr::relabelled(error, std::string("--") + name, name);
    return toPublic(error);
}

// The public frame of a backend's output: its images taken out of `out` unless `timingsOnly` (then the
// frame has the size, the times, the statistics and the device), the surface AOVs as planes into
// `surfacePlanes` when given, else interleaved into the frame.
Frame toFrame(sr::RenderOutput& out, const sr::RenderOptions& options, const DeviceInfo& device,
              const std::string& sceneName, const std::string& resolvedCamera, const sr::Scene& scene,
              const RenderRequest& request, bool timingsOnly, sr::AovImage* surfacePlanes)
{
    Frame f;
    f.width = out.color.width;
    f.height = out.color.height;
    f.gpuMs = out.total.medianMs;
    for (const sr::StageTiming& t : out.stages) f.stages.push_back({t.name, t.minMs, t.medianMs, t.maxMs});
    f.stages.push_back({"total", out.total.minMs, out.total.medianMs, out.total.maxMs});
    if (request.stats) f.statsJson = sr::statsJson(out, options, sceneName, resolvedCamera).dump(2);
    f.device = device;
    if (timingsOnly) return f;
    // Each pixel's word holds R in its low byte: the bytes of a little-endian word in memory order.
    f.color.resize(out.color.pixels.size() * 4);
    if (sr::littleEndianHost() && !f.color.empty())
        std::memcpy(f.color.data(), out.color.pixels.data(), f.color.size());
    else
        for (size_t i = 0; i < out.color.pixels.size(); ++i)
            for (int c = 0; c < 4; ++c) f.color[4 * i + c] = uint8_t(out.color.pixels[i] >> (8 * c));
    if (request.surfaceAovs && !out.aov.hasBary()) sr::fillSurfaceAovs(scene, out.params, out.aov);
    f.id = std::move(out.aov.id);
    f.depth = std::move(out.aov.depth);
    f.ao = std::move(out.aov.ao);
    if (out.aov.hasBary() && surfacePlanes) {
        *surfacePlanes = std::move(out.aov);  // what is left of it: the surface planes
    } else if (out.aov.hasBary()) {
        const size_t n = size_t(f.width) * f.height;
        f.bary.resize(2 * n);
        f.uv.resize(2 * n);
        f.normal.resize(3 * n);
        for (size_t i = 0; i < n; ++i) {
            f.bary[2 * i] = out.aov.baryU[i];
            f.bary[2 * i + 1] = out.aov.baryV[i];
            f.uv[2 * i] = out.aov.uvU[i];
            f.uv[2 * i + 1] = out.aov.uvV[i];
            f.normal[3 * i] = out.aov.normalX[i];
            f.normal[3 * i + 1] = out.aov.normalY[i];
            f.normal[3 * i + 2] = out.aov.normalZ[i];
        }
    }
    f.rasterWidth = out.samples.rasterWidth;
    f.rasterHeight = out.samples.rasterHeight;
    f.samples = out.samples.samples;
    f.sampleId = std::move(out.samples.id);
    f.sampleDepth = std::move(out.samples.depth);
    return f;
}

}  // namespace

// ---- sessions and frames ------------------------------------------------------------------------

Session::Session(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Session::Session(Session&&) noexcept = default;
Session& Session::operator=(Session&&) noexcept = default;
Session::~Session() = default;

Result<Session> Session::create(Device& device, const Scene& scene)
{
    auto impl = std::make_unique<Impl>();
    impl->device = &Internal::of(device);
    impl->scene = &Internal::of(scene);
    if (impl->device->compute) {
        auto session = sr::RenderSession::create(*impl->device->compute, impl->scene->scene);
        if (!session) return toPublic(session.error());
        impl->session.emplace(std::move(*session));
    } else {
        auto checked = sr::checkSceneInputs(impl->scene->scene);
        if (!checked) return toPublic(checked.error());
    }
    return Session(std::move(impl));
}

Result<std::pair<sr::Scene, sr::CameraMatrices>> Internal::view(const Scene& scene, const Camera& camera,
                                                                const Settings& settings)
{
    const sr::RenderOptions& options = settings.impl_->options;
    const Scene::Impl& record = *scene.impl_;
    sr::Scene drawn = sr::displayScene(record.scene, options.primitiveMode, options.wireframe);
    auto matrices = cameraMatrices(camera, *settings.impl_, drawn, record);
    if (!matrices) return matrices.error();
    return std::pair<sr::Scene, sr::CameraMatrices>(std::move(drawn), *matrices);
}

Result<Frame> Session::render(const Camera& camera, const Settings& settings, const RenderRequest& request)
{
    return Internal::render(*this, camera, settings, request, Internal::RenderControl{});
}

sr::Result<Device> Internal::openNamed(const std::string& name, int index)
{
    auto backend = parseBackend(name);
    if (!backend) return fromPublic(backend.error());
    auto device = Device::open(*backend, index);
    if (!device) return fromPublic(device.error());
    return std::move(*device);
}

Device Internal::makeDevice(std::unique_ptr<sr::ComputeDevice> compute)
{
    auto impl = std::make_unique<Device::Impl>();
    const sr::DeviceInfo& info = compute->info();
    impl->info.backend = info.backend == "cuda" ? Backend::Cuda : Backend::Vulkan;
    impl->info.name = info.name;
    impl->info.driver = info.driver;
    impl->info.cpu = info.isCpu;
    impl->compute = std::move(compute);
    return Device(std::move(impl));
}

Result<Frame> Internal::render(Session& session, const Camera& camera, const Settings& settings,
                               const RenderRequest& request, const RenderControl& control)
{
    sr::WarningCapture capture;  // the frame's warnings go to Frame::warnings, not to stderr
    Session::Impl& self = *session.impl_;
    const sr::RenderOptions& options = Internal::of(settings).options;
    const bool plain = options.primitiveMode == sr::PrimitiveMode::Triangles && !options.wireframe;
    const ImageTargets& t = request.targets;
    const uint32_t targeted = (t.color ? sr::OUTPUT_COLOR : 0u) | (t.id ? sr::OUTPUT_ID : 0u) |
                              (t.depth ? sr::OUTPUT_DEPTH : 0u) | (t.rast ? sr::OUTPUT_RAST : 0u);
    if (targeted != 0u && !self.device->compute)
        return usage(
            "images written in place come from the compute backends (cuda, vulkan), not vulkan-graphics");
    // Positions moved in place (Scene::updatePositions): the session uploads them again; a derived scene
    // (lines, points, the overlay) is derived again.
    const bool moved = self.scene->positionsVersion != self.positionsVersion;
    if (moved || options.primitiveMode != self.drawnMode || options.wireframe != self.drawnWireframe)
        self.warnedView.clear();
    self.positionsVersion = self.scene->positionsVersion;
    if (moved && plain && self.session) {
        auto status = self.session->positionsChanged(self.scene->flatNormals);
        if (!status) return toPublic(status.error());
    }
    if (options.primitiveMode != self.drawnMode || options.wireframe != self.drawnWireframe ||
        (moved && !plain)) {
        // Lines and points modes and the wireframe overlay draw a scene derived from the loaded one; the
        // device's buffers get that scene (or the loaded one again) in a session of their own.
        self.session.reset();
        self.derived = plain ? sr::Scene()
                             : sr::displayScene(self.scene->scene, options.primitiveMode, options.wireframe);
        self.drawnMode = options.primitiveMode;
        self.drawnWireframe = options.wireframe;
    }
    const sr::Scene& scene = plain ? self.scene->scene : self.derived;
    if (self.device->compute && !self.session) {
        auto session = sr::RenderSession::create(*self.device->compute, scene);
        if (!session) return toPublic(session.error());
        self.session.emplace(std::move(*session));
    }
    auto matrices = control.matrices ? Result<sr::CameraMatrices>(*control.matrices)
                                     : cameraMatrices(camera, Internal::of(settings), scene, *self.scene);
    if (!matrices) return matrices.error();
    sr::RenderSettings s = options.resolved();
    s.download = control.download;
    s.visibilityOnly = control.visibilityOnly;
    // What would make the image plain without the caller knowing why, for cameras given as specs (the
    // command line's, a viewer's): once per camera and shading, as the eye test may walk every triangle.
    if (!camera.explicitMatrices && !control.matrices) {
        const std::string key = cameraSpecText(camera, options) + "|" + options.model + "|" +
                                std::to_string(s.shadingMode) + "|" + std::to_string(s.width) + "x" +
                                std::to_string(s.height);
        if (key != self.warnedView) {
            self.warnedView = key;
            for (std::string& warning : sr::viewWarnings(scene, *matrices, s))
                sr::warnLine(std::move(warning));
        }
    }
    s.surfaceAovs = request.surfaceAovs;
    s.outputs = ((request.outputs & OutputColor) ? sr::OUTPUT_COLOR : 0u) |
                ((request.outputs & OutputId) ? sr::OUTPUT_ID : 0u) |
                ((request.outputs & OutputDepth) ? sr::OUTPUT_DEPTH : 0u) | targeted;
    // Tessellated and level-of-detail frames get their ids mapped on the host: their images reach the
    // targets from the frame's arrays.
    const bool direct = s.tessellate == TESS_OFF && s.lod == sr::LOD_OFF;
    if (targeted != 0u && !direct && t.onDevice)
        return usage(
            "images on the device do not combine with tessellate or lod (their ids are mapped on the host)");
    s.keptOutputs = direct ? targeted : 0u;
    auto out = self.session ? self.session->render(*matrices, s)
                            : sr::renderGraphics(scene, *matrices, s, self.device->info.index);
    if (!out) return toPublic(out.error());
    const size_t pixels = size_t(s.width) * s.height;
    for (const auto& [bit, target] : {std::pair<uint32_t, void*>{sr::OUTPUT_COLOR, t.color},
                                      {sr::OUTPUT_ID, t.id},
                                      {sr::OUTPUT_DEPTH, t.depth},
                                      {sr::OUTPUT_RAST, t.rast}}) {
        if (target == nullptr) continue;
        if (!direct) {
            // Colour, ids and depth alone: rasterize's output was refused with tessellation and lod.
            const size_t words = bit == sr::OUTPUT_COLOR ? out->color.pixels.size()
                                 : bit == sr::OUTPUT_ID  ? out->aov.id.size()
                                                         : out->aov.depth.size();
            if (words != pixels)
                return Error{ErrorKind::Runtime,
                             fmt::format("image {} has {} of {} pixels", bit, words, pixels)};
            const void* from = bit == sr::OUTPUT_COLOR ? static_cast<const void*>(out->color.pixels.data())
                               : bit == sr::OUTPUT_ID  ? static_cast<const void*>(out->aov.id.data())
                                                       : static_cast<const void*>(out->aov.depth.data());
            std::memcpy(target, from, pixels * 4);
            continue;
        }
        auto read =
            self.session->readImage(bit, target, pixels * (bit == sr::OUTPUT_RAST ? 16 : 4), t.onDevice);
        if (!read) return toPublic(read.error());
    }
    if (!direct) {
        if (t.color) out->color.pixels.clear();
        if (t.id) out->aov.id.clear();
        if (t.depth) out->aov.depth.clear();
    }
    // The graphics reference fills every image: the ones not asked for are dropped, as the others skip them.
    if (!(request.outputs & OutputColor)) out->color.pixels.clear();
    if (!(request.outputs & OutputId)) out->aov.id.clear();
    if (!(request.outputs & OutputDepth)) out->aov.depth.clear();
    // The statistics echo the camera the frame used (a spec given here replaces the settings' one) and
    // name it in absolute scene units; explicit matrices and a scene's own camera are in the matrices.
    sr::RenderOptions echoed = options;
    std::string resolved;
    if (!camera.explicitMatrices && !control.matrices) {
        echoed.camera = cameraSpecText(camera, options);
        auto spec = sr::parseCameraSpec(echoed.camera);
        if (spec && !usesOwnCamera(camera, options, *self.scene))
            resolved = sr::resolvedCameraSpec(*spec, scene, s.width, s.height);
    }
    // With `output` the images stay in the backend's output, for the caller that measures them.
    Frame frame = toFrame(*out, echoed, self.device->info, self.scene->name, resolved, scene, request,
                          control.output != nullptr, control.aovPlanes);
    if (control.output) *control.output = std::move(*out);
    frame.warnings = capture.take();
    return frame;
}

sr::Result<sr::RenderOutput> Internal::renderOutput(Session& session, const sr::CameraMatrices& camera,
                                                    const sr::RenderSettings& settings)
{
    sr::RenderOptions options;
    options.settings = settings;
    options.tessMaxLevel = settings.tessMaxLevel;
    RenderRequest request;
    request.outputs = ((settings.outputs & sr::OUTPUT_COLOR) ? OutputColor : 0u) |
                      ((settings.outputs & sr::OUTPUT_ID) ? OutputId : 0u) |
                      ((settings.outputs & sr::OUTPUT_DEPTH) ? OutputDepth : 0u);
    request.surfaceAovs = settings.surfaceAovs;
    request.stats = false;
    sr::RenderOutput out;
    RenderControl control;
    control.download = settings.download;
    control.visibilityOnly = settings.visibilityOnly;
    control.matrices = &camera;
    control.output = &out;
    auto frame = render(session, Camera::fromSpec("auto"), makeSettings(options), request, control);
    if (!frame) return fromPublic(frame.error());
    for (std::string& warning : frame->warnings) sr::warnLine(std::move(warning));
    return out;
}

namespace {

// renderViews' and renderMany's common part: the device and the drawing mode checked, the request's
// targets as the session takes them, and the session of the scene itself made (or kept).
Result<std::vector<sr::RenderSession::ViewTarget>> batchSession(Session::Impl& self,
                                                                const sr::RenderOptions& options,
                                                                const RenderRequest& request,
                                                                const char* what)
{
    if (!self.device->compute)
        return usage(
            fmt::format("{} are drawn by the compute backends (cuda, vulkan), not vulkan-graphics", what));
    if (options.primitiveMode != sr::PrimitiveMode::Triangles || options.wireframe)
        return usage(fmt::format("{} are drawn as triangles (no lines or points mode, no wireframe)", what));
    const ImageTargets& t = request.targets;
    std::vector<sr::RenderSession::ViewTarget> targets;
    for (const auto& [bit, target] : {std::pair<uint32_t, void*>{sr::OUTPUT_COLOR, t.color},
                                      {sr::OUTPUT_ID, t.id},
                                      {sr::OUTPUT_DEPTH, t.depth},
                                      {sr::OUTPUT_RAST, t.rast}})
        if (target != nullptr) targets.push_back({bit, target, t.onDevice});
    // Positions moved in place since the session drew (Scene::updatePositions) are uploaded again.
    if (self.scene->positionsVersion != self.positionsVersion && self.session) {
        auto status = self.session->positionsChanged(self.scene->flatNormals);
        if (!status) return toPublic(status.error());
    }
    self.positionsVersion = self.scene->positionsVersion;
    if (self.drawnMode != sr::PrimitiveMode::Triangles || self.drawnWireframe) {
        self.session.reset();
        self.derived = sr::Scene();
        self.drawnMode = sr::PrimitiveMode::Triangles;
        self.drawnWireframe = false;
    }
    if (!self.session) {
        auto session = sr::RenderSession::create(*self.device->compute, self.scene->scene);
        if (!session) return toPublic(session.error());
        self.session.emplace(std::move(*session));
    }
    return targets;
}

}  // namespace

Result<ViewsReport> Session::renderViews(const Camera& camera, const Settings& settings,
                                         const ViewPositions& positions, const RenderRequest& request)
{
    sr::WarningCapture capture;
    Impl& self = *impl_;
    const Scene::Impl& scene = *self.scene;
    const sr::RenderOptions& options = Internal::of(settings).options;
    if (!scene.fromArrays || scene.flatNormals)
        return usage(
            "views need a scene made from arrays with normals (flat normals would not follow the "
            "positions)");
    if (positions.views > 0 && positions.data == nullptr) return usage("views: no positions");
    if (positions.onDevice && scene.positionComponents != 4)
        return usage("views: positions on the device need 4 components per vertex");
    auto targets = batchSession(self, options, request, "views");
    if (!targets) return targets.error();
    auto matrices = cameraMatrices(camera, Internal::of(settings), scene.scene, scene);
    if (!matrices) return matrices.error();
    // The device holds a vec4 per vertex: three components are widened on the host first.
    const size_t vertices = scene.sourceVertexCount;
    std::vector<glm::vec4> widened;
    sr::ViewInputs inputs;
    inputs.positions = positions.data;
    inputs.bytes = vertices * sizeof(glm::vec4);
    inputs.onDevice = positions.onDevice;
    inputs.waitStream = positions.stream;
    if (scene.positionComponents == 3 && positions.views > 0) {
        widened.resize(vertices * positions.views);
        for (size_t i = 0; i < widened.size(); ++i) widened[i] = positionAt(positions.data, 3, i);
        inputs.positions = widened.data();
    }
    auto invalid =
        self.session->renderViews({*matrices}, options.resolved(), inputs, positions.views, *targets);
    if (!invalid) return toPublic(invalid.error());
    ViewsReport report;
    report.invalidTriangles = std::move(*invalid);
    report.warnings = capture.take();
    return report;
}

Result<ViewsReport> Session::renderMany(const std::vector<Camera>& cameras, const Settings& settings,
                                        const RenderRequest& request)
{
    sr::WarningCapture capture;
    Impl& self = *impl_;
    const sr::RenderOptions& options = Internal::of(settings).options;
    auto targets = batchSession(self, options, request, "frames of many cameras");
    if (!targets) return targets.error();
    std::vector<sr::CameraMatrices> matrices;
    for (const Camera& camera : cameras) {
        auto m = cameraMatrices(camera, Internal::of(settings), self.scene->scene, *self.scene);
        if (!m) return m.error();
        matrices.push_back(*m);
    }
    if (matrices.empty()) return ViewsReport{};
    auto invalid =
        self.session->renderViews(matrices, options.resolved(), sr::ViewInputs{}, matrices.size(), *targets);
    if (!invalid) return toPublic(invalid.error());
    ViewsReport report;
    report.invalidTriangles = std::move(*invalid);
    report.warnings = capture.take();
    return report;
}

Result<InterpolateReport> interpolate(const InterpolateArrays& a, Device* device)
{
    if (a.attrViews != 1 && a.attrViews != a.views)
        return usage(
            fmt::format("interpolate: attributes of {} views x {} vertices x {} channels for {} views",
                        a.attrViews, a.vertices, a.channels, a.views));
    const size_t pixelsPerView = a.height * a.width, pixels = a.views * pixelsPerView;
    if (pixels > 0 && (a.attr == nullptr || a.rast == nullptr || a.out == nullptr ||
                       (a.triangleCount > 0 && a.triangles == nullptr)))
        return usage("interpolate: an array is missing");
    InterpolateReport report;
    if (a.onDevice) {
        if (device == nullptr || !Internal::of(*device).compute)
            return usage("interpolate: arrays on the device need a CUDA device");
        sr::InterpolateJob job;
        job.attr = a.attr;
        job.attrViews = a.attrViews;
        job.vertices = a.vertices;
        job.channels = a.channels;
        job.rast = a.rast;
        job.views = a.views;
        job.pixelsPerView = pixelsPerView;
        job.triangles = a.triangles;
        job.triangleCount = a.triangleCount;
        job.out = a.out;
        job.waitStream = a.stream;
        auto status = Internal::of(*device).compute->interpolate(job, report.badPixel, report.badTriangle);
        if (!status) return toPublic(status.error());
        return report;
    }
    // The device's loop on the host, pixel by pixel (shared/interpolate.h).
    const auto triangles = uint32_t(std::min<size_t>(a.triangleCount, UINT32_MAX));
    for (size_t p = 0; p < pixels; ++p) {
        const float* view = a.attr + (a.attrViews == 1 ? 0 : p / pixelsPerView) * a.vertices * a.channels;
        const sr::InterpolateFault fault = sr::interpolatePixel(
            a.rast + 4 * p, view, a.triangles, triangles, a.vertices, a.channels, a.out + p * a.channels);
        if (fault.badSlot && report.badPixel < 0) report.badPixel = int64_t(p);
        if (fault.badTriangle && (report.badTriangle < 0 || int64_t(fault.triangle) < report.badTriangle))
            report.badTriangle = int64_t(fault.triangle);
    }
    return report;
}

// ---- comparisons ------------------------------------------------------------------------------

namespace {

sr::CompareTolerance tolerance(const CompareOptions& o)
{
    sr::CompareTolerance t;
    t.colorLsb = o.colorTolerance;
    t.maxIdMismatches = o.maxIdMismatches;
    t.depthTolerance = o.depthTolerance;
    t.surfaceTolerance = o.surfaceTolerance;
    return t;
}

CompareReport toPublic(const sr::CompareReport& r, const sr::CompareTolerance& t)
{
    CompareReport p;
    p.aov = r.isAov;
    p.pass = r.pass;
    p.width = r.width;
    p.height = r.height;
    p.meanError = r.meanError;
    p.rmsError = r.rmsError;
    p.psnr = r.psnr;
    p.maxError = r.maxError;
    p.maxX = r.maxX;
    p.maxY = r.maxY;
    p.pixelsOverTolerance = r.pixelsOverTolerance;
    p.idMismatches = r.idMismatches;
    p.coverageMismatches = r.coverageMismatches;
    p.maxDepthDiff = r.maxDepthDiff;
    p.meanDepthDiff = r.meanDepthDiff;
    p.maxBaryDiff = r.maxBaryDiff;
    p.maxUvDiff = r.maxUvDiff;
    p.maxNormalDiff = r.maxNormalDiff;
    p.surfaceOverTolerance = r.surfaceOverTolerance;
    p.samplesPerPixel = r.samplesPerPixel;
    p.sampleIdMismatches = r.sampleIdMismatches;
    p.sampleDepthOverTolerance = r.sampleDepthOverTolerance;
    p.text = sr::formatReport(r, t);
    return p;
}

}  // namespace

Result<CompareReport> compare(const Frame& a, const Frame& b, bool aov, const CompareOptions& options)
{
    const sr::CompareTolerance t = tolerance(options);
    auto report = aov ? sr::compareAov(sr::aovImage(a), sr::aovImage(b), t)
                      : sr::compareColor(sr::colorImage(a), sr::colorImage(b), t);
    if (!report) return toPublic(report.error());
    return toPublic(*report, t);
}

Result<CompareReport> compareFiles(const std::string& a, const std::string& b, const CompareOptions& options)
{
    const sr::CompareTolerance t = tolerance(options);
    auto report = sr::compareFiles(a, b, t);
    if (!report) return toPublic(report.error());
    return toPublic(*report, t);
}

// ---- files ------------------------------------------------------------------------------------

namespace {

Result<sr::ImageEncoding> encoding(const FileOptions& options)
{
    sr::ImageEncoding e;
    if (!options.pngCompression.empty()) {
        auto png = sr::parsePngCompression(options.pngCompression, "pngCompression");
        if (!png) return raster::toPublic(png.error());
        e.png = *png;
    }
    if (!options.exrCompression.empty()) {
        auto exr = sr::parseExrCompression(options.exrCompression, "exrCompression");
        if (!exr) return raster::toPublic(exr.error());
        e.exr = *exr;
    }
    return e;
}

// One file of the frame, written whole or not at all, after its extension and the frame's images are
// checked: what `raster render` writes for -o, --aov or --stats.
Status writeFrameFile(const Frame& frame, const std::string& path, const FileOptions& options,
                      const char* what, const char* extension)
{
    auto e = encoding(options);
    if (!e) return e.error();
    std::string lower = path;
    for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
    const std::string ext = extension;
    if (lower.size() < ext.size() || lower.compare(lower.size() - ext.size(), ext.size(), ext) != 0)
        return usage(fmt::format("{}: {} does not end in {}", what, sr::quotedInput(path), ext));
    const size_t pixels = size_t(frame.width) * frame.height;
    sr::OutputPaths paths;
    if (ext == ".png") {
        if (frame.color.size() != 4 * pixels)
            return usage(
                fmt::format("{}: the frame has no colour (render with outputs including OutputColor)", what));
        paths.png = path;
    } else {
        if (frame.id.size() != pixels || frame.depth.size() != pixels)
            return usage(fmt::format(
                "{}: the frame has no ids and depth (render with outputs including OutputId and OutputDepth)",
                what));
        paths.aov = path;
    }
    sr::FileGroup files;
    auto staged = sr::stageFrame(files, frame, paths, *e);
    if (!staged) return raster::toPublic(staged.error());
    auto committed = files.commit();
    if (!committed) return raster::toPublic(committed.error());
    return Status();
}

}  // namespace

Status writePng(const Frame& frame, const std::string& path, const FileOptions& options)
{
    return writeFrameFile(frame, path, options, "writePng", ".png");
}

Status writeExr(const Frame& frame, const std::string& path, const FileOptions& options)
{
    return writeFrameFile(frame, path, options, "writeExr", ".exr");
}

Result<Frame> render(Device& device, const Scene& scene, const Camera& camera, const Settings& settings,
                     const RenderRequest& request)
{
    auto session = Session::create(device, scene);
    if (!session) return session.error();
    return session->render(camera, settings, request);
}

}  // namespace raster
