// raster_module.cpp - the Python extension `raster._raster`: pybind11 bindings over the public C++ API
// alone (include/raster/raster.h), so that it builds from that header, this file and a prebuilt
// libraster.so (ci/gpu-python). The Python package `raster` (python/raster/__init__.py) wraps these
// classes with the documented interface; names here starting with an underscore are not part of it.
//
// Frames: a render's raster::Frame is moved into a FrameHolder that Python owns; every array handed
// out is a numpy view of the holder's buffers with the holder as its base, so no pixel is copied after
// the library's download. Rendering releases the GIL; a Renderer's mutex keeps one render at a time on
// its device (a Device belongs to one thread at a time; its sessions take turns on its buffers).
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <dlpack/dlpack.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "raster/raster.h"

namespace py = pybind11;

namespace {

// raster.Error: the library's one-line message as the exception's text.
struct RasterError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

[[noreturn]] void raise(const raster::Error& error)
{
    throw RasterError(error.message);
}

template <typename T>
T take(raster::Result<T>&& result)
{
    if (!result) raise(result.error());
    return std::move(*result);
}

void check(const raster::Status& status)
{
    if (!status) raise(status.error());
}

// ---- scenes ---------------------------------------------------------------------------------------

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;
using IndexArray = py::array_t<uint32_t, py::array::c_style | py::array::forcecast>;
using ByteArray = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>;

std::string shapeText(const py::array& a)
{
    std::string text = "(";
    for (py::ssize_t d = 0; d < a.ndim(); ++d) text += (d ? ", " : "") + std::to_string(a.shape(d));
    return text + (a.ndim() == 1 ? ",)" : ")");
}

// Checks that `a` is (rows, one of `columns`) and returns its rows; `what` names it in the error.
size_t rowsOf(const py::array& a, std::initializer_list<py::ssize_t> columns, const char* what)
{
    const bool ok = a.ndim() == 2 && std::find(columns.begin(), columns.end(), a.shape(1)) != columns.end();
    if (!ok) {
        std::string expected;
        for (py::ssize_t c : columns) expected += (expected.empty() ? "" : " or ") + std::to_string(c);
        throw RasterError(std::string("from_arrays: ") + what + " must have shape (N, " + expected +
                          "), not " + shapeText(a));
    }
    return size_t(a.shape(0));
}

std::shared_ptr<raster::Scene> sceneFromArrays(
    const FloatArray& positions, const IndexArray& triangles, const std::optional<FloatArray>& normals,
    const std::optional<FloatArray>& uv, const std::optional<FloatArray>& colors,
    const std::optional<ByteArray>& texture, bool textureSrgb, const std::optional<IndexArray>& lines,
    const std::optional<IndexArray>& points, const std::array<float, 4>& baseColor, bool doubleSided)
{
    raster::MeshArrays m;
    m.vertexCount = rowsOf(positions, {3, 4}, "positions");
    m.positionComponents = uint32_t(positions.shape(1));
    m.positions = positions.data();
    // Index arrays of any shape whose size fits are accepted as flat lists (T x 3, S x 2, P).
    m.triangleCount = rowsOf(triangles, {3}, "indices");
    m.triangles = triangles.data();
    auto perVertex = [&](const std::optional<FloatArray>& a, std::initializer_list<py::ssize_t> columns,
                         const char* what) -> const float* {
        if (!a) return nullptr;
        if (rowsOf(*a, columns, what) != m.vertexCount)
            throw RasterError(std::string("from_arrays: ") + what + " has " + std::to_string(a->shape(0)) +
                              " rows for " + std::to_string(m.vertexCount) + " vertices");
        return a->data();
    };
    m.normals = perVertex(normals, {3}, "normals");
    m.texcoords = perVertex(uv, {2}, "uv");
    m.colors = perVertex(colors, {4}, "colors");
    if (lines) {
        m.lineCount = rowsOf(*lines, {2}, "lines");
        m.lines = lines->data();
    }
    if (points) {
        if (points->ndim() != 1)
            throw RasterError("from_arrays: points must have shape (P,), not " + shapeText(*points));
        m.pointCount = size_t(points->shape(0));
        m.points = points->data();
    }
    if (texture) {
        if (texture->ndim() != 3 || texture->shape(2) != 4)
            throw RasterError("from_arrays: texture must have shape (H, W, 4), not " + shapeText(*texture));
        m.texture.rgba8 = texture->data();
        m.texture.height = uint32_t(texture->shape(0));
        m.texture.width = uint32_t(texture->shape(1));
        m.texture.srgb = textureSrgb;
    }
    m.baseColor = baseColor;
    m.doubleSided = doubleSided;
    py::gil_scoped_release release;
    return std::make_shared<raster::Scene>(take(raster::Scene::fromArrays(m)));
}

// ---- frames ---------------------------------------------------------------------------------------

// Page-locked host memory and GPU memory of one device for frames' images, kept for the next frames
// once a frame that held them is freed: a CUDA allocation of page-locked memory costs milliseconds, and
// freshly allocated pages fault on the first copy into them. A few of each size are kept.
class MemoryPool {
public:
    explicit MemoryPool(raster::Device& device) : device_(&device) {}

    raster::Memory acquire(size_t bytes, raster::Memory::Where where)
    {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            for (size_t i = 0; i < free_.size(); ++i) {
                if (free_[i].size() != bytes || free_[i].where() != where) continue;
                raster::Memory m = std::move(free_[i]);
                free_.erase(free_.begin() + long(i));
                return m;
            }
        }
        return take(raster::Memory::allocate(*device_, bytes, where));
    }

