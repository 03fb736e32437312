// gltf_files.cpp - the glTF loader's file access and tinygltf's messages: every file through readRegularFile,
// images kept encoded until a material needs them, tinygltf's wording turned into the loader's, and the
// JSON's nesting bounded before tinygltf parses it.
#include "loaders/gltf_internal.h"

#include <sys/stat.h>

#include <cstring>

#include "loaders/safe_file.h"

namespace sr::gltf {

// Keeps the still encoded bytes of images given by URI (external files, data URIs) instead of decoding
// them: only the images that used materials need are decoded, later, so that a broken or exotic image
// costs a warning about its texture rather than the whole file. Images in buffer views are read later
// from the validated buffers, since tinygltf passes them on without checking that the view lies inside
// its buffer. Always succeeds, so tinygltf never fails a load over an image. `failures` is the
// ImageFailures the reasons go to.
bool keepEncodedImage(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void* failures)
{
    if (image->bufferView >= 0 || !bytes) return true;
    if (size > 0) {
        image->image.assign(bytes, bytes + size);
        image->as_is = true;
    } else if (size < 0) {
        // tinygltf narrows the length to an int: a file of 2 GiB or more arrives negative.
        (*static_cast<ImageFailures*>(failures))[index] =
            fmt::format("the file is over the limit of {} bytes for an image", kMaxImageFileBytes);
    }
    return true;
}

// tinygltf reports a file its callback could not read as "File read error : <path> : <reason>"; the
// reason (readWholeFile's message) names the path already.
std::string withoutReadErrorPrefix(const std::string& line)
{
    static const std::string kPrefix = "File read error : ";
    if (line.rfind(kPrefix, 0) != 0) return line;
    size_t reason = line.find(" : cannot read '", kPrefix.size());
    return reason == std::string::npos ? line : line.substr(reason + 3);
}

// Every line of a tinygltf message through withoutReadErrorPrefix.
std::string withoutReadErrorPrefixes(const std::string& text)
{
    std::string out;
    size_t start = 0;
    while (start < text.size()) {
        size_t end = std::min(text.find('\n', start), text.size());
        out += withoutReadErrorPrefix(text.substr(start, end - start)) + "\n";
        start = end + 1;
    }
    return out;
}

// tinygltf's messages about external images it could not read, without those lines: the loader reports
// each unreadable image once itself, naming the image and what happens instead. Each failed image's
// reason (the file line that precedes "Failed to load external 'uri' for image[N]") goes to `failures`.
std::string withoutImageFileWarnings(const std::string& warn, ImageFailures& failures)
{
    static const std::string kImageFailed = "Failed to load external 'uri' for image[";
    struct FileLine {
        const char* prefix;
        const char* reason;  // nullptr: the rest of the line, without withoutReadErrorPrefix's prefix
    };
    static const FileLine kFileLines[] = {
        {"File not found : ", "file not found"},
        {"File read error : ", nullptr},
        {"File is empty : ", "the file is empty"},
    };
    std::string out, pending;
    size_t start = 0;
    while (start < warn.size()) {
        size_t end = std::min(warn.find('\n', start), warn.size());
        std::string line = warn.substr(start, end - start);
        start = end + 1;
        bool drop = line.rfind("Image data is empty for image[", 0) == 0;
        for (const FileLine& file : kFileLines) {
            if (line.rfind(file.prefix, 0) != 0) continue;
            pending = file.reason ? std::string(file.reason) : withoutReadErrorPrefix(line);
            drop = true;
        }
        if (line.rfind(kImageFailed, 0) == 0) {
            int index = std::atoi(line.c_str() + kImageFailed.size());
            if (!pending.empty()) failures.emplace(index, pending);
            pending.clear();
            drop = true;
        }
        if (!drop) out += line + "\n";
    }
    return out;
}

// tinygltf's file access, replaced: its own opens with a blocking fopen (a FIFO without a writer
// stalls the load forever) and takes the size of a directory as 2^63 - 1 bytes (std::bad_alloc).
// Every file a glTF names is read through readRegularFile instead.
bool fileExists(const std::string& path, void*)
{
    // Whatever exists counts, so that readWholeFile says what is wrong with a directory or a FIFO
    // instead of tinygltf calling it "not found".
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0;
}

std::string expandFilePath(const std::string& path, void*)
{
    return path;
}

bool readWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void*)
{
    Result<std::vector<unsigned char>> bytes = readRegularFile(path, kMaxSceneFileBytes, "read");
    if (!bytes) {
        if (err) *err += bytes.error().message;
        return false;
    }
    *out = std::move(*bytes);
    return true;
}

bool writeNothing(std::string* err, const std::string& path, const std::vector<unsigned char>&, void*)
{
    if (err) *err += fmt::format("the scene loader does not write files ('{}')", path);
    return false;
}

// glTF JSON nested deeper than this is refused before tinygltf parses it: tinygltf recurses per level
// (its conversion of `extras` and extensions into tinygltf::Value), and 20,000 levels, a 40 KB file,
// overflow an 8 MiB stack. glTF's own structure needs fewer than 10 levels; 512 leave `extras` room and
// load within a 384 KiB stack (measured on the Release build), far inside a thread's default 8 MiB.
constexpr size_t kMaxJsonDepth = 512;

// Fails when `text` nests arrays and objects more than kMaxJsonDepth deep. Brackets inside strings do
// not count (a string ends at a quote that no backslash escapes). The text need not be valid JSON:
// tinygltf reports whatever else is wrong with it.
Status checkJsonDepth(const unsigned char* text, size_t size)
{
    size_t depth = 0;
    bool inString = false;
    for (size_t i = 0; i < size; ++i) {
        unsigned char c = text[i];
        if (inString) {
            if (c == '\\')
                ++i;
            else if (c == '"')
                inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxJsonDepth)
                return fail(
                    fmt::format("its JSON nests arrays and objects more than {} levels deep (at byte {})",
                                kMaxJsonDepth, i));
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return okStatus();
}

// The JSON of a .gltf file (all of it) or of a .glb (its JSON chunk, as far as the file holds it; a
// malformed header is left to tinygltf), as a pointer and a length.
std::pair<const unsigned char*, size_t> jsonText(const std::vector<unsigned char>& file, bool binary)
{
    if (!binary) return {file.data(), file.size()};
    constexpr size_t kJsonChunk = 20;  // 12-byte header, then the chunk's length and type
    if (file.size() < kJsonChunk) return {file.data(), 0};
    uint32_t length = 0;
    for (int k = 3; k >= 0; --k) length = length << 8 | file[12 + size_t(k)];
    return {file.data() + kJsonChunk, std::min(size_t(length), file.size() - kJsonChunk)};
}

}  // namespace sr::gltf
