// bin_count.comp - stage `bin_count`: per piece of a big triangle, add one to the bin count of every
// screen tile of the piece that the triangle touches, unless setup counted it (the walk is in bin.glsl).
// One invocation per piece, striding; groups = RasterParams.binGroups.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"
#include "bin.glsl"

layout(local_size_x = GROUP_SIZE) in;

void main()
{
    binPieces(false);
}