    void give(std::vector<raster::Memory>& memory)
    {
        std::lock_guard<std::mutex> lock(mutex_);
        for (raster::Memory& m : memory) free_.push_back(std::move(m));
        if (free_.size() > kKept) free_.erase(free_.begin(), free_.end() - long(kKept));
        memory.clear();
    }

    // Called when the device closes: what is kept goes with it.
    void drop()
    {
        std::lock_guard<std::mutex> lock(mutex_);
        free_.clear();
        device_ = nullptr;
    }

private:
    static constexpr size_t kKept = 12;
    raster::Device* device_;
    std::mutex mutex_;
    std::vector<raster::Memory> free_;
};

// A frame's images: in the Frame's vectors, or written in place into memory from the renderer's pool
// (host, page-locked on CUDA; or the GPU's own with where="device"), returned to the pool with the
// holder.
struct FrameHolder {
    raster::Frame frame;
    raster::ImageTargets targets;
    std::vector<raster::Memory> memory;
    std::weak_ptr<MemoryPool> pool;
    int cudaDevice = -1;

    ~FrameHolder()
    {
        if (auto p = pool.lock()) p->give(memory);
    }
};

// An image of a frame in GPU memory, for CUDA libraries: __cuda_array_interface__ (version 3) and
// DLPack (__dlpack__, __dlpack_device__) describe it in place, and every array made from it keeps the
// frame alive.
struct DeviceArray {
    std::shared_ptr<FrameHolder> owner;
    void* data = nullptr;
    std::vector<int64_t> shape;
    char kind = 'u';  // numpy's typestr kind: 'u' uint, 'f' float
    int bytes = 4;    // per element
    int device = 0;   // CUDA device ordinal

    py::dict cudaArrayInterface() const
    {
        py::dict d;
        py::tuple s(shape.size());
        for (size_t i = 0; i < shape.size(); ++i) s[i] = shape[i];
        d["shape"] = s;
        d["typestr"] = std::string("<") + kind + std::to_string(bytes);
        d["data"] = py::make_tuple(reinterpret_cast<uintptr_t>(data), false);
        d["version"] = 3;
        d["strides"] = py::none();
        // The copies were waited for before render returned: nothing for a consumer's stream to wait on.
        d["stream"] = py::none();
        return d;
    }
};

// DLPack's managed tensor for a DeviceArray: the tensor's shape lives here, and the frame with it until
// the consumer calls the deleter.
struct DlpackExport {
    DLManagedTensor tensor{};
    std::vector<int64_t> shape;
    std::shared_ptr<FrameHolder> owner;
};

py::capsule dlpackCapsule(const DeviceArray& a)
{
    auto* e = new DlpackExport;
    e->shape = a.shape;
    e->owner = a.owner;
    DLTensor& t = e->tensor.dl_tensor;
    t.data = a.data;
    t.device = DLDevice{kDLCUDA, int32_t(a.device)};
    t.ndim = int32_t(e->shape.size());
    t.dtype = DLDataType{uint8_t(a.kind == 'f' ? kDLFloat : kDLUInt), uint8_t(8 * a.bytes), 1};
    t.shape = e->shape.data();
    t.strides = nullptr;  // compact, row-major
    t.byte_offset = 0;
    e->tensor.manager_ctx = e;
    e->tensor.deleter = [](DLManagedTensor* self) { delete static_cast<DlpackExport*>(self->manager_ctx); };
    // The protocol: a consumer renames the capsule "used_dltensor" and then owns the tensor; a capsule
    // never consumed frees it when it goes.
    return py::capsule(&e->tensor, "dltensor", [](PyObject* capsule) {
        if (!PyCapsule_IsValid(capsule, "dltensor")) return;
        auto* m = static_cast<DLManagedTensor*>(PyCapsule_GetPointer(capsule, "dltensor"));
        if (m != nullptr && m->deleter != nullptr) m->deleter(m);
    });
}

// A view of `data` as a numpy array of `shape` (C order) whose base is `owner`; None when empty.
template <typename T>
py::object view(const py::object& owner, std::vector<T>& data, std::vector<py::ssize_t> shape)
{
    if (data.empty()) return py::none();
    std::vector<py::ssize_t> strides(shape.size());
    py::ssize_t stride = sizeof(T);
    for (size_t d = shape.size(); d-- > 0;) {
        strides[d] = stride;
        stride *= shape[d];
    }
    return py::array(py::dtype::of<T>(), std::move(shape), std::move(strides), data.data(), owner);
}

// The frame with the images it wrote in place copied into its arrays, as raster::compare reads frames
// (Python may have changed them: the copy is of what the caller sees).
raster::Frame comparable(const FrameHolder& h)
{
    if (h.targets.onDevice)
        throw RasterError("compare: frames on the device (on_device=True) are not compared");
    raster::Frame f = h.frame;
    const size_t pixels = size_t(f.width) * f.height;
    auto copy = [&](auto& into, const void* from, size_t count) {
        if (from == nullptr) return;
        into.resize(count);
        std::memcpy(into.data(), from, count * sizeof(into[0]));
    };
    copy(f.color, h.targets.color, 4 * pixels);
    copy(f.id, h.targets.id, pixels);
    copy(f.depth, h.targets.depth, pixels);
    return f;
}

