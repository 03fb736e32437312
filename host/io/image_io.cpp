// image_io.cpp - PNG written through libpng and read through stb, NPY by hand, the AOV EXR (id, depth and
// the surface channels) through tinyexr.
#include "io/image_io.h"

#include "io/file_write.h"

#include <png.h>
#include <stb_image.h>
#include <tinyexr.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
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

// The optional channel groups: a group is written when filled and read when the file has all of its
// channels, so the reader and the writer share one table. The colour is HALF, as OpenEXR images
// usually are (11 significant bits hold every 8-bit sRGB code's linear value apart, linearColorAov).
struct ChannelGroup {
    const char* label;
    size_t count;
    const char* names[4];
    std::vector<float> AovImage::*planes[4];
    int filePixelType;  // TINYEXR_PIXELTYPE_FLOAT or _HALF
};
const ChannelGroup kChannelGroups[] = {
    {"bary",
     2,
     {"bary.u", "bary.v", nullptr, nullptr},
     {&AovImage::baryU, &AovImage::baryV, nullptr, nullptr},
     TINYEXR_PIXELTYPE_FLOAT},
    {"uv",
     2,
     {"uv.u", "uv.v", nullptr, nullptr},
     {&AovImage::uvU, &AovImage::uvV, nullptr, nullptr},
     TINYEXR_PIXELTYPE_FLOAT},
    {"N",
     3,
     {"N.x", "N.y", "N.z", nullptr},
     {&AovImage::normalX, &AovImage::normalY, &AovImage::normalZ, nullptr},
     TINYEXR_PIXELTYPE_FLOAT},
    {"colour",
     4,
     {"R", "G", "B", "A"},
     {&AovImage::colorR, &AovImage::colorG, &AovImage::colorB, &AovImage::colorA},
     TINYEXR_PIXELTYPE_HALF},
    {"ao",
     1,
     {"ao", nullptr, nullptr, nullptr},
     {&AovImage::ao, nullptr, nullptr, nullptr},
     TINYEXR_PIXELTYPE_FLOAT},
};

// One channel of the file being written.
struct ExrPlane {
    const char* name;
    int pixelType;  // TINYEXR_PIXELTYPE_* of `data`
    const void* data;
    int filePixelType;  // ... stored in the file (tinyexr converts FLOAT to HALF)
};

// A tEXt value must be Latin-1 without NUL; device names are ASCII, anything else becomes '?'.
std::string latin1Text(const std::string& text)
{
    std::string out = text;
    for (char& c : out)
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
    return out;
}

// The origin's (key, value) pairs that are set, in file order.
std::vector<std::pair<const char*, std::string>> originFields(const ImageOrigin& origin)
{
    std::vector<std::pair<const char*, std::string>> fields;
    if (!origin.backend.empty()) fields.push_back({kOriginBackendKey, origin.backend});
    if (!origin.device.empty()) fields.push_back({kOriginDeviceKey, origin.device});
    return fields;
}

void setOriginField(ImageOrigin& origin, const std::string& key, const std::string& value)
{
    if (key == kOriginBackendKey) origin.backend = value;
    if (key == kOriginDeviceKey) origin.device = value;
}

// One row's RGBA bytes, spelled out byte by byte so the file does not depend on the host's endianness.
void rgbaRow(const RgbaImage& image, uint32_t y, unsigned char* row)
{
    const uint32_t* p = image.pixels.data() + size_t(y) * image.width;
    for (uint32_t x = 0; x < image.width; ++x)
        for (int c = 0; c < 4; ++c) row[4 * size_t(x) + size_t(c)] = (p[x] >> (8 * c)) & 0xffu;
}

// What one libpng encode needs and gives back, reached from libpng's callbacks through its pointers.
struct PngEncode {
    const RgbaImage* image = nullptr;
    int level = 6;    // zlib level
    int filters = 0;  // PNG_FILTER_* mask: libpng tries each per row and keeps the cheapest
    const png_text* text = nullptr;
    int textCount = 0;
    std::vector<unsigned char>* file = nullptr;
    unsigned char* row = nullptr;  // one row of RGBA bytes
    char error[256] = {};
};

[[noreturn]] void pngFailed(png_structp png, png_const_charp message)
{
    auto* encode = static_cast<PngEncode*>(png_get_error_ptr(png));
    std::snprintf(encode->error, sizeof encode->error, "%s", message ? message : "libpng error");
    png_longjmp(png, 1);
}

// libpng warns only about what it corrects itself (such as text it shortens); the file is still right.
void pngWarned(png_structp, png_const_charp) {}

