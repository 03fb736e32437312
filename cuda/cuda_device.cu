// cuda_device.cu - the CUDA implementation of ComputeDevice: plain cudaMalloc buffers (one per BUF_*),
// synchronous copies, and one stream on which each dispatch is bracketed by a pair of CUDA events.
#include <algorithm>
#include <array>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "render/compute_device.h"
#include "cuda_check.h"
#include "cuda_device_internal.h"
#include "interpolate.h"
#include "kernels.h"

namespace sr {
namespace {

class CudaDevice final : public ComputeDevice {
public:
    ~CudaDevice() override
    {
        // Errors cannot be reported from a destructor; the process is ending or moving on.
        for (cudaEvent_t e : events_) cudaEventDestroy(e);
        if (waitEvent_) cudaEventDestroy(waitEvent_);
        if (laneStart_) cudaEventDestroy(laneStart_);
        if (interpolateBad_) cudaFree(interpolateBad_);
        if (interpolateBadHost_) cudaFreeHost(interpolateBadHost_);
        for (auto& cache : graphs_)
            for (CachedGraph& g : cache) cudaGraphExecDestroy(g.exec);
        for (Lane& l : lanes_) {
            for (void* p : l.ptr) cudaFree(p);
            cudaEventDestroy(l.done);
            cudaStreamDestroy(l.stream);
        }
        if (counterStaging_.data) cudaFreeHost(counterStaging_.data);
        for (void* p : ptr_) cudaFree(p);
        if (stream_) cudaStreamDestroy(stream_);
    }

    Status init(int index)
    {
        int count = 0;
        cudaError_t err = cudaGetDeviceCount(&count);
        if (err != cudaSuccess || count == 0)
            return makeError(ExitCode::Usage, "cuda backend unavailable: no CUDA GPU or driver found ({})",
                             err != cudaSuccess ? cudaGetErrorName(err) : "0 devices");
        const int device = index < 0 ? 0 : index;
        if (device >= count)
            return makeError(ExitCode::Usage, "cuda device {} does not exist ({} CUDA device(s))", device,
                             count);
        CUDA_TRY(cudaSetDevice(device));
        cudaDeviceProp prop{};
        CUDA_TRY(cudaGetDeviceProperties(&prop, device));
        int driver = 0, runtime = 0;
        CUDA_TRY(cudaDriverGetVersion(&driver));
        CUDA_TRY(cudaRuntimeGetVersion(&runtime));
        info_.backend = "cuda";
        info_.name = prop.name;
        info_.driver = fmt::format("CUDA driver {}.{}, runtime {}.{}", driver / 1000, (driver % 1000) / 10,
                                   runtime / 1000, (runtime % 1000) / 10);
        info_.isCpu = false;
        ordinal_ = device;
        std::copy(prop.uuid.bytes, prop.uuid.bytes + 16, reinterpret_cast<char*>(uuid_.data()));
        CUDA_TRY(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking));
        return okStatus();
    }

    const DeviceInfo& info() const override { return info_; }

    Status resize(uint32_t buffer, size_t bytes) override
    {
        if (buffer == BUF_PARAMS || buffer >= BUF_COUNT)
            return makeError(ExitCode::Runtime, "cuda: resize of invalid buffer {}", buffer);
        bytes = std::max<size_t>(bytes, 16);
        if (ptr_[buffer]) {
            CUDA_TRY(cudaFree(ptr_[buffer]));
            allocated_ -= bytes_[buffer];
            ptr_[buffer] = nullptr;
            bytes_[buffer] = 0;
        }
        CUDA_TRY(cudaMalloc(&ptr_[buffer], bytes));
        bytes_[buffer] = bytes;
        allocated_ += bytes;
        peak_ = std::max(peak_, allocated_);
        return okStatus();
    }

    size_t size(uint32_t buffer) const override { return buffer < BUF_COUNT ? bytes_[buffer] : 0; }

    Status upload(uint32_t buffer, const void* data, size_t bytes) override
    {
        if (buffer >= BUF_COUNT || bytes > bytes_[buffer])
            return makeError(ExitCode::Runtime, "cuda: upload of {} bytes to buffer {} ({} bytes)", bytes,
                             buffer, buffer < BUF_COUNT ? bytes_[buffer] : 0);
        if (bytes) CUDA_TRY(cudaMemcpy(ptr_[buffer], data, bytes, cudaMemcpyHostToDevice));
        return okStatus();
    }