// Frame.save: the file `raster render` writes for the path's extension (.png: -o, .exr: --aov, .json:
// --stats), byte for byte, whole or not at all.
void saveFrame(const FrameHolder& h, const std::string& path, const std::string& pngCompression,
               const std::string& exrCompression)
{
    std::string ext = path.size() >= 5 ? path.substr(path.size() - 5) : path;
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    auto endsIn = [&](const std::string& e) {
        return ext.size() >= e.size() && ext.compare(ext.size() - e.size(), e.size(), e) == 0;
    };
    if (!endsIn(".png") && !endsIn(".exr") && !endsIn(".json"))
        throw RasterError(
            "save: the path must end in .png (the colour), .exr (the AOVs) or .json (the "
            "statistics), not '" +
            path + "'");
    if (h.targets.onDevice)
        throw RasterError(
            "save: the images are in GPU memory (on_device=True); render with on_device=False to "
            "save them");
    const raster::Frame f = comparable(h);
    const size_t pixels = size_t(f.width) * f.height;
    raster::FileOptions options{pngCompression, exrCompression};
    // The library names the encoders by its fields; Python callers gave keywords.
    auto saved = [](const raster::Status& status) {
        if (status) return;
        std::string message = "save: " + status.error().message;
        for (const auto& [from, to] :
             {std::pair<std::string, std::string>{"pngCompression", "png_compression"},
              {"exrCompression", "exr_compression"}})
            for (size_t at = message.find(from); at != std::string::npos;
                 at = message.find(from, at + to.size()))
                message.replace(at, from.size(), to);
        throw RasterError(message);
    };
    if (endsIn(".png")) {
        if (f.color.size() != 4 * pixels)
            throw RasterError("save: the frame has no colour image (render with outputs including 'color')");
        saved(raster::writePng(f, path, options));
    } else if (endsIn(".exr")) {
        if (f.id.size() != pixels || f.depth.size() != pixels)
            throw RasterError(
                "save: an .exr holds the ids and depth, which the frame lacks (render with outputs including "
                "'ids' and 'depth')");
        saved(raster::writeExr(f, path, options));
    } else {
        if (f.statsJson.empty()) throw RasterError("save: the frame has no statistics");
        // Whole or not at all: a temporary file beside it, renamed into place.
        const std::string text = f.statsJson + "\n";
        const std::string temporary = path + ".tmp-save";
        FILE* file = std::fopen(temporary.c_str(), "wb");
        if (!file) throw RasterError("save: cannot write '" + path + "': " + std::strerror(errno));
        const bool written = std::fwrite(text.data(), 1, text.size(), file) == text.size();
        if (std::fclose(file) != 0 || !written || std::rename(temporary.c_str(), path.c_str()) != 0) {
            const std::string why = std::strerror(errno);
            std::remove(temporary.c_str());
            throw RasterError("save: cannot write '" + path + "': " + why);
        }
    }
}

// An image a frame wrote in place (FrameHolder::targets): a numpy view of host memory, or a DeviceArray
// of GPU memory, either keeping the frame alive.
py::object image(const py::object& owner, void* data, std::vector<int64_t> shape, char kind, int bytes)
{
    FrameHolder& h = owner.cast<FrameHolder&>();
    if (h.targets.onDevice) {
        DeviceArray a;
        a.owner = owner.cast<std::shared_ptr<FrameHolder>>();
        a.data = data;
        a.shape = std::move(shape);
        a.kind = kind;
        a.bytes = bytes;
        a.device = h.cudaDevice;
        return py::cast(std::move(a));
    }
    const py::dtype dtype = kind == 'f'  ? py::dtype::of<float>()
                            : bytes == 1 ? py::dtype::of<uint8_t>()
                                         : py::dtype::of<uint32_t>();
    std::vector<py::ssize_t> dims(shape.begin(), shape.end());
    return py::array(dtype, std::move(dims), data, owner);
}

py::dict deviceDict(const raster::DeviceInfo& d)
{
    py::dict out;
    out["backend"] = raster::backendName(d.backend);
    out["index"] = d.index;
    out["name"] = d.name;
    out["driver"] = d.driver;
    out["cpu"] = d.cpu;
    return out;
}

py::dict reportDict(const raster::CompareReport& r)
{
    py::dict out;
    out["kind"] = r.aov ? "aov" : "color";
    out["passed"] = r.pass;
    out["width"] = r.width;
    out["height"] = r.height;
    if (!r.aov) {
        out["mean_error"] = r.meanError;
        out["rms_error"] = r.rmsError;
        out["psnr"] = r.psnr;
        out["max_error"] = r.maxError;
        out["max_error_at"] = py::make_tuple(r.maxX, r.maxY);
        out["pixels_over_tolerance"] = r.pixelsOverTolerance;
    } else {
        out["id_mismatches"] = r.idMismatches;
        out["coverage_mismatches"] = r.coverageMismatches;
        out["max_depth_diff"] = r.maxDepthDiff;
        out["mean_depth_diff"] = r.meanDepthDiff;
        auto surface = [](double v) { return v < 0.0 ? py::object(py::none()) : py::object(py::float_(v)); };
        out["max_bary_diff"] = surface(r.maxBaryDiff);
        out["max_uv_diff"] = surface(r.maxUvDiff);
        out["max_normal_diff"] = surface(r.maxNormalDiff);
        out["surface_over_tolerance"] = r.surfaceOverTolerance;
        out["samples_per_pixel"] = r.samplesPerPixel;
        out["sample_id_mismatches"] = r.sampleIdMismatches;
        out["sample_depth_over_tolerance"] = r.sampleDepthOverTolerance;
    }
    out["text"] = r.text;
    return out;
}

