// compute_device.cpp - stage names.
#include "render/compute_device.h"

namespace sr {

const char* stageName(uint32_t stage)
{
    static const char* const names[STAGE_COUNT] = {
        "clear",        "vertex", "setup",      "bin_count",        "scan_blocks",    "scan_sums", "bin_fill",
        "raster_tiles", "shade",  "tess_count", "tess_scan_blocks", "tess_scan_sums", "tess_emit"};
    return stage < STAGE_COUNT ? names[stage] : "unknown";
}

}  // namespace sr
