// renderer_internal.h - what RenderSession's files share: the frame's state from step to step and a few
// sizes. Private to host/render/ (renderer.cpp: the session and its frames; frame_params.cpp: a frame's
// parameters and the checks before it; frame_readback.cpp: timings, statistics and images back).
#ifndef RASTER_RENDERER_INTERNAL_H
#define RASTER_RENDERER_INTERNAL_H

#include <cstdint>
#include <vector>

#include "render/renderer.h"
#include "settings/render_settings.h"

namespace sr {

inline uint32_t groupsFor(uint64_t threads, uint32_t groupSize)
{
    return uint32_t((threads + groupSize - 1) / groupSize);
}

// Screen tiles per row and per column for a width x height framebuffer (RasterParams.tilesX, tilesY).
inline glm::uvec2 tileGrid(uint32_t width, uint32_t height)
{
    return {(width + TILE_SIZE - 1) / TILE_SIZE, (height + TILE_SIZE - 1) / TILE_SIZE};
}

// No vertex shared on average: as many vertices as triangle corners.
inline bool transformsInSetup(const Scene& scene)
{
    return scene.vertexCount() >= scene.indices.size();
}

inline bool countsHits(const RenderSettings& s)
{
    return s.countHits || s.shadingMode == SHADING_HIT_COUNT;
}

// The state one render() call passes from step to step.
struct RenderSession::FrameState {
    uint64_t pixels = 0;        // output pixels
    uint64_t rasterPixels = 0;  // pixels of the raster grid: output pixels x ssaa^2
    uint64_t samples = 0;       // samples of the raster grid: raster pixels x msaa
    uint64_t tiles = 0;         // screen tiles of the raster grid
    bool tessellating = false;  // RenderSettings::tessellate is not TESS_OFF
    uint32_t clusters = 0;      // clusters the triangles go through (frameClusters); 0: setup
    FrameWork work;             // what the next frame runs
    uint32_t rasterChunk = 0;   // GroupCounts::rasterChunk
    // The last frame drawn: its parameters, its counters, and its tessellation totals (generated
    // vertices, triangles, culled scene triangles, overflow).
    RasterParams params{};
    uint32_t counters[COUNTER_COUNT] = {};
    glm::uvec4 tessTotals = glm::uvec4(0u);
    // The timed runs' GPU times per stage and per frame, and the last timed frame's dispatches in order.
    std::vector<std::vector<double>> stageMs = std::vector<std::vector<double>>(STAGE_COUNT);
    std::vector<double> totalMs;
    std::vector<Dispatch> lastDispatches;
    RenderOutput out;

    // Keeps a timed frame's GPU times: each dispatch's under its stage, and their sum.
    void keepTimes(const std::vector<Dispatch>& dispatches, const std::vector<double>& gpuMs)
    {
        lastDispatches = dispatches;
        double total = 0.0;
        for (size_t i = 0; i < dispatches.size(); ++i) {
            stageMs[dispatches[i].stage].push_back(gpuMs[i]);
            total += gpuMs[i];
        }
        totalMs.push_back(total);
    }
};

}  // namespace sr

#endif  // RASTER_RENDERER_INTERNAL_H
