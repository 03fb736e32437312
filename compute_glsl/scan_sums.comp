// scan_sums.comp - stage `scan_sums`: exclusive scan of the block totals in scanSums, in place, and the
// grand total of bin entries into counters[COUNTER_BIN_ENTRIES]. One group of SCAN_GROUP_SIZE threads.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"
#include "scan.glsl"

layout(local_size_x = SCAN_GROUP_SIZE) in;

void main()
{
    uint lane = gl_LocalInvocationID.x;
    uint blocks = (params.tilesX * params.tilesY + uint(SCAN_GROUP_SIZE) - 1u) / uint(SCAN_GROUP_SIZE);
    uint64_t carry = 0ul;  // every thread keeps the same running total
    for (uint base = 0u; base < blocks; base += uint(SCAN_GROUP_SIZE)) {
        uint i = base + lane;
        uint value = i < blocks ? scanSums[i] : 0u;
        partial[lane] = value;
        barrier();
        blockInclusiveScan(lane);
        if (i < blocks) scanSums[i] = uint(carry) + partial[lane] - value;
        carry += uint64_t(partial[SCAN_GROUP_SIZE - 1]);
        barrier();
    }
    if (lane == 0u) {
        // Bin offsets are uint; a total past 2^31 is reported instead of wrapping silently.
        bool overflow = carry >= (uint64_t(1) << 31);
        counters[COUNTER_BIN_ENTRIES] = overflow ? 0u : uint(carry);
        if (overflow) counters[COUNTER_WORK_OVERFLOW] = 1u;
    }
}
