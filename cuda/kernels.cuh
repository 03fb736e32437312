// kernels.cuh - the builds of the stages a raster method changes (setup, bin_count, bin_fill,
// raster_tiles), as thin __global__ shells, and their launch for one method (kMethod, RASTER_*).
// kernels.cu instantiates it for fixed8, kernels_<method>.cu for each other method: one translation unit
// per method, so that they compile in parallel.
#ifndef RASTER_CUDA_KERNELS_CUH
#define RASTER_CUDA_KERNELS_CUH

#include <type_traits>

#include "kernels.h"
// The stage files rely on kernels.h's buffers.cuh and raster_shared.h.
#include "bin.cuh"
#include "bin_count.cuh"
#include "bin_fill.cuh"
#include "raster_tiles.cuh"
#include "setup.cuh"
#include "clusters.cuh"

namespace sr {

// setup, clusters and raster_tiles come in two builds: with the alpha test of MASK materials, launched when
// the scene has MASK triangles (Dispatch::alphaTest), and without, so that the test's code (surface, material
// and texture lookups) costs every other scene neither registers nor instructions. setup also has a build
// with MSAA's per-sample loop and one without, and one with the line and point paths and one without, for the
// same reason.
template <bool kMaterials, bool kMultisample, bool kLinesPoints, uint kMethod>
__global__ void __launch_bounds__(GROUP_SIZE) setupKernel(const RasterParams params, const Buffers b)
{
    setupPrimitive<kMaterials, kMultisample, kLinesPoints, kMethod>(params, b);
}
// clusters has setup's triangle builds: with and without the alpha test, with and without MSAA. The plain
// fixed8 build is held to 8 blocks a SM (64 registers and 50% occupancy instead of 80 and 37.5%, 144
// bytes spilled): with clusters' two passes that ran the 10.2M and 100M spheres 4% and 6% faster on the
// H200 than 72 registers, which ran them 6-7% faster than 80 (with one pass both caps were slower:
// docs/benchmark.md, "Seventh pass"). 0 leaves the other builds to ptxas as before.
template <bool kMaterials, bool kMultisample, uint kMethod>
__global__ void __launch_bounds__(CLUSTER_LANES* CLUSTERS_PER_GROUP,
                                  (!kMaterials && !kMultisample && kMethod == RASTER_FIXED8) ? 8 : 0)
    clustersKernel(const RasterParams params, const Buffers b)
{
    clustersStage<kMaterials, kMultisample, kMethod>(params, b);
}
template <uint kMethod>
__global__ void __launch_bounds__(GROUP_SIZE) binCountKernel(const RasterParams params, const Buffers b)
{
    binCountStage<kMethod>(params, b);
}
template <uint kMethod>
__global__ void __launch_bounds__(GROUP_SIZE) binFillKernel(const RasterParams params, const Buffers b)
{
    binFillStage<kMethod>(params, b);
}
// raster_tiles also comes in one build per sample count (RasterParams.sampleCount), which sizes each
// thread's array of visibility keys at compile time so that they stay in registers.
template <bool kMaterials, uint kSamples, uint kMethod>
__global__ void __launch_bounds__(TILE_SIZE* TILE_SIZE)
    rasterTilesKernel(const RasterParams params, const Buffers b)
{
    rasterTilesStage<kMaterials, kSamples, kMethod>(params, b);
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

template <uint kMethod>
cudaError_t launchMethodStage(uint stage, uint blocks, bool alphaTest, const RasterParams& params,
                              const Buffers& buffers, cudaStream_t stream)
{
    uint threads = stageGroupSize(stage);
    switch (stage) {
    case STAGE_SETUP:
        forBool(alphaTest, [&](auto materials) {
            forBool(params.sampleCount > 1u, [&](auto multisample) {
                forBool(params.lineCount + params.pointCount > 0u, [&](auto linesPoints) {
                    setupKernel<materials.value, multisample.value, linesPoints.value, kMethod>
                        <<<blocks, threads, 0, stream>>>(params, buffers);
                });
            });
        });
        break;
    case STAGE_CLUSTERS:
        forBool(alphaTest, [&](auto materials) {
            forBool(params.sampleCount > 1u, [&](auto multisample) {
                clustersKernel<materials.value, multisample.value, kMethod>
                    <<<blocks, threads, 0, stream>>>(params, buffers);
            });
        });
        break;
    case STAGE_BIN_COUNT: binCountKernel<kMethod><<<blocks, threads, 0, stream>>>(params, buffers); break;
    case STAGE_BIN_FILL: binFillKernel<kMethod><<<blocks, threads, 0, stream>>>(params, buffers); break;
    case STAGE_RASTER_TILES:
        forSampleCount(params.sampleCount, [&](auto samples) {
            forBool(alphaTest, [&](auto materials) {
                rasterTilesKernel<materials.value, decltype(samples)::value, kMethod>
                    <<<blocks, threads, 0, stream>>>(params, buffers);
            });
        });
        break;
    default: return cudaErrorInvalidValue;
    }
    return cudaGetLastError();
}

}  // namespace sr

#endif  // RASTER_CUDA_KERNELS_CUH
