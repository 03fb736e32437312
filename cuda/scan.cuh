// scan.cuh - the block scan shared by scan_blocks and scan_sums (compute_glsl/scan.glsl has the GLSL
// twin).
namespace sr {

// Hillis-Steele inclusive scan of `partial` (one entry per thread of the block): after the step with
// offset d each entry sums its last 2d inputs.
__device__ inline void blockInclusiveScan(uint* partial, uint lane)
{
    for (uint d = 1u; d < uint(SCAN_GROUP_SIZE); d <<= 1u) {
        uint add = lane >= d ? partial[lane - d] : 0u;
        __syncthreads();
        partial[lane] += add;
        __syncthreads();
    }
}

}  // namespace sr
