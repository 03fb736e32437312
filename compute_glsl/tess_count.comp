// tess_count.comp - stage `tess_count`: per scene triangle, cull it or choose its edge factors, and
// count the vertices and triangles it will generate (shared/tessellate.h, tessCountTriangle).
// One thread per scene triangle; groups = ceil(tessSourceTriangles / GROUP_SIZE).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "tess_buffers.glsl"

layout(local_size_x = GROUP_SIZE) in;

void main()
{
    uint tri = gl_GlobalInvocationID.x;
    if (tri >= params.tessSourceTriangles) return;
    tessCounts[tri] = tessCountTriangle(params, loadTessPatch(tessSource[tri]));
}
