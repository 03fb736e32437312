// turntable.cpp - frame-number patterns and the orbit sequence of `raster render --frames`.
#include "cli/turntable.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "cli/outputs.h"

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

Result<TurntableResult> renderTurntable(RenderSession& session, OrbitCamera camera,
                                        const RenderOptions& render, const TurntableOptions& options)
{
    RenderSettings settings = render.resolved();
    auto model = parseModelSpec(render.model);
    if (!model) return model.error();
    // The surface channels cost a host pass over the frame, and the ids and depth a pass on the device
    // (stage aovs): only for EXRs that will hold them.
    settings.surfaceAovs = options.hasAov;
    settings.outputs = options.hasAov ? OUTPUT_IMAGES : OUTPUT_COLOR;
    TurntableResult result;
    result.triangles = session.scene().triangleCount();
    for (uint32_t k = 0; k < options.frames; ++k) {
        OrbitPose pose = camera.pose();
        pose.azimuthDeg = turntableAzimuth(options.azimuth, k, options.frames);
        camera.setPose(pose);
        auto out = session.render(camera.matrices(settings.width, settings.height, *model), settings);
        if (!out) return out.error();
        OutputPaths paths{options.hasPng ? framePath(options.png, k) : "",
                          options.hasAov ? framePath(options.aov, k) : "",
                          options.hasStats ? framePath(options.stats, k) : ""};
        // Each frame's statistics name its own camera, so that any frame renders again from its JSON.
        RenderOptions frame = render;
        frame.camera = camera.specString();
        SR_TRY(writeOutputs(*out, session.scene(), frame, paths, options.sceneName, options.encoding));
        result.device = out->device;
        result.frameGpuMs.push_back(out->total.medianMs);
        if (options.progress) options.progress(k + 1, options.frames);
    }
    return result;
}

}  // namespace sr
