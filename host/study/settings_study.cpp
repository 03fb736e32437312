// settings_study.cpp - see settings_study.h.
#include "study/settings_study.h"

#include <utility>

#include "settings/schema.h"

namespace sr {

// The names are the settings schema's (settings/schema.h), so the study's JSON, --quality and the
// command line spell every setting the same way.
const std::vector<std::string>& rasterMethodNames()
{
    static const std::vector<std::string> names = choiceNames(setting("raster-method"));
    return names;
}

Result<uint32_t> rasterMethodFromName(const std::string& name)
{
    return choiceValue(setting("raster-method"), name, "raster method");
}

std::string rasterMethodName(uint32_t method)
{
    return choiceName(setting("raster-method"), method);
}

Result<uint32_t> textureFilterFromName(const std::string& name)
{
    return choiceValue(setting("texture-filter"), name, "texture filter");
}

std::string textureFilterName(uint32_t filter)
{
    return choiceName(setting("texture-filter"), filter);
}

Result<uint32_t> uvInterpolationFromName(const std::string& name)
{
    return choiceValue(setting("uv-interpolation"), name, "UV interpolation");
}

std::string uvInterpolationName(uint32_t uv)
{
    return choiceName(setting("uv-interpolation"), uv);
}

std::vector<StudySetting> studySettings(bool textured, const std::vector<std::string>& methods,
                                        bool tessellation)
{
    std::vector<StudySetting> out;
    for (uint32_t m : {1u, 2u, 4u, 8u, 16u}) out.push_back({"aa", "msaa" + std::to_string(m), m, 1});
    out.push_back({"aa", "ssaa2", 1, 2});
    out.push_back({"aa", "ssaa3", 1, 3});
    out.push_back({"aa", "ssaa2+msaa4", 4, 2});
    if (textured) {
        out.push_back({"texture", "nearest", 1, 1, TEXTURE_FILTER_NEAREST});
        out.push_back({"texture", "bilinear", 1, 1, TEXTURE_FILTER_BILINEAR});
        out.push_back({"texture", "trilinear", 1, 1, TEXTURE_FILTER_TRILINEAR});
        out.push_back({"uv", "perspective", 1, 1, TEXTURE_FILTER_TRILINEAR, UV_PERSPECTIVE});
        out.push_back({"uv", "affine", 1, 1, TEXTURE_FILTER_TRILINEAR, UV_AFFINE});
    }
    for (const std::string& name : methods) {
        auto method = rasterMethodFromName(name);
        if (method) out.push_back({"method", name, 1, 1, TEXTURE_FILTER_TRILINEAR, UV_PERSPECTIVE, *method});
    }
    if (tessellation) {
        auto tess = [&](std::string label, uint32_t mode, float edgePx, uint32_t level) {
            out.push_back({"tessellation", std::move(label), 1, 1, TEXTURE_FILTER_TRILINEAR, UV_PERSPECTIVE,
                           RASTER_FIXED8, mode, edgePx, level});
        };
        tess("tess-off", TESS_OFF, 8.0f, 16);
        tess("flat-8px", TESS_FLAT, 8.0f, 16);
        for (int px : {32, 16, 8, 4, 2}) tess("pn-" + std::to_string(px) + "px", TESS_PN, float(px), 64);
        for (uint32_t level : {1u, 2u, 3u})
            tess("centroid-" + std::to_string(level), TESS_CENTROID, 8.0f, level);
    }
    return out;
}

RenderSettings withSetting(RenderSettings base, const StudySetting& setting)
{
    base.msaa = setting.msaa;
    base.ssaa = setting.ssaa;
    base.textureFilter = setting.textureFilter;
    base.uvInterpolation = setting.uvInterpolation;
    base.rasterMethod = setting.rasterMethod;
    base.tessellate = setting.tessellate;
    base.tessEdgePx = setting.tessEdgePx;
    base.tessMaxLevel = setting.tessMaxLevel;
    return base;
}

RenderSettings referenceSettings(RenderSettings base)
{
    base.msaa = 16;
    base.ssaa = 4;
    base.textureFilter = TEXTURE_FILTER_TRILINEAR;
    base.uvInterpolation = UV_PERSPECTIVE;
    base.rasterMethod = RASTER_FIXED8;
    base.tessellate = TESS_OFF;
    base.warmup = 0;
    base.repeat = 1;
    return base;
}

}  // namespace sr