    Status download(uint32_t buffer, void* data, size_t bytes, size_t offset = 0) override
    {
        if (buffer >= BUF_COUNT || offset > bytes_[buffer] || bytes > bytes_[buffer] - offset)
            return makeError(ExitCode::Runtime, "cuda: download of {} bytes at {} from buffer {} ({} bytes)",
                             bytes, offset, buffer, buffer < BUF_COUNT ? bytes_[buffer] : 0);
        if (bytes)
            CUDA_TRY(cudaMemcpy(data, static_cast<const char*>(ptr_[buffer]) + offset, bytes,
                                cudaMemcpyDeviceToHost));
        return okStatus();
    }

    Result<std::shared_ptr<void>> allocateMemory(bool onDevice, size_t bytes) override
    {
        CUDA_TRY(cudaSetDevice(ordinal_));
        void* p = nullptr;
        bytes = std::max<size_t>(bytes, 1);
        if (onDevice) {
            CUDA_TRY(cudaMalloc(&p, bytes));
            return std::shared_ptr<void>(p, [](void* q) { cudaFree(q); });
        }
        CUDA_TRY(cudaHostAlloc(&p, bytes, cudaHostAllocDefault));
        return std::shared_ptr<void>(p, [](void* q) { cudaFreeHost(q); });
    }

    Status downloadToDevice(uint32_t buffer, void* deviceData, size_t bytes, size_t offset) override
    {
        if (buffer >= BUF_COUNT || offset > bytes_[buffer] || bytes > bytes_[buffer] - offset)
            return makeError(ExitCode::Runtime,
                             "cuda: device copy of {} bytes at {} from buffer {} ({} bytes)", bytes, offset,
                             buffer, buffer < BUF_COUNT ? bytes_[buffer] : 0);
        if (bytes == 0) return okStatus();
        // On the device's stream, then waited for: the images are whole when render returns, on any
        // stream of any library.
        CUDA_TRY(cudaMemcpyAsync(deviceData, static_cast<const char*>(ptr_[buffer]) + offset, bytes,
                                 cudaMemcpyDeviceToDevice, stream_));
        CUDA_TRY(cudaStreamSynchronize(stream_));
        return okStatus();
    }

    Status run(const RasterParams& params, const std::vector<Dispatch>& dispatches,
               std::vector<double>& gpuMs) override
    {
        // A binding the scene does not use (e.g. colours) still needs a valid pointer.
        for (uint32_t buffer = 1; buffer < BUF_COUNT; ++buffer)
            if (!ptr_[buffer]) SR_TRY(resize(buffer, 16));
        Buffers b = bufferTable(params, ptr_);
        while (events_.size() < 2 * dispatches.size()) {
            cudaEvent_t e;
            CUDA_TRY(cudaEventCreate(&e));
            events_.push_back(e);
        }
        // Launches go back to back on one stream: a stream orders kernels, which is the full barrier
        // between stages that the interface promises. A dispatch of no blocks (a stage the frame skips)
        // launches nothing and records no events, and its time is 0: with its two events each such stage
        // measured 1.3 us of nothing on the H200, summed into the frame's time (docs/benchmark.md, "Sixth
        // pass").
        for (size_t i = 0; i < dispatches.size(); ++i) {
            if (dispatches[i].groups == 0) continue;
            CUDA_TRY(cudaEventRecord(events_[2 * i], stream_));
            CUDA_TRY(launchStage(dispatches[i].stage, dispatches[i].groups, dispatches[i].alphaTest,
                                 dispatches[i].rasterMethod, params, b, stream_));
            CUDA_TRY(cudaEventRecord(events_[2 * i + 1], stream_));
        }
        CUDA_TRY(cudaStreamSynchronize(stream_));
        gpuMs.assign(dispatches.size(), 0.0);
        for (size_t i = 0; i < dispatches.size(); ++i) {
            if (dispatches[i].groups == 0) continue;
            float ms = 0.0f;
            CUDA_TRY(cudaEventElapsedTime(&ms, events_[2 * i], events_[2 * i + 1]));
            gpuMs[i] = ms;
        }
        return okStatus();
    }

