// scan.glsl - the workgroup scan shared by scan_blocks and scan_sums (cuda/scan_blocks.cuh has the
// CUDA twin, blockInclusiveScan).
#ifndef RASTER_SCAN_GLSL
#define RASTER_SCAN_GLSL

shared uint partial[SCAN_GROUP_SIZE];

// Hillis-Steele inclusive scan of `partial` (one entry per invocation of the group): after the step
// with offset d each entry sums its last 2d inputs.
void blockInclusiveScan(uint lane)
{
    for (uint d = 1u; d < uint(SCAN_GROUP_SIZE); d <<= 1u) {
        uint add = lane >= d ? partial[lane - d] : 0u;
        barrier();
        partial[lane] += add;
        barrier();
    }
}

#endif  // RASTER_SCAN_GLSL
