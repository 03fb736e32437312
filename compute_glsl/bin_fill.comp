// bin_fill.comp - stage `bin_fill`: per piece of a big triangle, write its ref into the bin of every
// screen tile of the piece that the triangle touches, at the slots the scanned counts reserved (the walk
// is in bin.glsl). Afterwards binEnd(tile) is the end of the tile's bin and binEnd(tile - 1) its start.
// One invocation per piece, striding; groups = RasterParams.binGroups.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"
#include "bin.glsl"

layout(local_size_x = GROUP_SIZE) in;

void main()
{
    binPieces(true);
}
