// image_io_test.cpp - PNG and AOV EXR round trips (id, Z and the optional surface channels) must be bit
// exact; failures are one-line errors.
#include <stdlib.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <map>
#include <fstream>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "test_util.h"
#include <tinyexr.h>

#include "io/image_io.h"
#include "raster_shared.h"

namespace sr {
namespace {

template <typename T>
void expectOneLineError(const Result<T>& result, const std::string& path)
{
    ASSERT_FALSE(result.ok());
    EXPECT_NE(result.error().message.find("'" + path + "'"), std::string::npos) << result.error().message;
    EXPECT_EQ(result.error().message.find('\n'), std::string::npos);
}

float floatFromBits(uint32_t bits)
{
    float f;
    std::memcpy(&f, &bits, sizeof f);
    return f;
}

uint32_t bitsOf(float f)
{
    uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    return bits;
}

TEST(ImageIo, PngRoundTripIsExact)
{
    RgbaImage image;
    image.width = 37;  // odd sizes catch row-stride mistakes
    image.height = 23;
    std::mt19937 rng(1234);
    for (uint32_t i = 0; i < image.width * image.height; ++i) image.pixels.push_back(rng());
    image.pixels[0] = 0x000000ffu;            // pure red, transparent
    image.pixels[1] = 0xff00ff00u;            // pure green, opaque
    image.pixels[image.width] = 0x80ff0000u;  // first pixel of row 1: blue
    test::ScratchDir dir("sr_image");
    std::string path = dir.file("round.png");
    ASSERT_TRUE(writePng(path, image).ok());
    Result<RgbaImage> back = readPng(path);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->width, image.width);
    EXPECT_EQ(back->height, image.height);
    EXPECT_EQ(back->pixels, image.pixels);
}

TEST(ImageIo, PngErrors)
{
    test::ScratchDir dir("sr_image");
    std::string missing = dir.file("missing.png");
    expectOneLineError(readPng(missing), missing);

    std::string notPng = dir.file("text.png");
    std::ofstream(notPng) << "this is not an image\n";
    expectOneLineError(readPng(notPng), notPng);

    RgbaImage image;
    image.width = 2;
    image.height = 2;
    image.pixels.assign(4, 0xffffffffu);
    std::string noDir = dir.file("no/such/dir/out.png");
    expectOneLineError(writePng(noDir, image), noDir);

    image.pixels.pop_back();  // 3 pixels for 2x2
    std::string wrongSize = dir.file("wrong.png");
    expectOneLineError(writePng(wrongSize, image), wrongSize);
}

TEST(ImageIo, AovExrRoundTripIsBitExact)
{
    AovImage aov;
    aov.width = 19;
    aov.height = 11;
    size_t n = size_t(aov.width) * aov.height;
    std::mt19937 rng(99);
    for (size_t i = 0; i < n; ++i) {
        aov.id.push_back(rng());
        // Random bit patterns cover denormals, infinities and NaNs with payloads.
        aov.depth.push_back(floatFromBits(rng()));
    }
    aov.id[0] = 0xffffffffu;
    aov.id[1] = 0u;
    aov.id[2] = 0x7fffffffu;
    aov.depth[0] = 1.0f;
    aov.depth[1] = 0.0f;
    aov.depth[2] = floatFromBits(0x80000000u);  // -0
    aov.depth[3] = floatFromBits(0x00000001u);  // smallest denormal
    aov.depth[4] = floatFromBits(0x7fc00001u);  // quiet NaN with payload
    aov.depth[5] = 0.99999994f;                 // largest float below 1

    test::ScratchDir dir("sr_image");
    std::string path = dir.file("aov.exr");
    Status written = writeAovExr(path, aov);
    ASSERT_TRUE(written.ok()) << written.error().message;
    Result<AovImage> back = readAovExr(path);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->width, aov.width);
    EXPECT_EQ(back->height, aov.height);
    EXPECT_EQ(back->id, aov.id);
    ASSERT_EQ(back->depth.size(), n);
    for (size_t i = 0; i < n; ++i) ASSERT_EQ(bitsOf(back->depth[i]), bitsOf(aov.depth[i])) << "pixel " << i;
}

