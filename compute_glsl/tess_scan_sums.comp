// tess_scan_sums.comp - stage `tess_scan_sums`: exclusive scan of the blocks' totals in tessSums[1..], in
// place (each block's first vertex and triangle), and the frame's totals into tessSums[0], the one
// entry the host reads: generated vertices, generated triangles, culled scene triangles, and 1 in .w
// when a total passed 2^31 (the host reports it instead of letting offsets wrap). One group of SCAN_GROUP_SIZE threads.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "tess_buffers.glsl"
#include "scan.glsl"

layout(local_size_x = SCAN_GROUP_SIZE) in;

// Running exclusive scan of one component: returns this lane's base and adds the chunk to carry.
uint scanChunk(uint lane, uint value, inout uint64_t carry)
{
    partial[lane] = value;
    barrier();
    blockInclusiveScan(lane);
    uint base = uint(carry) + partial[lane] - value;
    carry += uint64_t(partial[SCAN_GROUP_SIZE - 1]);
    barrier();
    return base;
}

void main()
{
    uint lane = gl_LocalInvocationID.x;
    uint blocks = params.tessBlocks;
    uint64_t vertices = 0ul, triangles = 0ul, culled = 0ul;  // every thread keeps the same running totals
    for (uint base = 0u; base < blocks; base += uint(SCAN_GROUP_SIZE)) {
        uint i = base + lane;
        uvec4 sums = i < blocks ? tessSums[i + 1u] : uvec4(0u);
        uvec4 bases = uvec4(0u);
        bases.x = scanChunk(lane, sums.x, vertices);
        bases.y = scanChunk(lane, sums.y, triangles);
        bases.z = scanChunk(lane, sums.z, culled);
        if (i < blocks) tessSums[i + 1u] = bases;
    }
    if (lane == 0u) {
        bool overflow = vertices >= (uint64_t(1) << 31) || triangles >= (uint64_t(1) << 31);
        tessSums[0] = uvec4(overflow ? 0u : uint(vertices), overflow ? 0u : uint(triangles), uint(culled),
                                 overflow ? 1u : 0u);
    }
}