    Status uploadView(const ViewInputs& views, size_t b) override
    {
        if (views.positions == nullptr) return okStatus();
        SR_TRY(checkViews(views));
        SR_TRY(copyView(views, b, ptr_[BUF_POSITIONS], stream_));
        CUDA_TRY(cudaStreamSynchronize(stream_));
        return okStatus();
    }

    // Every view queued at once, one wait. Views go round-robin to up to kMaxLanes lanes: the device's
    // own stream and buffers, and streams with buffers of their own for everything a frame writes
    // (kLaneBuffers), so that the small kernels of several views overlap on the GPU. Each lane's views
    // are in order on its stream: positions in, the frame, counters and images out.
    Status runViews(const std::vector<RasterParams>& params, const std::vector<Dispatch>& dispatches,
                    const ViewInputs& views, size_t first, size_t count, const std::vector<ViewCopy>& copies,
                    uint32_t* counters) override
    {
        for (const ViewCopy& c : copies)
            if (c.offset > bytes_[BUF_FRAMEBUFFER] || c.bytes > bytes_[BUF_FRAMEBUFFER] - c.offset)
                return makeError(ExitCode::Runtime, "cuda: view copy of {} bytes at {} from the framebuffer",
                                 c.bytes, c.offset);
        for (uint32_t buffer = 1; buffer < BUF_COUNT; ++buffer)
            if (!ptr_[buffer]) SR_TRY(resize(buffer, 16));
        // The counters come back through page-locked memory, so that their copies queue like the rest.
        const size_t counterBytes = count * COUNTER_WORDS * sizeof(uint32_t);
        if (counterStaging_.size < counterBytes) {
            if (counterStaging_.data) CUDA_TRY(cudaFreeHost(counterStaging_.data));
            counterStaging_ = {};
            CUDA_TRY(cudaHostAlloc(&counterStaging_.data, counterBytes, cudaHostAllocDefault));
            counterStaging_.size = counterBytes;
        }
        const size_t lanes = std::max<size_t>(1, std::min(count, laneCount()));
        SR_TRY(prepareLanes(lanes, views.positions == nullptr));
        if (views.positions) SR_TRY(checkViews(views, lanes));
        std::vector<PointerTable> pointers;
        std::vector<Buffers> tables;
        for (size_t lane = 0; lane < lanes; ++lane) {
            pointers.push_back(lanePointers(lane));
            tables.push_back(bufferTable(params[0], pointers.back()));
        }
        auto* staged = static_cast<uint32_t*>(counterStaging_.data);
        for (size_t v = first; v < first + count; ++v) {
            const size_t lane = (v - first) % lanes;
            cudaStream_t stream = lane == 0 ? stream_ : lanes_[lane - 1].stream;
            const PointerTable& ptr = pointers[lane];
            const Buffers& b = tables[lane];
            if (views.positions) SR_TRY(copyView(views, v, ptr[BUF_POSITIONS], stream));
            if (params.size() == 1) {
                // Every view's kernels the same: one graph, made once.
                auto graph = frameGraph(lane, stream, params[0], b, dispatches);
                if (!graph) return graph.error();
                CUDA_TRY(cudaGraphLaunch(*graph, stream));
            } else {
                // A camera each: parameters of their own, launched as they are (a graph per view would
                // cost more to make than it saves).
                for (const Dispatch& d : dispatches)
                    CUDA_TRY(launchStage(d.stage, d.groups, d.alphaTest, d.rasterMethod, params[v - first], b,
                                         stream));
            }
            CUDA_TRY(cudaMemcpyAsync(staged + (v - first) * COUNTER_WORDS, ptr[BUF_COUNTERS],
                                     COUNTER_WORDS * sizeof(uint32_t), cudaMemcpyDeviceToHost, stream));
            for (const ViewCopy& c : copies)
                CUDA_TRY(cudaMemcpyAsync(
                    c.destination + v * c.bytes, static_cast<const char*>(ptr[BUF_FRAMEBUFFER]) + c.offset,
                    c.bytes, c.onDevice ? cudaMemcpyDeviceToDevice : cudaMemcpyDeviceToHost, stream));
        }
        // The device's stream waits for the other lanes, so that its next work follows theirs.
        for (size_t lane = 1; lane < lanes; ++lane) {
            CUDA_TRY(cudaEventRecord(lanes_[lane - 1].done, lanes_[lane - 1].stream));
            CUDA_TRY(cudaStreamWaitEvent(stream_, lanes_[lane - 1].done, 0));
        }
        CUDA_TRY(cudaStreamSynchronize(stream_));
        for (size_t v = 0; v < count; ++v)
            foldCounters(staged + v * COUNTER_WORDS, counters + v * COUNTER_COUNT);
        return okStatus();
    }