TEST(ImageIo, AovExrIsAnOrdinaryScanlineFile)
{
    AovImage aov;
    aov.width = 4;
    aov.height = 3;
    aov.id.assign(12, 7u);
    aov.depth.assign(12, 0.5f);
    test::ScratchDir dir("sr_image");
    std::string path = dir.file("layout.exr");
    ASSERT_TRUE(writeAovExr(path, aov).ok());

    // Read the header with tinyexr directly: two channels, the expected types, lossless.
    EXRVersion version;
    ASSERT_EQ(ParseEXRVersionFromFile(&version, path.c_str()), TINYEXR_SUCCESS);
    EXPECT_FALSE(version.tiled);
    EXPECT_FALSE(version.multipart);
    EXRHeader header;
    InitEXRHeader(&header);
    const char* err = nullptr;
    ASSERT_EQ(ParseEXRHeaderFromFile(&header, &version, path.c_str(), &err), TINYEXR_SUCCESS);
    ASSERT_EQ(header.num_channels, 2);
    EXPECT_STREQ(header.channels[0].name, "Z");
    EXPECT_EQ(header.pixel_types[0], TINYEXR_PIXELTYPE_FLOAT);
    EXPECT_STREQ(header.channels[1].name, "id");
    EXPECT_EQ(header.pixel_types[1], TINYEXR_PIXELTYPE_UINT);
    EXPECT_TRUE(header.compression_type == TINYEXR_COMPRESSIONTYPE_ZIP ||
                header.compression_type == TINYEXR_COMPRESSIONTYPE_NONE);
    FreeEXRHeader(&header);
}

TEST(ImageIo, AovExrErrors)
{
    test::ScratchDir dir("sr_image");
    std::string missing = dir.file("missing.exr");
    expectOneLineError(readAovExr(missing), missing);

    std::string notExr = dir.file("text.exr");
    std::ofstream(notExr) << "not an exr\n";
    expectOneLineError(readAovExr(notExr), notExr);

    // A valid EXR without the id channel (plain RGBA written by tinyexr).
    std::string rgba = dir.file("rgba.exr");
    std::vector<float> pixels(2 * 2 * 4, 0.25f);
    const char* err = nullptr;
    ASSERT_EQ(SaveEXR(pixels.data(), 2, 2, 4, 0, rgba.c_str(), &err), TINYEXR_SUCCESS);
    Result<AovImage> noId = readAovExr(rgba);
    expectOneLineError(noId, rgba);
    if (!noId.ok()) {
        EXPECT_NE(noId.error().message.find("'id'"), std::string::npos);
    }

    AovImage aov;
    aov.width = 2;
    aov.height = 2;
    aov.id.assign(4, 1u);
    aov.depth.assign(3, 1.0f);
    std::string wrongSize = dir.file("wrong.exr");
    expectOneLineError(Result<Unit>(writeAovExr(wrongSize, aov)), wrongSize);

    aov.depth.assign(4, 1.0f);
    std::string noDir = dir.file("no/such/dir/out.exr");
    expectOneLineError(Result<Unit>(writeAovExr(noDir, aov)), noDir);
}

// Random float bits, NaN payloads and signed zeros included, for a plane of n values.
std::vector<float> randomPlane(std::mt19937& rng, size_t n)
{
    std::vector<float> plane;
    for (size_t i = 0; i < n; ++i) plane.push_back(floatFromBits(rng()));
    return plane;
}

AovImage surfaceAov(uint32_t w, uint32_t h)
{
    AovImage aov;
    aov.width = w;
    aov.height = h;
    size_t n = size_t(w) * h;
    std::mt19937 rng(7);
    for (size_t i = 0; i < n; ++i) aov.id.push_back(rng());
    aov.depth = randomPlane(rng, n);
    for (std::vector<float>* plane :
         {&aov.baryU, &aov.baryV, &aov.uvU, &aov.uvV, &aov.normalX, &aov.normalY, &aov.normalZ})
        *plane = randomPlane(rng, n);
    aov.baryU[0] = floatFromBits(0x7fc00001u);  // quiet NaN with payload
    aov.uvV[1] = floatFromBits(0x80000000u);    // -0
    return aov;
}

std::vector<uint32_t> planeBits(const std::vector<float>& plane)
{
    std::vector<uint32_t> bits;
    for (float f : plane) bits.push_back(bitsOf(f));
    return bits;
}

