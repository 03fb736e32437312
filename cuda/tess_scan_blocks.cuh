// tess_scan_blocks.cuh - stage `tess_scan_blocks`: per block of SCAN_GROUP_SIZE scene triangles, the
// exclusive scans of their generated vertex and triangle counts (written back in place as offsets within
// the block) and the block's totals, with its culled triangles, into tessSums[block + 1]. One thread per
// triangle.
namespace sr {

// Exclusive scan of one value per lane of the block through `partial`; `total` receives the block's sum.
__device__ inline uint exclusiveScan(uint* partial, uint lane, uint value, uint& total)
{
    partial[lane] = value;
    __syncthreads();
    blockInclusiveScan(partial, lane);
    uint before = partial[lane] - value;
    total = partial[SCAN_GROUP_SIZE - 1];
    __syncthreads();
    return before;
}

__device__ inline void tessScanBlocksStage(const RasterParams& params, const Buffers& b)
{
    __shared__ uint partial[SCAN_GROUP_SIZE];
    uint lane = threadIdx.x;
    uint tri = blockIdx.x * uint(SCAN_GROUP_SIZE) + lane;
    bool inside = tri < params.tessSourceTriangles;
    uvec4 entry = inside ? b.tessCounts[tri] : uvec4(0u);
    uvec4 totals = uvec4(0u);
    uint vertices = exclusiveScan(partial, lane, entry.x, totals.x);
    uint triangles = exclusiveScan(partial, lane, entry.y, totals.y);
    exclusiveScan(partial, lane, (entry.w & TESS_STATE_CULLED) != 0u ? 1u : 0u, totals.z);
    if (inside) b.tessCounts[tri] = uvec4(vertices, triangles, entry.z, entry.w);
    if (lane == 0u) b.tessSums[blockIdx.x + 1u] = totals;
}

}  // namespace sr
