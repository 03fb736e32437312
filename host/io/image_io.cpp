// image_io.cpp - PNG through stb, the AOV EXR (id, depth and the surface channels) through tinyexr.
#include "io/image_io.h"

#include "io/file_write.h"

#include <stb_image.h>
#include <stb_image_write.h>
#include <tinyexr.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iterator>
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

// The surface channels by group: a group is written when computed and read when the file has all of
// its channels, so the reader and the writer share one table.
struct SurfaceGroup {
    const char* label;
    size_t count;
    const char* names[3];
    std::vector<float> AovImage::*planes[3];
};
const SurfaceGroup kSurfaceGroups[] = {
    {"bary", 2, {"bary.u", "bary.v", nullptr}, {&AovImage::baryU, &AovImage::baryV, nullptr}},
    {"uv", 2, {"uv.u", "uv.v", nullptr}, {&AovImage::uvU, &AovImage::uvV, nullptr}},
    {"N", 3, {"N.x", "N.y", "N.z"}, {&AovImage::normalX, &AovImage::normalY, &AovImage::normalZ}},
};

// One channel of the file being written.
struct ExrPlane {
    const char* name;
    int pixelType;  // TINYEXR_PIXELTYPE_*
    const void* data;
};

// RGBA bytes, spelled out byte by byte so the file does not depend on the host's endianness.
std::vector<unsigned char> rgbaBytes(const RgbaImage& image)
{
    std::vector<unsigned char> bytes(image.pixels.size() * 4);
    for (size_t i = 0; i < image.pixels.size(); ++i)
        for (int c = 0; c < 4; ++c) bytes[4 * i + size_t(c)] = (image.pixels[i] >> (8 * c)) & 0xffu;
    return bytes;
}

}  // namespace

Status writePng(const std::string& path, const RgbaImage& image)
{
    SR_TRY(checkSize(path, image.width, image.height, image.pixels.size(), "the image"));
    auto file = encodePng(image);
    if (!file) return file.error();
    return writeFileAtomically(path, file->data(), file->size());
}

