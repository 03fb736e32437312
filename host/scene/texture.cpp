// texture.cpp - image decoding (stb_image) and mip chain generation for SceneTexture.
//
// stb_image's implementation lives in Debian's libstb (linked through PkgConfig::STB), so this file
// only includes the header, like io/image_io.cpp.
#include "scene/texture.h"

#include <stb_image.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstring>
#include <memory>

#include "raster_shared.h"
#include "loaders/safe_file.h"

namespace sr {
namespace {

// Every size-limit message contains this phrase; isTextureSizeError looks for it, so that callers can
// tell a refused size (fatal for a scene) from an unreadable image (a warning) without a new Error field.
constexpr const char* kSizeLimitPhrase = "exceeds the texture size limit";
constexpr uint64_t kMaxTexels = uint64_t(1) << 28;

double srgbToLinear(double c)
{
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

double linearToSrgb(double l)
{
    return l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
}

uint32_t encodeExact(double linear)
{
    double s = std::floor(linearToSrgb(linear) * 255.0 + 0.5);
    return uint32_t(std::clamp(s, 0.0, 255.0));
}

// The sRGB tables in double: decode[b] is byte b's linear value; threshold[b] the linear value at which
// the rounded encoding steps from b to b + 1. Encoding by binary search over the thresholds avoids a
// pow() per channel per texel (a 16384^2 chain would otherwise take seconds); values within rounding
// distance of a threshold take the exact formula, so the result always equals encodeExact.
struct SrgbTables {
    std::array<double, 256> decode{};
    std::array<double, 255> threshold{};

    SrgbTables()
    {
        for (int b = 0; b < 256; ++b) decode[size_t(b)] = srgbToLinear(b / 255.0);
        for (int b = 0; b < 255; ++b) threshold[size_t(b)] = srgbToLinear((b + 0.5) / 255.0);
    }

    uint32_t encode(double linear) const
    {
        auto it = std::upper_bound(threshold.begin(), threshold.end(), linear);
        size_t b = size_t(it - threshold.begin());
        auto near = [&](size_t t) {
            return t < threshold.size() && std::fabs(linear - threshold[t]) <= 1e-9;
        };
        if ((b > 0 && near(b - 1)) || near(b)) return encodeExact(linear);
        return uint32_t(b);
    }
};

const SrgbTables& srgbTables()
{
    static const SrgbTables tables;
    return tables;
}

std::string tooLarge(const std::string& name, uint64_t width, uint64_t height)
{
    return fmt::format("image '{}' is {}x{}, which {} ({} per side, 2^28 texels)", name, width, height,
                       kSizeLimitPhrase, MAX_TEXTURE_DIM);
}

bool sizeWithinLimits(uint64_t width, uint64_t height)
{
    return width <= MAX_TEXTURE_DIM && height <= MAX_TEXTURE_DIM && width * height <= kMaxTexels;
}

// The size an encoded PNG or JPEG claims, read by hand from its header. stb_image refuses to even
// report the size of an image whose decoded form would pass 1 GiB, and its failure reason is then
// overwritten by the other formats it tries, so a huge image would read as a corrupt one; these two
// formats (the ones glTF allows) are checked here first. False when the header is not recognised.
bool headerSize(const uint8_t* bytes, size_t size, uint64_t& width, uint64_t& height)
{
    auto be16 = [&](size_t at) { return uint64_t(bytes[at]) << 8 | uint64_t(bytes[at + 1]); };
    auto be32 = [&](size_t at) { return be16(at) << 16 | be16(at + 2); };
    static const uint8_t kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (size >= 24 && std::memcmp(bytes, kPng, 8) == 0 && std::memcmp(bytes + 12, "IHDR", 4) == 0) {
        width = be32(16);
        height = be32(20);
        return true;
    }
    if (size < 4 || bytes[0] != 0xff || bytes[1] != 0xd8) return false;
    // JPEG: walk the marker segments up to the first start-of-frame (SOF0..SOF15 but DHT, JPG, DAC).
    size_t at = 2;
    while (at + 4 <= size) {
        if (bytes[at] != 0xff) return false;
        uint8_t marker = bytes[at + 1];
        if (marker == 0xff) {  // fill byte
            ++at;
            continue;
        }
        if (marker == 0x01 || (marker >= 0xd0 && marker <= 0xd8)) {  // no length
            at += 2;
            continue;
        }
        size_t length = size_t(be16(at + 2));
        bool sof = marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
        if (sof) {
            if (at + 9 > size || length < 7) return false;
            height = be16(at + 5);
            width = be16(at + 7);
            return true;
        }
        if (length < 2) return false;
        at += 2 + length;
    }
    return false;
}
}  // namespace

Result<SceneTexture> makeTexture(std::string name, uint32_t width, uint32_t height, const uint8_t* rgba8,
                                 bool srgb, TextureSampler sampler)
{
    if (width == 0 || height == 0)
        return makeError(ExitCode::Usage, "image '{}' has an empty size {}x{}", name, width, height);
    if (!sizeWithinLimits(width, height)) return Error{tooLarge(name, width, height), ExitCode::Usage};

    SceneTexture texture;
    texture.name = std::move(name);
    texture.width = width;
    texture.height = height;
    texture.srgb = srgb;
    texture.sampler = sampler;
    texture.levels = 1;
    for (uint32_t m = std::max(width, height); m > 1; m >>= 1) ++texture.levels;

    auto levelWidth = [&](uint32_t k) { return std::max(1u, width >> k); };
    auto levelHeight = [&](uint32_t k) { return std::max(1u, height >> k); };
    size_t total = 0;
    for (uint32_t k = 0; k < texture.levels; ++k) total += size_t(levelWidth(k)) * levelHeight(k);
    texture.texels.resize(total);

    size_t count0 = size_t(width) * height;
    for (size_t i = 0; i < count0; ++i) {
        const uint8_t* p = rgba8 + 4 * i;
        texture.texels[i] =
            uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
    }

    const SrgbTables& tables = srgbTables();
    size_t srcOffset = 0;
    for (uint32_t k = 0; k + 1 < texture.levels; ++k) {
        uint32_t sw = levelWidth(k), sh = levelHeight(k);
        uint32_t dw = levelWidth(k + 1), dh = levelHeight(k + 1);
        size_t dstOffset = srcOffset + size_t(sw) * sh;
        const uint32_t* src = texture.texels.data() + srcOffset;
        uint32_t* dst = texture.texels.data() + dstOffset;
        for (uint32_t y = 0; y < dh; ++y) {
            // At the border of an odd-sized level (or a level one texel wide) the second row/column
            // is clamped onto the first; the set of distinct texels is then 2x1, 1x2 or 1x1.
            uint32_t y0 = 2 * y, y1 = std::min(2 * y + 1, sh - 1);
            for (uint32_t x = 0; x < dw; ++x) {
                uint32_t x0 = 2 * x, x1 = std::min(2 * x + 1, sw - 1);
                uint32_t taps[4];
                uint32_t n = 0;
                taps[n++] = src[size_t(y0) * sw + x0];
                if (x1 != x0) taps[n++] = src[size_t(y0) * sw + x1];
                if (y1 != y0) {
                    taps[n++] = src[size_t(y1) * sw + x0];
                    if (x1 != x0) taps[n++] = src[size_t(y1) * sw + x1];
                }
                uint32_t out = 0;
                for (int c = 0; c < 4; ++c) {
                    uint32_t value;
                    if (srgb && c < 3) {
                        double sum = 0.0;
                        for (uint32_t i = 0; i < n; ++i) sum += tables.decode[(taps[i] >> (8 * c)) & 255u];
                        value = tables.encode(sum / n);
                    } else {
                        uint32_t sum = 0;
                        for (uint32_t i = 0; i < n; ++i) sum += (taps[i] >> (8 * c)) & 255u;
                        value = (sum + n / 2) / n;
                    }
                    out |= value << (8 * c);
                }
                dst[size_t(y) * dw + x] = out;
            }
        }
        srcOffset = dstOffset;
    }
    return texture;
}

Result<SceneTexture> loadTextureMemory(const std::string& name, const uint8_t* bytes, size_t size, bool srgb,
                                       TextureSampler sampler)
{
    if (!bytes || size == 0) return makeError(ExitCode::Usage, "image '{}' is empty", name);
    if (size > size_t(INT_MAX))
        return makeError(ExitCode::Usage, "image '{}' is too large a file ({} bytes)", name, size);
    int len = int(size);
    uint64_t claimedWidth = 0, claimedHeight = 0;
    if (headerSize(bytes, size, claimedWidth, claimedHeight) &&
        !sizeWithinLimits(claimedWidth, claimedHeight))
        return Error{tooLarge(name, claimedWidth, claimedHeight), ExitCode::Usage};
    int w = 0, h = 0, channels = 0;
    if (!stbi_info_from_memory(bytes, len, &w, &h, &channels)) {
        const char* reason = stbi_failure_reason();
        return makeError(ExitCode::Usage, "cannot decode image '{}': {}", name,
                         reason ? printableText(reason) : "unknown format");
    }
    if (w <= 0 || h <= 0)
        return makeError(ExitCode::Usage, "cannot decode image '{}': empty size {}x{}", name, w, h);
    if (!sizeWithinLimits(uint64_t(w), uint64_t(h)))
        return Error{tooLarge(name, uint64_t(w), uint64_t(h)), ExitCode::Usage};

    std::unique_ptr<stbi_uc, void (*)(void*)> data(stbi_load_from_memory(bytes, len, &w, &h, &channels, 4),
                                                   stbi_image_free);
    if (!data) {
        const char* reason = stbi_failure_reason();
        return makeError(ExitCode::Usage, "cannot decode image '{}': {}", name,
                         reason ? printableText(reason) : "unknown error");
    }
    // The header and the decoded image agree for every format stb reads; checked anyway, since the
    // sizes below index the decoded buffer.
    if (w <= 0 || h <= 0 || !sizeWithinLimits(uint64_t(w), uint64_t(h)))
        return Error{tooLarge(name, uint64_t(std::max(w, 0)), uint64_t(std::max(h, 0))), ExitCode::Usage};
    return makeTexture(name, uint32_t(w), uint32_t(h), data.get(), srgb, sampler);
}

Result<SceneTexture> loadTextureFile(const std::string& path, bool srgb, TextureSampler sampler)
{
    Result<std::vector<unsigned char>> bytes = readRegularFile(path, kMaxImageFileBytes, "read image");
    if (!bytes) return bytes.error();
    return loadTextureMemory(path, bytes->data(), bytes->size(), srgb, sampler);
}

bool isTextureSizeError(const Error& error)
{
    return error.message.find(kSizeLimitPhrase) != std::string::npos;
}

std::vector<float> srgbDecodeTable()
{
    std::vector<float> table(256);
    for (int b = 0; b < 256; ++b) table[size_t(b)] = float(srgbToLinear(b / 255.0));
    return table;
}

}  // namespace sr
