// study_runner.h - `raster study`: speed against accuracy and stability, the rasterization settings and
// methods side by side (issue 12).
//
// Accuracy: each scene of the set (study/scenes.h: the built-in scene, the textured grazing
// checkerboard, the dense sphere, the bunny when its file is present, a sliver fan, a jittered grid)
// rendered with every setting of study/settings_study.h -- anti-aliasing (MSAA 1-16, SSAA 2-3 and a
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
// lavapipe, the GPU's on NVIDIA), which draws each case once for all methods and backends.
//
// Level of detail (issue 29, study/lod_study.h): each LOD scene (the sphere of --lod-rings rings, the bunny,
// the bunny subdivided to 16 times its triangles) from a near and a far camera, drawn with --lod off and
// with --lod on at every error of --lod-errors, each frame against the --lod off one (coverage pixels
// that differ and those beyond 1 pixel of its silhouette, depth error, colour PSNR), and against the
// --lod off frame's SSAA reference (colour PSNR), with the triangles drawn and the visibility time (the
// GPU frame less the shade stage, as `raster bench` reports it). One JSON holds all three;
// ci/study-chart draws them.
#ifndef RASTER_STUDY_RUNNER_H
#define RASTER_STUDY_RUNNER_H

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "raster/raster.h"

#include "base/result.h"
#include "render/renderer.h"
#include "study/lod_study.h"
#include "study/scenes.h"
#include "study/ao_study.h"
#include "study/settings_study.h"

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
    // The level-of-detail group: its scenes (lodSceneNames(); "bunny" and "bunny-fine" are skipped when
    // bunnyPath does not exist; empty: the group is left out), the sphere's rings (builtin:dense:N: 200
    // is 160k triangles, for lavapipe; 5000 the 100M sphere) and the errors (--lod-error-px) each scene
    // and camera is drawn with besides --lod off.
    std::vector<std::string> lodScenes{"sphere", "bunny"};
    int lodRings = 200;
    std::vector<float> lodErrors{0.25f, 0.5f, 1.0f, 2.0f, 4.0f};
    // The ambient-occlusion group (issue 30, study/ao_study.h): its scenes (aoSceneNames(); "bunny-plane" is
    // skipped when bunnyPath does not exist; empty: the group is left out), each drawn with --ao reference
    // at every radius of aoStudySettings() and with --ao gtao at every setting of it.
    std::vector<std::string> aoScenes = aoSceneNames();
    uint32_t warmup = 1;
    uint32_t repeat = 5;
    int device = -1;
};

// Runs the study: {"date", "devices", "width", "height", "methods", "accuracy": [...], "stability":
// [...], "lod": [...], "lod_depth"} as ci/study-chart reads it (measureLod gives the "lod" rows;
// "lod_depth" says what their depth errors measure). Progress goes to stderr when it is a terminal; so does
// the one-line note when vulkan-graphics cannot run (oracle_mismatches is then null).
Result<nlohmann::json> runStudy(const StudyOptions& options);

// The accuracy rows (study/quality.h's format) of one scene on `device`: the reference and every
// setting of studySettings(scene.textured, methods), each rendered with `base` (size, shading, lights,
// warmup and repeat) changed by the setting. `progress` hears the label of each render.
Result<nlohmann::json> measureAccuracy(raster::Device& device, const StudyScene& scene,
                                       const RenderSettings& base, const std::vector<std::string>& methods,
                                       const std::function<void(const std::string&)>& progress = {});

// The level-of-detail rows of one scene on `device` (study/lod_study.h), its near camera's then its far
// camera's, each the --lod off frame (the baseline) and then one per error in `errors`, drawn with `base`
// (size, shading, warmup and repeat) and --lod on at that error. One RenderSession draws them all, so the
// hierarchy is built once per scene and device. Each row: {"scene", "camera", "camera_spec" (the --camera
// that draws the frame), "backend", "error_px" ("off" for the baseline, else the error), "triangles"
// (drawn: the cut's with --lod on), "scene_triangles", "ms" (median GPU frame), "visibility_ms" (ms less
// the shade stage), "coverage_px", "beyond_silhouette_px", "baseline_silhouette_px", "depth_max_error",
// "depth_mean_error" (LodImageDiff against the baseline), "psnr_vs_off" and "psnr_vs_reference" (dB,
// "inf" for an identical image; the reference is the baseline's frame at SSAA 4 x MSAA 16,
// referenceSettings)}. `progress` hears what is being drawn.
// The ambient-occlusion rows of one scene on `device` (study/ao_study.h): the reference (--ao reference, the
// host's rays) at each radius of aoStudySettings(), then every setting drawn with --ao gtao and
// --shading ao, with `base`'s size, warmup and repeat: {"scene", "camera_spec", "backend", "slices",
// "steps", "radius_scale", "radius", "denoise", "ao_ms" (the AO stages' median GPU time), "shade_ms",
// "pixels", "mean_error", "max_error", "psnr"} (aoImageError against the reference at its radius).
Result<nlohmann::json> measureAo(raster::Device& device, const AoStudyScene& scene,
                                 const RenderSettings& base,
                                 const std::function<void(const std::string&)>& progress = {});

Result<nlohmann::json> measureLod(raster::Device& device, const std::string& name, const raster::Scene& scene,
                                  const RenderSettings& base, const std::vector<float>& errors,
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
                                    raster::Device& device, const StudyScene& scene, RenderSettings base);

// PSNR in dB of `image` against `reference` (same size, RGBA8 words, R G B compared, alpha ignored) and
// the largest channel difference; PSNR is infinite for identical images.
struct ImageError {
    double psnr = 0.0;
    int maxError = 0;
};
ImageError imageError(const RgbaImage& image, const RgbaImage& reference);

// The markdown summary printed after a study: per scene and backend the settings with their time and
// PSNR, per axis the failures of each case and method, the first failing value per axis, backend and
// method ("none up to X" when no case fails; the cases run in order of increasing stress), and, when the
// study has "lod" rows, the level-of-detail table.
std::string studyMarkdown(const nlohmann::json& study);

}  // namespace sr

#endif  // RASTER_STUDY_RUNNER_H
