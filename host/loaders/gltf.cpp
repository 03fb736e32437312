// gltf.cpp - glTF 2.0 (.gltf, .glb) to the flat world-space triangle, segment and point lists,
// through tinygltf.
//
// Primitives of mode POINTS become Scene::points and those of the line modes (LINES, LINE_LOOP,
// LINE_STRIP) Scene::lines as segments, in document order, after the same attribute validation, node
// transform, COLOR_0 and material handling as triangles.
//
// tinygltf parses the JSON and resolves buffers (external files, data URIs, the GLB chunk); every
// index, offset and count it hands over is validated here before any byte is read, so a malformed
// file becomes a one-line error instead of an out-of-bounds read. The files themselves, the .gltf or
// .glb and every buffer and image it names, are read through readRegularFile (safe_file.h), never by
// tinygltf's own file functions, and the JSON's nesting depth is bounded before tinygltf parses it.
// The rules of the specification that tinygltf does not enforce are checked first (gltf_spec.h).
//
// Materials: base colour factor and texture (with KHR_texture_transform and its sampler), alpha mode,
// double-sidedness and emission (emissiveFactor, emissiveTexture without a transform,
// KHR_materials_emissive_strength); a primitive without a material gets glTF's default material (every
// property at its default: base colour 1), not defaultMaterial()'s grey. Images are decoded
// only when a used material needs them; an image that cannot be read or decoded is a warning (the material
// keeps its factor), one over the size limit an error.
#include <tiny_gltf.h>

#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>

#include "raster_shared.h"

#include "base/warnings.h"
#include "loaders/gltf_spec.h"
#include "loaders/safe_file.h"
#include "scene/scene.h"
#include "scene/texture.h"

namespace sr {
namespace {

// Stands for "no such vertex"; finalizeScene drops every triangle, segment or point that uses it and
// counts it.
constexpr uint32_t kInvalidIndex = 0xffffffffu;
// Same bound as finalizeScene's, checked early so a huge count fails before it is allocated.
constexpr size_t kMaxVertices = size_t(1) << 31;

Error fail(const std::string& reason)
{
    return Error{reason, ExitCode::Usage};
}

// Why each external image that could not be used failed, by image index: tinygltf only warns about
// such an image, in a wording of its own, and the loader's one warning per texture says why.
using ImageFailures = std::map<int, std::string>;

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

uint32_t wrapMode(int gltf)
{
    switch (gltf) {
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return WRAP_CLAMP_TO_EDGE;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return WRAP_MIRRORED_REPEAT;
    default: return WRAP_REPEAT;  // 10497 and anything invalid: glTF's default
    }
}

// A glTF sampler as TextureSampler; values the spec does not define fall back to its defaults
// (linear magnification, trilinear minification).
TextureSampler samplerOf(const tinygltf::Sampler& s)
{
    TextureSampler out;
    out.wrapS = wrapMode(s.wrapS);
    out.wrapT = wrapMode(s.wrapT);
    out.magFilter = s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST ? FILTER_NEAREST : FILTER_LINEAR;
    switch (s.minFilter) {
    case TINYGLTF_TEXTURE_FILTER_NEAREST:
        out.minFilter = FILTER_NEAREST;
        out.mipmapMode = MIPMAP_NONE;
        break;
    case TINYGLTF_TEXTURE_FILTER_LINEAR:
        out.minFilter = FILTER_LINEAR;
        out.mipmapMode = MIPMAP_NONE;
        break;
    case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST:
        out.minFilter = FILTER_NEAREST;
        out.mipmapMode = MIPMAP_NEAREST;
        break;
    case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_NEAREST:
        out.minFilter = FILTER_LINEAR;
        out.mipmapMode = MIPMAP_NEAREST;
        break;
    case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR:
        out.minFilter = FILTER_NEAREST;
        out.mipmapMode = MIPMAP_LINEAR;
        break;
    default:  // LINEAR_MIPMAP_LINEAR, undefined (-1) or invalid
        out.minFilter = FILTER_LINEAR;
        out.mipmapMode = MIPMAP_LINEAR;
        break;
    }
    return out;
}

// KHR_texture_transform of a textureInfo as T * R * S, column-major so that uv' = m * (u, v, 1). The
// rotation is counter-clockwise in UV space (v down): u' = cos u + sin v, v' = -sin u + cos v, the
// extension README's rows [cos, sin; -sin, cos] (its example, rotation pi/2 with offset (0, 1) and
// scale 0.5 selecting the lower left quadrant, pins the direction). `texCoord` is overridden when the
// extension gives one.
glm::mat3 textureTransform(const tinygltf::TextureInfo& info, int& texCoord)
{
    auto it = info.extensions.find("KHR_texture_transform");
    if (it == info.extensions.end() || !it->second.IsObject()) return glm::mat3(1.0f);
    const tinygltf::Value& ext = it->second;
    auto pair = [&](const char* key, double& a, double& b) {
        if (!ext.Has(key)) return;
        const tinygltf::Value& v = ext.Get(key);
        if (v.IsArray() && v.ArrayLen() == 2 && v.Get(0).IsNumber() && v.Get(1).IsNumber()) {
            a = v.Get(0).GetNumberAsDouble();
            b = v.Get(1).GetNumberAsDouble();
        }
    };
    double ox = 0.0, oy = 0.0, sx = 1.0, sy = 1.0, rotation = 0.0;
    pair("offset", ox, oy);
    pair("scale", sx, sy);
    if (ext.Has("rotation") && ext.Get("rotation").IsNumber())
        rotation = ext.Get("rotation").GetNumberAsDouble();
    if (ext.Has("texCoord") && ext.Get("texCoord").IsInt()) texCoord = ext.Get("texCoord").GetNumberAsInt();
    double c = std::cos(rotation), s = std::sin(rotation);
    glm::dmat3 t(1.0), r(1.0), scale(1.0);
    t[2] = glm::dvec3(ox, oy, 1.0);
    r[0] = glm::dvec3(c, -s, 0.0);
    r[1] = glm::dvec3(s, c, 0.0);
    scale[0][0] = sx;
    scale[1][1] = sy;
    return glm::mat3(t * r * scale);
}

int componentSize(int componentType)
{
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_INT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
    }
}

// A bounds-checked view of an accessor's elements.
struct AccessorView {
    const unsigned char* base = nullptr;  // null: accessor without buffer view, all zeros (spec)
    size_t stride = 0;
    size_t count = 0;
    int type = 0;
    int componentType = 0;

