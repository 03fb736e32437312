// turntable.h - `raster render --frames N --orbit AZ0:AZ1 -o frame_%04d.png`: an orbit sequence rendered
// in one process on one device, the scene uploaded once (RenderSession).
#ifndef RASTER_TURNTABLE_H
#define RASTER_TURNTABLE_H

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "base/result.h"
#include "cli/outputs.h"
#include "render/renderer.h"
#include "scene/orbit.h"

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
    std::string sceneName;   // for the JSON
    ImageEncoding encoding;  // how the PNGs and EXRs are encoded
    // Called after each frame is written with (frames done, frames): the progress line.
    std::function<void(uint32_t, uint32_t)> progress;
};

struct TurntableResult {
    DeviceInfo device;
    std::vector<double> frameGpuMs;  // each frame's GPU time (the median over its timed runs)
    uint64_t triangles = 0;
};

// Renders and writes the frames with the settings `render` resolves to (the surface AOVs when the frames
// write EXRs): frame k is the camera's pose with turntableAzimuth(k) (elevation,
// distance and target offset as given), exactly what `raster render --camera orbit:...` of that pose
// renders, written like `raster render` writes one frame (outputs.h).
Result<TurntableResult> renderTurntable(RenderSession& session, OrbitCamera camera,
                                        const RenderOptions& render, const TurntableOptions& options);

}  // namespace sr

#endif  // RASTER_TURNTABLE_H
