// turntable.h - `raster render --frames N --orbit AZ0:AZ1 -o frame_%04d.png`: an orbit sequence rendered
// in one process on one device through one raster::Session (the scene uploaded once), and the
// frame-number patterns of its file names (and of batch jobs').
#ifndef RASTER_TURNTABLE_H
#define RASTER_TURNTABLE_H

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "raster/raster.h"

#include "base/result.h"
#include "io/image_io.h"
#include "camera/orbit.h"
#include "settings/render_settings.h"

namespace sr {

// A file name with the frame number in it, printf style: exactly one %d or %0Nd (N = 1..9 digits, zero
// padded), and %% for a percent sign; no other conversion.
struct FramePattern {
    std::string before, after;  // the text around the number, %% already turned into %
    int digits = 0;             // zero-padded to this many digits (0: as many as it has)
};

// Parses `text`, the value of `option` (named in the one-line error).
Result<FramePattern> parseFramePattern(const std::string& option, const std::string& text);
std::string framePath(const FramePattern& pattern, uint32_t frame);

// `--orbit AZ0:AZ1` (both ends rendered) or `--orbit AZ0:AZ1)` (AZ1 left out, interval notation), degrees.
// A looped video of 0:360 repeats its first view at the end, a visible stutter; 0:360) ends one step
// short of it, so frame N - 1 flows into frame 0.
struct AzimuthRange {
    float from = 0.0f, to = 0.0f;
    bool endExclusive = false;
};
Result<AzimuthRange> parseAzimuthRange(const std::string& text);

// Azimuth of frame k of n: inclusive ends, from + (to - from) * k / (n - 1) in float, in that order, and
// exactly `to` for the last frame; end-exclusive, from + (to - from) * k / n. `from` when n is 1.
float turntableAzimuth(const AzimuthRange& range, uint32_t frame, uint32_t frames);

struct TurntableOptions {
    uint32_t frames = 1;
    AzimuthRange azimuth;
    FramePattern png;         // used when hasPng (no -o with --aov: EXRs only)
    FramePattern aov, stats;  // used when hasAov / hasStats
    bool hasPng = true, hasAov = false, hasStats = false;
    ImageEncoding encoding;  // how the PNGs and EXRs are encoded
    // Called after each frame is written with (frames done, frames): the progress line.
    std::function<void(uint32_t, uint32_t)> progress;
};

struct TurntableResult {
    raster::DeviceInfo device;
    std::vector<double> frameGpuMs;       // each frame's GPU time (the median over its timed runs)
    std::string firstCamera, lastCamera;  // the first and last frames' cameras as specs
    uint64_t triangles = 0;
};

// The orbit a turntable of `scene` with `options` turns: the pose of the settings' camera spec (auto or
// orbit) on the scene as the frames draw it (its lines, points or overlay), for their image size.
Result<OrbitCamera> turntableOrbit(const raster::Scene& scene, const RenderOptions& options);

// Renders and writes the frames of `scene` through `session` with `settings` (the surface AOVs when the
// frames write EXRs): frame k is the pose of the settings' camera (auto or orbit) with turntableAzimuth(k)
// (elevation, distance and target offset as given), as the spec orbitSpecString writes, so that each frame
// is exactly what `raster render --camera` of that spec renders; its files are written as `raster render`
// writes one frame's (api/frame_files.h). The frames' warnings go to `warnings`.
Result<TurntableResult> renderTurntable(raster::Session& session, const raster::Scene& scene,
                                        const raster::Settings& settings, const TurntableOptions& options);

}  // namespace sr

#endif  // RASTER_TURNTABLE_H