    Status interpolate(const InterpolateJob& job, int64_t& badPixel, int64_t& badTriangle) override
    {
        for (const void* p : {static_cast<const void*>(job.attr), static_cast<const void*>(job.rast),
                              static_cast<const void*>(job.triangles), static_cast<const void*>(job.out)})
            SR_TRY(checkOnDevice(p));
        SR_TRY(waitFor(job.waitStream, 1));
        if (!interpolateBad_) {
            CUDA_TRY(cudaMalloc(&interpolateBad_, 2 * sizeof(unsigned long long)));
            CUDA_TRY(
                cudaHostAlloc(&interpolateBadHost_, 2 * sizeof(unsigned long long), cudaHostAllocDefault));
        }
        auto* bad = static_cast<unsigned long long*>(interpolateBad_);
        auto* badHost = static_cast<unsigned long long*>(interpolateBadHost_);
        CUDA_TRY(cudaMemsetAsync(bad, 0xFF, 2 * sizeof(unsigned long long), stream_));
        CUDA_TRY(launchInterpolate(job, bad, stream_));
        CUDA_TRY(
            cudaMemcpyAsync(badHost, bad, 2 * sizeof(unsigned long long), cudaMemcpyDeviceToHost, stream_));
        CUDA_TRY(cudaStreamSynchronize(stream_));
        badPixel = badHost[0] == ~0ull ? -1 : int64_t(badHost[0]);
        badTriangle = badHost[1] == ~0ull ? -1 : int64_t(badHost[1]);
        return okStatus();
    }

    size_t allocatedBytes() const override { return allocated_; }
    size_t peakAllocatedBytes() const override { return peak_; }

    CudaDeviceView view() const
    {
        return {ordinal_, uuid_, stream_, ptr_[BUF_FRAMEBUFFER], bytes_[BUF_FRAMEBUFFER]};
    }

private:
    using PointerTable = std::array<void*, BUF_COUNT>;  // a pointer per BUF_*

    // Positions in device memory must be this device's (a pointer of another device or of the host
    // would fault in the copy); the stream they were written on is waited for by the first `lanes` lanes.
    Status checkViews(const ViewInputs& views, size_t lanes = 1)
    {
        if (views.bytes > bytes_[BUF_POSITIONS])
            return makeError(ExitCode::Runtime, "cuda: {} bytes of positions per view for {} bytes",
                             views.bytes, bytes_[BUF_POSITIONS]);
        if (!views.onDevice) return okStatus();
        SR_TRY(checkOnDevice(views.positions));
        return waitFor(views.waitStream, lanes);
    }

    // Memory a caller hands over as this device's must be (a pointer of another device or of the host
    // would fault in a copy or a kernel).
    Status checkOnDevice(const void* p) const
    {
        cudaPointerAttributes a{};
        CUDA_TRY(cudaPointerGetAttributes(&a, p));
        if ((a.type != cudaMemoryTypeDevice && a.type != cudaMemoryTypeManaged) || a.device != ordinal_)
            return makeError(ExitCode::Usage, "the arrays are not in memory of CUDA device {}", ordinal_);
        return okStatus();
    }

    // The device's stream and the first `lanes` lanes wait for the work queued so far on a producer's
    // stream, named as __cuda_array_interface__ names one (0: none, 1: the legacy default stream, 2: the
    // per-thread default stream, else a cudaStream_t).
    Status waitFor(uintptr_t waitStream, size_t lanes)
    {
        if (waitStream == 0) return okStatus();
        if (!waitEvent_) CUDA_TRY(cudaEventCreateWithFlags(&waitEvent_, cudaEventDisableTiming));
        cudaStream_t producer = waitStream == 1   ? cudaStreamLegacy
                                : waitStream == 2 ? cudaStreamPerThread
                                                  : reinterpret_cast<cudaStream_t>(waitStream);
        CUDA_TRY(cudaEventRecord(waitEvent_, producer));
        CUDA_TRY(cudaStreamWaitEvent(stream_, waitEvent_, 0));
        for (size_t lane = 1; lane < lanes; ++lane)
            CUDA_TRY(cudaStreamWaitEvent(lanes_[lane - 1].stream, waitEvent_, 0));
        return okStatus();
    }

