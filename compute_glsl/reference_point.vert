// reference_point.vert - vertex stage of the `vulkan-graphics` point draw (host/vulkan/vulkan_graphics.cpp):
// one non-indexed POINT_LIST draw of every point, so gl_VertexIndex is the point's index k and the
// fragment stage's gl_PrimitiveID is k too. The vertex is fetched through BUF_POINTS and transformed by
// mulPoint, as the compute setup stage transforms it, so both backends start from bit-identical clip
// coordinates. The side is params.pointSize raster pixels; the host has checked that the device draws
// that size exactly (pointSizeRange, pointSizeGranularity, largePoints).
// A point whose vertex lies outside the view volume is discarded whole (Vulkan's
// VK_POINT_CLIPPING_BEHAVIOR_ALL_CLIP_PLANES, pointInViewVolume). Devices need not do that themselves:
// lavapipe (Mesa 22.3) reports ALL_CLIP_PLANES yet draws the part of a point beyond the left, right, top
// or bottom plane that reaches into the viewport (tests/points_graphics_test.cpp), and a
// USER_CLIP_PLANES_ONLY device may too. So the shader applies the test and moves a failing point so far
// beyond the top-left corner that no sample of its square lies in the viewport: it is then outside the
// view volume and clear of the viewport, whichever the device looks at.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

void main()
{
    // A dropped point (kDroppedVertex, host/scene/scene.h) has no position: it goes where a point
    // outside the view volume goes, as the compute setup counts it invalid.
    uint v = points[gl_VertexIndex];
    bool dropped = v >= params.vertexCount;
    vec4 c = dropped ? vec4(0.0f) : mulPoint(params.clipFromWorld, positions[v]);
    bool inside = !dropped && pointInViewVolume(c);
    // pointSize + 2 pixels beyond the edge: half a side and then more than a pixel of margin.
    vec2 pixelsPerNdc = 0.5f * vec2(float(params.width), float(params.height));
    vec2 away = vec2(-1.0f) - (params.pointSize + 2.0f) / pixelsPerNdc;
    gl_Position = inside ? c : vec4(away, 0.5f, 1.0f);
    gl_PointSize = params.pointSize;
}
