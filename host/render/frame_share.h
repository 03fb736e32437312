// frame_share.h - a compute device's frame handed to a Vulkan presenter on the same GPU without a trip
// through the host (`raster view`, CUDA backend). The presenter allocates a buffer and a binary semaphore
// in Vulkan and exports both as POSIX file descriptors (VK_KHR_external_memory_fd,
// VK_KHR_external_semaphore_fd); the device imports them and, per frame, copies its framebuffer into
// the buffer and signals the semaphore on its own queue; the presenter's copy into the swapchain waits
// on that semaphore. Host code sees only this interface: the CUDA side lives in cuda/cuda_interop.cu
// (cuda/cuda_unavailable.cpp without CUDA), so no CUDA header reaches host/.
#ifndef RASTER_FRAME_SHARE_H
#define RASTER_FRAME_SHARE_H

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>

#include "base/result.h"
#include "render/compute_device.h"

namespace sr {

// What the presenter exported. The importer owns each descriptor once its import succeeded and must
// close it when the import failed (CUDA's rule); either way the caller must not use it again.
struct SharedFrameHandles {
    int memoryFd = -1;         // OPAQUE_FD of the buffer's memory
    uint64_t memoryBytes = 0;  // the size of that allocation (VkMemoryRequirements::size)
    uint64_t bufferBytes = 0;  // the bytes the device may write, from offset 0
    bool dedicated = false;  // a dedicated allocation (the importer must say so: cudaExternalMemoryDedicated)
    int semaphoreFd = -1;    // OPAQUE_FD of a binary semaphore, signalled once per frame
};

// The device's end of an imported buffer and semaphore.
class SharedFrameWriter {
public:
    virtual ~SharedFrameWriter() = default;
    // Queues, on the device's stream after the frame it rendered last: a copy of the first `bytes` of
    // its BUF_FRAMEBUFFER into the shared buffer, then the semaphore's signal. The caller (the
    // presenter) must submit exactly one wait on the semaphore per call, and must not call again
    // before that wait's submission has completed (its fence), which is what keeps the device from
    // overwriting the buffer while Vulkan still reads it.
    virtual Status writeFrame(size_t bytes) = 0;
};

// A compute device that can write its frames into a presenter's memory.
struct FrameShareSource {
    std::array<uint8_t, 16> deviceUuid{};  // the GPU's UUID: the presenter's Vulkan device must have it
    std::function<Result<std::unique_ptr<SharedFrameWriter>>(SharedFrameHandles&)> import;
};

// The CUDA backend's source, or nothing when `device` is not a CUDA device (or the build has no CUDA).
// `device` must outlive the writers it imports.
std::optional<FrameShareSource> cudaFrameShareSource(ComputeDevice& device);

}  // namespace sr

#endif  // RASTER_FRAME_SHARE_H