Result<std::vector<unsigned char>> encodePng(const RgbaImage& image)
{
    SR_TRY(checkSize("a PNG in memory", image.width, image.height, image.pixels.size(), "the image"));
    const std::vector<unsigned char> bytes = rgbaBytes(image);
    std::vector<unsigned char> file;
    auto append = [](void* context, void* data, int size) {
        auto* out = static_cast<std::vector<unsigned char>*>(context);
        out->insert(out->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
    };
    // The same encoder and settings as stbi_write_png, so the bytes equal writePng's file.
    if (!stbi_write_png_to_func(append, &file, int(image.width), int(image.height), 4, bytes.data(),
                                int(image.width * 4)))
        return makeError(ExitCode::Usage, "cannot encode a {}x{} PNG: stb_image_write failed", image.width,
                         image.height);
    return file;
}

Result<RgbaImage> readPng(const std::string& path)
{
    SR_TRY(checkReadable(path));
    int w = 0, h = 0, channels = 0;
    std::unique_ptr<stbi_uc, void (*)(void*)> data(stbi_load(path.c_str(), &w, &h, &channels, 4),
                                                   stbi_image_free);
    if (!data)
        return makeError(ExitCode::Usage, "cannot read '{}': {}", path, printableText(stbi_failure_reason()));
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
    std::vector<ExrPlane> planes = {{kDepthChannel, TINYEXR_PIXELTYPE_FLOAT, aov.depth.data()},
                                    {kIdChannel, TINYEXR_PIXELTYPE_UINT, aov.id.data()}};
    for (const SurfaceGroup& group : kSurfaceGroups) {
        bool any = false;
        for (size_t c = 0; c < group.count; ++c) any = any || !(aov.*group.planes[c]).empty();
        if (!any) continue;  // not computed: the file keeps the layout it had without the group
        for (size_t c = 0; c < group.count; ++c) {
            const std::vector<float>& plane = aov.*group.planes[c];
            std::string what = fmt::format("the {} channel", group.names[c]);
            SR_TRY(checkSize(path, aov.width, aov.height, plane.size(), what.c_str()));
            planes.push_back({group.names[c], TINYEXR_PIXELTYPE_FLOAT, plane.data()});
        }
    }
    if (aov.sampleId.size() != aov.sampleDepth.size())
        return makeError(ExitCode::Usage, "cannot write '{}': {} sample id planes for {} depth planes", path,
                         aov.sampleId.size(), aov.sampleDepth.size());
    std::vector<std::string> sampleNames;  // the planes point into it: sized once, never reallocated
    sampleNames.reserve(2 * aov.sampleId.size());
    for (size_t k = 0; k < aov.sampleId.size(); ++k) {
        SR_TRY(checkSize(path, aov.width, aov.height, aov.sampleId[k].size(), "a sample id channel"));
        SR_TRY(checkSize(path, aov.width, aov.height, aov.sampleDepth[k].size(), "a sample depth channel"));
        sampleNames.push_back(fmt::format("{}.s{}", kIdChannel, k));
        planes.push_back({sampleNames.back().c_str(), TINYEXR_PIXELTYPE_UINT, aov.sampleId[k].data()});
        sampleNames.push_back(fmt::format("{}.s{}", kDepthChannel, k));
        planes.push_back({sampleNames.back().c_str(), TINYEXR_PIXELTYPE_FLOAT, aov.sampleDepth[k].data()});
    }
    // OpenEXR wants channels sorted by name (bytewise: "N.x" < "Z" < "bary.u" < "id" < "uv.u"). ZIP is
    // lossless, so ids and float bits survive exactly.
    std::sort(planes.begin(), planes.end(),
              [](const ExrPlane& a, const ExrPlane& b) { return std::strcmp(a.name, b.name) < 0; });

    const size_t n = planes.size();
    std::vector<EXRChannelInfo> channels(n);
    std::vector<int> pixelTypes(n);
    std::vector<unsigned char*> images(n);
    for (size_t c = 0; c < n; ++c) {
        channels[c] = {};
        std::strcpy(channels[c].name, planes[c].name);
        pixelTypes[c] = planes[c].pixelType;
        // tinyexr's image is not const, but saving only reads it.
        images[c] = static_cast<unsigned char*>(const_cast<void*>(planes[c].data));
    }
    std::vector<int> requestedTypes = pixelTypes;

    EXRHeader header;
    InitEXRHeader(&header);
    header.num_channels = int(n);
    header.channels = channels.data();
    header.pixel_types = pixelTypes.data();
    header.requested_pixel_types = requestedTypes.data();
    header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;
    header.data_window = {0, 0, int(aov.width) - 1, int(aov.height) - 1};
    header.display_window = header.data_window;

    EXRImage image;
    InitEXRImage(&image);
    image.num_channels = int(n);
    image.images = images.data();
    image.width = int(aov.width);
    image.height = int(aov.height);

    // Encoded in memory and written through the checked, atomic path (io/file_write.h).
    const char* err = nullptr;
    unsigned char* memory = nullptr;
    const size_t size = SaveEXRImageToMemory(&image, &header, &memory, &err);
    std::unique_ptr<unsigned char, void (*)(void*)> owned(memory, std::free);
    if (size == 0) return makeError(ExitCode::Usage, "cannot write '{}': {}", path, takeExrError(err, 0));
    return writeFileAtomically(path, memory, size);
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

    auto channelIndex = [&](const char* name) {
        for (int c = 0; c < header.num_channels; ++c)
            if (std::strcmp(header.channels[c].name, name) == 0) return c;
        return -1;
    };
    for (int c = 0; c < header.num_channels; ++c) {
        // Half channels come back as float; UINT and FLOAT stay as stored.
        if (header.pixel_types[c] == TINYEXR_PIXELTYPE_HALF)
            header.requested_pixel_types[c] = TINYEXR_PIXELTYPE_FLOAT;
    }
    int depthChannel = channelIndex(kDepthChannel), idChannel = channelIndex(kIdChannel);
    if (depthChannel < 0 || idChannel < 0) return fail("the file needs both an 'id' and a 'Z' channel");
    if (header.pixel_types[idChannel] != TINYEXR_PIXELTYPE_UINT)
        return fail("channel 'id' is not of type UINT");
    if (header.pixel_types[depthChannel] == TINYEXR_PIXELTYPE_UINT)
        return fail("channel 'Z' is not of type FLOAT or HALF");
    // Surface groups: all channels of a group, or none (files from before them, or written without).
    int surfaceChannels[std::size(kSurfaceGroups)][3] = {};
    for (size_t g = 0; g < std::size(kSurfaceGroups); ++g) {
        const SurfaceGroup& group = kSurfaceGroups[g];
        const char* present = nullptr;
        const char* missing = nullptr;
        for (size_t c = 0; c < group.count; ++c) {
            int index = channelIndex(group.names[c]);
            surfaceChannels[g][c] = index;
            if (index >= 0)
                present = group.names[c];
            else
                missing = group.names[c];
            if (index >= 0 && header.pixel_types[index] == TINYEXR_PIXELTYPE_UINT)
                return fail(fmt::format("channel '{}' is not of type FLOAT or HALF", group.names[c]));
        }
        if (present && missing)
            return fail(fmt::format("channel '{}' without '{}' (the {} channels come together)", present,
                                    missing, group.label));
    }

    // Sample channels: id.s0 / Z.s0, id.s1 / Z.s1, ... up to the first k without both.
    std::vector<std::pair<int, int>> sampleChannels;
    for (size_t k = 0;; ++k) {
        int id = channelIndex(fmt::format("{}.s{}", kIdChannel, k).c_str());
        int depth = channelIndex(fmt::format("{}.s{}", kDepthChannel, k).c_str());
        if (id < 0 || depth < 0) break;
        if (header.pixel_types[id] != TINYEXR_PIXELTYPE_UINT ||
            header.pixel_types[depth] == TINYEXR_PIXELTYPE_UINT)
            return fail(fmt::format("sample channels id.s{0} / Z.s{0} are not of types UINT / FLOAT", k));
        sampleChannels.push_back({id, depth});
    }

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
    for (size_t g = 0; g < std::size(kSurfaceGroups); ++g) {
        const SurfaceGroup& group = kSurfaceGroups[g];
        for (size_t c = 0; c < group.count; ++c) {
            int index = surfaceChannels[g][c];
            if (index < 0) continue;
            std::vector<float>& plane = aov.*group.planes[c];
            plane.resize(count);
            std::memcpy(plane.data(), image.images[index], count * sizeof(float));
        }
    }
    for (auto [id, depth] : sampleChannels) {
        aov.sampleId.emplace_back(count);
        aov.sampleDepth.emplace_back(count);
        std::memcpy(aov.sampleId.back().data(), image.images[id], count * sizeof(uint32_t));
        std::memcpy(aov.sampleDepth.back().data(), image.images[depth], count * sizeof(float));
    }
    return aov;
}

}  // namespace sr
