// texture.h - decoded images with their mip chains, as SceneTexture (scene.h) holds them.
//
// Decoding goes through stb_image (PNG, JPEG, BMP, TGA, GIF, ...), always expanded to RGBA8. Every
// size is checked against MAX_TEXTURE_DIM before anything is allocated, so a forged header cannot
// make the loader allocate gigabytes.
#ifndef RASTER_TEXTURE_H
#define RASTER_TEXTURE_H

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "base/result.h"
#include "scene/scene.h"

namespace sr {

// A texture from width x height RGBA8 texels (4 bytes each, row-major from the top row) with its full
// mip chain: 1 + floor(log2(max(width, height))) levels, each texel of level k + 1 the box average of
// texels (2x, 2y) .. (min(2x + 1, w - 1), min(2y + 1, h - 1)) of level k. sRGB colour channels are
// averaged in linear space (exact EOTF, re-encoded and rounded to the nearest byte); alpha and
// non-sRGB channels are averaged as integers, rounded to nearest with ties up. Fails (one line) when
// a side is 0 or over MAX_TEXTURE_DIM.
Result<SceneTexture> makeTexture(std::string name, uint32_t width, uint32_t height, const uint8_t* rgba8,
                                 bool srgb, TextureSampler sampler);

// An image file or an encoded image in memory, decoded by stb_image and passed to makeTexture. The
// file must be a regular file of at most kMaxImageFileBytes (safe_file.h), checked before it is read.
// The header is read first: an image over MAX_TEXTURE_DIM per side or 2^28 texels is refused before it
// is decoded. Errors are one line naming `path` / `name`.
Result<SceneTexture> loadTextureFile(const std::string& path, bool srgb, TextureSampler sampler);
Result<SceneTexture> loadTextureMemory(const std::string& name, const uint8_t* bytes, size_t size, bool srgb,
                                       TextureSampler sampler);

// Whether a loadTextureFile / loadTextureMemory failure was the size limit (the header is readable
// and claims a larger image) rather than an unreadable or corrupt file. Scene loaders only warn about
// the latter but fail on the former: drawing such a scene without its texture would hide the problem.
bool isTextureSizeError(const Error& error);

// The linear value of each sRGB byte (the exact EOTF computed in double, rounded to float): 256
// entries, uploaded as BUF_SRGB_TABLE.
std::vector<float> srgbDecodeTable();

}  // namespace sr

#endif  // RASTER_TEXTURE_H
