// scan_add.comp - stage `scan_add`: adds each block's offset, turning bigOffsets into global exclusive
// offsets. Same grid as scan_blocks.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(local_size_x = SCAN_GROUP_SIZE) in;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i < counters[COUNTER_BIG]) bigOffsets[i] += scanSums[gl_WorkGroupID.x];
}
