// clear.comp - stage `clear`: every sample's visibility key to empty (~0) (and hit count to 0 when
// counting), every counter and every screen tile's bin count to 0. Each invocation clears CLEAR_SPAN
// elements GROUP_SIZE apart, so every store of a group is contiguous and a frame needs an eighth of
// the groups (launching a group per 128 pixels cost more than the stores).
// groups = ceil(max(samples, tiles, COUNTER_WORDS) / (GROUP_SIZE * CLEAR_SPAN)), samples = samplePlane *
// sampleCount.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(local_size_x = GROUP_SIZE) in;

void main()
{
    uint first = gl_WorkGroupID.x * uint(GROUP_SIZE * CLEAR_SPAN) + gl_LocalInvocationID.x;
    for (uint k = 0u; k < uint(CLEAR_SPAN); ++k) {
        uint i = first + k * uint(GROUP_SIZE);
        if (i < uint(COUNTER_WORDS)) counters[i] = 0u;
        if (i < params.tilesX * params.tilesY) tileBins[i] = 0u;
        // No early return: a frame of fewer samples than COUNTER_WORDS still clears every counter.
        if (i < params.samplePlane * params.sampleCount) {
            visibility[i] = ~uint64_t(0);
            if ((params.debugFlags & DEBUG_COUNT_HITS) != 0u) hitCount[i] = 0u;
        }
    }
}