    // runViews' lanes: kMaxLanes, fewer where their buffers would take more than a quarter of the free
    // device memory (a lane holds a copy of every buffer a frame writes).
    size_t laneCount()
    {
        size_t laneBytes = 0;
        for (uint32_t buffer : kLaneBuffers) laneBytes += bytes_[buffer];
        size_t free = 0, total = 0;
        if (cudaMemGetInfo(&free, &total) != cudaSuccess) return 1;
        for (const Lane& l : lanes_)  // memory the lanes hold already counts as theirs
            for (uint32_t buffer : kLaneBuffers) free += l.bytes[buffer];
        return std::min<size_t>(kMaxLanes, 1 + free / 4 / std::max<size_t>(laneBytes, 1));
    }

    // Lanes 1 .. lanes - 1 made, their buffers sized as the device's own, and waiting for its stream;
    // with scenePositions, the scene's positions copied into theirs (the views draw them).
    Status prepareLanes(size_t lanes, bool scenePositions)
    {
        while (lanes_.size() + 1 < lanes) {
            Lane l;
            CUDA_TRY(cudaStreamCreateWithFlags(&l.stream, cudaStreamNonBlocking));
            CUDA_TRY(cudaEventCreateWithFlags(&l.done, cudaEventDisableTiming));
            lanes_.push_back(l);
        }
        if (lanes > 1) {  // the lanes start after what the device's stream has queued
            if (!laneStart_) CUDA_TRY(cudaEventCreateWithFlags(&laneStart_, cudaEventDisableTiming));
            CUDA_TRY(cudaEventRecord(laneStart_, stream_));
        }
        for (size_t lane = 1; lane < lanes; ++lane) {
            Lane& l = lanes_[lane - 1];
            for (uint32_t buffer : kLaneBuffers) {
                if (l.bytes[buffer] == bytes_[buffer]) continue;
                if (l.ptr[buffer]) {
                    CUDA_TRY(cudaFree(l.ptr[buffer]));
                    allocated_ -= l.bytes[buffer];
                    l.ptr[buffer] = nullptr;
                    l.bytes[buffer] = 0;
                }
                CUDA_TRY(cudaMalloc(&l.ptr[buffer], bytes_[buffer]));
                l.bytes[buffer] = bytes_[buffer];
                allocated_ += bytes_[buffer];
                peak_ = std::max(peak_, allocated_);
            }
            CUDA_TRY(cudaStreamWaitEvent(l.stream, laneStart_, 0));
            if (scenePositions)
                CUDA_TRY(cudaMemcpyAsync(l.ptr[BUF_POSITIONS], ptr_[BUF_POSITIONS], bytes_[BUF_POSITIONS],
                                         cudaMemcpyDeviceToDevice, l.stream));
        }
        return okStatus();
    }

    // A lane's frame as a CUDA graph, made once per parameters, buffers and dispatches (a view's kernels
    // differ from the previous view's in nothing) and launched as one call: the launches of a view cost
    // the host as much as a small view costs the GPU. The last kGraphsPerLane graphs are kept.
    Result<cudaGraphExec_t> frameGraph(size_t lane, cudaStream_t stream, const RasterParams& params,
                                       const Buffers& b, const std::vector<Dispatch>& dispatches)
    {
        std::vector<uint8_t> key(sizeof params + sizeof b);
        std::memcpy(key.data(), &params, sizeof params);
        std::memcpy(key.data() + sizeof params, &b, sizeof b);
        for (const Dispatch& d : dispatches)
            for (uint32_t word : {d.stage, d.groups, uint32_t(d.alphaTest), d.rasterMethod})
                key.insert(key.end(), reinterpret_cast<const uint8_t*>(&word),
                           reinterpret_cast<const uint8_t*>(&word) + 4);
        std::vector<CachedGraph>& cache = graphs_[lane];
        for (size_t i = 0; i < cache.size(); ++i)
            if (cache[i].key == key) {
                std::rotate(cache.begin() + long(i), cache.begin() + long(i) + 1, cache.end());
                return cache.back().exec;
            }
        CUDA_TRY(cudaStreamBeginCapture(stream, cudaStreamCaptureModeThreadLocal));
        cudaError_t launched = cudaSuccess;
        for (const Dispatch& d : dispatches) {
            launched = launchStage(d.stage, d.groups, d.alphaTest, d.rasterMethod, params, b, stream);
            if (launched != cudaSuccess) break;
        }
        cudaGraph_t graph = nullptr;
        const cudaError_t ended = cudaStreamEndCapture(stream, &graph);
        if (launched != cudaSuccess || ended != cudaSuccess) {
            if (graph) cudaGraphDestroy(graph);
            CUDA_TRY(launched);
            CUDA_TRY(ended);
        }
        cudaGraphExec_t exec = nullptr;
        const cudaError_t made = cudaGraphInstantiate(&exec, graph, 0);
        cudaGraphDestroy(graph);
        CUDA_TRY(made);
        if (cache.size() >= kGraphsPerLane) {
            cudaGraphExecDestroy(cache.front().exec);
            cache.erase(cache.begin());
        }
        cache.push_back({std::move(key), exec});
        return exec;
    }

