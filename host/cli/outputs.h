// outputs.h - the files of one rendered frame, written the same way by `raster render` (-o, --aov,
// --stats), by every frame of a turntable and by the viewer's saves.
#ifndef RASTER_OUTPUTS_H
#define RASTER_OUTPUTS_H

#include <string>

#include "base/result.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace sr {

struct OutputPaths {
    std::string png;    // colour image (sRGB PNG)
    std::string aov;    // EXR of the AOVs; empty: none
    std::string stats;  // JSON statistics; empty: none
};

// PREFIX.png, PREFIX.exr and PREFIX.json: what the viewer's `s` key and a script's `save PREFIX` write.
OutputPaths savePaths(const std::string& prefix);

// Writes the PNG, and the EXR (with the surface channels, computed here from the ids if the frame was
// rendered without RenderSettings::surfaceAovs, and every sample with aovSamples) and the JSON where
// `paths` names them. `out` is the frame of `scene` rendered with `options`; its AOV image gains the
// channels the EXR needs.
Status writeOutputs(RenderOutput& out, const Scene& scene, const RenderOptions& options,
                    const OutputPaths& paths, const std::string& sceneName);

}  // namespace sr

#endif  // RASTER_OUTPUTS_H
