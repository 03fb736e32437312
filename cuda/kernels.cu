// kernels.cu - the thin __global__ shells around the stage functions of cuda/<stage>.cuh, one per
// stage, each taking the frame parameters and the buffer table by value (kernel parameter space).
#include "kernels.h"

#include <type_traits>

#include "bin.cuh"
#include "bin_count.cuh"
#include "bin_fill.cuh"
#include "clear.cuh"
#include "raster_tiles.cuh"
#include "scan.cuh"
#include "scan_blocks.cuh"
#include "scan_sums.cuh"
#include "setup.cuh"
#include "shade.cuh"
#include "vertex.cuh"

namespace sr {

__global__ void __launch_bounds__(GROUP_SIZE) clearKernel(const RasterParams params, const Buffers b)
{
    clearStage(params, b);
}
__global__ void __launch_bounds__(GROUP_SIZE) vertexKernel(const RasterParams params, const Buffers b)
{
    vertexStage(params, b);
}
// setup and raster_tiles come in two builds: with the alpha test of MASK materials, launched when the
// scene has MASK triangles (Dispatch::alphaTest), and without, so that the test's code (surface,
// material and texture lookups) costs every other scene neither registers nor instructions. setup also
// has a build with MSAA's per-sample loop and one without, and one with the line and point paths and one
// without, for the same reason.
template <bool kMaterials, bool kMultisample, bool kLinesPoints>
__global__ void __launch_bounds__(GROUP_SIZE) setupKernel(const RasterParams params, const Buffers b)
{
    setupStage<kMaterials, kMultisample, kLinesPoints>(params, b);
}
__global__ void __launch_bounds__(GROUP_SIZE) binCountKernel(const RasterParams params, const Buffers b)
{
    binCountStage(params, b);
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
__global__ void __launch_bounds__(GROUP_SIZE) binFillKernel(const RasterParams params, const Buffers b)
{
    binFillStage(params, b);
}
// raster_tiles and shade also come in one build per sample count (RasterParams.sampleCount), which
// sizes each thread's array of visibility keys or ids at compile time so that they stay in registers;
// shade's one-sample build without the resolve (kResolve) runs frames without MSAA and SSAA.
template <bool kMaterials, uint kSamples>
__global__ void __launch_bounds__(TILE_SIZE* TILE_SIZE)
    rasterTilesKernel(const RasterParams params, const Buffers b)
{
    rasterTilesStage<kMaterials, kSamples>(params, b);
}

template <uint kSamples, bool kResolve>
__global__ void __launch_bounds__(GROUP_SIZE) shadeKernel(const RasterParams params, const Buffers b)
{
    shadeStage<kSamples, kResolve>(params, b);
}

// Calls launch(std::integral_constant<uint, S>{}) with S the frame's sample count: the builds of
// raster_tiles and shade for it.
template <typename Launch>
void forSampleCount(uint samples, Launch launch)
{
    switch (samples) {
    case 2: launch(std::integral_constant<uint, 2>{}); break;
    case 4: launch(std::integral_constant<uint, 4>{}); break;
    case 8: launch(std::integral_constant<uint, 8>{}); break;
    case 16: launch(std::integral_constant<uint, 16>{}); break;
    default: launch(std::integral_constant<uint, 1>{}); break;
    }
}

// Calls launch(std::integral_constant<bool, B>{}) with B = value: a build chosen by a run-time flag.
template <typename Launch>
void forBool(bool value, Launch launch)
{
    if (value)
        launch(std::true_type{});
    else
        launch(std::false_type{});
}

uint stageBlockSize(uint stage)
{
    switch (stage) {
    case STAGE_SCAN_BLOCKS:
    case STAGE_SCAN_SUMS: return SCAN_GROUP_SIZE;
    case STAGE_RASTER_TILES: return TILE_SIZE * TILE_SIZE;
    default: return GROUP_SIZE;
    }
}

cudaError_t launchStage(uint stage, uint blocks, bool alphaTest, const RasterParams& params,
                        const Buffers& buffers, cudaStream_t stream)
{
    if (blocks == 0) return cudaSuccess;
    uint threads = stageBlockSize(stage);
    switch (stage) {
    case STAGE_CLEAR: clearKernel<<<blocks, threads, 0, stream>>>(params, buffers); break;
    case STAGE_VERTEX: vertexKernel<<<blocks, threads, 0, stream>>>(params, buffers); break;
    case STAGE_SETUP:
        forBool(alphaTest, [&](auto materials) {
            forBool(params.sampleCount > 1u, [&](auto multisample) {
                forBool(params.lineCount + params.pointCount > 0u, [&](auto linesPoints) {
                    setupKernel<materials.value, multisample.value, linesPoints.value>
                        <<<blocks, threads, 0, stream>>>(params, buffers);
                });
            });
        });
        break;
    case STAGE_BIN_COUNT: binCountKernel<<<blocks, threads, 0, stream>>>(params, buffers); break;
    case STAGE_SCAN_BLOCKS: scanBlocksKernel<<<blocks, threads, 0, stream>>>(params, buffers); break;
    case STAGE_SCAN_SUMS: scanSumsKernel<<<blocks, threads, 0, stream>>>(params, buffers); break;
    case STAGE_BIN_FILL: binFillKernel<<<blocks, threads, 0, stream>>>(params, buffers); break;
    case STAGE_RASTER_TILES:
        forSampleCount(params.sampleCount, [&](auto samples) {
            if (alphaTest)
                rasterTilesKernel<true, decltype(samples)::value>
                    <<<blocks, threads, 0, stream>>>(params, buffers);
            else
                rasterTilesKernel<false, decltype(samples)::value>
                    <<<blocks, threads, 0, stream>>>(params, buffers);
        });
        break;
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
