// vertex.comp - stage `vertex`: world-space vertex position to clip space, for setup.
// One thread per vertex; groups = ceil(vertexCount / GROUP_SIZE).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(local_size_x = GROUP_SIZE) in;

void main()
{
    uint v = gl_GlobalInvocationID.x;
    if (v < params.vertexCount) clipPos[v] = mulPoint(params.clipFromWorld, positions[v]);
}