raster::CompareOptions compareOptions(int tolerance, uint64_t maxIdMismatches, float depthTolerance,
                                      const std::optional<double>& surfaceTolerance)
{
    raster::CompareOptions o;
    o.colorTolerance = tolerance;
    o.maxIdMismatches = maxIdMismatches;
    o.depthTolerance = depthTolerance;
    o.surfaceTolerance = surfaceTolerance.value_or(-1.0);
    return o;
}

// ---- settings and cameras -------------------------------------------------------------------------

// The caller's value in a one-line message: its repr, cut to a readable length.
std::string shown(const py::handle& value)
{
    std::string text = py::str(py::repr(value));
    for (char& c : text)
        if (c == '\n' || c == '\r' || c == '\t') c = ' ';
    return text.size() <= 80 ? text : text.substr(0, 77) + "...";
}

// One keyword argument into `settings`: bool as a flag, an integer or a float as a number (integers
// exactly: 2**31 stays 2147483648), a string as on the command line, a sequence of three numbers as
// X,Y,Z. The schema checks the value against the setting (a bool for a number is refused there).
void setOne(raster::Settings& settings, const std::string& name, const py::handle& value)
{
    if (py::isinstance<py::bool_>(value)) return check(settings.set(name, value.cast<bool>()));
    if (py::isinstance<py::str>(value)) return check(settings.set(name, value.cast<std::string>()));
    if (py::isinstance<py::int_>(value)) {
        // As its decimal text: any size, no rounding through double.
        return check(settings.set(name, std::string(py::str(value))));
    }
    if (py::isinstance<py::float_>(value)) return check(settings.set(name, value.cast<double>()));
    if (py::isinstance<py::sequence>(value) && py::len(value) == 3) {
        std::array<double, 3> v{};
        py::sequence items = py::reinterpret_borrow<py::sequence>(value);
        for (size_t k = 0; k < 3; ++k) {
            py::object item = items[k];
            if (py::isinstance<py::bool_>(item) ||
                !(py::isinstance<py::int_>(item) || py::isinstance<py::float_>(item)))
                throw RasterError(name + ": " + shown(value) + " is not three numbers");
            v[k] = item.cast<double>();
        }
        return check(settings.set(name, v));
    }
    throw RasterError(name + ": " + shown(value) + " is not a number, a string, a bool or three numbers");
}

raster::Settings makeSettings(const py::object& camera, const py::dict& kwargs)
{
    raster::Settings settings;
    // A camera spec is also the setting, so that the frame's statistics echo it as the command line's do.
    if (py::isinstance<py::str>(camera)) check(settings.set("camera", camera.cast<std::string>()));
    for (auto item : kwargs) setOne(settings, item.first.cast<std::string>(), item.second);
    return settings;
}

// A numpy 4x4 (row r, column c at [r, c]) as the API's column-major array.
std::array<float, 16> matrix(const py::handle& value, const char* what)
{
    auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(value);
    if (!a || a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4)
        throw RasterError(std::string("camera: the ") + what + " matrix must be a 4x4 array");
    std::array<float, 16> m{};
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m[size_t(4 * c + r)] = a.at(r, c);
    return m;
}

raster::Camera makeCamera(const py::object& camera)
{
    if (py::isinstance<py::str>(camera)) return raster::Camera::fromSpec(camera.cast<std::string>());
    if (py::isinstance<py::sequence>(camera) && py::len(camera) == 2) {
        py::sequence pair = camera;
        return raster::Camera::fromMatrices(matrix(pair[0], "view"), matrix(pair[1], "projection"));
    }
    throw RasterError(
        "camera: expected a spec string (auto, gltf:N, orbit:AZ,EL,DIST) or a (view, "
        "projection) pair of 4x4 arrays");
}

// ---- renderers ------------------------------------------------------------------------------------

class Renderer {
public:
    Renderer(const std::string& backend, int index)
    {
        const raster::Backend b = take(raster::parseBackend(backend));
        py::gil_scoped_release release;
        device_ = std::make_unique<raster::Device>(take(raster::Device::open(b, index)));
        pool_ = std::make_shared<MemoryPool>(*device_);
    }

    ~Renderer()
    {
        if (pool_) pool_->drop();
    }
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    py::dict info() const { return deviceDict(device_->info()); }

    // Renders `scene`; with keep, the scene's session (its upload and buffers) stays for the next call.
    // outputs: raster::Output bits, the images the frame fills.
    // onDevice: the images stay in GPU memory (CUDA), as DeviceArrays.
    std::shared_ptr<FrameHolder> render(const std::shared_ptr<raster::Scene>& scene, const py::object& camera,
                                        const py::dict& kwargs, bool surfaceAovs, bool keep, uint32_t outputs,
                                        bool onDevice)
    {
        const raster::Settings settings = makeSettings(camera, kwargs);
        const raster::Camera cam = makeCamera(camera);
        const size_t pixels =
            size_t(std::stoul(take(settings.get("width")))) * std::stoul(take(settings.get("height")));
        raster::RenderRequest request;
        request.surfaceAovs = surfaceAovs;
        request.outputs = outputs;
        auto holder = std::make_shared<FrameHolder>();
        const bool compute = device_->info().backend != raster::Backend::VulkanGraphics;
        if (onDevice && device_->info().backend != raster::Backend::Cuda)
            throw RasterError(std::string("render: on_device needs a CUDA device, not ") +
                              raster::backendName(device_->info().backend));
        py::gil_scoped_release release;
        if (compute) {
            // The images go straight into memory of the pool, which the frame returns there when it goes.
            request.targets = poolTargets(*holder, outputs, 4 * pixels, onDevice);
            holder->pool = pool_;
            holder->cudaDevice = std::max(device_->info().index, 0);
        }
        std::lock_guard<std::mutex> lock(mutex_);
        std::unique_ptr<raster::Session> once;
        raster::Session* session = cached(scene);
        if (session == nullptr && !keep) {
            once = std::make_unique<raster::Session>(take(raster::Session::create(*device_, *scene)));
            session = once.get();
        }
        if (session == nullptr) session = &add(scene);
        holder->frame = take(session->render(cam, settings, request));
        return holder;
    }

