// tess_scan_sums.cuh - stage `tess_scan_sums`: exclusive scan of the blocks' totals in tessSums[1..], in
// place (each block's first vertex and triangle), and the frame's totals into tessSums[0], the one
// entry the host reads: generated vertices, generated triangles, culled scene triangles, and 1 in .w
// when a total passed 2^31 (the host reports it instead of letting offsets wrap). One block of SCAN_GROUP_SIZE threads.
namespace sr {

// Running exclusive scan of one component: returns this lane's base and adds the chunk to carry.
__device__ inline uint scanChunk(uint* partial, uint lane, uint value, uint64_t& carry)
{
    partial[lane] = value;
    __syncthreads();
    blockInclusiveScan(partial, lane);
    uint base = uint(carry) + partial[lane] - value;
    carry += uint64_t(partial[SCAN_GROUP_SIZE - 1]);
    __syncthreads();
    return base;
}

__device__ inline void tessScanSumsStage(const RasterParams& params, const Buffers& b)
{
    __shared__ uint partial[SCAN_GROUP_SIZE];
    uint lane = threadIdx.x;
    uint blocks = params.tessBlocks;
    uint64_t vertices = 0u, triangles = 0u, culled = 0u;  // every thread keeps the same running totals
    for (uint base = 0u; base < blocks; base += uint(SCAN_GROUP_SIZE)) {
        uint i = base + lane;
        uvec4 sums = i < blocks ? b.tessSums[i + 1u] : uvec4(0u);
        uvec4 bases = uvec4(0u);
        bases.x = scanChunk(partial, lane, sums.x, vertices);
        bases.y = scanChunk(partial, lane, sums.y, triangles);
        bases.z = scanChunk(partial, lane, sums.z, culled);
        if (i < blocks) b.tessSums[i + 1u] = bases;
    }
    if (lane == 0u) {
        bool overflow = vertices >= (uint64_t(1) << 31) || triangles >= (uint64_t(1) << 31);
        b.tessSums[0] = uvec4(overflow ? 0u : uint(vertices), overflow ? 0u : uint(triangles), uint(culled),
                              overflow ? 1u : 0u);
    }
}

}  // namespace sr