    // View v's positions into `to` (a BUF_POSITIONS), queued on `stream`.
    static Status copyView(const ViewInputs& views, size_t v, void* to, cudaStream_t stream)
    {
        CUDA_TRY(cudaMemcpyAsync(to, static_cast<const char*>(views.positions) + v * views.bytes, views.bytes,
                                 views.onDevice ? cudaMemcpyDeviceToDevice : cudaMemcpyHostToDevice, stream));
        return okStatus();
    }

    // Lane `lane`'s pointer table: the device's own buffers, with the lane's in place of every buffer a
    // frame writes (kLaneBuffers); lane 0 is the device's own.
    PointerTable lanePointers(size_t lane) const
    {
        PointerTable ptr = ptr_;
        if (lane > 0)
            for (uint32_t buffer : kLaneBuffers) ptr[buffer] = lanes_[lane - 1].ptr[buffer];
        return ptr;
    }

    template <typename T>
    static T* as(const PointerTable& ptr, uint32_t buffer)
    {
        return static_cast<T*>(ptr[buffer]);
    }

    // The kernels' buffer table over `ptr`: the device's own buffers, or a runViews lane's (lanePointers).
    static Buffers bufferTable(const RasterParams& params, const PointerTable& ptr)
    {
        Buffers b{};
        b.positions = as<vec4>(ptr, BUF_POSITIONS);
        b.normals = as<vec4>(ptr, BUF_NORMALS);
        b.colors = as<vec4>(ptr, BUF_COLORS);
        b.indices = as<uint>(ptr, BUF_INDICES);
        b.triFlags = as<uint>(ptr, BUF_TRI_FLAGS);
        b.clipPos = as<vec4>(ptr, BUF_CLIP_POS);
        b.setupTris = as<TriSetup>(ptr, BUF_SETUP_TRIS);
        b.pieces = as<uvec2>(ptr, BUF_PIECES);
        b.tileBins = as<uint>(ptr, BUF_TILE_BINS);
        b.scanSums = as<uint>(ptr, BUF_SCAN_SUMS);
        b.binEntries = as<uint>(ptr, BUF_BIN_ENTRIES);
        b.activeTiles = as<uint>(ptr, BUF_ACTIVE_TILES);
        b.counters = as<uint>(ptr, BUF_COUNTERS);
        b.visibility = as<unsigned long long>(ptr, BUF_VISIBILITY);
        b.framebuffer = as<uint>(ptr, BUF_FRAMEBUFFER);
        b.hitCount = as<uint>(ptr, BUF_HIT_COUNT);
        b.materials = as<GpuMaterial>(ptr, BUF_MATERIALS);
        b.triMaterials = as<uint>(ptr, BUF_TRI_MATERIALS);
        b.texcoords = as<vec4>(ptr, BUF_TEXCOORDS);
        b.textures = as<GpuTexture>(ptr, BUF_TEXTURES);
        b.texels = as<uint>(ptr, BUF_TEXELS);
        b.srgbTable = as<float>(ptr, BUF_SRGB_TABLE);
        b.points = as<uint>(ptr, BUF_POINTS);
        b.lines = as<uint>(ptr, BUF_LINES);
        b.tessSource = as<TessSource>(ptr, BUF_TESS_SOURCE);
        b.tessCounts = as<uvec4>(ptr, BUF_TESS_COUNTS);
        b.tessSums = as<uvec4>(ptr, BUF_TESS_SUMS);
        b.clusters = as<GpuCluster>(ptr, BUF_CLUSTERS);
        b.clusterData = as<uint>(ptr, BUF_CLUSTER_DATA);
        b.lodCut = as<uint>(ptr, BUF_LOD_CUT);
        b.ao = as<float>(ptr, BUF_AO);
        TessWriter& w = b.tess;
        w.positions = as<vec4>(ptr, BUF_POSITIONS);
        w.normals = as<vec4>(ptr, BUF_NORMALS);
        w.texcoords = as<vec4>(ptr, BUF_TEXCOORDS);
        w.colors = as<vec4>(ptr, BUF_COLORS);
        w.indices = as<uint>(ptr, BUF_INDICES);
        w.triFlags = as<uint>(ptr, BUF_TRI_FLAGS);
        w.triMaterials = as<uint>(ptr, BUF_TRI_MATERIALS);
        w.ids = as<uint>(ptr, BUF_TESS_IDS);
        w.materials = params.materialCount > 0u ? as<uint>(ptr, BUF_TESS_MATERIALS) : nullptr;
        w.sources = as<TessSource>(ptr, BUF_TESS_SOURCE);
        w.sourceVertices = params.tessSourceVertices;
        w.hasTexcoords = params.textureCount > 0u;
        w.hasColors = params.hasColors != 0u;
        return b;
    }

