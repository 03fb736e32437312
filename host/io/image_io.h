// image_io.h - PNG colour images and EXR AOVs.
//
// PNG: 8-bit RGBA, written through libpng at a chosen speed (PngCompression), read through stb (Debian's
// libstb). NPY: the same RGBA8 pixels as a NumPy (H, W, 4) uint8 array, uncompressed. EXR: through tinyexr,
// with a UINT channel `id` (triangle id, 0xFFFFFFFF for background) and a FLOAT channel `Z` (window
// depth, 1.0 background), plus, when the renderer was asked for them (RenderSettings::surfaceAovs), the FLOAT
// surface channels `bary.u`, `bary.v`, `uv.u`, `uv.v`, `N.x`, `N.y`, `N.z` (see AovImage; 0 on background),
// the HALF colour channels `R`, `G`, `B`, `A` (linear), and with anti-aliasing and --aov-samples every
// sample's `id.s<k>` and `Z.s<k>`. Both formats carry an ImageOrigin: PNG tEXt chunks, EXR string attributes.
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

// One plane per channel, row-major from the top row. The surface channels come in three groups (bary,
// uv, normal), each either empty (not computed, or absent from the file) or one value per pixel in
// every one of its channels; files written without them keep the two-channel layout of old files.
struct AovImage {
    uint32_t width = 0, height = 0;
    std::vector<uint32_t> id;  // EXR `id`
    std::vector<float> depth;  // EXR `Z`
    // EXR `bary.u`, `bary.v`: perspective-correct barycentrics of vertices 1 and 2 at the pixel centre
    // (vertex 0's weight is 1 - u - v).
    std::vector<float> baryU, baryV;
    // EXR `uv.u`, `uv.v`: base colour texture coordinates after the material's KHR_texture_transform;
    // 0 where the triangle's material has no texture.
    std::vector<float> uvU, uvV;
    // EXR `N.x`, `N.y`, `N.z`: unit view-space shading normal, facing the viewer.
    std::vector<float> normalX, normalY, normalZ;
    // EXR `R`, `G`, `B`, `A` (HALF in the file): the frame's linear colour, as linearColorAov decodes it
    // from the 8-bit sRGB image (the pipeline keeps no other copy of it).
    std::vector<float> colorR, colorG, colorB, colorA;
    // EXR `ao`: the ambient occlusion shade used (--ao gtao or reference), 1 = unoccluded; the mean of the
    // pixel's raster pixels with SSAA. Empty without AO.
    std::vector<float> ao;

    // EXR `id.s<k>` (UINT) and `Z.s<k>` (FLOAT), written only when asked for (--aov-samples): the id and
    // depth of every sample of the pixel, k = (j * ssaa + i) * msaa + s for sample s of raster pixel
    // (i, j) of the pixel's ssaa x ssaa block. One plane per k; empty when not written.
    std::vector<std::vector<uint32_t>> sampleId;
    std::vector<std::vector<float>> sampleDepth;

    bool hasBary() const { return !baryU.empty(); }
    bool hasUv() const { return !uvU.empty(); }
    bool hasNormal() const { return !normalX.empty(); }
    bool hasColor() const { return !colorR.empty(); }
    bool hasAo() const { return !ao.empty(); }
};

// Which backend and device made an image, so that `raster compare` can apply the tolerance documented for
// the pair (io/compare.h). Written as PNG tEXt chunks and EXR string attributes named kOriginBackendKey
// and kOriginDeviceKey; empty fields are not written, and read back empty where a file has none.
struct ImageOrigin {
    std::string backend;  // "cuda", "vulkan" or "vulkan-graphics"
    std::string device;   // the device's name as its API reports it
    bool empty() const { return backend.empty() && device.empty(); }
};
constexpr const char* kOriginBackendKey = "raster:backend";
constexpr const char* kOriginDeviceKey = "raster:device";

