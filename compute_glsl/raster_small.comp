// raster_small.comp - stage `raster_small`: one thread per small triangle tests every pixel centre of
// its bbox (at most SMALL_TRI_SPAN^2) and merges covered pixels with mergeFragment.
// Grid-stride loop over the small list; groups = RasterParams.rasterGroups.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(local_size_x = GROUP_SIZE) in;

void main()
{
    uint count = counters[COUNTER_SMALL];
    uint stride = gl_NumWorkGroups.x * uint(GROUP_SIZE);
    for (uint i = gl_GlobalInvocationID.x; i < count; i += stride) {
        TriSetup t = setupTris[smallTris[i]];
        ivec4 bounds = setupPixelBounds(t, params.width, params.height);
        uint id = setupTriId(t);
        for (int y = bounds.y; y <= bounds.w; ++y) {
            for (int x = bounds.x; x <= bounds.z; ++x) {
                float depth;
                if (rasterPixel(t, x, y, depth))
                    mergeFragment(uint(y) * params.width + uint(x), depth, id);
            }
        }
    }
}
