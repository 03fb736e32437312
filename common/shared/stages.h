// shared/stages.h - the stage table: every stage of the pipeline, once, one X(...) line each, in id
// order.
//
// Adding a stage = one line here + cuda/<name>.cuh + compute_glsl/<name>.comp + its dispatch in
// host/render/renderer.cpp.
//
// Every other list of the stages is generated from this one: the STAGE_* ids and kStages below;
// stageName() (host/render/compute_device.cpp); the SPIR-V modules, which CMake compiles from the names
// it reads off the X(...) lines (SR_STAGES) and includes in <builddir>/spirv/stage_spirv.h for
// host/vulkan/vulkan_device.cpp's kStageSpirv; the CUDA shells and launches of the PLAIN stages
// (cuda/kernels.cu, with their cuda/<name>.cuh included by CMake's <builddir>/stages/stage_kernels.cuh).
//
// X(ID, name, function, threads, kind):
//   ID        the stage's id is STAGE_<ID>, its row in this table
//   name      its files, cuda/<name>.cuh and compute_glsl/<name>.comp, and its name in timings
//   function  the prefix of its CUDA device function <function>Stage and kernel <function>Kernel
//   threads   threads per group: the CUDA block size and local_size_x of compute_glsl/<name>.comp
//   kind      how CUDA launches it: PLAIN, its one kernel (cuda/kernels.cu generates both); METHOD, the
//             build of the frame's raster method (launchMethodStage, cuda/kernels.cuh); SHADE, shade's
//             builds per sample count (launchShade, cuda/kernels.cu)
// CMake reads the lines that start with `X(` with a regular expression: one stage per line, no line
// break inside it.
//
// Part of raster_shared.h, C++ and CUDA only (included from there, after the constants that the group
// sizes name): no shader names a stage, each compute_glsl/<name>.comp is its stage's whole module.
#ifndef RASTER_SHARED_STAGES_H
#define RASTER_SHARED_STAGES_H