void pngAppend(png_structp png, png_bytep data, size_t size)
{
    auto* encode = static_cast<PngEncode*>(png_get_io_ptr(png));
    encode->file->insert(encode->file->end(), data, data + size);
}

void pngFlush(png_structp) {}

// The encode itself. libpng reports errors by longjmp to the setjmp here, so this function holds no
// object with a destructor: what it skips on the way out is only plain data.
bool runPngEncode(PngEncode& encode)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &encode, pngFailed, pngWarned);
    if (!png) {
        std::snprintf(encode.error, sizeof encode.error, "libpng could not start (out of memory)");
        return false;
    }
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_destroy_write_struct(&png, nullptr);
        std::snprintf(encode.error, sizeof encode.error, "libpng could not start (out of memory)");
        return false;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return false;
    }
    png_set_write_fn(png, &encode, pngAppend, pngFlush);
    const RgbaImage& image = *encode.image;
    png_set_IHDR(png, info, image.width, image.height, 8, PNG_COLOR_TYPE_RGB_ALPHA, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(png, encode.level);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, encode.filters);
    // Written by png_write_info, before the first IDAT, where readPngOrigin looks for them.
    if (encode.textCount > 0) png_set_text(png, info, encode.text, encode.textCount);
    png_write_info(png, info);
    for (uint32_t y = 0; y < image.height; ++y) {
        rgbaRow(image, y, encode.row);
        png_write_row(png, encode.row);
    }
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return true;
}

// "a, b or c" for messages.
std::string choiceList(const std::vector<std::string>& names)
{
    std::string text;
    for (size_t i = 0; i < names.size(); ++i)
        text += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
    return text;
}

template <typename Enum>
Result<Enum> parseChoice(const std::vector<std::string>& names, const std::string& name,
                         const std::string& option)
{
    for (size_t i = 0; i < names.size(); ++i)
        if (names[i] == name) return Enum(i);
    return makeError(ExitCode::Usage, "{} must be {}, not {}", option, choiceList(names), quotedInput(name));
}

}  // namespace

const std::vector<std::string>& pngCompressionNames()
{
    static const std::vector<std::string> names = {"fast", "default", "small"};
    return names;
}

const char* pngCompressionName(PngCompression compression)
{
    return pngCompressionNames()[size_t(compression)].c_str();
}

Result<PngCompression> parsePngCompression(const std::string& name, const std::string& option)
{
    return parseChoice<PngCompression>(pngCompressionNames(), name, option);
}

const std::vector<std::string>& exrCompressionNames()
{
    static const std::vector<std::string> names = {"none", "rle", "zips", "zip", "piz"};
    return names;
}

const char* exrCompressionName(ExrCompression compression)
{
    return exrCompressionNames()[size_t(compression)].c_str();
}

Result<ExrCompression> parseExrCompression(const std::string& name, const std::string& option)
{
    return parseChoice<ExrCompression>(exrCompressionNames(), name, option);
}

const std::vector<std::string>& colorExtensions()
{
    static const std::vector<std::string> extensions = {".png", ".npy"};
    return extensions;
}

bool isNpyPath(const std::string& path)
{
    return hasExtension(path, ".npy");
}

Status checkColorExtension(const std::string& label, const std::string& path)
{
    if (path.empty()) return okStatus();
    for (const std::string& extension : colorExtensions())
        if (hasExtension(path, extension)) return okStatus();
    return makeError(ExitCode::Usage, "{} {} must end in .png or .npy", label, quotedInput(path));
}

Status writePng(const std::string& path, const RgbaImage& image, const ImageOrigin& origin,
                PngCompression compression)
{
    SR_TRY(checkSize(path, image.width, image.height, image.pixels.size(), "the image"));
    auto file = encodePng(image, origin, compression);
    if (!file) return file.error();
    return writeFileAtomically(path, file->data(), file->size());
}

