// vertex.comp - stage `vertex`: world-space vertex to clip position, view position and view normal.
// One thread per vertex; groups = ceil(vertexCount / GROUP_SIZE).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(local_size_x = GROUP_SIZE) in;

void main()
{
    uint v = gl_GlobalInvocationID.x;
    if (v >= params.vertexCount) return;
    vec4 clip, eyePos, eyeNormal;
    transformVertex(params, positions[v], normals[v], clip, eyePos, eyeNormal);
    clipPos[v] = clip;
    viewPos[v] = eyePos;
    viewNormal[v] = eyeNormal;
}
