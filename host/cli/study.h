// study.h - `raster study`: speed against accuracy and stability, the rasterization settings side by side
// (issue 12).
//
// Accuracy: each scene of a fixed set (the built-in scene, the textured grazing checkerboard, the dense
// sphere, the bunny when its file is present) rendered with every setting of a group -- anti-aliasing
// (MSAA 1-16, SSAA 2-3 and a combination), texture filter (nearest, bilinear, trilinear) and UV
// interpolation (perspective, affine) -- and compared with the scene's reference, a render better than
// every setting: SSAA 4 x MSAA 16 (64 samples per pixel) with trilinear filtering and perspective UVs.
// Metrics: PSNR and the largest channel error of the sRGB image against the reference, the median GPU
// frame time, peak device memory. Stability: every case of every stress axis (study/stress.h) with its
// cracks, double hits and wrong-depth-order pixels. One JSON holds both; ci/study-chart draws them.
#ifndef RASTER_STUDY_H
#define RASTER_STUDY_H

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/result.h"
#include "render/renderer.h"

namespace sr {

struct StudyOptions {
    std::vector<std::string> backends{"vulkan"};  // cuda and/or vulkan
    uint32_t width = 160, height = 120;           // accuracy renders
    uint32_t stressSize = 64;                     // stress cases (stressCases' size)
    std::vector<std::string> axes{"magnitude", "slivers", "near", "coplanar"};
    std::string bunnyPath = "/usr/share/glmark2/models/bunny.obj";
    uint32_t warmup = 1;
    uint32_t repeat = 5;
    int device = -1;
};

// Runs the study: {"command", "date", "devices", "accuracy": [...], "stability": [...]} as
// ci/study-chart reads it. Progress goes to stderr when it is a terminal.
Result<nlohmann::json> runStudy(const StudyOptions& options);

// PSNR in dB of `image` against `reference` (same size, RGBA8 words, R G B compared, alpha ignored) and
// the largest channel difference; PSNR is infinite for identical images.
struct ImageError {
    double psnr = 0.0;
    int maxError = 0;
};
ImageError imageError(const RgbaImage& image, const RgbaImage& reference);

// The markdown summary printed after a study: per scene and backend the settings by time with their
// PSNR, and per axis the failures of each case.
std::string studyMarkdown(const nlohmann::json& study);

}  // namespace sr

#endif  // RASTER_STUDY_H