    // Component c of element i as a float: floats as stored, unsigned integers normalised.
    float component(size_t i, int c) const
    {
        if (!base) return 0.0f;
        const unsigned char* p = base + i * stride + size_t(c) * componentSize(componentType);
        switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: {
            float f;
            std::memcpy(&f, p, sizeof f);
            return f;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return float(p[0]) / 255.0f;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            uint16_t u;
            std::memcpy(&u, p, sizeof u);
            return float(u) / 65535.0f;
        }
        default: return 0.0f;
        }
    }

    uint32_t index(size_t i) const
    {
        if (!base) return 0;
        const unsigned char* p = base + i * stride;
        switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return p[0];
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            uint16_t u;
            std::memcpy(&u, p, sizeof u);
            return u;
        }
        default: {
            uint32_t u;
            std::memcpy(&u, p, sizeof u);
            return u;
        }
        }
    }

    glm::vec3 vec3(size_t i) const { return {component(i, 0), component(i, 1), component(i, 2)}; }
};

Result<AccessorView> viewAccessor(const tinygltf::Model& model, int index)
{
    if (index < 0 || size_t(index) >= model.accessors.size())
        return fail(fmt::format("accessor {} does not exist", index));
    const tinygltf::Accessor& a = model.accessors[size_t(index)];
    if (a.sparse.isSparse)
        return fail(fmt::format("accessor {} is sparse (sparse accessors are not supported)", index));
    int components = tinygltf::GetNumComponentsInType(uint32_t(a.type));
    int size = componentSize(a.componentType);
    if (components <= 0 || size <= 0)
        return fail(fmt::format("accessor {} has an unsupported type or component type", index));
    if (a.count > kMaxVertices)
        return fail(fmt::format("accessor {} has too many elements ({})", index, a.count));

    AccessorView view;
    view.count = a.count;
    view.type = a.type;
    view.componentType = a.componentType;
    if (a.bufferView < 0) return view;
    if (size_t(a.bufferView) >= model.bufferViews.size())
        return fail(
            fmt::format("accessor {} uses buffer view {}, which does not exist", index, a.bufferView));
    const tinygltf::BufferView& bv = model.bufferViews[size_t(a.bufferView)];
    if (bv.buffer < 0 || size_t(bv.buffer) >= model.buffers.size())
        return fail(
            fmt::format("buffer view {} uses buffer {}, which does not exist", a.bufferView, bv.buffer));
    const std::vector<unsigned char>& data = model.buffers[size_t(bv.buffer)].data;
    if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset)
        return fail(
            fmt::format("buffer view {} (offset {}, length {}) lies outside buffer {} "
                        "({} bytes)",
                        a.bufferView, bv.byteOffset, bv.byteLength, bv.buffer, data.size()));
    int stride = a.ByteStride(bv);
    if (stride <= 0)
        return fail(fmt::format("accessor {} has an invalid byte stride {}", index, bv.byteStride));
    view.stride = size_t(stride);
    if (a.count == 0) return view;
    // Written to avoid overflow: offset + (count - 1) * stride + element size <= view length.
    size_t element = size_t(components) * size_t(size);
    bool inside = a.byteOffset <= bv.byteLength && bv.byteLength - a.byteOffset >= element &&
                  (a.count - 1) <= (bv.byteLength - a.byteOffset - element) / view.stride;
    if (inside) view.base = data.data() + bv.byteOffset + a.byteOffset;
    if (!inside)
        return fail(
            fmt::format("accessor {} ({} elements, offset {}, stride {}) reads past the end "
                        "of buffer view {} ({} bytes)",
                        index, a.count, a.byteOffset, view.stride, a.bufferView, bv.byteLength));
    return view;
}

// Local transform of a node: its matrix, or T * R * S.
Result<glm::dmat4> localMatrix(const tinygltf::Node& node, int index)
{
    glm::dmat4 m(1.0);
    if (!node.matrix.empty()) {
        if (node.matrix.size() != 16)
            return fail(fmt::format("node {} has a matrix with {} values", index, node.matrix.size()));
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) m[c][r] = node.matrix[size_t(c * 4 + r)];
        return m;
    }
    if ((!node.translation.empty() && node.translation.size() != 3) ||
        (!node.rotation.empty() && node.rotation.size() != 4) ||
        (!node.scale.empty() && node.scale.size() != 3))
        return fail(fmt::format("node {} has a malformed translation, rotation or scale", index));
    glm::dmat4 r(1.0);
    if (!node.rotation.empty()) {
        double x = node.rotation[0], y = node.rotation[1], z = node.rotation[2];
        double w = node.rotation[3];
        double len = std::sqrt(x * x + y * y + z * z + w * w);
        if (!(len > 0.0) || !std::isfinite(len))
            return fail(fmt::format("node {} has a zero or non-finite rotation", index));
        x /= len, y /= len, z /= len, w /= len;
        // Unit quaternion (x, y, z, w) to a rotation matrix, indexed [column][row] like glm.
        r[0][0] = 1 - 2 * (y * y + z * z);
        r[0][1] = 2 * (x * y + w * z);
        r[0][2] = 2 * (x * z - w * y);
        r[1][0] = 2 * (x * y - w * z);
        r[1][1] = 1 - 2 * (x * x + z * z);
        r[1][2] = 2 * (y * z + w * x);
        r[2][0] = 2 * (x * z + w * y);
        r[2][1] = 2 * (y * z - w * x);
        r[2][2] = 1 - 2 * (x * x + y * y);
    }
    glm::dmat4 s(1.0);
    if (!node.scale.empty()) {
        s[0][0] = node.scale[0];
        s[1][1] = node.scale[1];
        s[2][2] = node.scale[2];
    }
    glm::dmat4 t(1.0);
    if (!node.translation.empty())
        t[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
    return t * r * s;
}