    DeviceInfo info_;
    int ordinal_ = 0;
    std::array<uint8_t, 16> uuid_{};
    cudaStream_t stream_ = nullptr;
    std::array<void*, BUF_COUNT> ptr_{};
    std::array<size_t, BUF_COUNT> bytes_{};
    std::vector<cudaEvent_t> events_;
    cudaEvent_t waitEvent_ = nullptr;     // marks a producer's stream for runViews to wait on
    cudaEvent_t laneStart_ = nullptr;     // the device's stream, where runViews' other lanes start
    void* interpolateBad_ = nullptr;      // interpolate's two flags, on the device
    void* interpolateBadHost_ = nullptr;  // and page-locked for their copy back
    // runViews' lanes beyond the device's own stream and buffers: the buffers a frame writes.
    static constexpr size_t kMaxLanes = 4;
    static constexpr std::array<uint32_t, 14> kLaneBuffers = {
        BUF_POSITIONS,   BUF_CLIP_POS,    BUF_SETUP_TRIS,   BUF_PIECES,   BUF_TILE_BINS,
        BUF_SCAN_SUMS,   BUF_BIN_ENTRIES, BUF_ACTIVE_TILES, BUF_COUNTERS, BUF_VISIBILITY,
        BUF_FRAMEBUFFER, BUF_HIT_COUNT,   BUF_LOD_CUT,      BUF_AO};
    struct Lane {
        cudaStream_t stream = nullptr;
        cudaEvent_t done = nullptr;
        std::array<void*, BUF_COUNT> ptr{};
        std::array<size_t, BUF_COUNT> bytes{};
    };
    std::vector<Lane> lanes_;
    struct CachedGraph {
        std::vector<uint8_t> key;  // the parameters', buffer table's and dispatches' bytes
        cudaGraphExec_t exec = nullptr;
    };
    static constexpr size_t kGraphsPerLane = 4;
    std::array<std::vector<CachedGraph>, kMaxLanes> graphs_;
    struct {
        void* data = nullptr;
        size_t size = 0;
    } counterStaging_;  // runViews' counters, page-locked
    size_t allocated_ = 0;
    size_t peak_ = 0;
};

}  // namespace

Result<std::unique_ptr<ComputeDevice>> makeCudaDevice(int index)
{
    auto device = std::make_unique<CudaDevice>();
    SR_TRY(device->init(index));
    return std::unique_ptr<ComputeDevice>(std::move(device));
}

std::optional<CudaDeviceView> cudaDeviceView(ComputeDevice& device)
{
    auto* cuda = dynamic_cast<CudaDevice*>(&device);
    if (cuda == nullptr) return std::nullopt;
    return cuda->view();
}

}  // namespace sr
