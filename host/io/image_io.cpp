// image_io.cpp - PNG through stb, the id/depth AOV EXR through tinyexr.
#include "io/image_io.h"

#include <stb_image.h>
#include <stb_image_write.h>
#include <tinyexr.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

namespace sr {
namespace {

// Both libraries fail on open without saying why; the OS does.
Status checkReadable(const std::string& path)
{
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return makeError(ExitCode::Usage, "cannot read '{}': {}", path, std::strerror(errno));
    std::fclose(f);
    return okStatus();
}

Status checkSize(const std::string& path, uint32_t width, uint32_t height, size_t count, const char* what)
{
    if (width == 0 || height == 0 || width > (1u << 16) || height > (1u << 16) ||
        count != size_t(width) * height) {
        return makeError(ExitCode::Usage, "cannot write '{}': {} holds {} values for {}x{}", path, what,
                         count, width, height);
    }
    return okStatus();
}

// Takes ownership of a tinyexr error string and returns it as a std::string.
std::string takeExrError(const char* err, int code)
{
    std::string text = err ? err : fmt::format("tinyexr error {}", code);
    if (err) FreeEXRErrorMessage(err);
    return text;
}

// Frees what tinyexr allocated into a header or image when the scope ends.
struct ExrHeaderGuard {
    EXRHeader* header;
    ~ExrHeaderGuard() { FreeEXRHeader(header); }
};
struct ExrImageGuard {
    EXRImage* image;
    ~ExrImageGuard() { FreeEXRImage(image); }
};

constexpr const char* kDepthChannel = "Z";
constexpr const char* kIdChannel = "id";

}  // namespace

Status writePng(const std::string& path, const RgbaImage& image)
{
    SR_TRY(checkSize(path, image.width, image.height, image.pixels.size(), "the image"));
    // Spelled out byte by byte so the file does not depend on the host's endianness.
    std::vector<unsigned char> bytes(image.pixels.size() * 4);
    for (size_t i = 0; i < image.pixels.size(); ++i)
        for (int c = 0; c < 4; ++c) bytes[4 * i + size_t(c)] = (image.pixels[i] >> (8 * c)) & 0xffu;
    errno = 0;
    int ok = stbi_write_png(path.c_str(), int(image.width), int(image.height), 4, bytes.data(),
                            int(image.width * 4));
    if (!ok) {
        return makeError(ExitCode::Usage, "cannot write '{}': {}", path,
                         errno ? std::strerror(errno) : "stb_image_write failed");
    }
    return okStatus();
}

Result<RgbaImage> readPng(const std::string& path)
{
    SR_TRY(checkReadable(path));
    int w = 0, h = 0, channels = 0;
    std::unique_ptr<stbi_uc, void (*)(void*)> data(stbi_load(path.c_str(), &w, &h, &channels, 4),
                                                   stbi_image_free);
    if (!data) return makeError(ExitCode::Usage, "cannot read '{}': {}", path, stbi_failure_reason());
    RgbaImage image;
    image.width = uint32_t(w);
    image.height = uint32_t(h);
    image.pixels.resize(size_t(w) * size_t(h));
    const stbi_uc* p = data.get();
    for (size_t i = 0; i < image.pixels.size(); ++i, p += 4)
        image.pixels[i] = uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
    return image;
}

Status writeAovExr(const std::string& path, const AovImage& aov)
{
    SR_TRY(checkSize(path, aov.width, aov.height, aov.id.size(), "the id channel"));
    SR_TRY(checkSize(path, aov.width, aov.height, aov.depth.size(), "the depth channel"));

    // OpenEXR wants channels sorted by name: "Z" < "id" in ASCII. ZIP is lossless, so ids and
    // depth bits survive exactly.
    EXRChannelInfo channels[2] = {};
    std::strcpy(channels[0].name, kDepthChannel);
    std::strcpy(channels[1].name, kIdChannel);
    int pixelTypes[2] = {TINYEXR_PIXELTYPE_FLOAT, TINYEXR_PIXELTYPE_UINT};
    int requestedTypes[2] = {TINYEXR_PIXELTYPE_FLOAT, TINYEXR_PIXELTYPE_UINT};

    EXRHeader header;
    InitEXRHeader(&header);
    header.num_channels = 2;
    header.channels = channels;
    header.pixel_types = pixelTypes;
    header.requested_pixel_types = requestedTypes;
    header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;
    header.data_window = {0, 0, int(aov.width) - 1, int(aov.height) - 1};
    header.display_window = header.data_window;

    unsigned char* planes[2] = {
        reinterpret_cast<unsigned char*>(const_cast<float*>(aov.depth.data())),
        reinterpret_cast<unsigned char*>(const_cast<uint32_t*>(aov.id.data())),
    };
    EXRImage image;
    InitEXRImage(&image);
    image.num_channels = 2;
    image.images = planes;
    image.width = int(aov.width);
    image.height = int(aov.height);

    const char* err = nullptr;
    errno = 0;
    int rc = SaveEXRImageToFile(&image, &header, path.c_str(), &err);
    if (rc != TINYEXR_SUCCESS) {
        int savedErrno = errno;
        std::string reason = takeExrError(err, rc);
        if (savedErrno) reason += fmt::format(" ({})", std::strerror(savedErrno));
        return makeError(ExitCode::Usage, "cannot write '{}': {}", path, reason);
    }
    return okStatus();
}

Result<AovImage> readAovExr(const std::string& path)
{
    SR_TRY(checkReadable(path));
    auto fail = [&](const std::string& reason) {
        return makeError(ExitCode::Usage, "cannot read '{}': {}", path, reason);
    };
    EXRVersion version;
    int rc = ParseEXRVersionFromFile(&version, path.c_str());
    if (rc != TINYEXR_SUCCESS) return fail("not an OpenEXR file");
    if (version.multipart || version.non_image || version.tiled)
        return fail("multi-part, deep or tiled EXR files are not supported");

    EXRHeader header;
    InitEXRHeader(&header);
    const char* err = nullptr;
    rc = ParseEXRHeaderFromFile(&header, &version, path.c_str(), &err);
    if (rc != TINYEXR_SUCCESS) return fail(takeExrError(err, rc));
    ExrHeaderGuard headerGuard{&header};

    int depthChannel = -1, idChannel = -1;
    for (int c = 0; c < header.num_channels; ++c) {
        if (std::strcmp(header.channels[c].name, kDepthChannel) == 0) depthChannel = c;
        if (std::strcmp(header.channels[c].name, kIdChannel) == 0) idChannel = c;
        // Half channels come back as float; UINT and FLOAT stay as stored.
        if (header.pixel_types[c] == TINYEXR_PIXELTYPE_HALF)
            header.requested_pixel_types[c] = TINYEXR_PIXELTYPE_FLOAT;
    }
    if (depthChannel < 0 || idChannel < 0) return fail("the file needs both an 'id' and a 'Z' channel");
    if (header.pixel_types[idChannel] != TINYEXR_PIXELTYPE_UINT)
        return fail("channel 'id' is not of type UINT");
    if (header.pixel_types[depthChannel] == TINYEXR_PIXELTYPE_UINT)
        return fail("channel 'Z' is not of type FLOAT or HALF");

    EXRImage image;
    InitEXRImage(&image);
    rc = LoadEXRImageFromFile(&image, &header, path.c_str(), &err);
    if (rc != TINYEXR_SUCCESS) return fail(takeExrError(err, rc));
    ExrImageGuard imageGuard{&image};
    if (!image.images || image.width <= 0 || image.height <= 0)
        return fail("the file holds no scanline image");

    AovImage aov;
    aov.width = uint32_t(image.width);
    aov.height = uint32_t(image.height);
    size_t count = size_t(image.width) * size_t(image.height);
    aov.id.resize(count);
    aov.depth.resize(count);
    std::memcpy(aov.id.data(), image.images[idChannel], count * sizeof(uint32_t));
    std::memcpy(aov.depth.data(), image.images[depthChannel], count * sizeof(float));
    return aov;
}

}  // namespace sr
