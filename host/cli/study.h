// study.h - `raster study`: speed against accuracy and stability, the rasterization settings and methods
// side by side (issue 12).
//
// Accuracy: each scene of the set (study/scenes.h: the built-in scene, the textured grazing
// checkerboard, the dense sphere, the bunny when its file is present, a sliver fan, a jittered grid)
// rendered with every setting of study/settings.h -- anti-aliasing (MSAA 1-16, SSAA 2-3 and a
// combination), texture filter (nearest, bilinear, trilinear), UV interpolation (perspective, affine)
// and raster method (fixed8, fixed4, float, scanline) -- and compared with the scene's reference, a
// render better than every setting: SSAA 4 x MSAA 16 (64 samples per pixel) with fixed8 coverage,
// trilinear filtering and perspective UVs. Metrics: PSNR and the largest channel error of the sRGB
// image against the reference, the median GPU frame time, and the device memory of the setting's frame
// (its buffers as the renderer sizes them for the scene and setting).
//
// Stability: every case of every stress axis (study/stress.h) with every raster method: its cracks,
// double hits and wrong-depth-order pixels, and its oracle mismatches, the pixels whose visible
// primitive differs from the conformant graphics pipeline's (vulkan-graphics: Mesa's rasterizer on
// lavapipe, the GPU's on NVIDIA), which draws each case once for all methods and backends. One JSON
// holds both halves; ci/study-chart draws them.
#ifndef RASTER_STUDY_H
#define RASTER_STUDY_H

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/result.h"
#include "render/renderer.h"
#include "study/scenes.h"
#include "study/settings.h"

namespace sr {

struct StudyOptions {
    std::vector<std::string> backends{"vulkan"};  // cuda and/or vulkan
    uint32_t width = 160, height = 120;           // accuracy renders
    uint32_t stressSize = 64;                     // stress cases (stressCases' size)
    std::vector<std::string> axes{"magnitude", "slivers", "near", "coplanar"};
    std::vector<std::string> methods = rasterMethodNames();
    // Accuracy scenes (studySceneNames()); "bunny" is skipped when bunnyPath does not exist. Empty: the
    // accuracy half is left out.
    std::vector<std::string> scenes = studySceneNames();
    std::string bunnyPath = "/usr/share/glmark2/models/bunny.obj";
    uint32_t warmup = 1;
    uint32_t repeat = 5;
    int device = -1;
};

// Runs the study: {"date", "devices", "width", "height", "methods", "accuracy": [...], "stability":
// [...]} as ci/study-chart reads it. Progress goes to stderr when it is a terminal; so does the one-line
// note when vulkan-graphics cannot run (oracle_mismatches is then null).
Result<nlohmann::json> runStudy(const StudyOptions& options);

// The accuracy rows (study/quality.h's format) of one scene on `device`: the reference and every
// setting of studySettings(scene.textured, methods), each rendered with `base` (size, shading, lights,
// warmup and repeat) changed by the setting. `progress` hears the label of each render.
Result<nlohmann::json> measureAccuracy(ComputeDevice& device, const StudyScene& scene,
                                       const RenderSettings& base, const std::vector<std::string>& methods,
                                       const std::function<void(const std::string&)>& progress = {});

// `raster render --quality TARGET [--study FILE]`: the setting to render `scene` with on `device`, and
// the line that reports it (study/quality.h). With a study file, its rows for the scene's name and the
// device's backend; without, measureAccuracy's rows for the scene, measured now with `base` (the
// render's size, shading and lights; warmup 1, kQualityRepeat timed runs) and every raster method.
constexpr uint32_t kQualityRepeat = 3;
struct QualityChoice {
    StudySetting setting;
    std::string line;
};
Result<QualityChoice> chooseQuality(const std::string& target, const std::string& studyPath,
                                    ComputeDevice& device, const StudyScene& scene, RenderSettings base);

// PSNR in dB of `image` against `reference` (same size, RGBA8 words, R G B compared, alpha ignored) and
// the largest channel difference; PSNR is infinite for identical images.
struct ImageError {
    double psnr = 0.0;
    int maxError = 0;
};
ImageError imageError(const RgbaImage& image, const RgbaImage& reference);

// The markdown summary printed after a study: per scene and backend the settings with their time and
// PSNR, per axis the failures of each case and method, and the first failing value per axis, backend
// and method ("none up to X" when no case fails; the cases run in order of increasing stress).
std::string studyMarkdown(const nlohmann::json& study);

}  // namespace sr

#endif  // RASTER_STUDY_H