Result<std::vector<unsigned char>> encodePng(const RgbaImage& image, const ImageOrigin& origin,
                                             PngCompression compression)
{
    SR_TRY(checkSize("a PNG in memory", image.width, image.height, image.pixels.size(), "the image"));
    PngEncode encode;
    encode.image = &image;
    switch (compression) {
    case PngCompression::Fast:
        encode.level = 1;
        encode.filters = PNG_FILTER_NONE;
        break;
    case PngCompression::Default:
        encode.level = 6;
        encode.filters = PNG_ALL_FILTERS;
        break;
    case PngCompression::Small:
        encode.level = 9;
        encode.filters = PNG_ALL_FILTERS;
        break;
    }
    // libpng keeps pointers to the keys and values until the file is written.
    const auto fields = originFields(origin);
    std::vector<std::string> values;
    values.reserve(fields.size());
    std::vector<png_text> text(fields.size());
    for (size_t i = 0; i < fields.size(); ++i) {
        values.push_back(latin1Text(fields[i].second));
        text[i] = {};
        text[i].compression = PNG_TEXT_COMPRESSION_NONE;
        text[i].key = const_cast<char*>(fields[i].first);
        text[i].text = values.back().data();
        text[i].text_length = values.back().size();
    }
    encode.text = text.data();
    encode.textCount = int(text.size());
    std::vector<unsigned char> row(size_t(image.width) * 4);
    encode.row = row.data();
    std::vector<unsigned char> file;
    // Deflate at the fast setting shrinks a rendered frame to about a third of its raw size: start there.
    file.reserve(image.pixels.size() + 1024);
    encode.file = &file;
    if (!runPngEncode(encode))
        return makeError(ExitCode::Usage, "cannot encode a {}x{} PNG: {}", image.width, image.height,
                         printableText(encode.error));
    return file;
}

Result<std::vector<unsigned char>> encodeNpy(const RgbaImage& image)
{
    SR_TRY(checkSize("an NPY in memory", image.width, image.height, image.pixels.size(), "the image"));
    // Format 1.0: the magic "\x93NUMPY", the version 1 0, the header's length (little-endian uint16),
    // then the header: a Python dict literal, padded with spaces and ended by '\n' so that the array
    // starts at a multiple of 64 bytes (numpy can then map it aligned). Its keys in numpy's order.
    std::string header = fmt::format("{{'descr': '|u1', 'fortran_order': False, 'shape': ({}, {}, 4), }}",
                                     image.height, image.width);
    constexpr size_t kPrefix = 10;  // magic, version, length
    const size_t total = (kPrefix + header.size() + 1 + 63) / 64 * 64;
    header.append(total - kPrefix - header.size() - 1, ' ');
    header.push_back('\n');
    std::vector<unsigned char> file;
    file.reserve(total + image.pixels.size() * 4);
    static const unsigned char kMagic[8] = {0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0};
    file.insert(file.end(), kMagic, kMagic + 8);
    file.push_back(header.size() & 0xffu);
    file.push_back(header.size() >> 8);
    file.insert(file.end(), header.begin(), header.end());
    file.resize(total + image.pixels.size() * 4);
    for (uint32_t y = 0; y < image.height; ++y)
        rgbaRow(image, y, file.data() + total + size_t(y) * image.width * 4);
    return file;
}

Status writeNpy(const std::string& path, const RgbaImage& image)
{
    SR_TRY(checkSize(path, image.width, image.height, image.pixels.size(), "the image"));
    auto file = encodeNpy(image);
    if (!file) return file.error();
    return writeFileAtomically(path, file->data(), file->size());
}

Result<ImageOrigin> readPngOrigin(const std::string& path)
{
    SR_TRY(checkReadable(path));
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), std::fclose);
    if (!f) return makeError(ExitCode::Usage, "cannot read '{}': {}", path, std::strerror(errno));
    static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    unsigned char head[8];
    if (std::fread(head, 1, 8, f.get()) != 8 || std::memcmp(head, kSignature, 8) != 0)
        return makeError(ExitCode::Usage, "cannot read '{}': not a PNG file", path);
    ImageOrigin origin;
    // Chunks up to the first IDAT (text after the pixels is not ours); a file cut short has no origin.
    for (;;) {
        unsigned char header[8];
        if (std::fread(header, 1, 8, f.get()) != 8) break;
        const uint32_t length = uint32_t(header[0]) << 24 | uint32_t(header[1]) << 16 |
                                uint32_t(header[2]) << 8 | uint32_t(header[3]);
        const std::string type(reinterpret_cast<const char*>(header + 4), 4);
        if (type == "IDAT" || type == "IEND") break;
        if (type == "tEXt" && length <= 4096) {
            std::string data(length, '\0');
            if (std::fread(data.data(), 1, length, f.get()) != length) break;
            const size_t nul = data.find('\0');
            if (nul != std::string::npos) setOriginField(origin, data.substr(0, nul), data.substr(nul + 1));
            if (std::fseek(f.get(), 4, SEEK_CUR) != 0) break;  // the CRC
            continue;
        }
        if (std::fseek(f.get(), long(length) + 4, SEEK_CUR) != 0) break;
    }
    return origin;
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

