// raster/raster.h - the public C++ API of raster: one software rasterization pipeline on CUDA and on
// Vulkan compute (and the Vulkan graphics pipeline as a reference), as a library.
//
//   auto device = raster::Device::open(raster::Backend::Auto);       // CUDA if present, else Vulkan
//   auto scene = raster::Scene::load("model.gltf");                   // or Scene::fromArrays(...)
//   raster::Settings settings;                                        // the schema's defaults
//   raster::Status msaa = settings.set("msaa", 4);                    // any `raster render` option
//   if (!device || !scene || !msaa) return 1;                         // each holds its error()
//   auto frame = raster::render(*device, *scene, raster::Camera::fromSpec("auto"), settings);
//   // frame->color (RGBA8, sRGB), frame->id, frame->depth, frame->statsJson ...
//
// Errors are values: every call that can fail returns raster::Status or raster::Result<T> holding a
// one-line message (the same the `raster` command prints) and its category. Nothing throws.
//
// Settings are named as the `raster render` options without dashes ("texture-filter") or with
// underscores ("texture_filter"); Settings::names() lists them, Settings::schemaJson() describes each
// (type, default, allowed values, help). `raster settings` prints the same table.
//
// Threads: a Device and everything made with it belong to one thread at a time. Any number of sessions
// may be made on one device and used in any order: they share the device's buffers, and a session whose
// scene another one replaced there uploads it again before its next frame (only that frame pays).
#ifndef RASTER_RASTER_H
#define RASTER_RASTER_H

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace raster {

struct Internal;  // the library's own access to what the handles below hold (not part of the API)

// ---- errors -------------------------------------------------------------------------------------

enum class ErrorKind : int {
    Usage = 2,    // bad settings or input, missing backend, unreadable or malformed file
    Runtime = 3,  // a GPU API call failed while rendering
};

struct Error {
    ErrorKind kind = ErrorKind::Usage;
    std::string message;  // one line, no trailing newline
};

template <typename T>
class [[nodiscard]] Result {
public:
    Result(T value) : v_(std::move(value)) {}
    Result(Error error) : v_(std::move(error)) {}
    bool ok() const { return v_.index() == 0; }
    explicit operator bool() const { return ok(); }
    T& value() { return std::get<0>(v_); }
    const T& value() const { return std::get<0>(v_); }
    T& operator*() { return value(); }
    const T& operator*() const { return value(); }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }
    const Error& error() const { return std::get<1>(v_); }

private:
    std::variant<T, Error> v_;
};

class [[nodiscard]] Status {
public:
    Status() = default;  // success
    Status(Error error) : error_(std::move(error)), ok_(false) {}
    bool ok() const { return ok_; }
    explicit operator bool() const { return ok_; }
    const Error& error() const { return error_; }

private:
    Error error_;
    bool ok_ = true;
};

// ---- devices ------------------------------------------------------------------------------------

enum class Backend {
    Auto,            // CUDA when a CUDA GPU is present, else Vulkan (a GPU first, else Mesa lavapipe)
    Cuda,            // the CUDA kernels (cuda/)
    Vulkan,          // the Vulkan compute shaders (compute_glsl/)
    VulkanGraphics,  // the reference: the same scene through the Vulkan graphics pipeline
};

// "auto", "cuda", "vulkan", "vulkan-graphics"; parseBackend is its inverse.
const char* backendName(Backend backend);
Result<Backend> parseBackend(const std::string& name);

struct DeviceInfo {
    Backend backend = Backend::Vulkan;  // never Auto: the backend that opened
    int index = -1;                     // as asked for (-1: the backend's first device)
    std::string name;                   // as the API reports it
    std::string driver;                 // driver or runtime version
    bool cpu = false;                   // a CPU implementation (lavapipe)
};