    // rasterize's batch: view b of `scene` has the positions pos[b] (B x V x 4, the scene's vertices), given
    // as a host array or as (pointer, stream) of CUDA memory; its (u, v, z/w, id + 1) go straight from the
    // device into slice b of one B x H x W x 4 array of pool memory: page-locked host memory returned as
    // numpy, or with onDevice GPU memory returned as a DeviceArray. Every view is drawn by the renderer's
    // one session of the scene (Session::renderViews: on CUDA one submission and one wait). Returns the
    // array, per view the triangles dropped for a non-finite corner, and the warnings.
    py::tuple rasterize(const std::shared_ptr<raster::Scene>& scene, const std::optional<FloatArray>& hostPos,
                        const std::optional<std::pair<uintptr_t, uintptr_t>>& devicePos,
                        const std::array<int64_t, 3>& shape, const py::object& camera, const py::dict& kwargs,
                        bool onDevice)
    {
        if ((onDevice || devicePos) && device_->info().backend != raster::Backend::Cuda)
            throw RasterError(std::string("rasterize: tensors on the GPU need a CUDA device, not ") +
                              raster::backendName(device_->info().backend));
        const raster::Settings settings = makeSettings(camera, kwargs);
        const raster::Camera cam = makeCamera(camera);
        const size_t viewBytes = size_t(shape[1]) * size_t(shape[2]) * 16;
        auto holder = std::make_shared<FrameHolder>();
        holder->pool = pool_;
        holder->cudaDevice = std::max(device_->info().index, 0);
        holder->targets.onDevice = onDevice;
        raster::ViewPositions positions;
        positions.views = size_t(shape[0]);
        if (hostPos) {
            positions.data = hostPos->data();
        } else if (devicePos) {
            positions.data = reinterpret_cast<const float*>(devicePos->first);
            positions.onDevice = true;
            positions.stream = devicePos->second;
        }
        raster::ViewsReport report;
        {
            py::gil_scoped_release release;
            const auto where = onDevice ? raster::Memory::Where::Device : raster::Memory::Where::Host;
            holder->memory.push_back(pool_->acquire(viewBytes * size_t(shape[0]), where));
            raster::RenderRequest request;
            request.targets.rast = holder->memory.back().data();
            request.targets.onDevice = onDevice;
            std::lock_guard<std::mutex> lock(mutex_);
            raster::Session* session = cached(scene);
            if (session == nullptr) session = &add(scene);
            report = take(session->renderViews(cam, settings, positions, request));
        }
        void* base = holder->memory.back().data();
        py::list invalid;
        for (uint32_t n : report.invalidTriangles) invalid.append(n);
        return py::make_tuple(image(py::cast(holder), base, {shape[0], shape[1], shape[2], 4}, 'f', 4),
                              invalid, report.warnings);
    }

    // Frames of `scene` from every camera of `cameras` with one settings (Session::renderMany: on CUDA all
    // queued at once over several streams): the images of `outputs` (raster::Output bits), each as one
    // N x H x W[ x 4] array of pool memory (page-locked host memory, or GPU memory with onDevice), in the
    // order color, ids, depth (None where not asked for); then the warnings.
    py::tuple renderMany(const std::shared_ptr<raster::Scene>& scene, const py::list& cameras,
                         const py::dict& kwargs, uint32_t outputs, bool onDevice)
    {
        if (onDevice && device_->info().backend != raster::Backend::Cuda)
            throw RasterError(std::string("render_many: on_device needs a CUDA device, not ") +
                              raster::backendName(device_->info().backend));
        const raster::Settings settings = makeSettings(py::none(), kwargs);
        std::vector<raster::Camera> cams;
        for (const py::handle& c : cameras) cams.push_back(makeCamera(py::reinterpret_borrow<py::object>(c)));
        const auto width = int64_t(std::stoul(take(settings.get("width"))));
        const auto height = int64_t(std::stoul(take(settings.get("height"))));
        const size_t pixels = size_t(width) * size_t(height), n = cams.size();
        auto holder = std::make_shared<FrameHolder>();
        holder->pool = pool_;
        holder->cudaDevice = std::max(device_->info().index, 0);
        raster::RenderRequest request;
        raster::ViewsReport report;
        {
            py::gil_scoped_release release;
            request.targets = poolTargets(*holder, outputs, std::max<size_t>(4 * pixels * n, 4), onDevice);
            std::lock_guard<std::mutex> lock(mutex_);
            raster::Session* session = cached(scene);
            if (session == nullptr) session = &add(scene);
            report = take(session->renderMany(cams, settings, request));
        }
        py::object owner = py::cast(holder);
        const auto count = int64_t(n);
        auto out = [&](void* data, std::vector<int64_t> shape, char kind, int bytes) -> py::object {
            if (data == nullptr) return py::none();
            return image(owner, data, std::move(shape), kind, bytes);
        };
        return py::make_tuple(out(request.targets.color, {count, height, width, 4}, 'u', 1),
                              out(request.targets.id, {count, height, width}, 'u', 4),
                              out(request.targets.depth, {count, height, width}, 'f', 4), report.warnings);
    }

