// scan_blocks.comp - stage `scan_blocks`: exclusive scan of the big triangles' tile counts within each
// block of SCAN_GROUP_SIZE, in place in bigOffsets; each block's total goes to scanSums.
// One thread per big-list entry; groups = ceil(setupCapacity / SCAN_GROUP_SIZE), idle past the count.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"
#include "scan.glsl"

layout(local_size_x = SCAN_GROUP_SIZE) in;

void main()
{
    uint count = counters[COUNTER_BIG];
    if (gl_WorkGroupID.x * uint(SCAN_GROUP_SIZE) >= count) return;  // uniform across the group
    uint i = gl_GlobalInvocationID.x;
    uint lane = gl_LocalInvocationID.x;
    uint value = i < count ? bigOffsets[i] : 0u;
    partial[lane] = value;
    barrier();
    blockInclusiveScan(lane);
    if (i < count) bigOffsets[i] = partial[lane] - value;
    if (lane == uint(SCAN_GROUP_SIZE) - 1u) scanSums[gl_WorkGroupID.x] = partial[lane];
}
