// kernels.cu - the thin __global__ shells around the stage functions of cuda/<stage>.cuh, one per
// stage, each taking the frame parameters and the buffer table by value (kernel parameter space); those
// of the stages a raster method changes are in kernels.cuh.
#include "kernels.cuh"
#include "clear.cuh"
#include "scan.cuh"
#include "scan_blocks.cuh"
#include "scan_sums.cuh"
#include "shade.cuh"
#include "tess_count.cuh"
#include "tess_emit.cuh"
#include "tess_scan_blocks.cuh"
#include "tess_scan_sums.cuh"
#include "vertex.cuh"

namespace sr {

// The other methods' builds, each in its own translation unit (kernels_<method>.cu).
extern template cudaError_t launchMethodStage<RASTER_FIXED4>(uint, uint, bool, const RasterParams&,
                                                             const Buffers&, cudaStream_t);
extern template cudaError_t launchMethodStage<RASTER_FLOAT>(uint, uint, bool, const RasterParams&,
                                                            const Buffers&, cudaStream_t);
extern template cudaError_t launchMethodStage<RASTER_SCANLINE>(uint, uint, bool, const RasterParams&,
                                                               const Buffers&, cudaStream_t);

__global__ void __launch_bounds__(GROUP_SIZE) clearKernel(const RasterParams params, const Buffers b)
{
    clearStage(params, b);
}
__global__ void __launch_bounds__(GROUP_SIZE) vertexKernel(const RasterParams params, const Buffers b)
{
    vertexStage(params, b);
}
__global__ void __launch_bounds__(SCAN_GROUP_SIZE)
    scanBlocksKernel(const RasterParams params, const Buffers b)
{
    scanBlocksStage(params, b);
}
__global__ void __launch_bounds__(SCAN_GROUP_SIZE) scanSumsKernel(const RasterParams params, const Buffers b)
{
    scanSumsStage(params, b);
}
__global__ void __launch_bounds__(GROUP_SIZE) tessCountKernel(const RasterParams params, const Buffers b)
{
    tessCountStage(params, b);
}
__global__ void __launch_bounds__(SCAN_GROUP_SIZE)
    tessScanBlocksKernel(const RasterParams params, const Buffers b)
{
    tessScanBlocksStage(params, b);
}
__global__ void __launch_bounds__(SCAN_GROUP_SIZE)
    tessScanSumsKernel(const RasterParams params, const Buffers b)
{
    tessScanSumsStage(params, b);
}
__global__ void __launch_bounds__(GROUP_SIZE) tessEmitKernel(const RasterParams params, const Buffers b)
{
    tessEmitStage(params, b);
}
// shade comes in one build per sample count (RasterParams.sampleCount), which sizes each thread's array
// of ids at compile time so that they stay in registers; its one-sample build without the resolve
// (kResolve) runs frames without MSAA and SSAA.
template <uint kSamples, bool kResolve>
__global__ void __launch_bounds__(GROUP_SIZE) shadeKernel(const RasterParams params, const Buffers b)
{
    shadeStage<kSamples, kResolve>(params, b);
}

uint stageBlockSize(uint stage)
{
    switch (stage) {
    case STAGE_SCAN_BLOCKS:
    case STAGE_SCAN_SUMS:
    case STAGE_TESS_SCAN_BLOCKS:
    case STAGE_TESS_SCAN_SUMS: return SCAN_GROUP_SIZE;
    case STAGE_RASTER_TILES: return TILE_SIZE * TILE_SIZE;
    default: return GROUP_SIZE;
    }
}

cudaError_t launchStage(uint stage, uint blocks, bool alphaTest, uint rasterMethod,
                        const RasterParams& params, const Buffers& buffers, cudaStream_t stream)
{
    if (blocks == 0) return cudaSuccess;
    uint threads = stageBlockSize(stage);
    switch (stage) {
    case STAGE_CLEAR: clearKernel<<<blocks, threads, 0, stream>>>(params, buffers); break;
    case STAGE_VERTEX: vertexKernel<<<blocks, threads, 0, stream>>>(params, buffers); break;
    case STAGE_SETUP:
    case STAGE_BIN_COUNT:
    case STAGE_BIN_FILL:
    case STAGE_RASTER_TILES:
        switch (rasterMethod) {
        case RASTER_FIXED8:
            return launchMethodStage<RASTER_FIXED8>(stage, blocks, alphaTest, params, buffers, stream);
        case RASTER_FIXED4:
            return launchMethodStage<RASTER_FIXED4>(stage, blocks, alphaTest, params, buffers, stream);
        case RASTER_FLOAT:
            return launchMethodStage<RASTER_FLOAT>(stage, blocks, alphaTest, params, buffers, stream);
        case RASTER_SCANLINE:
            return launchMethodStage<RASTER_SCANLINE>(stage, blocks, alphaTest, params, buffers, stream);
        default: return cudaErrorInvalidValue;
        }
    case STAGE_SCAN_BLOCKS: scanBlocksKernel<<<blocks, threads, 0, stream>>>(params, buffers); break;
    case STAGE_SCAN_SUMS: scanSumsKernel<<<blocks, threads, 0, stream>>>(params, buffers); break;
    case STAGE_TESS_COUNT: tessCountKernel<<<blocks, threads, 0, stream>>>(params, buffers); break;
    case STAGE_TESS_SCAN_BLOCKS: tessScanBlocksKernel<<<blocks, threads, 0, stream>>>(params, buffers); break;
    case STAGE_TESS_SCAN_SUMS: tessScanSumsKernel<<<blocks, threads, 0, stream>>>(params, buffers); break;
    case STAGE_TESS_EMIT: tessEmitKernel<<<blocks, threads, 0, stream>>>(params, buffers); break;
    case STAGE_SHADE:
        if (params.sampleCount == 1u && params.ssaa == 1u)
            shadeKernel<1, false><<<blocks, threads, 0, stream>>>(params, buffers);
        else
            forSampleCount(params.sampleCount, [&](auto samples) {
                shadeKernel<decltype(samples)::value, true><<<blocks, threads, 0, stream>>>(params, buffers);
            });
        break;
    default: return cudaErrorInvalidValue;
    }
    return cudaGetLastError();
}

}  // namespace sr
