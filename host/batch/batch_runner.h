// batch_runner.h - `raster batch MANIFEST`: every job of a JSON Lines manifest (batch/manifest.h) in one
// process, a shard of it (--shard i/N or the Slurm array task), on one or several devices (--devices),
// resumable (batch/outputs.h), with a JSON summary of where the time went.
//
// One worker thread per device renders; each keeps a RenderSession per scene, so a scene is uploaded
// once per device and its buffers are reused by every frame of it. Finished frames go through a bounded
// queue to the I/O threads, which encode the PNG (and EXR, JSON) and write the files while the next
// frames render; the next scene is loaded on a thread of its own while the current one renders.
#ifndef RASTER_BATCH_RUNNER_H
#define RASTER_BATCH_RUNNER_H

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/result.h"
#include "batch/manifest.h"

namespace sr {

struct BatchOptions {
    std::string manifest;
    std::string backend = "auto";  // auto, cuda or vulkan
    std::string devices;           // --devices: "all" or "0,1"; empty: the backend's first device
    std::string shard;             // --shard i/N; empty: the Slurm array task, else every job
    uint32_t ioThreads = 0;        // encoder/writer threads; 0: the cores left over by the workers (>= 1)
    uint32_t queueFrames = 0;      // finished frames waiting for the I/O threads; 0: 2 per I/O thread
    std::string summaryPath;       // --summary FILE: the JSON summary there too
    bool force = false;            // render every job of the shard, done or not
    bool quiet = false;            // no progress line, no summary on stdout
    uint32_t ioDelayMs = 0;        // tests: sleep between writing a PNG's temporary file and its rename
    // Render settings given on the command line (--width etc.), under the manifest's defaults; a batch
    // renders each frame once unless told otherwise (warmup 0).
    nlohmann::json defaults = nlohmann::json{{"warmup", 0}};
};

// One frame to render: a job of the manifest, or frame k of a job's turntable (frames > 0).
struct BatchFrame {
    const ManifestJob* job = nullptr;
    uint32_t frame = 0;
    float azimuthDeg = 0.0f;  // turntables: the azimuth of this frame (turntableAzimuth)
    std::string png, aov, stats;
    nlohmann::json settings;  // the job's canonical settings with this frame's number and paths
    std::string sceneKey;     // frames with equal keys draw the same scene (file, primitive mode, wireframe)
};

// The manifest's frames in order: a turntable's patterns filled in, each output written by one frame
// only (else a one-line error naming both lines).
Result<std::vector<BatchFrame>> expandJobs(const Manifest& manifest);

// Renders the shard's frames that are not done. False when some frame failed (each is in the summary
// with its one-line error; the others were rendered); an error only for a problem before rendering
// (manifest, shard, devices).
Result<bool> runBatch(const BatchOptions& options);

}  // namespace sr

#endif  // RASTER_BATCH_RUNNER_H