Status writeAovExr(const std::string& path, const AovImage& aov, const ImageOrigin& origin,
                   ExrCompression compression)
{
    auto file = encodeAovExr(aov, origin, path, compression);
    if (!file) return file.error();
    return writeFileAtomically(path, file->data(), file->size());
}

Result<std::vector<unsigned char>> encodeAovExr(const AovImage& aov, const ImageOrigin& origin,
                                                const std::string& path, ExrCompression compression)
{
    SR_TRY(checkSize(path, aov.width, aov.height, aov.id.size(), "the id channel"));
    SR_TRY(checkSize(path, aov.width, aov.height, aov.depth.size(), "the depth channel"));
    std::vector<ExrPlane> planes = {
        {kDepthChannel, TINYEXR_PIXELTYPE_FLOAT, aov.depth.data(), TINYEXR_PIXELTYPE_FLOAT},
        {kIdChannel, TINYEXR_PIXELTYPE_UINT, aov.id.data(), TINYEXR_PIXELTYPE_UINT}};
    for (const ChannelGroup& group : kChannelGroups) {
        bool any = false;
        for (size_t c = 0; c < group.count; ++c) any = any || !(aov.*group.planes[c]).empty();
        if (!any) continue;  // not computed: the file keeps the layout it had without the group
        for (size_t c = 0; c < group.count; ++c) {
            const std::vector<float>& plane = aov.*group.planes[c];
            std::string what = fmt::format("the {} channel", group.names[c]);
            SR_TRY(checkSize(path, aov.width, aov.height, plane.size(), what.c_str()));
            planes.push_back({group.names[c], TINYEXR_PIXELTYPE_FLOAT, plane.data(), group.filePixelType});
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
        planes.push_back({sampleNames.back().c_str(), TINYEXR_PIXELTYPE_UINT, aov.sampleId[k].data(),
                          TINYEXR_PIXELTYPE_UINT});
        sampleNames.push_back(fmt::format("{}.s{}", kDepthChannel, k));
        planes.push_back({sampleNames.back().c_str(), TINYEXR_PIXELTYPE_FLOAT, aov.sampleDepth[k].data(),
                          TINYEXR_PIXELTYPE_FLOAT});
    }
    // OpenEXR wants channels sorted by name (bytewise: "A" < "N.x" < "R" < "Z" < "bary.u" < "id" <
    // "uv.u"). Every codec offered is lossless, so ids and float bits survive exactly.
    std::sort(planes.begin(), planes.end(),
              [](const ExrPlane& a, const ExrPlane& b) { return std::strcmp(a.name, b.name) < 0; });

    const size_t n = planes.size();
    std::vector<EXRChannelInfo> channels(n);
    std::vector<int> pixelTypes(n), requestedTypes(n);
    std::vector<unsigned char*> images(n);
    for (size_t c = 0; c < n; ++c) {
        channels[c] = {};
        std::strcpy(channels[c].name, planes[c].name);
        pixelTypes[c] = planes[c].pixelType;
        requestedTypes[c] = planes[c].filePixelType;
        // tinyexr's image is not const, but saving only reads it.
        images[c] = static_cast<unsigned char*>(const_cast<void*>(planes[c].data));
    }
    // The origin as string attributes (tinyexr writes custom attributes as given: name, type, bytes).
    const auto fields = originFields(origin);
    std::vector<EXRAttribute> attributes(fields.size());
    for (size_t i = 0; i < fields.size(); ++i) {
        attributes[i] = {};
        std::strcpy(attributes[i].name, fields[i].first);
        std::strcpy(attributes[i].type, "string");
        attributes[i].value = reinterpret_cast<unsigned char*>(const_cast<char*>(fields[i].second.data()));
        attributes[i].size = int(fields[i].second.size());
    }

    EXRHeader header;
    InitEXRHeader(&header);
    header.num_channels = int(n);
    header.channels = channels.data();
    header.pixel_types = pixelTypes.data();
    header.requested_pixel_types = requestedTypes.data();
    static const int kCodecs[] = {TINYEXR_COMPRESSIONTYPE_NONE, TINYEXR_COMPRESSIONTYPE_RLE,
                                  TINYEXR_COMPRESSIONTYPE_ZIPS, TINYEXR_COMPRESSIONTYPE_ZIP,
                                  TINYEXR_COMPRESSIONTYPE_PIZ};
    header.compression_type = kCodecs[size_t(compression)];
    header.data_window = {0, 0, int(aov.width) - 1, int(aov.height) - 1};
    header.display_window = header.data_window;
    header.num_custom_attributes = int(attributes.size());
    header.custom_attributes = attributes.empty() ? nullptr : attributes.data();

    EXRImage image;
    InitEXRImage(&image);
    image.num_channels = int(n);
    image.images = images.data();
    image.width = int(aov.width);
    image.height = int(aov.height);

    // Encoded in memory; the caller writes it through the checked, atomic path (io/file_write.h).
    const char* err = nullptr;
    unsigned char* memory = nullptr;
    const size_t size = SaveEXRImageToMemory(&image, &header, &memory, &err);
    std::unique_ptr<unsigned char, void (*)(void*)> owned(memory, std::free);
    if (size == 0) return makeError(ExitCode::Usage, "cannot write '{}': {}", path, takeExrError(err, 0));
    return std::vector<unsigned char>(memory, memory + size);
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
    // Optional groups: all channels of a group, or none (files from before them, or written without).
    int groupChannels[std::size(kChannelGroups)][4] = {};
    for (size_t g = 0; g < std::size(kChannelGroups); ++g) {
        const ChannelGroup& group = kChannelGroups[g];
        const char* present = nullptr;
        const char* missing = nullptr;
        for (size_t c = 0; c < group.count; ++c) {
            int index = channelIndex(group.names[c]);
            groupChannels[g][c] = index;
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
    for (size_t g = 0; g < std::size(kChannelGroups); ++g) {
        const ChannelGroup& group = kChannelGroups[g];
        for (size_t c = 0; c < group.count; ++c) {
            int index = groupChannels[g][c];
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

Result<ImageOrigin> readExrOrigin(const std::string& path)
{
    SR_TRY(checkReadable(path));
    EXRVersion version;
    if (ParseEXRVersionFromFile(&version, path.c_str()) != TINYEXR_SUCCESS)
        return makeError(ExitCode::Usage, "cannot read '{}': not an OpenEXR file", path);
    if (version.multipart || version.non_image) return ImageOrigin{};
    EXRHeader header;
    InitEXRHeader(&header);
    const char* err = nullptr;
    int rc = ParseEXRHeaderFromFile(&header, &version, path.c_str(), &err);
    if (rc != TINYEXR_SUCCESS)
        return makeError(ExitCode::Usage, "cannot read '{}': {}", path, takeExrError(err, rc));
    ExrHeaderGuard headerGuard{&header};
    ImageOrigin origin;
    for (int i = 0; i < header.num_custom_attributes; ++i) {
        const EXRAttribute& a = header.custom_attributes[i];
        if (std::strcmp(a.type, "string") != 0 || a.size < 0 || !a.value) continue;
        setOriginField(origin, a.name, std::string(reinterpret_cast<const char*>(a.value), size_t(a.size)));
    }
    return origin;
}

float srgbCodeToLinear(uint32_t code)
{
    const double c = std::min(code, 255u) / 255.0;
    return float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

void linearColorAov(const RgbaImage& image, AovImage& aov)
{
    static const std::array<float, 256> decode = [] {
        std::array<float, 256> t{};
        for (uint32_t b = 0; b < 256; ++b) t[b] = srgbCodeToLinear(b);
        return t;
    }();
    const size_t n = image.pixels.size();
    for (auto* plane : {&aov.colorR, &aov.colorG, &aov.colorB, &aov.colorA}) plane->resize(n);
    for (size_t i = 0; i < n; ++i) {
        const uint32_t p = image.pixels[i];
        aov.colorR[i] = decode[p & 0xffu];
        aov.colorG[i] = decode[(p >> 8) & 0xffu];
        aov.colorB[i] = decode[(p >> 16) & 0xffu];
        aov.colorA[i] = float(p >> 24) / 255.0f;  // alpha is linear coverage, never sRGB-encoded
    }
}

std::string pngCompressionHelp()
{
    return "PNG encoder: fast (zlib level 1, no row filter: several times quicker, files 1.5-2x larger), "
           "default (level 6, adaptive filters) or small (level 9, every filter tried per row: slowest, "
           "under 2% smaller); the pixels are the same";
}

std::string exrCompressionHelp()
{
    return "EXR codec, all lossless: none (quick, largest), rle (about as quick, several times smaller: the "
           "fast choice), zips (zlib per scanline), zip (zlib per 16 scanlines, the default) or piz "
           "(wavelet)";
}

}  // namespace sr
