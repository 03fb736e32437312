// scan_tiles.comp - stage `scan_tiles`: the screen tiles' bin counts become bin offsets, in place (an
// exclusive scan), the tiles with a non-empty bin go to the active tile list, and the total to
// counters[COUNTER_BIN_ENTRIES]. One group: each invocation sums a run of consecutive tiles, the group
// scans the run totals (Hillis-Steele: after the step with offset d each entry sums its last 2d
// inputs), and each invocation writes its run's offsets. One launch instead of a scan per block plus a
// scan of the block totals: at 1080p the whole stage is 32,400 counts, which one group reads in a few
// microseconds.
// groups = 1 of SCAN_GROUP_SIZE invocations.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(local_size_x = SCAN_GROUP_SIZE) in;

shared uint64_t partial[SCAN_GROUP_SIZE];

void main()
{
    uint lane = gl_LocalInvocationID.x;
    uint tiles = params.tilesX * params.tilesY;
    uint run = (tiles + uint(SCAN_GROUP_SIZE) - 1u) / uint(SCAN_GROUP_SIZE);
    uint first = min(lane * run, tiles);
    uint last = min(first + run, tiles);
    uint64_t sum = 0ul;
    for (uint i = first; i < last; ++i) sum += uint64_t(tileBins[i]);
    partial[lane] = sum;
    barrier();
    for (uint d = 1u; d < uint(SCAN_GROUP_SIZE); d <<= 1u) {
        uint64_t add = lane >= d ? partial[lane - d] : 0ul;
        barrier();
        partial[lane] += add;
        barrier();
    }
    // Bin offsets are uint; a total past 2^31 is reported instead of wrapping silently.
    uint64_t total = partial[SCAN_GROUP_SIZE - 1];
    if (total >= (uint64_t(1) << 31)) {
        if (lane == 0u) counters[COUNTER_WORK_OVERFLOW] = 1u;
        return;
    }
    uint offset = uint(partial[lane] - sum);
    for (uint i = first; i < last; ++i) {
        uint count = tileBins[i];
        tileBins[i] = offset;
        offset += count;
        if (count > 0u) activeTiles[atomicAdd(counters[COUNTER_ACTIVE_TILES], 1u)] = i;
    }
    if (lane == 0u) counters[COUNTER_BIN_ENTRIES] = uint(total);
}