// How hard the PNG encoder works: the pixels are the same (lossless), the file's size and the time to
// write it are not. Fast: zlib level 1, no row filter (of the level-1 settings the quickest on a rendered
// frame; the Up filter saves 15% of the size for 10-25% more time, docs/batch.md); default: level 6 with
// libpng's adaptive filter choice per row; small: level 9, every filter tried per row.
enum class PngCompression { Fast, Default, Small };
// "fast", "default", "small" (the values of --png-compression and png_compression).
const std::vector<std::string>& pngCompressionNames();
const char* pngCompressionName(PngCompression compression);
// The compression `name` stands for, or a one-line error naming `option` and the allowed values.
Result<PngCompression> parsePngCompression(const std::string& name, const std::string& option);

// The EXR's codec (tinyexr's lossless ones): none (the quickest, the largest), rle, zips (zlib per
// scanline), zip (zlib per 16 scanlines: today's and the default), piz (wavelet, for noisy images).
enum class ExrCompression { None, Rle, Zips, Zip, Piz };
const std::vector<std::string>& exrCompressionNames();
const char* exrCompressionName(ExrCompression compression);
Result<ExrCompression> parseExrCompression(const std::string& name, const std::string& option);

// How a frame's image files are encoded (--png-compression, --exr-compression; a manifest's
// png_compression and exr_compression): only the files' size and the time to write them change, never
// their pixels.
struct ImageEncoding {
    PngCompression png = PngCompression::Default;
    ExrCompression exr = ExrCompression::Zip;
};

// The help of --png-compression and --exr-compression (render and batch).
std::string pngCompressionHelp();
std::string exrCompressionHelp();

// The extensions a colour output may have, each selecting its format: ".png" or ".npy".
const std::vector<std::string>& colorExtensions();
// Whether the colour output `path` is written as NPY (it ends in .npy) rather than PNG.
bool isNpyPath(const std::string& path);
// An error unless `path` (empty: none) ends in one of colorExtensions(): "LABEL 'PATH' must end in .png
// or .npy".
Status checkColorExtension(const std::string& label, const std::string& path);

Status writePng(const std::string& path, const RgbaImage& image, const ImageOrigin& origin = {},
                PngCompression compression = PngCompression::Default);
// The bytes writePng writes, in memory (`raster batch` encodes on its I/O threads and times the write
// apart).
Result<std::vector<unsigned char>> encodePng(const RgbaImage& image, const ImageOrigin& origin = {},
                                             PngCompression compression = PngCompression::Default);
// The image as a NumPy .npy file (format 1.0): an (height, width, 4) uint8 array in C order, R G B A per
// pixel, the header padded to a multiple of 64 bytes as the format asks. It carries no origin (the format
// has no room for metadata beside the array).
Result<std::vector<unsigned char>> encodeNpy(const RgbaImage& image);
Status writeNpy(const std::string& path, const RgbaImage& image);
Result<RgbaImage> readPng(const std::string& path);  // any PNG, expanded to RGBA8
// The origin a PNG's tEXt chunks record (empty fields for a PNG without them).
Result<ImageOrigin> readPngOrigin(const std::string& path);
Status writeAovExr(const std::string& path, const AovImage& aov, const ImageOrigin& origin = {},
                   ExrCompression compression = ExrCompression::Zip);
// The bytes writeAovExr writes, in memory; `path` names the file in errors.
Result<std::vector<unsigned char>> encodeAovExr(const AovImage& aov, const ImageOrigin& origin,
                                                const std::string& path,
                                                ExrCompression compression = ExrCompression::Zip);
// Needs the `id` and `Z` channels; reads each surface and colour group whose channels are all present,
// and fails on a group with only some of them (a file cut short or renamed by another tool).
Result<AovImage> readAovExr(const std::string& path);
// The origin an EXR's header attributes record (empty fields for a file without them).
Result<ImageOrigin> readExrOrigin(const std::string& path);

// The linear value of each 8-bit sRGB code (the exact inverse transfer function, in double, rounded to
// float once): what linearColorAov stores.
float srgbCodeToLinear(uint32_t code);
// Fills `aov`'s colour channels from the sRGB image: each 8-bit code decoded exactly (srgbCodeToLinear),
// alpha as code / 255. Encoding a value back with the shaders' linearToSrgb gives the same code, so the
// EXR's colour is the PNG's, in linear light, to the precision of the 8-bit image.
void linearColorAov(const RgbaImage& image, AovImage& aov);

}  // namespace sr

#endif  // RASTER_IMAGE_IO_H