glm::vec3 safeNormalize(glm::dvec3 v)
{
    double len = glm::length(v);
    if (!(len > 0.0) || !std::isfinite(len)) return {0.0f, 0.0f, 1.0f};
    return glm::vec3(v / len);
}

// A line primitive's vertex sequence as segments, two sequence elements each, following the glTF spec
// (section 3.7.2.1): LINES pairs elements (a trailing odd one is left out), LINE_STRIP joins neighbours
// and LINE_LOOP adds the closing segment last. Fewer than two elements make no segment.
std::vector<uint32_t> lineSegments(int mode, const std::vector<uint32_t>& sequence)
{
    std::vector<uint32_t> segments;
    size_t n = sequence.size();
    if (n < 2) return segments;
    if (mode == TINYGLTF_MODE_LINE) {
        segments.assign(sequence.begin(), sequence.begin() + ptrdiff_t(n / 2 * 2));
        return segments;
    }
    segments.reserve(2 * n);
    for (size_t i = 0; i + 1 < n; ++i) segments.insert(segments.end(), {sequence[i], sequence[i + 1]});
    if (mode == TINYGLTF_MODE_LINE_LOOP) segments.insert(segments.end(), {sequence[n - 1], sequence[0]});
    return segments;
}

class GltfFlattener {
public:
    GltfFlattener(const tinygltf::Model& model, const ImageFailures& imageFailures, const std::string& path)
        : model_(model), imageFailures_(imageFailures), path_(path)
    {
    }

    Status run();
    Scene& scene() { return scene_; }

private:
    Status visitTree(int root);
    Status addMesh(int meshIndex, const glm::dmat4& world);
    Status addPrimitive(const tinygltf::Primitive& prim, const std::string& where, const glm::dmat4& world,
                        const glm::dmat3& normalMatrix, bool flip);
    Status addCamera(int cameraIndex, int nodeIndex, const glm::dmat4& world);
    void pushVertex(const glm::vec3& p, const glm::vec3& n, const glm::vec4& c, const glm::vec4& uv);
    Result<uint32_t> useMaterial(int gltfMaterial);
    Result<int32_t> useTexture(int gltfTexture, const std::string& material);
    Status readEmission(const tinygltf::Material& src, SceneMaterial& m);
    bool imageBytes(int index, const uint8_t*& bytes, size_t& size, std::string& why) const;
    void warnOnce(bool& done, const std::string& message);

    const tinygltf::Model& model_;
    const ImageFailures& imageFailures_;
    const std::string& path_;
    Scene scene_;
    std::vector<bool> visited_;
    size_t oddLinePrimitives_ = 0;  // LINES primitives whose last element had no partner
    size_t skippedWithoutPositions_ = 0;
    bool anyNonWhite_ = false;
    // glTF material / texture index -> Scene::materials / Scene::textures index; -1 not yet used.
    std::vector<int32_t> materialIndex_;
    std::vector<int32_t> textureIndex_;
    std::vector<bool> textureTried_;
    int32_t defaultMaterial_ = -1;
    std::vector<bool> texCoordWarned_;  // per scene material: missing texture coordinate set reported
    bool blendWarned_ = false;
    std::array<bool, 3> ignoredTextureWarned_{};
    bool emissiveTransformWarned_ = false;
};

void GltfFlattener::warnOnce(bool& done, const std::string& message)
{
    if (done) return;
    done = true;
    warn("{}: {}", path_, message);
}

// The encoded bytes of image `index`: kept by keepEncodedImage for URIs, read from its buffer view
// (bounds-checked) otherwise. False with a reason when there are none.
bool GltfFlattener::imageBytes(int index, const uint8_t*& bytes, size_t& size, std::string& why) const
{
    const tinygltf::Image& image = model_.images[size_t(index)];
    if (image.bufferView < 0) {
        if (image.image.empty() || !image.as_is) {
            auto failure = imageFailures_.find(index);
            why = failure != imageFailures_.end() ? failure->second
                  : image.uri.empty()             ? "no image data"
                                                  : "file not found or unreadable";
            return false;
        }
        bytes = image.image.data();
        size = image.image.size();
        return true;
    }
    if (size_t(image.bufferView) >= model_.bufferViews.size()) {
        why = fmt::format("buffer view {} does not exist", image.bufferView);
        return false;
    }
    const tinygltf::BufferView& bv = model_.bufferViews[size_t(image.bufferView)];
    if (bv.buffer < 0 || size_t(bv.buffer) >= model_.buffers.size()) {
        why = fmt::format("buffer view {} uses buffer {}, which does not exist", image.bufferView, bv.buffer);
        return false;
    }
    const std::vector<unsigned char>& data = model_.buffers[size_t(bv.buffer)].data;
    if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset || bv.byteLength == 0) {
        why = fmt::format("buffer view {} lies outside its buffer", image.bufferView);
        return false;
    }
    bytes = data.data() + bv.byteOffset;
    size = bv.byteLength;
    return true;
}

