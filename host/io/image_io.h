// image_io.h - PNG colour images and EXR AOVs.
//
// PNG: 8-bit RGBA through stb (Debian's libstb). EXR: through tinyexr, with a UINT channel `id`
// (triangle id, 0xFFFFFFFF for background) and a FLOAT channel `Z` (window depth, 1.0 background).
#ifndef RASTER_IMAGE_IO_H
#define RASTER_IMAGE_IO_H

#include <cstdint>
#include <string>
#include <vector>

#include "base/result.h"

namespace sr {

struct RgbaImage {
    uint32_t width = 0, height = 0;
    std::vector<uint32_t> pixels;  // row-major from the top row, R in the low byte
};

struct AovImage {
    uint32_t width = 0, height = 0;
    std::vector<uint32_t> id;  // row-major from the top row
    std::vector<float> depth;
};

Status writePng(const std::string& path, const RgbaImage& image);
Result<RgbaImage> readPng(const std::string& path);  // any PNG, expanded to RGBA8
Status writeAovExr(const std::string& path, const AovImage& aov);
Result<AovImage> readAovExr(const std::string& path);  // needs the `id` and `Z` channels

}  // namespace sr

#endif  // RASTER_IMAGE_IO_H
