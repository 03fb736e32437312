// option_names.h - the command-line names of the render settings that are enums in raster_shared.h,
// for every front end that reads them (`raster render`, `raster batch` manifests).
#ifndef RASTER_OPTION_NAMES_H
#define RASTER_OPTION_NAMES_H

#include <cstdint>
#include <map>
#include <string>

#include "raster_shared.h"

namespace sr {

// --cull: CULL_*.
inline const std::map<std::string, uint32_t>& cullModesByName()
{
    static const std::map<std::string, uint32_t> names = {
        {"back", CULL_BACK}, {"front", CULL_FRONT}, {"none", CULL_NONE}};
    return names;
}

// --texture-filter: TEXTURE_FILTER_*.
inline const std::map<std::string, uint32_t>& textureFiltersByName()
{
    static const std::map<std::string, uint32_t> names = {{"auto", TEXTURE_FILTER_AUTO},
                                                          {"nearest", TEXTURE_FILTER_NEAREST},
                                                          {"bilinear", TEXTURE_FILTER_BILINEAR},
                                                          {"trilinear", TEXTURE_FILTER_TRILINEAR}};
    return names;
}

// --uv-interpolation: UV_*.
inline const std::map<std::string, uint32_t>& uvInterpolationsByName()
{
    static const std::map<std::string, uint32_t> names = {{"perspective", UV_PERSPECTIVE},
                                                          {"affine", UV_AFFINE}};
    return names;
}

// --raster-method: RASTER_*.
inline const std::map<std::string, uint32_t>& rasterMethodsByName()
{
    static const std::map<std::string, uint32_t> names = {{"fixed8", RASTER_FIXED8},
                                                          {"fixed4", RASTER_FIXED4},
                                                          {"float", RASTER_FLOAT},
                                                          {"scanline", RASTER_SCANLINE}};
    return names;
}

// --tessellate: TESS_*.
inline const std::map<std::string, uint32_t>& tessModesByName()
{
    static const std::map<std::string, uint32_t> names = {
        {"off", TESS_OFF}, {"flat", TESS_FLAT}, {"pn", TESS_PN}, {"centroid", TESS_CENTROID}};
    return names;
}

}  // namespace sr

#endif  // RASTER_OPTION_NAMES_H