// Scene::textures index of glTF texture `gltfTexture` (image + sampler), loaded on first use; -1 when it
// cannot be used (reported once). Fails only for an image over the size limit.
Result<int32_t> GltfFlattener::useTexture(int gltfTexture, const std::string& material)
{
    if (gltfTexture < 0 || size_t(gltfTexture) >= model_.textures.size()) {
        warn(
            "{}: material '{}' uses texture {}, which does not exist; drawn with its base "
            "colour factor only",
            path_, material, gltfTexture);
        return int32_t(-1);
    }
    size_t index = size_t(gltfTexture);
    if (textureTried_[index]) return textureIndex_[index];
    textureTried_[index] = true;

    const tinygltf::Texture& texture = model_.textures[index];
    TextureSampler sampler;
    if (texture.sampler >= 0 && size_t(texture.sampler) < model_.samplers.size())
        sampler = samplerOf(model_.samplers[size_t(texture.sampler)]);
    // Named after the image's URI (data URIs are not kept as URIs) or name, so messages point at it.
    std::string name = fmt::format("image {}", texture.source);
    std::string why;
    const uint8_t* bytes = nullptr;
    size_t size = 0;
    bool haveBytes = false;
    if (texture.source < 0 || size_t(texture.source) >= model_.images.size()) {
        why = texture.source < 0 ? "the texture has no image (extension-only sources are not supported)"
                                 : "no such image";
    } else {
        const tinygltf::Image& image = model_.images[size_t(texture.source)];
        if (!image.uri.empty() && image.uri.rfind("data:", 0) != 0)
            name = image.uri;
        else if (!image.name.empty())
            name = image.name;
        haveBytes = imageBytes(texture.source, bytes, size, why);
    }
    if (haveBytes) {
        Result<SceneTexture> loaded = loadTextureMemory(name, bytes, size, true, sampler);
        if (loaded) {
            textureIndex_[index] = int32_t(scene_.textures.size());
            scene_.textures.push_back(std::move(*loaded));
            return textureIndex_[index];
        }
        if (isTextureSizeError(loaded.error())) return loaded.error();
        why = loaded.error().message;
    }
    warn(
        "{}: cannot load image '{}' of texture {} ({}); drawn with the base colour factor "
        "only",
        path_, name, gltfTexture, why);
    return int32_t(-1);
}

// The material's emission: emissiveFactor times KHR_materials_emissive_strength's emissiveStrength (a
// multiplier that lets the factor exceed 1), and emissiveTexture (sRGB like the base colour, read with
// its own coordinate set; a KHR_texture_transform on it is ignored with one warning).
Status GltfFlattener::readEmission(const tinygltf::Material& src, SceneMaterial& m)
{
    float strength = 1.0f;
    auto ext = src.extensions.find("KHR_materials_emissive_strength");
    if (ext != src.extensions.end() && ext->second.IsObject() && ext->second.Has("emissiveStrength") &&
        ext->second.Get("emissiveStrength").IsNumber())
        strength = float(ext->second.Get("emissiveStrength").GetNumberAsDouble());
    const std::vector<double>& factor = src.emissiveFactor;
    if (factor.size() == 3)
        m.emissive = glm::vec3(float(factor[0]), float(factor[1]), float(factor[2])) * strength;
    const tinygltf::TextureInfo& info = src.emissiveTexture;
    if (info.index < 0 || m.emissive == glm::vec3(0.0f)) return okStatus();
    int texCoord = info.texCoord;
    if (textureTransform(info, texCoord) != glm::mat3(1.0f))
        warnOnce(emissiveTransformWarned_, "KHR_texture_transform of emissiveTexture ignored");
    Result<int32_t> texture = useTexture(info.index, m.name);
    if (!texture) return texture.error();
    if (*texture >= 0 && (texCoord < 0 || texCoord > 1)) {
        warn(
            "{}: material '{}' uses TEXCOORD_{} for emission (only sets 0 and 1 are "
            "supported); drawn without its emissive texture",
            path_, m.name, texCoord);
    } else {
        m.emissiveTexture = *texture;
        m.emissiveTexCoord = uint32_t(std::max(texCoord, 0));
    }
    return okStatus();
}

// Scene::materials index for a glTF material (-1: the default material), created on first use. glTF 2.0
// (3.9.6) defines the default material as one with no properties given, every one at its default: base
// colour 1, opaque, single-sided, no emission, the same as "materials": [{}].
Result<uint32_t> GltfFlattener::useMaterial(int gltfMaterial)
{
    if (gltfMaterial < 0) {
        if (defaultMaterial_ < 0) {
            defaultMaterial_ = int32_t(scene_.materials.size());
            SceneMaterial m;
            m.name = "glTF default";
            scene_.materials.push_back(m);
            texCoordWarned_.push_back(false);
        }
        return uint32_t(defaultMaterial_);
    }
    size_t index = size_t(gltfMaterial);
    if (materialIndex_[index] >= 0) return uint32_t(materialIndex_[index]);

    const tinygltf::Material& src = model_.materials[index];
    SceneMaterial m;
    m.name = src.name.empty() ? fmt::format("material {}", gltfMaterial) : src.name;
    const std::vector<double>& factor = src.pbrMetallicRoughness.baseColorFactor;
    if (factor.size() == 4)
        m.baseColorFactor = glm::vec4(float(factor[0]), float(factor[1]), float(factor[2]), float(factor[3]));
    if (src.alphaMode == "MASK") {
        m.alphaMode = ALPHA_MASK;
        m.alphaCutoff = float(src.alphaCutoff);
    } else if (src.alphaMode == "BLEND") {
        warnOnce(blendWarned_, "alphaMode BLEND drawn as opaque");
    }

    const char* kIgnored[3] = {"metallicRoughnessTexture", "normalTexture", "occlusionTexture"};
    const int ignoredIndex[3] = {src.pbrMetallicRoughness.metallicRoughnessTexture.index,
                                 src.normalTexture.index, src.occlusionTexture.index};
    for (size_t i = 0; i < 3; ++i) {
        if (ignoredIndex[i] >= 0)
            warnOnce(ignoredTextureWarned_[i],
                     fmt::format("{} ignored (only base colour is supported)", kIgnored[i]));
    }

    const tinygltf::TextureInfo& info = src.pbrMetallicRoughness.baseColorTexture;
    if (info.index >= 0) {
        int texCoord = info.texCoord;
        m.uvTransform = textureTransform(info, texCoord);
        Result<int32_t> texture = useTexture(info.index, m.name);
        if (!texture) return texture.error();
        if (*texture >= 0 && (texCoord < 0 || texCoord > 1)) {
            warn(
                "{}: material '{}' uses TEXCOORD_{} (only sets 0 and 1 are supported); drawn "
                "without its texture",
                path_, m.name, texCoord);
        } else {
            m.baseColorTexture = *texture;
            m.texCoord = uint32_t(std::max(texCoord, 0));
        }
    }
    SR_TRY(readEmission(src, m));
    materialIndex_[index] = int32_t(scene_.materials.size());
    scene_.materials.push_back(m);
    texCoordWarned_.push_back(false);
    return uint32_t(materialIndex_[index]);
}

