// buffers.cuh - the device buffer table as the CUDA stages see it: the BUF_* bindings of
// raster_shared.h with the same names as compute_glsl/buffers.glsl, mergeFragment (the small-triangle
// write), and the loads of a triangle that several stages share.
#ifndef RASTER_CUDA_BUFFERS_CUH
#define RASTER_CUDA_BUFFERS_CUH

#include "raster_shared.h"

namespace sr {

struct Buffers {
    const vec4* positions;           // BUF_POSITIONS
    const vec4* normals;             // BUF_NORMALS
    const vec4* colors;              // BUF_COLORS
    const uint* indices;             // BUF_INDICES
    const uint* triFlags;            // BUF_TRI_FLAGS
    vec4* clipPos;                   // BUF_CLIP_POS
    TriSetup* setupTris;             // BUF_SETUP_TRIS
    uvec2* pieces;                   // BUF_PIECES
    uint* tileBins;                  // BUF_TILE_BINS
    uint* scanSums;                  // BUF_SCAN_SUMS
    uint* binEntries;                // BUF_BIN_ENTRIES
    uint* activeTiles;               // BUF_ACTIVE_TILES
    uint* counters;                  // BUF_COUNTERS
    unsigned long long* visibility;  // BUF_VISIBILITY (CUDA's 64-bit atomics take unsigned long long)
    uint* framebuffer;               // BUF_FRAMEBUFFER
    uint* hitCount;                  // BUF_HIT_COUNT
};

// The depth test and id write of one covered pixel in a single 64-bit atomicMin (see packVisibility),
// plus the debug hit count. Used by setup for small triangles; raster_tiles owns its pixels and writes
// them plainly.
__device__ inline void mergeFragment(const RasterParams& params, const Buffers& b, uint pixel, float depth,
                                     uint id)
{
    atomicMin(&b.visibility[pixel], packVisibility(depth, id));
    if ((params.debugFlags & DEBUG_COUNT_HITS) != 0u) atomicAdd(&b.hitCount[pixel], 1u);
}

// Clip positions of input triangle `tri`'s vertices, as setup sees them (setupClipPosition). False when
// an index is out of range.
__device__ inline bool loadClipTriangle(const RasterParams& params, const Buffers& b, uint tri, vec4& c0,
                                        vec4& c1, vec4& c2)
{
    uint i0 = b.indices[3u * tri];
    uint i1 = b.indices[3u * tri + 1u];
    uint i2 = b.indices[3u * tri + 2u];
    if (max(i0, max(i1, i2)) >= params.vertexCount) return false;
    bool stored = params.transformInSetup == 0u;
    c0 = setupClipPosition(params, b.positions[i0], stored ? b.clipPos[i0] : vec4(0.0f));
    c1 = setupClipPosition(params, b.positions[i1], stored ? b.clipPos[i1] : vec4(0.0f));
    c2 = setupClipPosition(params, b.positions[i2], stored ? b.clipPos[i2] : vec4(0.0f));
    return true;
}

// The big triangle a bin ref names: a stored record, or an unclipped input triangle set up again from
// the scene exactly as setup did (same function, same bits; setup already culled it, so facing needs
// no second look). False for a ref setup would never have written (a slot of an overflowed frame).
__device__ inline bool loadBinTriangle(const RasterParams& params, const Buffers& b, uint ref, TriSetup& t)
{
    if ((ref & BIN_REF_RECORD) != 0u) {
        if ((ref & ~BIN_REF_RECORD) >= params.setupCapacity) return false;
        t = b.setupTris[ref & ~BIN_REF_RECORD];
        return true;
    }
    if (ref >= params.triangleCount) return false;
    vec4 c0, c1, c2;
    if (!loadClipTriangle(params, b, ref, c0, c1, c2)) return false;
    return setupTriangle(c0, c1, c2, ref, true, CULL_NONE, params.width, params.height, t);
}

// End of screen tile `tile`'s bin in binEntries, once bin_fill has run (its start is the previous tile's
// end): the tile's offset within its scan block, advanced by every slot bin_fill took, plus the block's
// base from scan_sums.
__device__ inline uint binEnd(const Buffers& b, uint tile)
{
    return b.scanSums[tile / uint(SCAN_GROUP_SIZE)] + b.tileBins[tile];
}

// Thread index in a 1D grid, as gl_GlobalInvocationID.x.
__device__ inline uint globalThreadId()
{
    return blockIdx.x * blockDim.x + threadIdx.x;
}

}  // namespace sr

#endif  // RASTER_CUDA_BUFFERS_CUH
