// compute_device.cpp - stage names, and what a backend without memory of its own to lend gives.
#include "render/compute_device.h"

#include <new>

namespace sr {

Result<std::shared_ptr<void>> ComputeDevice::allocateMemory(bool onDevice, size_t bytes)
{
    if (onDevice)
        return makeError(ExitCode::Usage,
                         "images on the device need a CUDA device ({} has no memory to lend)",
                         info().backend);
    // Aligned as a cache line, as the copies into it read and write whole lines.
    constexpr std::align_val_t kAlign{64};
    void* p = ::operator new(bytes == 0 ? 1 : bytes, kAlign, std::nothrow);
    if (p == nullptr) return makeError(ExitCode::Runtime, "cannot allocate {} bytes of host memory", bytes);
    return std::shared_ptr<void>(p, [](void* q) { ::operator delete (q, std::align_val_t{64}); });
}

Status ComputeDevice::downloadToDevice(uint32_t, void*, size_t, size_t)
{
    return makeError(ExitCode::Usage, "images on the device need a CUDA device, not {}", info().backend);
}

const char* stageName(uint32_t stage)
{
    return stage < STAGE_COUNT ? kStages[stage].name : "unknown";
}

}  // namespace sr