Status GltfFlattener::run()
{
    // Required extensions that compress geometry were refused by checkGltfSpec, before tinygltf.
    std::vector<int> roots;
    if (!model_.scenes.empty()) {
        // checkGltfSpec has refused a `scene` that names no scene; without one, the first is drawn.
        int sceneIndex = model_.defaultScene < 0 ? 0 : model_.defaultScene;
        roots = model_.scenes[size_t(sceneIndex)].nodes;
    } else {
        // No scenes: every node that is nobody's child is a root, in document order.
        std::vector<bool> isChild(model_.nodes.size(), false);
        for (const tinygltf::Node& node : model_.nodes)
            for (int child : node.children)
                if (child >= 0 && size_t(child) < isChild.size()) isChild[size_t(child)] = true;
        for (size_t i = 0; i < model_.nodes.size(); ++i)
            if (!isChild[i]) roots.push_back(int(i));
    }

    visited_.assign(model_.nodes.size(), false);
    materialIndex_.assign(model_.materials.size(), -1);
    textureIndex_.assign(model_.textures.size(), -1);
    textureTried_.assign(model_.textures.size(), false);
    for (int root : roots) SR_TRY(visitTree(root));

    if (oddLinePrimitives_ > 0) {
        warn(
            "{}: dropped the unpaired last vertex of {} LINES primitive(s) with an odd "
            "vertex count",
            path_, oddLinePrimitives_);
    }
    if (skippedWithoutPositions_ > 0) {
        warn("{}: skipping {} primitive(s) without POSITION", path_, skippedWithoutPositions_);
    }
    if (!anyNonWhite_) scene_.colors.clear();

    return okStatus();
}

// Depth-first, children in listed order; an explicit stack so that deep hierarchies cannot
// overflow the call stack.
Status GltfFlattener::visitTree(int root)
{
    struct Pending {
        int node;
        glm::dmat4 parentWorld;
    };
    std::vector<Pending> stack{{root, glm::dmat4(1.0)}};
    while (!stack.empty()) {
        Pending item = stack.back();
        stack.pop_back();
        if (item.node < 0 || size_t(item.node) >= model_.nodes.size())
            return fail(fmt::format("node {} does not exist", item.node));
        // The spec requires disjoint trees; a node reached twice means a cycle or a shared child.
        if (visited_[size_t(item.node)])
            return fail(
                fmt::format("node {} is reached twice (the node hierarchy must be a set "
                            "of disjoint trees)",
                            item.node));
        visited_[size_t(item.node)] = true;
        const tinygltf::Node& node = model_.nodes[size_t(item.node)];
        Result<glm::dmat4> local = localMatrix(node, item.node);
        if (!local) return local.error();
        glm::dmat4 world = item.parentWorld * *local;
        if (node.mesh >= 0) SR_TRY(addMesh(node.mesh, world));
        if (node.camera >= 0) SR_TRY(addCamera(node.camera, item.node, world));
        for (auto it = node.children.rbegin(); it != node.children.rend(); ++it)
            stack.push_back({*it, world});
    }
    return okStatus();
}

Status GltfFlattener::addMesh(int meshIndex, const glm::dmat4& world)
{
    if (size_t(meshIndex) >= model_.meshes.size())
        return fail(fmt::format("mesh {} does not exist", meshIndex));
    glm::dmat3 linear(world);
    double det = glm::determinant(linear);
    // Inverse transpose up to a positive factor, written as the cofactor matrix so that it stays
    // defined for singular (zero-scale) transforms; the sign keeps mirrored normals pointing out.
    glm::dmat3 cofactor(glm::cross(linear[1], linear[2]), glm::cross(linear[2], linear[0]),
                        glm::cross(linear[0], linear[1]));
    glm::dmat3 normalMatrix = det < 0.0 ? -cofactor : cofactor;
    const tinygltf::Mesh& mesh = model_.meshes[size_t(meshIndex)];
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
        std::string where = fmt::format("mesh {} primitive {}", meshIndex, p);
        SR_TRY(addPrimitive(mesh.primitives[p], where, world, normalMatrix, det < 0.0));
    }
    return okStatus();
}

void GltfFlattener::pushVertex(const glm::vec3& p, const glm::vec3& n, const glm::vec4& c,
                               const glm::vec4& uv)
{
    scene_.positions.emplace_back(p, 1.0f);
    scene_.normals.emplace_back(n, 0.0f);
    scene_.colors.push_back(c);
    scene_.texcoords.push_back(uv);
    if (c != glm::vec4(1.0f)) anyNonWhite_ = true;
}

