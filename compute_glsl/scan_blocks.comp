// scan_blocks.comp - stage `scan_blocks`: exclusive scan of the screen tiles' bin counts within each
// block of SCAN_GROUP_SIZE tiles, in place in tileBins; each block's total goes to scanSums, and every
// tile with a non-empty bin to the active tile list that raster_tiles works through.
// One invocation per screen tile; groups = ceil(tilesX * tilesY / SCAN_GROUP_SIZE).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"
#include "scan.glsl"

layout(local_size_x = SCAN_GROUP_SIZE) in;

void main()
{
    uint count = params.tilesX * params.tilesY;
    uint i = gl_GlobalInvocationID.x;
    uint lane = gl_LocalInvocationID.x;
    uint value = i < count ? tileBins[i] : 0u;
    partial[lane] = value;
    barrier();
    blockInclusiveScan(lane);
    if (i < count) tileBins[i] = partial[lane] - value;
    if (value > 0u) activeTiles[atomicAdd(counters[COUNTER_ACTIVE_TILES], 1u)] = i;
    if (params.rasterChunk != 0u && value > 0u) atomicMax(counters[COUNTER_MAX_BIN], value);
    if (lane == uint(SCAN_GROUP_SIZE) - 1u) scanSums[gl_WorkGroupID.x] = partial[lane];
}
