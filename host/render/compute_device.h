// compute_device.h - what a backend must provide to run the pipeline.
//
// The pipeline itself (buffer sizes, stage order, group counts, grow-and-redraw) is written once in
// host/render/renderer.cpp. A backend only allocates the buffers named in raster_shared.h (BUF_*), copies
// data, and runs a list of stage dispatches with a full barrier between consecutive dispatches,
// timing each one on the GPU. CUDA (cuda/cuda_device.cu) and Vulkan (host/vulkan/vulkan_device.cpp)
// implement it; the backend is chosen at run time in one place, makeComputeDevice() (host/api/backend.h).
#ifndef RASTER_COMPUTE_DEVICE_H
#define RASTER_COMPUTE_DEVICE_H

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "raster_shared.h"
#include "base/result.h"

namespace sr {

// Name of stage `stage` (STAGE_*) in the stage table (common/shared/stages.h), matching cuda/<name>.cuh
// and compute_glsl/<name>.comp; "unknown" for any other number.
const char* stageName(uint32_t stage);

struct DeviceInfo {
    std::string backend;  // "cuda" or "vulkan"
    std::string name;     // device name as the API reports it
    std::string driver;   // driver / runtime version string
    bool isCpu = false;   // true for lavapipe and other CPU implementations
};

// renderViews' views: frames that differ in their vertex positions (nvdiffrast's batch) or in their
// camera (renderMany, positions null). View b's positions are `bytes` at positions + b * bytes, copied
// over the head of BUF_POSITIONS before its frame; host memory, or with onDevice memory of the device
// (CUDA). waitStream (onDevice, CUDA): a
// stream whose work so far the copies wait for, as __cuda_array_interface__ names one (0: none, 1: the
// legacy default stream, 2: the per-thread default stream, else a cudaStream_t).
struct ViewInputs {
    const void* positions = nullptr;
    size_t bytes = 0;
    bool onDevice = false;
    uintptr_t waitStream = 0;
};

// After each view's frame: `bytes` from `offset` bytes into BUF_FRAMEBUFFER to destination + b * bytes
// (host memory, or with onDevice memory of the device).
struct ViewCopy {
    size_t offset = 0;
    size_t bytes = 0;
    char* destination = nullptr;
    bool onDevice = false;
};

// nvdiffrast's interpolate over rasterize's output (raster::interpolate, shared/interpolate.h): every
// array in memory of the device. badPixel: where the first pixel whose fourth channel is no triangle's
// id + 1 (nor 0) is written, badTriangle the first triangle drawn with a vertex index out of range
// (both -1 when there is none); such pixels get zeros.
struct InterpolateJob {
    const float* attr = nullptr;  // attrViews x vertices x channels
    size_t attrViews = 1, vertices = 0, channels = 0;
    const float* rast = nullptr;  // views x pixelsPerView x 4
    size_t views = 0, pixelsPerView = 0;
    const uint32_t* triangles = nullptr;  // triangleCount x 3
    size_t triangleCount = 0;
    float* out = nullptr;      // views x pixelsPerView x channels
    uintptr_t waitStream = 0;  // as ViewInputs::waitStream
};

struct Dispatch {
    uint32_t stage = 0;   // STAGE_*
    uint32_t groups = 0;  // number of groups (1D); group sizes are fixed per stage in the kernels
    // setup and raster_tiles: run their build with the alpha test of MASK materials (SPEC_MATERIALS),
    // which a scene without MASK triangles never pays for (a CPU device evaluates both sides of a
    // per-pixel branch, a GPU loses registers).
    bool alphaTest = false;
    // setup, bin_count, bin_fill and raster_tiles: the build of this raster method (RASTER_*,
    // RenderSettings::rasterMethod); the other stages ignore it.
    uint32_t rasterMethod = RASTER_FIXED8;
};

class ComputeDevice {
public:
    virtual ~ComputeDevice() = default;
    virtual const DeviceInfo& info() const = 0;

