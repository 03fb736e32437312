// settings_study.h - the settings the accuracy half of `raster study` compares, and the names they go by in
// its JSON and on the command line (`--raster-method`, `--texture-filter`, `--uv-interpolation`).
#ifndef RASTER_STUDY_SETTINGS_H
#define RASTER_STUDY_SETTINGS_H

#include <cstdint>
#include <string>
#include <vector>

#include "base/result.h"
#include "render/renderer.h"

namespace sr {

// One setting of a group: its label and what it changes from the baseline (fixed8, 1x, trilinear,
// perspective-correct UVs).
struct StudySetting {
    std::string group;  // "aa", "texture", "uv", "method" or "tessellation"
    std::string label;  // e.g. "msaa4", "ssaa2+msaa4", "bilinear", "affine", "scanline"
    uint32_t msaa = 1, ssaa = 1;
    uint32_t textureFilter = TEXTURE_FILTER_TRILINEAR;
    uint32_t uvInterpolation = UV_PERSPECTIVE;
    uint32_t rasterMethod = RASTER_FIXED8;
    uint32_t tessellate = TESS_OFF;  // the "tessellation" group: TESS_*, its edge length and level
    float tessEdgePx = 8.0f;
    uint32_t tessMaxLevel = 16;
};

// The raster methods in the study's order: fixed8, fixed4, float, scanline.
const std::vector<std::string>& rasterMethodNames();

// Name <-> value of a raster method (RASTER_*), a texture filter (TEXTURE_FILTER_*) and a UV
// interpolation (UV_*), as the settings schema names them. An unknown name is a one-line Usage error
// listing the known ones.
Result<uint32_t> rasterMethodFromName(const std::string& name);
std::string rasterMethodName(uint32_t method);
Result<uint32_t> textureFilterFromName(const std::string& name);
std::string textureFilterName(uint32_t filter);
Result<uint32_t> uvInterpolationFromName(const std::string& name);
std::string uvInterpolationName(uint32_t uv);

// Every setting the study renders a scene with: the "aa" group (MSAA 1, 2, 4, 8, 16; SSAA 2 and 3;
// SSAA 2 + MSAA 4); on a textured scene the "texture" group (nearest, bilinear, trilinear) and the "uv"
// group (perspective, affine); and the "method" group, one setting per name in `methods` (1x,
// trilinear). `methods` holds names from rasterMethodNames(). With `tessellation`, the "tessellation"
// group: off, flat at 8 px, pn at 32, 16, 8, 4 and 2 px, and the centroid baseline at 1, 2 and 3 levels.
std::vector<StudySetting> studySettings(bool textured, const std::vector<std::string>& methods,
                                        bool tessellation = false);

// `base` with the setting's anti-aliasing, filter, UV interpolation and raster method.
RenderSettings withSetting(RenderSettings base, const StudySetting& setting);

// The study's reference for `base`: SSAA 4 x MSAA 16 (64 samples per pixel, fixed8 coverage),
// trilinear, perspective-correct; rendered once (warmup 0, repeat 1), since its time is not compared.
RenderSettings referenceSettings(RenderSettings base);

}  // namespace sr

#endif  // RASTER_STUDY_SETTINGS_H