Status GltfFlattener::addPrimitive(const tinygltf::Primitive& prim, const std::string& where,
                                   const glm::dmat4& world, const glm::dmat3& normalMatrix, bool flip)
{
    int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    bool lineMode =
        mode == TINYGLTF_MODE_LINE || mode == TINYGLTF_MODE_LINE_LOOP || mode == TINYGLTF_MODE_LINE_STRIP;
    if (mode != TINYGLTF_MODE_POINTS && !lineMode && mode != TINYGLTF_MODE_TRIANGLES &&
        mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN)
        return fail(fmt::format("{} has unknown mode {}", where, mode));

    auto attribute = [&](const char* name) {
        auto it = prim.attributes.find(name);
        return it == prim.attributes.end() ? -1 : it->second;
    };
    int positionIndex = attribute("POSITION");
    if (positionIndex < 0) {
        ++skippedWithoutPositions_;
        return okStatus();
    }
    Result<AccessorView> positions = viewAccessor(model_, positionIndex);
    if (!positions) return positions.error();
    if (positions->type != TINYGLTF_TYPE_VEC3 || positions->componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
        return fail(fmt::format("{}: POSITION must be VEC3 float", where));
    size_t vertexCount = positions->count;

    AccessorView normals;
    bool hasNormals = attribute("NORMAL") >= 0;
    if (hasNormals) {
        Result<AccessorView> view = viewAccessor(model_, attribute("NORMAL"));
        if (!view) return view.error();
        normals = *view;
        if (normals.type != TINYGLTF_TYPE_VEC3 || normals.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
            return fail(fmt::format("{}: NORMAL must be VEC3 float", where));
        if (normals.count != vertexCount)
            return fail(fmt::format("{}: {} normals for {} positions", where, normals.count, vertexCount));
    }

    AccessorView colors;
    bool hasColors = attribute("COLOR_0") >= 0;
    if (hasColors) {
        Result<AccessorView> view = viewAccessor(model_, attribute("COLOR_0"));
        if (!view) return view.error();
        colors = *view;
        bool typeOk = colors.type == TINYGLTF_TYPE_VEC3 || colors.type == TINYGLTF_TYPE_VEC4;
        bool componentOk = colors.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT ||
                           colors.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                           colors.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
        if (!typeOk || !componentOk)
            return fail(
                fmt::format("{}: COLOR_0 must be VEC3 or VEC4 of float, unsigned byte or "
                            "unsigned short",
                            where));
        if (colors.count != vertexCount)
            return fail(fmt::format("{}: {} colours for {} positions", where, colors.count, vertexCount));
    }

    // TEXCOORD_0 and TEXCOORD_1: float, or normalised unsigned byte / short (glTF 2.0, 3.7.2.1).
    std::array<AccessorView, 2> uvSets;
    std::array<bool, 2> hasUv{};
    for (int set = 0; set < 2; ++set) {
        std::string name = fmt::format("TEXCOORD_{}", set);
        int accessor = attribute(name.c_str());
        if (accessor < 0) continue;
        Result<AccessorView> view = viewAccessor(model_, accessor);
        if (!view) return view.error();
        bool componentOk = view->componentType == TINYGLTF_COMPONENT_TYPE_FLOAT ||
                           view->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                           view->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
        if (view->type != TINYGLTF_TYPE_VEC2 || !componentOk)
            return fail(
                fmt::format("{}: {} must be VEC2 of float, unsigned byte or unsigned short", where, name));
        if (view->count != vertexCount)
            return fail(fmt::format("{}: {} texture coordinates in {} for {} positions", where, view->count,
                                    name, vertexCount));
        uvSets[size_t(set)] = *view;
        hasUv[size_t(set)] = true;
    }

    bool doubleSided = false;
    if (prim.material >= 0) {
        if (size_t(prim.material) >= model_.materials.size())
            return fail(fmt::format("{} uses material {}, which does not exist", where, prim.material));
        doubleSided = model_.materials[size_t(prim.material)].doubleSided;
    }
    Result<uint32_t> materialId = useMaterial(prim.material);
    if (!materialId) return materialId.error();
    SceneMaterial& material = scene_.materials[*materialId];
    if (material.baseColorTexture >= 0 && !hasUv[material.texCoord]) {
        // The material is shared by every primitive that uses it, so it loses its texture everywhere.
        if (!texCoordWarned_[*materialId])
            warn(
                "{}: material '{}' uses TEXCOORD_{}, which {} does not have; drawn without "
                "its texture",
                path_, material.name, material.texCoord, where);
        texCoordWarned_[*materialId] = true;
        material.baseColorTexture = -1;
    }
    if (material.emissiveTexture >= 0 && !hasUv[material.emissiveTexCoord]) {
        warn(
            "{}: material '{}' uses TEXCOORD_{} for emission, which {} does not have; drawn "
            "without its emissive texture",
            path_, material.name, material.emissiveTexCoord, where);
        material.emissiveTexture = -1;
    }
    // The base colour factor stays in the material (the shading stage multiplies it in), so the vertex
    // colours are COLOR_0 alone.
    auto colorOf = [&](size_t v) {
        glm::vec4 c(1.0f);
        if (hasColors) {
            c = glm::vec4(colors.component(v, 0), colors.component(v, 1), colors.component(v, 2), 1.0f);
            if (colors.type == TINYGLTF_TYPE_VEC4) c.w = colors.component(v, 3);
        }
        return c;
    };
    auto uvOf = [&](size_t v) {
        glm::vec4 uv(0.0f);
        if (hasUv[0]) uv.x = uvSets[0].component(v, 0), uv.y = uvSets[0].component(v, 1);
        if (hasUv[1]) uv.z = uvSets[1].component(v, 0), uv.w = uvSets[1].component(v, 1);
        return uv;
    };

    // The primitive's vertex sequence: its indices, or 0..count-1 without them.
    std::vector<uint32_t> sequence;
    if (prim.indices >= 0) {
        Result<AccessorView> view = viewAccessor(model_, prim.indices);
        if (!view) return view.error();
        bool indexType = view->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                         view->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
                         view->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
        if (view->type != TINYGLTF_TYPE_SCALAR || !indexType)
            return fail(fmt::format("{}: indices must be SCALAR unsigned byte, short or int", where));
        sequence.resize(view->count);
        for (size_t i = 0; i < view->count; ++i) sequence[i] = view->index(i);
    } else {
        sequence.resize(vertexCount);
        for (size_t i = 0; i < vertexCount; ++i) sequence[i] = uint32_t(i);
    }

    auto worldPosition = [&](size_t v) {
        return glm::vec3(world * glm::dvec4(glm::dvec3(positions->vec3(v)), 1.0));
    };
    size_t base = scene_.positions.size();

    // Points and segments use the primitive's vertices stored once. They are shaded unlit, so a
    // primitive without NORMAL gets zero normals rather than invented ones.
    auto pushUnlitVertices = [&]() -> Status {
        if (vertexCount > kMaxVertices - base)
            return fail(fmt::format("{}: the scene has more than {} vertices", where, kMaxVertices));
        for (size_t v = 0; v < vertexCount; ++v) {
            glm::vec3 normal(0.0f);
            if (hasNormals) normal = safeNormalize(normalMatrix * glm::dvec3(normals.vec3(v)));
            pushVertex(worldPosition(v), normal, colorOf(v), uvOf(v));
        }
        return okStatus();
    };
    auto sceneIndex = [&](uint32_t local) {
        return local < vertexCount ? uint32_t(base + local) : kInvalidIndex;
    };

    if (mode == TINYGLTF_MODE_POINTS) {
        // One point per element of the sequence.
        SR_TRY(pushUnlitVertices());
        for (uint32_t local : sequence) scene_.points.push_back(sceneIndex(local));
        scene_.pointMaterials.insert(scene_.pointMaterials.end(), sequence.size(), *materialId);
        return okStatus();
    }
    if (lineMode) {
        if (mode == TINYGLTF_MODE_LINE && sequence.size() % 2 != 0) ++oddLinePrimitives_;
        std::vector<uint32_t> segments = lineSegments(mode, sequence);
        if (segments.empty()) return okStatus();
        SR_TRY(pushUnlitVertices());
        for (uint32_t local : segments) scene_.lines.push_back(sceneIndex(local));
        scene_.lineMaterials.insert(scene_.lineMaterials.end(), segments.size() / 2, *materialId);
        return okStatus();
    }

    // Triangle lists, with the vertex order of the glTF spec (section 3.7.2.1).
    std::vector<uint32_t> tris;
    size_t n = sequence.size();
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        tris.assign(sequence.begin(), sequence.begin() + ptrdiff_t(n / 3 * 3));
    } else if (n >= 3) {
        tris.reserve(3 * (n - 2));
        for (size_t i = 0; i + 2 < n; ++i) {
            if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                // Odd triangles swap their last two vertices so every triangle keeps the winding.
                size_t odd = i % 2;
                tris.insert(tris.end(), {sequence[i], sequence[i + 1 + odd], sequence[i + 2 - odd]});
            } else {
                tris.insert(tris.end(), {sequence[i + 1], sequence[i + 2], sequence[0]});
            }
        }
    }
    if (flip) {
        // A mirroring transform turns counter-clockwise into clockwise; the spec asks for the
        // winding to be reversed so the front faces stay front faces.
        for (size_t t = 0; t + 2 < tris.size(); t += 3) std::swap(tris[t + 1], tris[t + 2]);
    }

    size_t triangleCount = tris.size() / 3;
    uint32_t flags = (doubleSided ? TRI_FLAG_DOUBLE_SIDED : 0u) |
                     (material.alphaMode == ALPHA_MASK ? TRI_FLAG_ALPHA_MASK : 0u);
    size_t added = hasNormals ? vertexCount : 3 * triangleCount;
    if (added > kMaxVertices - base)
        return fail(fmt::format("{}: the scene has more than {} vertices", where, kMaxVertices));

    if (hasNormals) {
        for (size_t v = 0; v < vertexCount; ++v) {
            glm::vec3 normal = safeNormalize(normalMatrix * glm::dvec3(normals.vec3(v)));
            pushVertex(worldPosition(v), normal, colorOf(v), uvOf(v));
        }
        for (uint32_t local : tris)
            scene_.indices.push_back(local < vertexCount ? uint32_t(base + local) : kInvalidIndex);
    } else {
        // Flat shading: each triangle gets its own three vertices carrying the face normal.
        for (size_t t = 0; t < triangleCount; ++t) {
            const uint32_t* tri = &tris[3 * t];
            if (tri[0] >= vertexCount || tri[1] >= vertexCount || tri[2] >= vertexCount) {
                scene_.indices.insert(scene_.indices.end(), 3, kInvalidIndex);
                continue;
            }
            glm::vec3 p[3] = {worldPosition(tri[0]), worldPosition(tri[1]), worldPosition(tri[2])};
            glm::dvec3 e1 = glm::dvec3(p[1]) - glm::dvec3(p[0]);
            glm::dvec3 e2 = glm::dvec3(p[2]) - glm::dvec3(p[0]);
            glm::vec3 normal = safeNormalize(glm::cross(e1, e2));
            for (int k = 0; k < 3; ++k) {
                scene_.indices.push_back(uint32_t(scene_.positions.size()));
                pushVertex(p[k], normal, colorOf(tri[k]), uvOf(tri[k]));
            }
        }
    }
    scene_.triFlags.insert(scene_.triFlags.end(), triangleCount, flags);
    scene_.triMaterials.insert(scene_.triMaterials.end(), triangleCount, *materialId);
    return okStatus();
}

