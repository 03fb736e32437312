// scan_add.cuh - stage `scan_add`: adds each block's offset, turning bigOffsets into global exclusive
// offsets. Same grid as scan_blocks.
namespace sr {

__device__ inline void scanAddStage(const RasterParams&, const Buffers& b)
{
    uint i = globalThreadId();
    if (i < b.counters[COUNTER_BIG]) b.bigOffsets[i] += b.scanSums[blockIdx.x];
}

}  // namespace sr