TEST(ImageIo, AovExrSurfaceChannelsRoundTripBitExact)
{
    AovImage aov = surfaceAov(13, 7);
    test::ScratchDir dir("sr_image");
    std::string path = dir.file("surface.exr");
    Status written = writeAovExr(path, aov);
    ASSERT_TRUE(written.ok()) << written.error().message;
    Result<AovImage> back = readAovExr(path);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->id, aov.id);
    EXPECT_EQ(planeBits(back->depth), planeBits(aov.depth));
    EXPECT_EQ(planeBits(back->baryU), planeBits(aov.baryU));
    EXPECT_EQ(planeBits(back->baryV), planeBits(aov.baryV));
    EXPECT_EQ(planeBits(back->uvU), planeBits(aov.uvU));
    EXPECT_EQ(planeBits(back->uvV), planeBits(aov.uvV));
    EXPECT_EQ(planeBits(back->normalX), planeBits(aov.normalX));
    EXPECT_EQ(planeBits(back->normalY), planeBits(aov.normalY));
    EXPECT_EQ(planeBits(back->normalZ), planeBits(aov.normalZ));

    // The header: nine channels in OpenEXR's (bytewise) name order, only `id` UINT.
    EXRVersion version;
    ASSERT_EQ(ParseEXRVersionFromFile(&version, path.c_str()), TINYEXR_SUCCESS);
    EXRHeader header;
    InitEXRHeader(&header);
    const char* err = nullptr;
    ASSERT_EQ(ParseEXRHeaderFromFile(&header, &version, path.c_str(), &err), TINYEXR_SUCCESS);
    const char* names[] = {"N.x", "N.y", "N.z", "Z", "bary.u", "bary.v", "id", "uv.u", "uv.v"};
    ASSERT_EQ(header.num_channels, 9);
    for (int c = 0; c < 9; ++c) {
        EXPECT_STREQ(header.channels[c].name, names[c]);
        EXPECT_EQ(header.pixel_types[c], c == 6 ? TINYEXR_PIXELTYPE_UINT : TINYEXR_PIXELTYPE_FLOAT)
            << names[c];
    }
    FreeEXRHeader(&header);
}

TEST(ImageIo, AovExrSurfaceGroupsAreOptional)
{
    // Only the normal group: the file holds id, Z and N.*, and reads back without bary and uv.
    AovImage aov = surfaceAov(5, 4);
    aov.baryU.clear();
    aov.baryV.clear();
    aov.uvU.clear();
    aov.uvV.clear();
    test::ScratchDir dir("sr_image");
    std::string path = dir.file("normals.exr");
    ASSERT_TRUE(writeAovExr(path, aov).ok());
    Result<AovImage> back = readAovExr(path);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_FALSE(back->hasBary());
    EXPECT_FALSE(back->hasUv());
    ASSERT_TRUE(back->hasNormal());
    EXPECT_EQ(planeBits(back->normalZ), planeBits(aov.normalZ));
}

TEST(ImageIo, AovExrSurfaceErrors)
{
    test::ScratchDir dir("sr_image");
    AovImage aov = surfaceAov(4, 2);
    aov.uvV.pop_back();  // a plane of the wrong size
    std::string wrongSize = dir.file("wrong.exr");
    Status written = writeAovExr(wrongSize, aov);
    expectOneLineError(Result<Unit>(written), wrongSize);
    if (!written.ok()) {
        EXPECT_NE(written.error().message.find("uv.v"), std::string::npos) << written.error().message;
    }
    aov.uvV.clear();  // half a group
    expectOneLineError(Result<Unit>(writeAovExr(wrongSize, aov)), wrongSize);

    // A file with `bary.u` but no `bary.v`, written with tinyexr directly.
    std::vector<float> depth(4, 0.5f), baryU(4, 0.25f);
    std::vector<uint32_t> id(4, 3u);
    EXRChannelInfo channels[3] = {};
    std::strcpy(channels[0].name, "Z");
    std::strcpy(channels[1].name, "bary.u");
    std::strcpy(channels[2].name, "id");
    int types[3] = {TINYEXR_PIXELTYPE_FLOAT, TINYEXR_PIXELTYPE_FLOAT, TINYEXR_PIXELTYPE_UINT};
    EXRHeader header;
    InitEXRHeader(&header);
    header.num_channels = 3;
    header.channels = channels;
    header.pixel_types = types;
    header.requested_pixel_types = types;
    unsigned char* planes[3] = {reinterpret_cast<unsigned char*>(depth.data()),
                                reinterpret_cast<unsigned char*>(baryU.data()),
                                reinterpret_cast<unsigned char*>(id.data())};
    EXRImage image;
    InitEXRImage(&image);
    image.num_channels = 3;
    image.images = planes;
    image.width = 2;
    image.height = 2;
    std::string partial = dir.file("partial.exr");
    const char* err = nullptr;
    ASSERT_EQ(SaveEXRImageToFile(&image, &header, partial.c_str(), &err), TINYEXR_SUCCESS);
    Result<AovImage> read = readAovExr(partial);
    expectOneLineError(read, partial);
    if (!read.ok()) {
        EXPECT_NE(read.error().message.find("'bary.v'"), std::string::npos) << read.error().message;
    }
}