// Stages, in dispatch order. Each is one CUDA kernel (cuda/<name>.cuh) and one compute shader
// (compute_glsl/<name>.comp).
// clang-format off
#define SR_STAGE_TABLE(X)                                                                                 \
    /* visibility := empty, counters and tile bins := 0 */                                                \
    X(CLEAR,            clear,            clear,          GROUP_SIZE,            PLAIN)                   \
    /* per vertex: clip position */                                                                       \
    X(VERTEX,           vertex,           vertex,         GROUP_SIZE,            PLAIN)                   \
    /* per cluster of a level-of-detail hierarchy: list the clusters the cut draws */                    \
    X(LOD_CUT,          lod_cut,          lodCut,         GROUP_SIZE,            PLAIN)                   \
    /* per cluster (a warp each): cull it whole, transform its vertices once, set up its triangles as */ \
    /* setup does */                                                                                      \
    X(CLUSTERS,         clusters,         clusters,       CLUSTER_LANES * CLUSTERS_PER_GROUP, METHOD)     \
    /* per primitive: cull, clip, snap (a line to its rectangle's two triangles); rasterize points and */ \
    /* small triangles, cut big triangles into pieces */                                                  \
    X(SETUP,            setup,            setup,          GROUP_SIZE,            METHOD)                  \
    /* per piece: count the screen tiles its triangle touches, per tile */                                \
    X(BIN_COUNT,        bin_count,        binCount,       GROUP_SIZE,            METHOD)                  \
    /* per 256 screen tiles: local exclusive scan of the bin counts, active tile list */                  \
    X(SCAN_BLOCKS,      scan_blocks,      scanBlocks,     SCAN_GROUP_SIZE,       PLAIN)                   \
    /* one group: exclusive scan of the block totals (each block's base offset) */                        \
    X(SCAN_SUMS,        scan_sums,        scanSums,       SCAN_GROUP_SIZE,       PLAIN)                   \
    /* per piece: write its triangle's ref into the bin of every tile it touches */                       \
    X(BIN_FILL,         bin_fill,         binFill,        GROUP_SIZE,            METHOD)                  \
    /* per active 8x8 screen tile: resolve its bin in registers, no atomics */                            \
    X(RASTER_TILES,     raster_tiles,     rasterTiles,    TILE_SIZE * TILE_SIZE, METHOD)                  \
    /* Ambient occlusion (RasterParams.aoMode == AO_GTAO; shared/ao.h), per raster pixel: */              \
    /* view distance and normal of its nearest sample's surface */                                        \
    X(AO_GBUFFER,       ao_gbuffer,       aoGbuffer,      GROUP_SIZE,            PLAIN)                   \
    /* GTAO: horizons along aoSlices directions, aoSteps samples a side */                                \
    X(AO,               ao,               ao,             GROUP_SIZE,            PLAIN)                   \
    /* depth-aware 5 x 5 filter of the AO (unless --ao-denoise off) */                                    \
    X(AO_DENOISE,       ao_denoise,       aoDenoise,      GROUP_SIZE,            PLAIN)                   \
    /* per pixel: resolve the visibility key and shade */                                                 \
    X(SHADE,            shade,            shade,          GROUP_SIZE,            SHADE)                   \
    /* per output pixel: its AOV sample's id and depth, and its surface or rasterize's output */       \
    X(AOVS,             aovs,             aovs,           GROUP_SIZE,            PLAIN)                   \
    /* Tessellation, before the others (a frame of its own: tess_count and the scans run first, the */    \
    /* host sizes the generated buffers from their totals, then tess_emit runs at the head of the */      \
    /* frame). */                                                                                         \
    /* per scene triangle: cull, edge factors, generated vertex/triangle counts */                        \
    X(TESS_COUNT,       tess_count,       tessCount,      GROUP_SIZE,            PLAIN)                   \
    /* per 256 scene triangles: local exclusive scans of the counts */                                    \
    X(TESS_SCAN_BLOCKS, tess_scan_blocks, tessScanBlocks, SCAN_GROUP_SIZE,       PLAIN)                   \
    /* one group: scan of the block totals, the grand totals */                                           \
    X(TESS_SCAN_SUMS,   tess_scan_sums,   tessScanSums,   SCAN_GROUP_SIZE,       PLAIN)                   \
    /* per scene triangle: write its generated vertices and triangles */                                  \
    X(TESS_EMIT,        tess_emit,        tessEmit,       GROUP_SIZE,            PLAIN)
// clang-format on

namespace sr {

// STAGE_<ID>: the stage's row in the table (Dispatch::stage); STAGE_COUNT: the number of stages.
enum StageId : uint {
#define SR_STAGE_ID(ID, name, function, threads, kind) STAGE_##ID,
    SR_STAGE_TABLE(SR_STAGE_ID)  // STAGE_CLEAR = 0, STAGE_VERTEX = 1, ...: one per row, in order
#undef SR_STAGE_ID
    STAGE_COUNT
};

enum StageKind : uint { STAGE_KIND_PLAIN, STAGE_KIND_METHOD, STAGE_KIND_SHADE };

struct StageInfo {
    const char* name;  // cuda/<name>.cuh, compute_glsl/<name>.comp
    uint groupSize;    // threads per group
    StageKind kind;    // STAGE_KIND_<kind>
};

// The table's rows, indexed by STAGE_*.
constexpr StageInfo kStages[] = {
#define SR_STAGE_INFO(ID, name, function, threads, kind) {#name, threads, STAGE_KIND_##kind},
    SR_STAGE_TABLE(SR_STAGE_INFO)
#undef SR_STAGE_INFO
};
static_assert(sizeof kStages / sizeof kStages[0] == STAGE_COUNT, "one row of kStages per stage");

// Threads per group of `stage`; 0 for an unknown stage.
constexpr uint stageGroupSize(uint stage)
{
    return stage < STAGE_COUNT ? kStages[stage].groupSize : 0u;
}

// Whether the raster method selects `stage`'s build (Dispatch::rasterMethod).
constexpr bool methodStage(uint stage)
{
    return stage < STAGE_COUNT && kStages[stage].kind == STAGE_KIND_METHOD;
}

}  // namespace sr

#endif  // RASTER_SHARED_STAGES_H