    // nvdiffrast's interpolate on this CUDA device: attr (A, V, C), rast (B, H, W, 4) and tri (T x 3) given
    // as pointers into its memory with their shapes, `stream` the producers' (as the CUDA array interface
    // names it); the output, B x H x W x C floats of pool memory, as a DeviceArray, with the first bad
    // pixel and triangle (raster::InterpolateReport).
    py::tuple interpolateOnDevice(uintptr_t attr, const std::array<int64_t, 3>& attrShape, uintptr_t rast,
                                  const std::array<int64_t, 4>& rastShape, uintptr_t tri, int64_t triangles,
                                  uintptr_t stream)
    {
        if (device_->info().backend != raster::Backend::Cuda)
            throw RasterError(std::string("interpolate: tensors on the GPU need a CUDA device, not ") +
                              raster::backendName(device_->info().backend));
        auto holder = std::make_shared<FrameHolder>();
        holder->pool = pool_;
        holder->cudaDevice = std::max(device_->info().index, 0);
        holder->targets.onDevice = true;
        raster::InterpolateArrays a;
        a.attr = reinterpret_cast<const float*>(attr);
        a.attrViews = size_t(attrShape[0]);
        a.vertices = size_t(attrShape[1]);
        a.channels = size_t(attrShape[2]);
        a.rast = reinterpret_cast<const float*>(rast);
        a.views = size_t(rastShape[0]);
        a.height = size_t(rastShape[1]);
        a.width = size_t(rastShape[2]);
        a.triangles = reinterpret_cast<const uint32_t*>(tri);
        a.triangleCount = size_t(triangles);
        a.onDevice = true;
        a.stream = stream;
        raster::InterpolateReport report;
        {
            py::gil_scoped_release release;
            holder->memory.push_back(
                pool_->acquire(std::max<size_t>(a.views * a.height * a.width * a.channels * sizeof(float), 4),
                               raster::Memory::Where::Device));
            a.out = static_cast<float*>(holder->memory.back().data());
            report = take(raster::interpolate(a, device_.get()));
        }
        return py::make_tuple(
            image(py::cast(holder), a.out, {rastShape[0], rastShape[1], rastShape[2], attrShape[2]}, 'f', 4),
            report.badPixel, report.badTriangle);
    }

    // The C++ session's own wall time per frame in ms (Session::render alone, `count` times), for the
    // benchmark's comparison with the same call made from Python.
    std::vector<double> sessionFrameTimes(const std::shared_ptr<raster::Scene>& scene,
                                          const py::object& camera, const py::dict& kwargs, int count)
    {
        const raster::Settings settings = makeSettings(camera, kwargs);
        const raster::Camera cam = makeCamera(camera);
        std::vector<double> ms;
        py::gil_scoped_release release;
        std::lock_guard<std::mutex> lock(mutex_);
        raster::Session* session = cached(scene);
        if (session == nullptr) session = &add(scene);
        for (int i = 0; i < count; ++i) {
            const auto start = std::chrono::steady_clock::now();
            // The frame is freed after the timing, as the benchmark frees the Python one.
            const raster::Frame frame = take(session->render(cam, settings));
            ms.push_back(
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        }
        return ms;
    }

    void release()
    {
        py::gil_scoped_release release;
        std::lock_guard<std::mutex> lock(mutex_);
        sessions_.clear();
    }

    size_t sessionCount() const { return sessions_.size(); }

private:
    struct Entry {
        std::shared_ptr<raster::Scene> scene;  // outlives its session, as the API requires
        std::unique_ptr<raster::Session> session;
    };
    // Sessions kept per renderer: the scenes last drawn, the oldest dropped first.
    static constexpr size_t kMaxSessions = 4;

    // Targets in pool memory for the colour, ids and depth of `outputs` (raster::Output bits), `bytes` each,
    // held by `holder` (which returns them to the pool when it goes) and recorded as its targets.
    raster::ImageTargets poolTargets(FrameHolder& holder, uint32_t outputs, size_t bytes, bool onDevice)
    {
        const auto where = onDevice ? raster::Memory::Where::Device : raster::Memory::Where::Host;
        raster::ImageTargets targets;
        auto slot = [&](uint32_t bit, void*& target) {
            if ((outputs & bit) == 0u) return;
            holder.memory.push_back(pool_->acquire(bytes, where));
            target = holder.memory.back().data();
        };
        slot(raster::OutputColor, targets.color);
        slot(raster::OutputId, targets.id);
        slot(raster::OutputDepth, targets.depth);
        targets.onDevice = onDevice;
        holder.targets = targets;
        return targets;
    }

    // The session kept for `scene`, made the most recently used; nullptr when there is none.
    raster::Session* cached(const std::shared_ptr<raster::Scene>& scene)
    {
        for (size_t i = 0; i < sessions_.size(); ++i) {
            if (sessions_[i].scene != scene) continue;
            std::rotate(sessions_.begin() + long(i), sessions_.begin() + long(i) + 1, sessions_.end());
            return sessions_.back().session.get();
        }
        return nullptr;
    }

    // A new session for `scene`, kept; the least recently used one goes when there are too many.
    raster::Session& add(const std::shared_ptr<raster::Scene>& scene)
    {
        auto session = std::make_unique<raster::Session>(take(raster::Session::create(*device_, *scene)));
        if (sessions_.size() >= kMaxSessions) sessions_.erase(sessions_.begin());
        sessions_.push_back({scene, std::move(session)});
        return *sessions_.back().session;
    }

    std::unique_ptr<raster::Device> device_;
    std::shared_ptr<MemoryPool> pool_;
    std::vector<Entry> sessions_;
    std::mutex mutex_;
};

py::list devices()
{
    std::vector<raster::DeviceInfo> list;
    {
        py::gil_scoped_release release;
        list = raster::devices();
    }
    py::list out;
    for (const raster::DeviceInfo& d : list) out.append(deviceDict(d));
    return out;
}

}  // namespace