// CRC-32 of the PNG specification, bit by bit (no table), to check the chunks the writer adds.
uint32_t crc32Bitwise(const std::string& bytes)
{
    uint32_t c = 0xffffffffu;
    for (unsigned char b : bytes) {
        c ^= b;
        for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return ~c;
}

struct PngChunk {
    std::string type, data;
    uint32_t crc;
};

// Every chunk of a PNG file, parsed by hand.
std::vector<PngChunk> pngChunks(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    std::string file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    auto be32 = [&](size_t at) {
        return uint32_t(uint8_t(file[at])) << 24 | uint32_t(uint8_t(file[at + 1])) << 16 |
               uint32_t(uint8_t(file[at + 2])) << 8 | uint32_t(uint8_t(file[at + 3]));
    };
    std::vector<PngChunk> chunks;
    for (size_t at = 8; at + 12 <= file.size();) {
        const uint32_t length = be32(at);
        chunks.push_back({file.substr(at + 4, 4), file.substr(at + 8, length), be32(at + 8 + length)});
        at += 12 + length;
    }
    return chunks;
}

TEST(ImageIo, PngNamesItsBackendInTextChunksBeforeThePixels)
{
    ASSERT_EQ(crc32Bitwise("IEND"), 0xae426082u);  // the checker against the specification's value
    RgbaImage image;
    image.width = 5;
    image.height = 3;
    for (uint32_t i = 0; i < 15; ++i) image.pixels.push_back(0xff000000u | i * 0x010203u);
    test::ScratchDir dir("sr_image");
    const std::string path = dir.file("tagged.png"), plain = dir.file("plain.png");
    ASSERT_TRUE(writePng(path, image, {"vulkan-graphics", "llvmpipe (LLVM 15)"}).ok());
    ASSERT_TRUE(writePng(plain, image).ok());

    const std::vector<PngChunk> chunks = pngChunks(path);
    ASSERT_GE(chunks.size(), 5u);
    EXPECT_EQ(chunks[0].type, "IHDR");
    EXPECT_EQ(chunks[1].type, "tEXt");
    EXPECT_EQ(chunks[1].data, std::string("raster:backend\0vulkan-graphics", 30));
    EXPECT_EQ(chunks[2].type, "tEXt");
    EXPECT_EQ(chunks[2].data, std::string("raster:device\0llvmpipe (LLVM 15)", 32));
    for (const PngChunk& c : chunks) EXPECT_EQ(c.crc, crc32Bitwise(c.type + c.data)) << c.type;
    for (const PngChunk& c : pngChunks(plain)) EXPECT_NE(c.type, "tEXt");

    // The pixels are untouched, and the origin reads back; a PNG without it has none.
    auto back = readPng(path);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->pixels, image.pixels);
    auto origin = readPngOrigin(path);
    ASSERT_TRUE(origin.ok()) << origin.error().message;
    EXPECT_EQ(origin->backend, "vulkan-graphics");
    EXPECT_EQ(origin->device, "llvmpipe (LLVM 15)");
    auto none = readPngOrigin(plain);
    ASSERT_TRUE(none.ok());
    EXPECT_TRUE(none->empty());
    expectOneLineError(readPngOrigin(dir.file("missing.png")), dir.file("missing.png"));
}

