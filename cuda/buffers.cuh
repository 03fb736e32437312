// buffers.cuh - the device buffer table as the CUDA stages see it: the BUF_* bindings of
// raster_shared.h with the same names as compute_glsl/buffers.glsl, and mergeFragment, the one place a
// covered pixel is written.
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
    uint* bigTris;                   // BUF_BIG_TRIS
    uint* bigOffsets;                // BUF_BIG_OFFSETS
    uint* scanSums;                  // BUF_SCAN_SUMS
    uint* counters;                  // BUF_COUNTERS
    unsigned long long* visibility;  // BUF_VISIBILITY (CUDA's 64-bit atomics take unsigned long long)
    uint* framebuffer;               // BUF_FRAMEBUFFER
    uint* hitCount;                  // BUF_HIT_COUNT
};

// The depth test and id write of one covered pixel in a single 64-bit atomicMin (see packVisibility),
// plus the debug hit count. Used by setup (small triangles) and raster_tiles.
__device__ inline void mergeFragment(const RasterParams& params, const Buffers& b, uint pixel, float depth,
                                     uint id)
{
    atomicMin(&b.visibility[pixel], packVisibility(depth, id));
    if ((params.debugFlags & DEBUG_COUNT_HITS) != 0u) atomicAdd(&b.hitCount[pixel], 1u);
}

// Thread index in a 1D grid, as gl_GlobalInvocationID.x.
__device__ inline uint globalThreadId()
{
    return blockIdx.x * blockDim.x + threadIdx.x;
}

}  // namespace sr

#endif  // RASTER_CUDA_BUFFERS_CUH
