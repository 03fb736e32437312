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

Status ComputeDevice::uploadView(const ViewInputs& views, size_t b)
{
    if (views.positions == nullptr) return okStatus();
    if (views.onDevice)
        return makeError(ExitCode::Usage, "positions in device memory need a CUDA device, not {}",
                         info().backend);
    return upload(BUF_POSITIONS, static_cast<const char*>(views.positions) + b * views.bytes, views.bytes);
}

Status ComputeDevice::runViews(const std::vector<RasterParams>& params,
                               const std::vector<Dispatch>& dispatches, const ViewInputs& views, size_t first,
                               size_t count, const std::vector<ViewCopy>& copies, uint32_t* counters)
{
    std::vector<double> ms;
    for (size_t b = first; b < first + count; ++b) {
        SR_TRY(uploadView(views, b));
        SR_TRY(run(params[params.size() == 1 ? 0 : b - first], dispatches, ms));
        SR_TRY(downloadCounters(counters + (b - first) * COUNTER_COUNT));
        for (const ViewCopy& c : copies) SR_TRY(copyView(c, b));
    }
    return okStatus();
}

Status ComputeDevice::downloadCounters(uint32_t* counters)
{
    uint32_t words[COUNTER_WORDS];
    SR_TRY(download(BUF_COUNTERS, words, sizeof words));
    foldCounters(words, counters);
    return okStatus();
}

Status ComputeDevice::copyView(const ViewCopy& c, size_t b)
{
    char* to = c.destination + b * c.bytes;
    return c.onDevice ? downloadToDevice(BUF_FRAMEBUFFER, to, c.bytes, c.offset)
                      : download(BUF_FRAMEBUFFER, to, c.bytes, c.offset);
}

Status ComputeDevice::interpolate(const InterpolateJob&, int64_t&, int64_t&)
{
    return makeError(ExitCode::Usage, "interpolate on the device needs a CUDA device, not {}",
                     info().backend);
}

const char* stageName(uint32_t stage)
{
    return stage < STAGE_COUNT ? kStages[stage].name : "unknown";
}

}  // namespace sr