TEST(ImageIo, EverySrgbCodeDecodesToALinearValueThatEncodesBack)
{
    // The sRGB definition (IEC 61966-2-1) at a few codes, by hand.
    EXPECT_EQ(srgbCodeToLinear(0), 0.0f);
    EXPECT_EQ(srgbCodeToLinear(255), 1.0f);
    EXPECT_NEAR(srgbCodeToLinear(10), 10.0 / 255.0 / 12.92, 1e-9);
    EXPECT_NEAR(srgbCodeToLinear(128), std::pow((128.0 / 255.0 + 0.055) / 1.055, 2.4), 1e-7);
    for (uint32_t code = 0; code < 256; ++code) {
        const float v = srgbCodeToLinear(code);
        // The shaders' own encode (common/shared/shade.h) gives the code back.
        EXPECT_EQ(packRgba8(vec3(v, v, v)) & 0xffu, code) << code;
    }
}

TEST(ImageIo, AovExrCarriesTheLinearColourAsHalfAndItsOrigin)
{
    // 256 pixels: every code in red, reversed in green, a ramp in blue, alpha from 0 to 255.
    RgbaImage image;
    image.width = 16;
    image.height = 16;
    for (uint32_t i = 0; i < 256; ++i)
        image.pixels.push_back(i | (255u - i) << 8 | ((i * 7u) & 255u) << 16 | i << 24);
    AovImage aov;
    aov.width = 16;
    aov.height = 16;
    aov.id.assign(256, 3u);
    aov.depth.assign(256, 0.25f);
    linearColorAov(image, aov);
    test::ScratchDir dir("sr_image");
    const std::string path = dir.file("colour.exr");
    ASSERT_TRUE(writeAovExr(path, aov, {"cuda", "NVIDIA H100"}).ok());

    // The file, through tinyexr directly: R, G, B, A are HALF; the origin is two string attributes.
    EXRVersion version;
    ASSERT_EQ(ParseEXRVersionFromFile(&version, path.c_str()), TINYEXR_SUCCESS);
    EXRHeader header;
    InitEXRHeader(&header);
    const char* err = nullptr;
    ASSERT_EQ(ParseEXRHeaderFromFile(&header, &version, path.c_str(), &err), TINYEXR_SUCCESS);
    int halves = 0;
    for (int c = 0; c < header.num_channels; ++c) {
        const std::string name = header.channels[c].name;
        if (name == "R" || name == "G" || name == "B" || name == "A") {
            EXPECT_EQ(header.pixel_types[c], TINYEXR_PIXELTYPE_HALF) << name;
            ++halves;
        }
    }
    EXPECT_EQ(halves, 4);
    std::map<std::string, std::string> attributes;
    for (int i = 0; i < header.num_custom_attributes; ++i) {
        const EXRAttribute& a = header.custom_attributes[i];
        if (std::string(a.type) == "string")
            attributes[a.name] = std::string(reinterpret_cast<const char*>(a.value), size_t(a.size));
    }
    FreeEXRHeader(&header);
    EXPECT_EQ(attributes["raster:backend"], "cuda");
    EXPECT_EQ(attributes["raster:device"], "NVIDIA H100");

    // Read back and encoded with the shaders' encode: the PNG's codes exactly; alpha as code / 255.
    auto back = readAovExr(path);
    ASSERT_TRUE(back.ok()) << back.error().message;
    ASSERT_TRUE(back->hasColor());
    for (uint32_t i = 0; i < 256; ++i) {
        const uint32_t rgb = packRgba8(vec3(back->colorR[i], back->colorG[i], back->colorB[i])) & 0xffffffu;
        EXPECT_EQ(rgb, image.pixels[i] & 0xffffffu) << i;
        EXPECT_EQ(uint32_t(std::lround(back->colorA[i] * 255.0f)), i) << i;
    }
    auto origin = readExrOrigin(path);
    ASSERT_TRUE(origin.ok());
    EXPECT_EQ(origin->backend, "cuda");
    EXPECT_EQ(origin->device, "NVIDIA H100");

    // A colour group cut short is refused, as the surface groups are.
    AovImage partial = aov;
    partial.colorA.clear();
    EXPECT_FALSE(writeAovExr(dir.file("partial.exr"), partial).ok());
}

}  // namespace
}  // namespace sr
