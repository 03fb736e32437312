// reference_line.vert - vertex stage of the `vulkan-graphics` line draw (host/vulkan/vulkan_graphics.cpp):
// one non-indexed LINE_LIST draw of 2 * lineCount vertices, so gl_VertexIndex 2k and 2k + 1 are the two
// ends of segment k and the fragment stage's gl_PrimitiveID is k. Each end is fetched through BUF_LINES
// and transformed by mulPoint, as the compute setup stage transforms it, so both backends start from
// bit-identical clip coordinates.
// vT is the parameter along the segment (0 at its first vertex, 1 at its second), interpolated by the
// hardware perspective-correct, as Vulkan interpolates line attributes (the sample projected onto the
// segment); lineBaseColor mixes the vertex colours with it.
// The depth bias b (params.lineDepthBias) draws window depth z = zc / w as z - b (1 - z). That is
// affine in z, so applying it to the vertices gives the same screen-linear depth along the segment as
// applying it per fragment; in clip terms it is zc - b (w - zc). It moves the near plane along with the
// depth: the hardware clips where the biased depth reaches 0, at unbiased z = b / (1 + b), while the far
// plane stays at z = 1.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(location = 0) smooth out float vT;

void main()
{
    vT = float(gl_VertexIndex & 1);
    uint v = lines[gl_VertexIndex];
    if (v >= params.vertexCount) {
        // A dropped segment (both ends kDroppedVertex, host/scene/scene.h): both ends at one point
        // outside the view volume (x < -w), where clipping removes it whole, as the compute setup
        // counts it invalid.
        gl_Position = vec4(-2.0f, -2.0f, 0.5f, 1.0f);
        return;
    }
    vec4 c = mulPoint(params.clipFromWorld, positions[v]);
    if (params.lineDepthBias != 0.0f) c.z -= params.lineDepthBias * (c.w - c.z);
    gl_Position = c;
}
