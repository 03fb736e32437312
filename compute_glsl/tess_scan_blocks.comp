// tess_scan_blocks.comp - stage `tess_scan_blocks`: per block of SCAN_GROUP_SIZE scene triangles, the
// exclusive scans of their generated vertex and triangle counts (written back in place as offsets within
// the block) and the block's totals, with its culled triangles, into tessSums[block + 1]. One thread per triangle.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "tess_buffers.glsl"
#include "scan.glsl"

layout(local_size_x = SCAN_GROUP_SIZE) in;

// Exclusive scan of one value per lane; `total` receives the block's sum.
uint exclusiveScan(uint lane, uint value, out uint total)
{
    partial[lane] = value;
    barrier();
    blockInclusiveScan(lane);
    uint before = partial[lane] - value;
    total = partial[SCAN_GROUP_SIZE - 1];
    barrier();
    return before;
}

void main()
{
    uint lane = gl_LocalInvocationID.x;
    uint tri = gl_WorkGroupID.x * uint(SCAN_GROUP_SIZE) + lane;
    bool inside = tri < params.tessSourceTriangles;
    uvec4 entry = inside ? tessCounts[tri] : uvec4(0u);
    uvec4 totals = uvec4(0u);
    uint vertices = exclusiveScan(lane, entry.x, totals.x);
    uint triangles = exclusiveScan(lane, entry.y, totals.y);
    exclusiveScan(lane, (entry.w & TESS_STATE_CULLED) != 0u ? 1u : 0u, totals.z);
    if (inside) tessCounts[tri] = uvec4(vertices, triangles, entry.z, entry.w);
    if (lane == 0u) tessSums[gl_WorkGroupID.x + 1u] = totals;
}