    // (Re)allocates buffer `buffer` (BUF_*) to at least `bytes` (>= 16); contents become undefined.
    // BUF_PARAMS is managed by the device and never passed here.
    virtual Status resize(uint32_t buffer, size_t bytes) = 0;
    virtual size_t size(uint32_t buffer) const = 0;
    virtual Status upload(uint32_t buffer, const void* data, size_t bytes) = 0;
    // Copies `bytes` from `offset` bytes into `buffer` to `data`.
    virtual Status download(uint32_t buffer, void* data, size_t bytes, size_t offset = 0) = 0;
    // BUF_COUNTERS as the host reads it: its COUNTER_WORDS words folded (foldCounters) into `counters`
    // (COUNTER_COUNT).
    Status downloadCounters(uint32_t* counters);

    // Memory for a caller's images (raster::Memory), freed when the last pointer goes: host memory,
    // page-locked where the device copies into it directly (CUDA: no staging through the driver's own
    // buffers), or memory of the device itself (CUDA only; an error elsewhere).
    virtual Result<std::shared_ptr<void>> allocateMemory(bool onDevice, size_t bytes);
    // As download, into memory of this device (allocateMemory(true, ...)); CUDA only.
    virtual Status downloadToDevice(uint32_t buffer, void* deviceData, size_t bytes, size_t offset);

    // Runs the dispatches in order with a full memory barrier between each, with `params` visible to
    // every stage, waits for completion, and stores each dispatch's GPU time in ms (same order).
    virtual Status run(const RasterParams& params, const std::vector<Dispatch>& dispatches,
                       std::vector<double>& gpuMs) = 0;

    // Views first .. first + count - 1, each as: its positions copied in (none where views.positions is
    // null: the scene's stay), the dispatches run with its parameters (params[b - first], or params[0]
    // for every view), BUF_COUNTERS folded (foldCounters) into counters + (b - first) * COUNTER_COUNT
    // and the copies made; returns when all are done. No GPU times. The base class does it view by view
    // with the calls above (one wait per view); CUDA queues every view at once and waits once.
    virtual Status runViews(const std::vector<RasterParams>& params, const std::vector<Dispatch>& dispatches,
                            const ViewInputs& views, size_t first, size_t count,
                            const std::vector<ViewCopy>& copies, uint32_t* counters);
    // View b's image of `copy` out of BUF_FRAMEBUFFER (runViews' last step, alone).
    Status copyView(const ViewCopy& copy, size_t b);
    // Copies view b's positions over the head of BUF_POSITIONS (runViews' first step, alone; nothing
    // without positions).
    virtual Status uploadView(const ViewInputs& views, size_t b);

    // Runs `job` on the device and waits for it (CUDA; an error elsewhere): badPixel and badTriangle as
    // InterpolateJob says.
    virtual Status interpolate(const InterpolateJob& job, int64_t& badPixel, int64_t& badTriangle);

    // Bytes currently allocated on the device by this object, and the peak over its lifetime.
    virtual size_t allocatedBytes() const = 0;
    virtual size_t peakAllocatedBytes() const = 0;

    // Which session's scene the buffers hold. A device has one set of BUF_* buffers and any number of
    // sessions (RenderSession) may be made on it: each takes the buffers over with claim() before it
    // uploads or draws, and a session that finds another's token here uploads its scene again. 0: none.
    uint64_t resident() const { return resident_; }
    void claim(uint64_t session) { resident_ = session; }

private:
    uint64_t resident_ = 0;
};

// Vulkan: device `index` among the physical devices that support the pipeline (GPUs first, CPU
// implementations such as lavapipe last); -1 picks the first. Validation layers are enabled when the
// environment sets SR_VULKAN_VALIDATION=1, and any validation error then fails the call that caused it.
Result<std::unique_ptr<ComputeDevice>> makeVulkanDevice(int index);
// CUDA: device `index` (-1 = 0). Fails with a one-line error when CUDA or a CUDA GPU is absent, or when
// the binary was built without CUDA.
Result<std::unique_ptr<ComputeDevice>> makeCudaDevice(int index);

}  // namespace sr

#endif  // RASTER_COMPUTE_DEVICE_H
