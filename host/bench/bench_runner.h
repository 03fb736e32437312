// bench_runner.h - `raster bench`: the scene suite on several backends of one machine, in one run.
//
// Scenes: a triangle-size sweep (about 1M triangles of 0.5, 2, 8, 32 and 128 px area each, scattered at
// random depths), as many 1-px points (`points-1m`) and 8-px, 1-px wide line segments in random
// directions (`lines-1m`; the triangle columns count primitives), 16
// overlapping full-screen layers in random depth order, the Stanford bunny, a dense
// tessellated sphere and the built-in scene; then textured scenes next to untextured twins: a
// full-screen grazing checkerboard plane per texture filter and a textured sphere of about 1M triangles.
// Every (scene, resolution, sample count) is run on every backend back to back, so their ratios come from the
// same machine in the same minute. Reported per run: min/median/max of each stage's GPU time over the timed
// repeats, total GPU ms, visibility ms (the frame less deferred shading; for vulkan-graphics its depth + id
// pass, the hardware baseline), frame ms (the whole shaded frame: the compute backends' total, and for
// vulkan-graphics a second run that shades in its fragment shader, so that both sides shade alike),
// triangles/s, pixels/s, peak and working device memory (peak less the scene's own buffers) against
// 40 B/triangle + 8 B/pixel + 8 B/sample. `--warmup-ms` warms each run's GPU up by time first.
#ifndef RASTER_BENCH_RUNNER_H
#define RASTER_BENCH_RUNNER_H

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "render/renderer.h"
#include "base/result.h"

namespace sr {

struct BenchOptions {
    std::vector<std::string> backends{"cuda", "vulkan", "vulkan-graphics"};
    std::vector<std::pair<uint32_t, uint32_t>> resolutions{{1920, 1080}};
    std::vector<std::string> scenes;                // empty: all
    std::vector<uint32_t> msaa{1};                  // sample counts, each a run of every scene and backend
    std::vector<uint32_t> clusters{CLUSTERS_AUTO};  // CLUSTERS_* modes, each a run of every scene and backend
    // Level of detail: 0 for --lod off, else a --lod-error-px value; each a run of every scene on the
    // compute backends (the runs with level of detail share one session per scene and backend, so the
    // hierarchy is built once; vulkan-graphics runs --lod off alone).
    std::vector<float> lod{0.0f};
    // Ambient occlusion (AO_OFF, AO_GTAO), each a run of every scene; a run's "ao_ms" is its AO stages'
    // GPU time (ao_gbuffer + ao + ao_denoise).
    std::vector<uint32_t> ao{AO_OFF};
    uint32_t sweepTriangles = 1u << 20;  // per sweep scene
    int denseRings = 1600;               // tessellated sphere: ~4 rings^2 triangles (10.2M)
    std::string bunnyPath = "/usr/share/glmark2/models/bunny.obj";
    uint32_t warmup = 3;
    uint32_t repeat = 20;
    // Before each run's frames (its `warmup` and `repeat`), untimed frames of the same session: a first one
    // (the scene's upload), then more until this much wall time has passed after it, so that a GPU that
    // idled through the scene's generation and upload has its clock up again when the timed frames start
    // (a few warm-up frames of a tenth of a millisecond may not be enough); 0: none. Each run reports the
    // frames, the first one's time and the time after it ("prewarm_frames", "prewarm_first_ms",
    // "prewarm_ms").
    double warmupMs = 0.0;
    int device = -1;
};

// Runs the suite; returns one JSON object per (scene, resolution, backend) run under "runs", plus the
// machine description. Progress goes to stderr when it is a terminal.
Result<nlohmann::json> runBench(const BenchOptions& options);

// The markdown table printed at the end of a bench (one row per run).
std::string benchMarkdown(const nlohmann::json& bench);

}  // namespace sr

#endif  // RASTER_BENCH_RUNNER_H
