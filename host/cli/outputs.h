// outputs.h - the files of one rendered frame, written the same way by `raster render` (-o, --aov,
// --stats), by every frame of a turntable and by the viewer's saves.
#ifndef RASTER_OUTPUTS_H
#define RASTER_OUTPUTS_H

#include <string>
#include <vector>

#include "base/result.h"
#include "io/file_write.h"
#include "io/image_io.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace sr {

struct OutputPaths {
    std::string png;    // colour image: an sRGB PNG, or the same pixels as a NumPy array when it ends in .npy
    std::string aov;    // EXR of the AOVs; empty: none
    std::string stats;  // JSON statistics; empty: none
};

// The help of --png-compression and --exr-compression (render and batch).
std::string pngCompressionHelp();
std::string exrCompressionHelp();

// What would make a render of `scene` from `camera` with `settings` a plain image without the user
// knowing why, one line each (without the "warning: " prefix): a texture debug view (--shading texcoord
// or mip) of a scene without textures, and an eye inside the scene's geometry (eyeInsideScene).
std::vector<std::string> viewWarnings(const Scene& scene, const CameraMatrices& camera,
                                      const RenderSettings& settings);

// The frame's camera spec in absolute scene units for its statistics (resolvedCameraSpec); "" for a
// study scene under the auto camera, which renders with the study's own camera (the matrices say which).
std::string absoluteCamera(const RenderOptions& options, const Scene& scene, const std::string& sceneName);

// PREFIX.png, PREFIX.exr and PREFIX.json: what the viewer's `s` key and a script's `save PREFIX` write.
OutputPaths savePaths(const std::string& prefix);

// Who made the frame, as its PNG and EXR record it (ImageOrigin: the backend and the device's name).
ImageOrigin outputOrigin(const RenderOutput& out);

// Time a frame's files took, ms: encoding the colour image (PNG or NPY); computing and encoding the EXR's
// channels and the JSON; writing them under their temporary names.
struct OutputTimes {
    double encode = 0.0, aux = 0.0, write = 0.0;
};

// Encodes the colour image (PNG or NPY, by its extension), the EXR (with the surface channels, computed here
// from the ids if the frame was rendered without RenderSettings::surfaceAovs, every sample with aovSamples,
// and the linear colour decoded from the PNG's, linearColorAov) and the JSON where `paths` names them (an
// empty path: none), the image files tagged with outputOrigin, and stages them in `files` (files.commit()
// puts them in place). `out` is the frame of `scene` rendered with `options`; its AOV image gains the
// channels the EXR needs. The images are encoded as `encoding` says. `times`, when given, receives what each
// part took.
Status stageOutputs(FileGroup& files, RenderOutput& out, const Scene& scene, const RenderOptions& options,
                    const OutputPaths& paths, const std::string& sceneName, const ImageEncoding& encoding,
                    OutputTimes* times = nullptr);
// stageOutputs, then the commit: every file of the frame, or none of them.
Status writeOutputs(RenderOutput& out, const Scene& scene, const RenderOptions& options,
                    const OutputPaths& paths, const std::string& sceneName,
                    const ImageEncoding& encoding = {});

}  // namespace sr

#endif  // RASTER_OUTPUTS_H
