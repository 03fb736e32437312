// cuda_interop.cu - the CUDA backend's end of the viewer's shared framebuffer (render/frame_share.h):
// the presenter's Vulkan buffer and binary semaphore imported from their file descriptors
// (cudaImportExternalMemory, cudaImportExternalSemaphore), and per frame a device-to-device copy of
// BUF_FRAMEBUFFER into the buffer followed by the semaphore's signal, both on the device's stream.
#include <unistd.h>

#include <memory>

#include "render/frame_share.h"
#include "cuda_check.h"
#include "cuda_device_internal.h"

namespace sr {
namespace {

void closeFd(int& fd)
{
    if (fd >= 0) close(fd);
    fd = -1;
}

class CudaFrameWriter final : public SharedFrameWriter {
public:
    explicit CudaFrameWriter(ComputeDevice& device) : device_(device) {}

    ~CudaFrameWriter() override
    {
        // Errors cannot be reported from a destructor. The presenter waited for its last copy; the
        // stream may still hold this writer's last signal.
        cudaSetDevice(ordinal_);
        if (stream_ != nullptr) cudaStreamSynchronize(stream_);
        if (mapped_ != nullptr) cudaFree(mapped_);
        if (memory_ != nullptr) cudaDestroyExternalMemory(memory_);
        if (semaphore_ != nullptr) cudaDestroyExternalSemaphore(semaphore_);
    }

    // Takes both descriptors: each is CUDA's once its import succeeded, and closed here otherwise
    // (`handles` says -1 for both on return).
    Status import(SharedFrameHandles& handles)
    {
        Status status = importBoth(handles);
        closeFd(handles.memoryFd);
        closeFd(handles.semaphoreFd);
        return status;
    }

    Status writeFrame(size_t bytes) override
    {
        std::optional<CudaDeviceView> view = cudaDeviceView(device_);
        if (!view)
            return makeError(ExitCode::Runtime, "cuda: the shared frame's device is not a CUDA device");
        if (bytes > bytes_ || bytes > view->framebufferBytes)
            return makeError(ExitCode::Runtime,
                             "cuda: a frame of {} bytes does not fit the shared buffer ({} bytes) or the "
                             "framebuffer ({} bytes)",
                             bytes, bytes_, view->framebufferBytes);
        CUDA_TRY(cudaSetDevice(view->ordinal));
        stream_ = view->stream;
        // Stream order puts both after the frame's kernels, and the signal after the copy.
        CUDA_TRY(cudaMemcpyAsync(mapped_, view->framebuffer, bytes, cudaMemcpyDeviceToDevice, stream_));
        cudaExternalSemaphoreSignalParams signal{};
        CUDA_TRY(cudaSignalExternalSemaphoresAsync(&semaphore_, &signal, 1, stream_));
        return okStatus();
    }

private:
    Status importBoth(SharedFrameHandles& handles)
    {
        std::optional<CudaDeviceView> view = cudaDeviceView(device_);
        if (!view)
            return makeError(ExitCode::Runtime, "cuda: the shared frame's device is not a CUDA device");
        if (handles.memoryFd < 0 || handles.semaphoreFd < 0 || handles.bufferBytes > handles.memoryBytes)
            return makeError(ExitCode::Runtime, "cuda: invalid handles for the shared frame");
        ordinal_ = view->ordinal;
        CUDA_TRY(cudaSetDevice(ordinal_));

        cudaExternalMemoryHandleDesc memoryDesc{};
        memoryDesc.type = cudaExternalMemoryHandleTypeOpaqueFd;
        memoryDesc.handle.fd = handles.memoryFd;
        memoryDesc.size = handles.memoryBytes;
        memoryDesc.flags = handles.dedicated ? cudaExternalMemoryDedicated : 0;
        CUDA_TRY(cudaImportExternalMemory(&memory_, &memoryDesc));
        handles.memoryFd = -1;  // CUDA's now

        cudaExternalMemoryBufferDesc bufferDesc{};
        bufferDesc.offset = 0;
        bufferDesc.size = handles.bufferBytes;
        CUDA_TRY(cudaExternalMemoryGetMappedBuffer(&mapped_, memory_, &bufferDesc));
        bytes_ = handles.bufferBytes;

        cudaExternalSemaphoreHandleDesc semaphoreDesc{};
        semaphoreDesc.type = cudaExternalSemaphoreHandleTypeOpaqueFd;
        semaphoreDesc.handle.fd = handles.semaphoreFd;
        CUDA_TRY(cudaImportExternalSemaphore(&semaphore_, &semaphoreDesc));
        handles.semaphoreFd = -1;  // CUDA's now
        return okStatus();
    }

    ComputeDevice& device_;
    int ordinal_ = 0;
    cudaStream_t stream_ = nullptr;
    cudaExternalMemory_t memory_ = nullptr;
    void* mapped_ = nullptr;
    size_t bytes_ = 0;
    cudaExternalSemaphore_t semaphore_ = nullptr;
};

}  // namespace

std::optional<FrameShareSource> cudaFrameShareSource(ComputeDevice& device)
{
    std::optional<CudaDeviceView> view = cudaDeviceView(device);
    if (!view) return std::nullopt;
    FrameShareSource source;
    source.deviceUuid = view->uuid;
    source.import = [&device](SharedFrameHandles& handles) -> Result<std::unique_ptr<SharedFrameWriter>> {
        auto writer = std::make_unique<CudaFrameWriter>(device);
        SR_TRY(writer->import(handles));
        return std::unique_ptr<SharedFrameWriter>(std::move(writer));
    };
    return source;
}

}  // namespace sr