Status GltfFlattener::addCamera(int cameraIndex, int nodeIndex, const glm::dmat4& world)
{
    if (size_t(cameraIndex) >= model_.cameras.size())
        return fail(fmt::format("node {} uses camera {}, which does not exist", nodeIndex, cameraIndex));
    const tinygltf::Camera& cam = model_.cameras[size_t(cameraIndex)];
    SceneCamera out;
    out.name = !cam.name.empty() ? cam.name : model_.nodes[size_t(nodeIndex)].name;
    // Cameras ignore scale (spec); normalising the axes keeps a rigid view transform.
    glm::dmat4 m = world;
    for (int axis = 0; axis < 3; ++axis) {
        glm::dvec3 column(m[axis]);
        double len = glm::length(column);
        if (!(len > 0.0) || !std::isfinite(len))
            return fail(fmt::format("camera node {} has a degenerate transform", nodeIndex));
        m[axis] = glm::dvec4(column / len, 0.0);
    }
    out.worldFromView = glm::mat4(m);
    bool valid = false;
    if (cam.type == "perspective") {
        const tinygltf::PerspectiveCamera& p = cam.perspective;
        out.perspective = true;
        out.yfov = float(p.yfov);
        out.aspectRatio = float(p.aspectRatio);
        out.znear = float(p.znear);
        out.zfar = float(p.zfar);
        valid = out.yfov > 0.0f && out.yfov < 3.14159f && out.aspectRatio >= 0.0f && out.znear > 0.0f &&
                (out.zfar == 0.0f || out.zfar > out.znear);
    } else if (cam.type == "orthographic") {
        const tinygltf::OrthographicCamera& o = cam.orthographic;
        out.perspective = false;
        out.xmag = float(std::fabs(o.xmag));
        out.ymag = float(std::fabs(o.ymag));
        out.znear = float(o.znear);
        out.zfar = float(o.zfar);
        valid = out.xmag > 0.0f && out.ymag > 0.0f && out.znear >= 0.0f &&
                (out.zfar == 0.0f || out.zfar > out.znear);
    } else {
        return fail(fmt::format("camera {} has unknown type '{}'", cameraIndex, cam.type));
    }
    if (!valid || !std::isfinite(out.zfar))
        return fail(fmt::format("camera {} has invalid projection parameters", cameraIndex));
    scene_.cameras.push_back(out);
    return okStatus();
}

}  // namespace