// nvdiffrast's interpolate on the host (raster::interpolate): attr is (1 or B, V, C), rast (B, H, W, 4),
// out (B, H, W, C). Returns the first bad pixel and the first bad triangle (-1: none; the caller raises
// the error with the value).
std::pair<int64_t, int64_t> interpolateInto(const FloatArray& attr, const FloatArray& rast,
                                            const IndexArray& tri,
                                            py::array_t<float, py::array::c_style>& out)
{
    raster::InterpolateArrays a;
    a.attr = attr.data();
    a.attrViews = size_t(attr.shape(0));
    a.vertices = size_t(attr.shape(1));
    a.channels = size_t(attr.shape(2));
    a.rast = rast.data();
    a.views = size_t(rast.shape(0));
    a.height = size_t(rast.shape(1));
    a.width = size_t(rast.shape(2));
    a.triangles = tri.data();
    a.triangleCount = size_t(tri.shape(0));
    a.out = out.mutable_data();
    py::gil_scoped_release release;
    const raster::InterpolateReport r = take(raster::interpolate(a));
    return {r.badPixel, r.badTriangle};
}

PYBIND11_MODULE(_raster, m)
{
    m.doc() = "raster's C++ API (include/raster/raster.h) for the Python package raster; use raster itself.";
    py::register_exception<RasterError>(m, "Error");

    m.def("version", &raster::version);
    m.def("devices", &devices);
    m.def("interpolate", &interpolateInto, py::arg("attr"), py::arg("rast"), py::arg("tri"), py::arg("out"));
    m.def("settings_schema", &raster::Settings::schemaJson);
    m.def("settings_names", &raster::Settings::names);

    py::class_<raster::Scene, std::shared_ptr<raster::Scene>>(m, "Scene")
        .def_static("load",
                    [](const std::string& path) {
                        py::gil_scoped_release release;
                        return std::make_shared<raster::Scene>(take(raster::Scene::load(path)));
                    })
        .def_static("from_arrays", &sceneFromArrays, py::arg("positions"), py::arg("indices"),
                    py::arg("normals"), py::arg("uv"), py::arg("colors"), py::arg("texture"),
                    py::arg("texture_srgb"), py::arg("lines"), py::arg("points"), py::arg("base_color"),
                    py::arg("double_sided"))
        .def_property_readonly("vertex_count", &raster::Scene::vertexCount)
        .def_property_readonly("triangle_count", &raster::Scene::triangleCount)
        .def_property_readonly("line_count", &raster::Scene::lineCount)
        .def_property_readonly("point_count", &raster::Scene::pointCount)
        .def_property_readonly("warnings", &raster::Scene::warnings)
        .def("update_positions",
             [](raster::Scene& scene, const FloatArray& positions) {
                 if (positions.ndim() != 2)
                     throw RasterError("update_positions: positions must have shape (N, 3) or (N, 4), not " +
                                       shapeText(positions));
                 const float* data = positions.data();
                 const auto rows = size_t(positions.shape(0));
                 const auto components = uint32_t(positions.shape(1));
                 raster::Status status;
                 {
                     py::gil_scoped_release release;
                     status = scene.updatePositions(data, rows, components);
                 }
                 // The library names its C++ function; the Python caller called update_positions.
                 const std::string cpp = "updatePositions";
                 if (!status) {
                     std::string message = status.error().message;
                     if (message.compare(0, cpp.size(), cpp) == 0)
                         message = "update_positions" + message.substr(cpp.size());
                     throw RasterError(message);
                 }
             })
        .def_property_readonly("bounds_min", &raster::Scene::boundsMin)
        .def_property_readonly("bounds_max", &raster::Scene::boundsMax);

    py::class_<FrameHolder, std::shared_ptr<FrameHolder>>(m, "Frame")
        .def_property_readonly("width", [](const FrameHolder& h) { return h.frame.width; })
        .def_property_readonly("height", [](const FrameHolder& h) { return h.frame.height; })
        .def_property_readonly("color",
                               [](py::object self) {
                                   FrameHolder& h = self.cast<FrameHolder&>();
                                   raster::Frame& f = h.frame;
                                   if (h.targets.color)
                                       return image(self, h.targets.color, {f.height, f.width, 4}, 'u', 1);
                                   return view(self, f.color, {f.height, f.width, 4});
                               })
        .def_property_readonly("ids",
                               [](py::object self) {
                                   FrameHolder& h = self.cast<FrameHolder&>();
                                   raster::Frame& f = h.frame;
                                   if (h.targets.id)
                                       return image(self, h.targets.id, {f.height, f.width}, 'u', 4);
                                   return view(self, f.id, {f.height, f.width});
                               })
        .def_property_readonly("depth",
                               [](py::object self) {
                                   FrameHolder& h = self.cast<FrameHolder&>();
                                   raster::Frame& f = h.frame;
                                   if (h.targets.depth)
                                       return image(self, h.targets.depth, {f.height, f.width}, 'f', 4);
                                   return view(self, f.depth, {f.height, f.width});
                               })
        .def_property_readonly("bary",
                               [](py::object self) {
                                   raster::Frame& f = self.cast<FrameHolder&>().frame;
                                   return view(self, f.bary, {f.height, f.width, 2});
                               })
        .def_property_readonly("uv",
                               [](py::object self) {
                                   raster::Frame& f = self.cast<FrameHolder&>().frame;
                                   return view(self, f.uv, {f.height, f.width, 2});
                               })
        .def_property_readonly("normal",
                               [](py::object self) {
                                   raster::Frame& f = self.cast<FrameHolder&>().frame;
                                   return view(self, f.normal, {f.height, f.width, 3});
                               })
        .def_property_readonly("ao",
                               [](py::object self) {
                                   raster::Frame& f = self.cast<FrameHolder&>().frame;
                                   return view(self, f.ao, {f.height, f.width});
                               })
        .def_property_readonly("sample_ids",
                               [](py::object self) {
                                   raster::Frame& f = self.cast<FrameHolder&>().frame;
                                   return view(self, f.sampleId, {f.samples, f.rasterHeight, f.rasterWidth});
                               })
        .def_property_readonly(
            "sample_depth",
            [](py::object self) {
                raster::Frame& f = self.cast<FrameHolder&>().frame;
                return view(self, f.sampleDepth, {f.samples, f.rasterHeight, f.rasterWidth});
            })
        .def_property_readonly("gpu_ms", [](const FrameHolder& h) { return h.frame.gpuMs; })
        .def_property_readonly("stats_json", [](const FrameHolder& h) { return h.frame.statsJson; })
        .def_property_readonly("device", [](const FrameHolder& h) { return deviceDict(h.frame.device); })
        .def_property_readonly("warnings", [](const FrameHolder& h) { return h.frame.warnings; })
        .def("save", &saveFrame, py::arg("path"), py::kw_only(), py::arg("png_compression") = "",
             py::arg("exr_compression") = "");

    py::class_<DeviceArray>(m, "DeviceArray")
        .def_property_readonly("shape",
                               [](const DeviceArray& a) {
                                   py::tuple s(a.shape.size());
                                   for (size_t i = 0; i < a.shape.size(); ++i) s[i] = a.shape[i];
                                   return s;
                               })
        .def_property_readonly(
            "typestr",
            [](const DeviceArray& a) { return std::string("<") + a.kind + std::to_string(a.bytes); })
        .def_property_readonly("device", [](const DeviceArray& a) { return a.device; })
        .def_property_readonly("data_ptr",
                               [](const DeviceArray& a) { return reinterpret_cast<uintptr_t>(a.data); })
        .def_property_readonly("__cuda_array_interface__", &DeviceArray::cudaArrayInterface)
        // Any stream, version or device keywords a consumer passes: the images are whole already, in
        // the one form this export has (DLPack's unversioned tensor, which consumers accept).
        .def("__dlpack__",
             [](const DeviceArray& a, const py::args&, const py::kwargs&) { return dlpackCapsule(a); })
        .def("__dlpack_device__",
             [](const DeviceArray& a) { return py::make_tuple(int(kDLCUDA), a.device); });

    py::class_<Renderer>(m, "Renderer")
        .def(py::init<const std::string&, int>(), py::arg("backend"), py::arg("device"))
        .def_property_readonly("device", &Renderer::info)
        .def("render", &Renderer::render, py::arg("scene"), py::arg("camera"), py::arg("settings"),
             py::arg("surface_aovs"), py::arg("keep"), py::arg("outputs"), py::arg("on_device"))
        .def("render_many", &Renderer::renderMany, py::arg("scene"), py::arg("cameras"), py::arg("settings"),
             py::arg("outputs"), py::arg("on_device"))
        .def("interpolate_on_device", &Renderer::interpolateOnDevice, py::arg("attr"), py::arg("attr_shape"),
             py::arg("rast"), py::arg("rast_shape"), py::arg("tri"), py::arg("triangles"), py::arg("stream"))
        .def("rasterize", &Renderer::rasterize, py::arg("scene"), py::arg("host_pos"), py::arg("device_pos"),
             py::arg("shape"), py::arg("camera"), py::arg("settings"), py::arg("on_device"))
        .def("session_frame_times", &Renderer::sessionFrameTimes, py::arg("scene"), py::arg("camera"),
             py::arg("settings"), py::arg("count"))
        .def("release", &Renderer::release)
        .def_property_readonly("session_count", &Renderer::sessionCount);

    m.def(
        "compare",
        [](const FrameHolder& a, const FrameHolder& b, bool aov, int tolerance, uint64_t maxIdMismatches,
           float depthTolerance, std::optional<double> surfaceTolerance) {
            return reportDict(take(raster::compare(
                comparable(a), comparable(b), aov,
                compareOptions(tolerance, maxIdMismatches, depthTolerance, surfaceTolerance))));
        },
        py::arg("a"), py::arg("b"), py::arg("aov"), py::arg("tolerance"), py::arg("max_id_mismatches"),
        py::arg("depth_tolerance"), py::arg("surface_tolerance"));
    m.def(
        "compare_files",
        [](const std::string& a, const std::string& b, int tolerance, uint64_t maxIdMismatches,
           float depthTolerance, std::optional<double> surfaceTolerance) {
            return reportDict(take(raster::compareFiles(
                a, b, compareOptions(tolerance, maxIdMismatches, depthTolerance, surfaceTolerance))));
        },
        py::arg("a"), py::arg("b"), py::arg("tolerance"), py::arg("max_id_mismatches"),
        py::arg("depth_tolerance"), py::arg("surface_tolerance"));
}
