// turntable.cpp - frame-number patterns and the orbit sequence of `raster render --frames`.
#include "batch/turntable.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <set>

#include "api/api_internal.h"
#include "api/frame_files.h"
#include "base/warnings.h"
#include "camera/orbit.h"
#include "scene/primitive_mode.h"

namespace sr {

Result<FramePattern> parseFramePattern(const std::string& option, const std::string& text)
{
    auto invalid = [&](const char* why) {
        return makeError(ExitCode::Usage,
                         "invalid {} '{}': {}; --frames needs exactly one %d or %0Nd for the frame number "
                         "(e.g. frame_%04d.png, %% for a percent sign)",
                         option, text, why);
    };
    FramePattern pattern;
    bool found = false;
    std::string* out = &pattern.before;
    for (size_t i = 0; i < text.size(); ++i) {
        if (text[i] != '%') {
            *out += text[i];
            continue;
        }
        if (i + 1 < text.size() && text[i + 1] == '%') {
            *out += '%';
            ++i;
            continue;
        }
        // %d or %0Nd: a zero, then 1..9 as the width, then d.
        size_t j = i + 1;
        int digits = 0;
        if (j + 1 < text.size() && text[j] == '0' && text[j + 1] >= '1' && text[j + 1] <= '9') {
            digits = text[j + 1] - '0';
            j += 2;
        }
        if (j >= text.size() || text[j] != 'd') return invalid("a % that is not %d, %0Nd (N = 1..9) or %%");
        if (found) return invalid("more than one frame number");
        found = true;
        pattern.digits = digits;
        out = &pattern.after;
        i = j;
    }
    if (!found) return invalid("no frame number");
    return pattern;
}

std::string framePath(const FramePattern& pattern, uint32_t frame)
{
    return fmt::format("{}{:0{}}{}", pattern.before, frame, pattern.digits, pattern.after);
}

Result<AzimuthRange> parseAzimuthRange(const std::string& text)
{
    auto number = [](const std::string& s, float& out) {
        if (s.empty() || std::isspace(static_cast<unsigned char>(s.front()))) return false;
        errno = 0;
        char* end = nullptr;
        out = std::strtof(s.c_str(), &end);
        return errno == 0 && end == s.c_str() + s.size() && std::isfinite(out);
    };
    AzimuthRange range;
    std::string ends = text;
    if (!ends.empty() && ends.back() == ')') {
        range.endExclusive = true;
        ends.pop_back();
    }
    size_t colon = ends.find(':');
    if (colon == std::string::npos || !number(ends.substr(0, colon), range.from) ||
        !number(ends.substr(colon + 1), range.to))
        return makeError(ExitCode::Usage,
                         "invalid --orbit '{}': expected AZ0:AZ1 (degrees, both ends rendered) or AZ0:AZ1) "
                         "(AZ1 left out, for a loop)",
                         text);
    return range;
}

float turntableAzimuth(const AzimuthRange& range, uint32_t frame, uint32_t frames)
{
    if (frames <= 1) return range.from;
    if (range.endExclusive) return range.from + (range.to - range.from) * float(frame) / float(frames);
    if (frame + 1 >= frames) return range.to;
    return range.from + (range.to - range.from) * float(frame) / float(frames - 1);
}

Result<OrbitCamera> turntableOrbit(const raster::Scene& scene, const RenderOptions& options)
{
    const Scene& loaded = raster::Internal::of(scene).scene;
    auto spec = parseCameraSpec(options.camera);
    if (!spec) return spec.error();
    const uint32_t w = options.settings.width, h = options.settings.height;
    if (options.primitiveMode == PrimitiveMode::Triangles && !options.wireframe)
        return OrbitCamera::fromSpec(*spec, loaded, w, h);
    return OrbitCamera::fromSpec(*spec, displayScene(loaded, options.primitiveMode, options.wireframe), w, h);
}

Result<TurntableResult> renderTurntable(raster::Session& session, const raster::Scene& scene,
                                        const raster::Settings& settings, const TurntableOptions& options)
{
    const RenderOptions& render = raster::Internal::of(settings).options;
    auto orbit = turntableOrbit(scene, render);
    if (!orbit) return orbit.error();
    // The surface channels cost a host pass over the frame, and the ids and depth a pass on the device
    // (stage aovs): only for EXRs that will hold them.
    raster::RenderRequest request;
    request.surfaceAovs = options.hasAov;
    request.outputs = options.hasAov ? raster::OutputImages : raster::OutputColor;
    request.stats = options.hasStats;
    TurntableResult result;
    result.triangles = scene.triangleCount();
    std::set<std::string> warned;  // each warning once for the sequence, not once per frame
    for (uint32_t k = 0; k < options.frames; ++k) {
        OrbitPose pose = orbit->pose();
        pose.azimuthDeg = turntableAzimuth(options.azimuth, k, options.frames);
        // Each frame's statistics name its own camera, so that any frame renders again from its JSON.
        const std::string camera = orbitSpecString(pose);
        if (k == 0) result.firstCamera = camera;
        result.lastCamera = camera;
        auto frame = session.render(raster::Camera::fromSpec(camera), settings, request);
        if (!frame) return raster::fromPublic(frame.error());
        for (const std::string& warning : frame->warnings)
            if (warned.insert(warning).second) warnLine(warning);
        OutputPaths paths{options.hasPng ? framePath(options.png, k) : "",
                          options.hasAov ? framePath(options.aov, k) : "",
                          options.hasStats ? framePath(options.stats, k) : ""};
        FileGroup files;
        SR_TRY(stageFrame(files, *frame, paths, options.encoding));
        SR_TRY(files.commit());
        result.device = frame->device;
        result.frameGpuMs.push_back(frame->gpuMs);
        if (options.progress) options.progress(k + 1, options.frames);
    }
    return result;
}

}  // namespace sr