Result<Scene> loadGltf(const std::string& path)
{
    tinygltf::Model model;
    ImageFailures imageFailures;
    {
        // Read here rather than by tinygltf, like every file the glTF names (readWholeFile): a clear
        // "No such file" beats tinygltf's wording, and the JSON's depth is checked before it is parsed.
        Result<std::vector<unsigned char>> file = readRegularFile(path, kMaxSceneFileBytes, "load");
        if (!file) return file.error();
        const std::vector<unsigned char>& bytes = *file;
        if (bytes.empty()) return makeError(ExitCode::Usage, "cannot load '{}': the file is empty", path);
        // The magic number decides between .glb and .gltf whatever the extension says.
        bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
        auto [json, jsonSize] = jsonText(bytes, binary);
        Status shallow = checkJsonDepth(json, jsonSize);
        if (!shallow)
            return makeError(ExitCode::Usage, "cannot load '{}': {}", path, shallow.error().message);
        // The spec's rules first, so that what breaks them is named by its path in the document; JSON
        // that does not parse is left to tinygltf, which says where.
        nlohmann::json doc = nlohmann::json::parse(json, json + jsonSize, nullptr, false);
        std::vector<std::string> unsupported;
        if (!doc.is_discarded()) {
            Status valid = checkGltfSpec(doc, unsupported);
            if (!valid)
                return makeError(ExitCode::Usage, "cannot load '{}': {}", path, valid.error().message);
        }

        tinygltf::TinyGLTF loader;
        loader.SetImageLoader(&keepEncodedImage, &imageFailures);
        loader.SetFsCallbacks({&fileExists, &expandFilePath, &readWholeFile, &writeNothing, nullptr});
        // Buffers and images are found relative to the file's folder, as tinygltf's own LoadFromFile
        // functions do (but "/" for a file in the root, where they would take the current folder).
        size_t slash = path.find_last_of('/');
        std::string baseDir =
            slash == std::string::npos ? std::string() : path.substr(0, std::max<size_t>(slash, 1));
        std::string err, warn;
        // kMaxSceneFileBytes keeps the length within tinygltf's unsigned int.
        auto length = static_cast<unsigned int>(bytes.size());
        bool ok =
            binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), length, baseDir)
                   : loader.LoadASCIIFromString(&model, &err, &warn,
                                                reinterpret_cast<const char*>(bytes.data()), length, baseDir);
        if (!ok) {
            std::string reason =
                flattenMessage(withoutReadErrorPrefixes(err.empty() ? warn : err + "\n" + warn));
            if (reason.empty()) reason = "tinygltf could not parse the file";
            return makeError(ExitCode::Usage, "cannot load '{}': {}", path, reason);
        }
        warn = withoutImageFileWarnings(warn, imageFailures);
        if (!warn.empty()) sr::warn("{}: {}", path, flattenMessage(warn));

        for (const std::string& line : unsupported) sr::warn("{}: {}", path, line);
    }

    GltfFlattener flattener(model, imageFailures, path);
    Status flattened = flattener.run();
    if (!flattened)
        return makeError(ExitCode::Usage, "cannot load '{}': {}", path, flattened.error().message);
    Scene& scene = flattener.scene();
    SR_TRY(finalizeLoadedScene(scene, path));
    return std::move(scene);
}

}  // namespace sr
