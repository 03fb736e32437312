// cuda_device.cu - the CUDA implementation of ComputeDevice: plain cudaMalloc buffers (one per BUF_*),
// synchronous copies, and one stream on which each dispatch is bracketed by a pair of CUDA events.
#include <algorithm>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "render/compute_device.h"
#include "cuda_check.h"
#include "cuda_device_internal.h"
#include "kernels.h"

namespace sr {
namespace {

class CudaDevice final : public ComputeDevice {
public:
    ~CudaDevice() override
    {
        // Errors cannot be reported from a destructor; the process is ending or moving on.
        for (cudaEvent_t e : events_) cudaEventDestroy(e);
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
        Buffers b = bufferTable(params);
        while (events_.size() < 2 * dispatches.size()) {
            cudaEvent_t e;
            CUDA_TRY(cudaEventCreate(&e));
            events_.push_back(e);
        }
        // Launches go back to back on one stream: a stream orders kernels, which is the full barrier
        // between stages that the interface promises.
        for (size_t i = 0; i < dispatches.size(); ++i) {
            CUDA_TRY(cudaEventRecord(events_[2 * i], stream_));
            CUDA_TRY(launchStage(dispatches[i].stage, dispatches[i].groups, dispatches[i].alphaTest,
                                 dispatches[i].rasterMethod, params, b, stream_));
            CUDA_TRY(cudaEventRecord(events_[2 * i + 1], stream_));
        }
        CUDA_TRY(cudaStreamSynchronize(stream_));
        gpuMs.assign(dispatches.size(), 0.0);
        for (size_t i = 0; i < dispatches.size(); ++i) {
            float ms = 0.0f;
            CUDA_TRY(cudaEventElapsedTime(&ms, events_[2 * i], events_[2 * i + 1]));
            gpuMs[i] = ms;
        }
        return okStatus();
    }

    size_t allocatedBytes() const override { return allocated_; }
    size_t peakAllocatedBytes() const override { return peak_; }

    CudaDeviceView view() const
    {
        return {ordinal_, uuid_, stream_, ptr_[BUF_FRAMEBUFFER], bytes_[BUF_FRAMEBUFFER]};
    }

private:
    template <typename T>
    T* as(uint32_t buffer) const
    {
        return static_cast<T*>(ptr_[buffer]);
    }

    Buffers bufferTable(const RasterParams& params) const
    {
        Buffers b{};
        b.positions = as<vec4>(BUF_POSITIONS);
        b.normals = as<vec4>(BUF_NORMALS);
        b.colors = as<vec4>(BUF_COLORS);
        b.indices = as<uint>(BUF_INDICES);
        b.triFlags = as<uint>(BUF_TRI_FLAGS);
        b.clipPos = as<vec4>(BUF_CLIP_POS);
        b.setupTris = as<TriSetup>(BUF_SETUP_TRIS);
        b.pieces = as<uvec2>(BUF_PIECES);
        b.tileBins = as<uint>(BUF_TILE_BINS);
        b.scanSums = as<uint>(BUF_SCAN_SUMS);
        b.binEntries = as<uint>(BUF_BIN_ENTRIES);
        b.activeTiles = as<uint>(BUF_ACTIVE_TILES);
        b.counters = as<uint>(BUF_COUNTERS);
        b.visibility = as<unsigned long long>(BUF_VISIBILITY);
        b.framebuffer = as<uint>(BUF_FRAMEBUFFER);
        b.hitCount = as<uint>(BUF_HIT_COUNT);
        b.materials = as<GpuMaterial>(BUF_MATERIALS);
        b.triMaterials = as<uint>(BUF_TRI_MATERIALS);
        b.texcoords = as<vec4>(BUF_TEXCOORDS);
        b.textures = as<GpuTexture>(BUF_TEXTURES);
        b.texels = as<uint>(BUF_TEXELS);
        b.srgbTable = as<float>(BUF_SRGB_TABLE);
        b.points = as<uint>(BUF_POINTS);
        b.lines = as<uint>(BUF_LINES);
        b.tessSource = as<TessSource>(BUF_TESS_SOURCE);
        b.tessCounts = as<uvec4>(BUF_TESS_COUNTS);
        b.tessSums = as<uvec4>(BUF_TESS_SUMS);
        b.clusters = as<GpuCluster>(BUF_CLUSTERS);
        b.clusterData = as<uint>(BUF_CLUSTER_DATA);
        b.lodCut = as<uint>(BUF_LOD_CUT);
        b.ao = as<float>(BUF_AO);
        TessWriter& w = b.tess;
        w.positions = as<vec4>(BUF_POSITIONS);
        w.normals = as<vec4>(BUF_NORMALS);
        w.texcoords = as<vec4>(BUF_TEXCOORDS);
        w.colors = as<vec4>(BUF_COLORS);
        w.indices = as<uint>(BUF_INDICES);
        w.triFlags = as<uint>(BUF_TRI_FLAGS);
        w.triMaterials = as<uint>(BUF_TRI_MATERIALS);
        w.ids = as<uint>(BUF_TESS_IDS);
        w.materials = params.materialCount > 0u ? as<uint>(BUF_TESS_MATERIALS) : nullptr;
        w.sources = as<TessSource>(BUF_TESS_SOURCE);
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