// Every device this machine offers: each CUDA GPU, then each Vulkan device the pipeline can use (GPUs
// first, CPU implementations such as lavapipe last), as Device::open(backend, index) would open it
// (info.index is that index). A backend that is absent or unusable contributes nothing.
std::vector<DeviceInfo> devices();

class Device {
public:
    // Opens device `index` (-1: the first) of `backend`. Auto tries CUDA, then Vulkan; when none opens
    // the error gives each backend's reason ("CUDA: no CUDA GPU ...; Vulkan: ...").
    static Result<Device> open(Backend backend = Backend::Auto, int index = -1);

    const DeviceInfo& info() const;

    Device(Device&&) noexcept;
    Device& operator=(Device&&) noexcept;
    ~Device();

    struct Impl;  // what the handle holds, opaque here

private:
    friend struct Internal;
    explicit Device(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

// ---- scenes -------------------------------------------------------------------------------------

// A base colour texture: width x height RGBA8 texels, 4 bytes each, rows from the top.
struct TextureView {
    const uint8_t* rgba8 = nullptr;  // nullptr: no texture
    uint32_t width = 0, height = 0;
    bool srgb = true;  // colour data (glTF base colour textures are sRGB)
};

// A mesh in world space as plain arrays (borrowed: Scene::fromArrays copies them). Counts are of
// elements (vertices, triangles, segments, points), not of floats.
struct MeshArrays {
    const float* positions = nullptr;  // positionComponents floats per vertex; finite
    size_t vertexCount = 0;
    // 3: (x, y, z) in world space; 4: homogeneous (x, y, z, w), such as clip-space positions drawn with
    // identity view and projection matrices (flat normals then come from x/w, y/w, z/w).
    uint32_t positionComponents = 3;
    const uint32_t* triangles = nullptr;  // 3 vertex indices per triangle, counter-clockwise in front
    size_t triangleCount = 0;
    const float* normals = nullptr;    // 3 per vertex; nullptr: flat normals from each triangle
    const float* texcoords = nullptr;  // 2 per vertex (u, v; v down, as glTF); needed with a texture
    const float* colors = nullptr;     // 4 per vertex, linear RGBA; nullptr: white
    const uint32_t* lines = nullptr;   // 2 vertex indices per segment
    size_t lineCount = 0;
    const uint32_t* points = nullptr;  // 1 vertex index per point
    size_t pointCount = 0;
    TextureView texture;                                     // base colour texture of every primitive
    std::array<float, 4> baseColor{1.0f, 1.0f, 1.0f, 1.0f};  // linear RGBA factor of every primitive
    bool doubleSided = false;                                // never culled (glTF doubleSided)
};

class Scene {
public:
    // A .gltf/.glb or .obj file, or a procedural scene: "builtin", "builtin:dense", "builtin:huge",
    // "builtin:checker", "builtin:cutout", "builtin:lowpoly". Broken parts are dropped with a warning
    // (warnings(); nothing is printed); a scene with nothing to draw is an error.
    static Result<Scene> load(const std::string& path);
    // A scene from arrays, with the loaders' checks: a triangle, segment or point with an index out of
    // range or a NaN/Inf position is not drawn, with a warning, and keeps its id (ids index the arrays
    // given); a texture within the size limit.
    static Result<Scene> fromArrays(const MeshArrays& mesh);

    // Replaces the vertex positions of a scene made by fromArrays, in place: `vertexCount` vertices of
    // `components` (3 or 4) floats, as many and as wide as it was made with; every triangle, segment and
    // point keeps its vertices (primitives dropped when the scene was made stay dropped). Flat normals
    // follow the new positions. Sessions of the scene upload the positions alone before their next frame
    // (no scene rebuild; clusters, level of detail and the AO reference's BVH are built again when a frame
    // uses them). A non-finite position is an error, and the scene is then unchanged.
    Status updatePositions(const float* positions, size_t vertexCount, uint32_t components);

    // What making the scene dropped or drew otherwise than the input asked, one line each (the lines
    // `raster render` prints after "warning: ").
    const std::vector<std::string>& warnings() const;

    size_t vertexCount() const;
    size_t triangleCount() const;
    size_t lineCount() const;
    size_t pointCount() const;
    std::array<float, 3> boundsMin() const;
    std::array<float, 3> boundsMax() const;

    Scene(const Scene&);
    Scene(Scene&&) noexcept;
    Scene& operator=(Scene&&) noexcept;
    ~Scene();

    struct Impl;  // what the handle holds, opaque here

private:
    friend struct Internal;
    explicit Scene(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

// ---- settings and cameras -----------------------------------------------------------------------

// Every render setting by name (the settings schema: `raster render`'s options, batch manifests' keys).
// A new Settings holds the defaults; set() checks the value and names the setting in its one-line error.
class Settings {
public:
    Settings();
    Settings(const Settings&);
    Settings& operator=(const Settings&);
    ~Settings();

    Status set(const std::string& name, const std::string& text);  // as on the command line: "4", "1,0,0"
    Status set(const std::string& name, const char* text) { return set(name, std::string(text)); }
    Status set(const std::string& name, double number);  // uint and float settings
    Status set(const std::string& name, int number) { return set(name, double(number)); }
    Status set(const std::string& name, bool flag);                       // flags (wireframe, aov-samples)
    Status set(const std::string& name, const std::array<double, 3>& v);  // light-dir, light-color, ...

    // The value as the command line writes it; an error for an unknown name.
    Result<std::string> get(const std::string& name) const;
    // Every setting's value as one JSON object (keys with underscores), as --stats echoes them.
    std::string json() const;
    // The `raster render` arguments that reproduce these settings (the ones not at their defaults).
    std::string commandLine() const;

    // Every setting's name, in the reference's order; the whole schema as JSON.
    static std::vector<std::string> names();
    static std::string schemaJson();

    struct Impl;  // what the handle holds, opaque here

private:
    friend struct Internal;
    std::unique_ptr<Impl> impl_;
};

// How the scene is seen: a `--camera` spec ("auto", "gltf:N", "orbit:AZ,EL,DIST[,TX,TY,TZ]", DIST in
// scene units or "Nr", N radii of the bounds' sphere), or
// explicit view and projection matrices (column-major 4x4: element (row r, column c) at index 4 c + r)
// in Vulkan's clip conventions, as the pipeline's own cameras: depth 0..1 with the near plane at 0, and
// NDC y = -1 the top row of the image (glm::perspective's matrix needs its y row negated and its depth
// mapped from -1..1). A perspective projection has (0, 0, -1, 0) as its last row; any other is taken
// as orthographic. A spec other than "auto" overrides the settings' "camera".
struct Camera {
    std::string spec = "auto";
    bool explicitMatrices = false;
    std::array<float, 16> view{};
    std::array<float, 16> projection{};

    static Camera fromSpec(std::string spec);
    static Camera fromMatrices(const std::array<float, 16>& view, const std::array<float, 16>& projection);
};

// ---- frames -------------------------------------------------------------------------------------

// One stage's GPU time over a frame's timed runs (settings "warmup" and "repeat"), ms.
struct StageTime {
    std::string name;
    double minMs = 0.0, medianMs = 0.0, maxMs = 0.0;
};

// What a render returns, as plain buffers. Pixel (x, y) is at index y * width + x, rows from the top.
struct Frame {
    uint32_t width = 0, height = 0;
    std::vector<uint8_t> color;  // RGBA8, sRGB, 4 per pixel: every sample resolved in linear space
    std::vector<uint32_t> id;    // triangle id (scene order; lines and points after the triangles),
                                 // 0xffffffff where nothing covers the pixel's AOV sample
    std::vector<float> depth;    // window depth 0..1 of that sample, 1 where empty
    // Surface AOVs at pixel centres (filled when RenderRequest::surfaceAovs asks for them), interleaved:
    // perspective-correct barycentrics of the triangle's vertices 1 and 2 (2 per pixel), base colour
    // texture coordinates (2), unit view-space shading normal facing the viewer (3); 0 where empty.
    std::vector<float> bary, uv, normal;
    // Ambient occlusion shade used, 1 = unoccluded (setting "ao" gtao or reference; empty when off): the
    // mean over the pixel's raster pixels with SSAA.
    std::vector<float> ao;
    // Every sample's id and depth (setting "aov-samples"): sample s of raster pixel p at index
    // s * rasterWidth * rasterHeight + p; the raster grid is the image times "ssaa" per side.
    uint32_t rasterWidth = 0, rasterHeight = 0, samples = 0;
    std::vector<uint32_t> sampleId;
    std::vector<float> sampleDepth;
    double gpuMs = 0.0;             // median GPU time of the whole frame over the timed runs
    std::vector<StageTime> stages;  // each stage that ran, in pipeline order, then "total" (the frame)
    std::string statsJson;  // the statistics `raster render --stats` writes (counts, stage times, settings)
    DeviceInfo device;
    std::vector<std::string> warnings;  // what rendering drew otherwise than asked, one line each
};

// Which of a frame's images a render fills (RenderRequest::outputs): the others are left empty, and are
// neither unpacked on the device nor copied back.
enum Output : uint32_t {
    OutputColor = 1,  // Frame::color
    OutputId = 2,     // Frame::id
    OutputDepth = 4,  // Frame::depth
    OutputImages = OutputColor | OutputId | OutputDepth,
};

// Memory for images a render writes in place (ImageTargets), owned by the object and every copy of it,
// freed with the last: host memory, page-locked on a CUDA device (the GPU copies into it at the bus's
// speed, with no staging through the driver's buffers), or memory of the GPU itself (CUDA devices only),
// where the images stay for CUDA libraries (the Python module hands them to torch, CuPy and JAX through
// DLPack without a copy). The device need not outlive it.
class Memory {
public:
    enum class Where { Host, Device };
    static Result<Memory> allocate(Device& device, size_t bytes, Where where = Where::Host);

    void* data() const { return data_.get(); }
    size_t size() const { return size_; }
    Where where() const { return where_; }

private:
    Memory(std::shared_ptr<void> data, size_t size, Where where);
    std::shared_ptr<void> data_;
    size_t size_ = 0;
    Where where_ = Where::Host;
};

// Where a render writes images itself instead of into the Frame's arrays (which then stay empty), each
// non-null pointer width x height pixels, rows from the top: in host memory, or with onDevice in memory
// of the rendering CUDA device (Memory::allocate gives both; the caller sizes it). The copies are done
// when render() returns. Compute backends only.
struct ImageTargets {
    void* color = nullptr;  // RGBA8, 4 bytes per pixel, as Frame::color
    void* id = nullptr;     // uint32 per pixel, as Frame::id
    void* depth = nullptr;  // float per pixel, as Frame::depth
    // nvdiffrast's rasterize output, 4 floats per pixel (u, v, z/w, id + 1), computed on the device: u and
    // v the perspective-correct weights of the triangle's vertices 0 and 1, z/w = 2 depth - 1, all 0 where
    // empty. For frames drawn with rasterize's camera (identity view, OpenGL's depth mapped to Vulkan's),
    // without tessellation or level of detail.
    void* rast = nullptr;
    bool onDevice = false;
};

struct RenderRequest {
    bool surfaceAovs = false;         // fill Frame::bary, uv, normal (computed on the device)
    uint32_t outputs = OutputImages;  // Output bits: which of Frame::color, id, depth to fill
    ImageTargets targets;             // images written in place instead (whatever `outputs` says)
    bool stats = true;                // fill Frame::statsJson (a JSON document of every count and time)
};

// A scene uploaded to a device once and rendered any number of times with any camera and settings:
// buffers are reused and grown, never sized for the worst case. Sessions of other scenes on the same
// device may draw in between (each frame shows its own session's scene; the first one after another
// session drew uploads the scene again). The device and the scene must outlive the session.
// Session::renderViews' positions: `views` sets of the scene's vertex positions one after another, each
// as Scene::fromArrays took them (vertexCount x positionComponents floats). With onDevice they are in
// memory of the session's CUDA device and `stream` names the CUDA stream they were written on, as
// __cuda_array_interface__ does (0: none to wait for, 1: the legacy default stream, 2: the per-thread
// default stream, else a cudaStream_t): the views wait for its work so far.
struct ViewPositions {
    const float* data = nullptr;
    size_t views = 0;
    bool onDevice = false;
    uintptr_t stream = 0;
};

// What renderViews drew: per view, the triangles dropped because a corner's clip position is not finite
// (a NaN or infinite position, or one too large to transform).
struct ViewsReport {
    std::vector<uint32_t> invalidTriangles;
    std::vector<std::string> warnings;
};

class Session {
public:
    static Result<Session> create(Device& device, const Scene& scene);
    Result<Frame> render(const Camera& camera, const Settings& settings, const RenderRequest& request = {});
    // Frames that differ in the scene's vertex positions alone (nvdiffrast's batch of views), all with
    // one camera and settings, written straight into request.targets: each non-null target holds
    // `views` images one after another (request.outputs is ignored; no Frame is made). On CUDA every
    // view is queued at once and the call waits once; elsewhere views are drawn one by one. Needs a scene
    // made by Scene::fromArrays with normals (flat normals would not follow the positions) and, for
    // positions on the device, 4 components. Clusters are not used; tessellation, level of detail,
    // reference AO, per-sample and surface AOVs are refused. The scene's own positions are unchanged and
    // are drawn again by the next render().
    Result<ViewsReport> renderViews(const Camera& camera, const Settings& settings,
                                    const ViewPositions& positions, const RenderRequest& request);
    // Frames of the scene from many cameras with one settings, written straight into request.targets as
    // renderViews writes them (each target holds one image per camera, in order). On CUDA every frame is
    // queued at once over several streams, so that one frame's images are copied out while the next is
    // drawn, and the call waits once; elsewhere frames are drawn one by one. The same refusals as
    // renderViews, except that any scene is taken.
    Result<ViewsReport> renderMany(const std::vector<Camera>& cameras, const Settings& settings,
                                   const RenderRequest& request);

    Session(Session&&) noexcept;
    Session& operator=(Session&&) noexcept;
    ~Session();

    struct Impl;  // what the handle holds, opaque here

private:
    friend struct Internal;
    explicit Session(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

// ---- comparisons ------------------------------------------------------------------------------

// What `raster compare` allows (its --tolerance, --max-id-mismatches, --depth-tolerance).
struct CompareOptions {
    int colorTolerance = 0;        // largest allowed per-channel difference of 8-bit colour
    uint64_t maxIdMismatches = 0;  // AOVs: pixels (or samples) whose triangle id or coverage may differ
    float depthTolerance = 0.0f;   // AOVs: largest allowed depth difference where both are covered
    double surfaceTolerance = -1;  // AOVs: largest allowed bary/uv/normal difference; < 0: not checked
};

// `raster compare`'s metrics. Colour: per-channel differences of R, G, B in 8-bit units. AOVs: ids and
// depth of the pixels (and of every sample when both frames have them), and the surface AOVs where both
// have them and show the same triangle (-1: not compared).
struct CompareReport {
    bool aov = false;  // an AOV comparison (ids, depth, ...), else colour
    bool pass = false;
    uint32_t width = 0, height = 0;
    double meanError = 0, rmsError = 0, psnr = 0;
    int maxError = 0;
    uint32_t maxX = 0, maxY = 0;
    uint64_t pixelsOverTolerance = 0;
    uint64_t idMismatches = 0, coverageMismatches = 0;
    double maxDepthDiff = 0, meanDepthDiff = 0;
    double maxBaryDiff = -1, maxUvDiff = -1, maxNormalDiff = -1;
    uint64_t surfaceOverTolerance = 0;
    uint32_t samplesPerPixel = 0;
    uint64_t sampleIdMismatches = 0, sampleDepthOverTolerance = 0;
    std::string text;  // the report `raster compare` prints, ending in PASS or FAILURE
};

// Two frames of the same size: their colour, or their ids, depth, surface AOVs and samples (aov = true).
Result<CompareReport> compare(const Frame& a, const Frame& b, bool aov, const CompareOptions& options = {});
// Two files of one kind (.png colour, .exr AOVs), as `raster compare A B` reads them.
Result<CompareReport> compareFiles(const std::string& a, const std::string& b,
                                   const CompareOptions& options = {});

// ---- files --------------------------------------------------------------------------------------

// How the image files are encoded: PNG "fast", "default" or "small" (only the size and the time to write
// change, never the pixels); EXR "none", "rle", "zips", "zip" or "piz" (all lossless). Empty: "default"
// and "zip", as `raster render`'s --png-compression and --exr-compression.
struct FileOptions {
    std::string pngCompression;
    std::string exrCompression;
};

// The files `raster render` writes, from a frame, byte for byte (the same frame, the same file): each is
// written whole or not at all, and records the backend and device that drew it (`raster compare` reads
// them). writePng: Frame::color as an sRGB PNG (-o). writeExr: the AOVs (--aov): id and Z, the surface
// AOVs, ao and every sample's id and depth where the frame holds them, and the linear colour (HALF). The
// path must end in .png or .exr; a frame without the images asked for is refused. Frame::statsJson plus a
// newline is what --stats writes.
Status writePng(const Frame& frame, const std::string& path, const FileOptions& options = {});
Status writeExr(const Frame& frame, const std::string& path, const FileOptions& options = {});

// nvdiffrast's interpolate (forward) over rasterize's output: out[b, y, x, c] = u a0 + v a1 + (1 - u - v) a2
// of attribute c of the vertices of triangle rast[b, y, x, 3] - 1, with (u, v) = rast[b, y, x, 0..1];
// 0 where rast[b, y, x, 3] is 0. Every product and sum is rounded on its own, the same bits on the host
// and on a CUDA device.
struct InterpolateArrays {
    const float* attr = nullptr;  // attrViews x vertices x channels (attrViews 1: shared by every view)
    size_t attrViews = 1, vertices = 0, channels = 0;
    const float* rast = nullptr;  // views x height x width x 4, rasterize's output
    size_t views = 0, height = 0, width = 0;
    const uint32_t* triangles = nullptr;  // triangleCount x 3 vertex indices
    size_t triangleCount = 0;
    float* out = nullptr;  // views x height x width x channels
    // Every array in memory of `device` (CUDA), the work done there; `stream` as ViewPositions::stream.
    bool onDevice = false;
    uintptr_t stream = 0;
};

// What interpolate found wrong: the first pixel (flat index over views x height x width) whose
// rast[..., 3] is neither 0 nor a triangle's id + 1, and the first triangle drawn with a vertex index
// out of range; -1 where there is none. Those pixels are written as 0.
struct InterpolateReport {
    int64_t badPixel = -1;
    int64_t badTriangle = -1;
};

// On the host, or with arrays.onDevice on `device` (a CUDA device; the call returns when the output is
// written).
Result<InterpolateReport> interpolate(const InterpolateArrays& arrays, Device* device = nullptr);

// One frame of a fresh session.
Result<Frame> render(Device& device, const Scene& scene, const Camera& camera, const Settings& settings,
                     const RenderRequest& request = {});

// The library's version, "MAJOR.MINOR.PATCH".
const char* version();

}  // namespace raster

#endif  // RASTER_RASTER_H
