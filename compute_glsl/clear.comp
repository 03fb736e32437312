// clear.comp - stage `clear`: every pixel's visibility key to empty (~0) (and hit count to 0 when
// counting), every counter and every screen tile's bin count to 0.
// One thread per pixel; groups = ceil(width * height / GROUP_SIZE).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(local_size_x = GROUP_SIZE) in;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i < uint(COUNTER_COUNT)) counters[i] = 0u;
    if (i < params.tilesX * params.tilesY) tileBins[i] = 0u;
    if (i >= params.width * params.height) return;
    visibility[i] = ~uint64_t(0);
    if ((params.debugFlags & DEBUG_COUNT_HITS) != 0u) hitCount[i] = 0u;
}
