// outputs.cpp - PNG, EXR and JSON of a rendered frame.
#include "cli/outputs.h"

#include "api/stats_json.h"
#include "io/image_io.h"
#include "render/aov.h"

namespace sr {

OutputPaths savePaths(const std::string& prefix)
{
    return {prefix + ".png", prefix + ".exr", prefix + ".json"};
}

Status writeOutputs(RenderOutput& out, const Scene& scene, const RenderOptions& options,
                    const OutputPaths& paths, const std::string& sceneName)
{
    const RenderSettings settings = options.resolved();
    SR_TRY(writePng(paths.png, out.color));
    if (!paths.aov.empty()) {
        if (!out.aov.hasBary()) fillSurfaceAovs(scene, out.params, out.aov);
        if (settings.aovSamples && out.aov.sampleId.empty())
            fillSampleAovs(out.samples, settings.ssaa, out.aov);
        SR_TRY(writeAovExr(paths.aov, out.aov));
    }
    if (!paths.stats.empty()) SR_TRY(writeJson(paths.stats, statsJson(out, options, sceneName)));
    return okStatus();
}

}  // namespace sr
