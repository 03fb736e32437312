// ao_study.h - the ambient-occlusion group of `raster study` (issue 30, item 5): its scenes and cameras, the
// GTAO settings it sweeps, and what a GTAO image is compared with the ground truth (--ao reference) by.
//
// Scenes: "builtin" (the built-in scene under the auto camera), "bunny-plane" (the Stanford bunny
// standing on a floor, under the auto camera: contact shadows and the creases of a real mesh) and the
// stress scene builtin:ao (a thin plate and a thin post standing on a floor, a box floating above it, a
// low step) from two cameras: "stress-grazing", low over the floor (a grazing floor, depth
// discontinuities behind every object), and "stress-near", half a unit from the post (a surface close to
// the camera, where the radius projects to hundreds of pixels and AO_MAX_RADIUS_PX clamps it).
#ifndef RASTER_STUDY_AO_H
#define RASTER_STUDY_AO_H

#include <cstdint>
#include <string>
#include <vector>

#include "base/result.h"
#include "io/image_io.h"
#include "camera/camera.h"
#include "scene/scene.h"

namespace sr {

// The group's scene names in the study's order: builtin, bunny-plane, stress-grazing, stress-near.
const std::vector<std::string>& aoSceneNames();

struct AoStudyScene {
    std::string name;
    std::string cameraSpec;  // the --camera that frames it ("auto" or an orbit spec)
    Scene scene;
    CameraMatrices camera;
};

// The AO scene `name` framed for width x height; bunny-plane reads the bunny from `bunnyPath`. An
// unknown name or a bunny that does not load is a one-line Usage error.
Result<AoStudyScene> makeAoScene(const std::string& name, unsigned width, unsigned height,
                                 const std::string& bunnyPath);

// `mesh` standing on a floor: a square quad (facing +y, the mesh's grey) at the bottom of its bounds,
// three times its larger horizontal extent on a side, centred under it.
Scene standingOnFloor(Scene mesh);

// One GTAO setting of the sweep: --ao-slices, --ao-steps, the radius as a multiple of the default
// (kAoRadiusFraction of the scene's bounding radius) and --ao-denoise.
struct AoSetting {
    uint32_t slices = 1;  // RenderSettings' defaults
    uint32_t steps = 8;
    float radiusScale = 1.0f;
    bool denoise = true;
};
// The sweep: slices 1, 2, 3, 4 x steps 2, 4, 8 x denoise on, off at the default radius, and the default
// slices and steps at half and twice the radius, denoised.
std::vector<AoSetting> aoStudySettings();

// An AO image against the reference, over the pixels the reference's frame covers (id not EMPTY_ID):
// the mean and largest |ao - reference| and the PSNR of the AO image (peak 1: 10 log10(1 / MSE), capped
// at kAoPsnrCap dB where the images agree to rounding).
constexpr double kAoPsnrCap = 100.0;
struct AoImageError {
    uint64_t pixels = 0;
    double meanError = 0.0;
    double maxError = 0.0;
    double psnr = kAoPsnrCap;
};
AoImageError aoImageError(const AovImage& image, const AovImage& reference);

}  // namespace sr

#endif  // RASTER_STUDY_AO_H
