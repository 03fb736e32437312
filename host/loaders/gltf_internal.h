// gltf_internal.h - what the glTF loader's files share (gltf.cpp builds the scene; gltf_files.cpp holds
// tinygltf's file and image callbacks and the JSON checks; gltf_accessors.cpp reads accessors and node
// transforms; gltf_materials.cpp turns materials, textures and samplers into the scene's). Private to
// host/loaders/.
#ifndef RASTER_GLTF_INTERNAL_H
#define RASTER_GLTF_INTERNAL_H

#include <tiny_gltf.h>

#include <array>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "raster_shared.h"

#include "base/result.h"
#include "scene/scene.h"

namespace sr::gltf {

// Stands for "no such vertex"; finalizeScene drops every triangle, segment or point that uses it and
// counts it.
constexpr uint32_t kInvalidIndex = 0xffffffffu;
// Same bound as finalizeScene's, checked early so a huge count fails before it is allocated.
constexpr size_t kMaxVertices = size_t(1) << 31;

inline Error fail(const std::string& reason)
{
    return Error{reason, ExitCode::Usage};
}

// Why each external image that could not be used failed, by image index: tinygltf only warns about
// such an image, in a wording of its own, and the loader's one warning per texture says why.
using ImageFailures = std::map<int, std::string>;

// ---- gltf_files.cpp: tinygltf's callbacks, its messages, the JSON's depth
// Keeps the still encoded bytes of images given by URI (external files, data URIs) instead of decoding
// them: only the images that used materials need are decoded, later, so that a broken or exotic image
// costs a warning about its texture rather than the whole file. Images in buffer views are read later
// from the validated buffers, since tinygltf passes them on without checking that the view lies inside
// its buffer. Always succeeds, so tinygltf never fails a load over an image. `failures` is the
// ImageFailures the reasons go to.
bool keepEncodedImage(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void* failures);

// Every line of a tinygltf message through withoutReadErrorPrefix.
std::string withoutReadErrorPrefixes(const std::string& text);

// tinygltf's messages about external images it could not read, without those lines: the loader reports
// each unreadable image once itself, naming the image and what happens instead. Each failed image's
// reason (the file line that precedes "Failed to load external 'uri' for image[N]") goes to `failures`.
std::string withoutImageFileWarnings(const std::string& warn, ImageFailures& failures);

// tinygltf's file access, replaced: its own opens with a blocking fopen (a FIFO without a writer
// stalls the load forever) and takes the size of a directory as 2^63 - 1 bytes (std::bad_alloc).
// Every file a glTF names is read through readRegularFile instead.
bool fileExists(const std::string& path, void*);

std::string expandFilePath(const std::string& path, void*);

bool readWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void*);

bool writeNothing(std::string* err, const std::string& path, const std::vector<unsigned char>&, void*);

// Fails when `text` nests arrays and objects more than kMaxJsonDepth deep. Brackets inside strings do
// not count (a string ends at a quote that no backslash escapes). The text need not be valid JSON:
// tinygltf reports whatever else is wrong with it.
Status checkJsonDepth(const unsigned char* text, size_t size);

// The JSON of a .gltf file (all of it) or of a .glb (its JSON chunk, as far as the file holds it; a
// malformed header is left to tinygltf), as a pointer and a length.
std::pair<const unsigned char*, size_t> jsonText(const std::vector<unsigned char>& file, bool binary);

// ---- gltf_accessors.cpp: accessors, node transforms, line modes
int componentSize(int componentType);

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

Result<AccessorView> viewAccessor(const tinygltf::Model& model, int index);

// Local transform of a node: its matrix, or T * R * S.
Result<glm::dmat4> localMatrix(const tinygltf::Node& node, int index);

glm::vec3 safeNormalize(glm::dvec3 v);

// A line primitive's vertex sequence as segments, two sequence elements each, following the glTF spec
// (section 3.7.2.1): LINES pairs elements (a trailing odd one is left out), LINE_STRIP joins neighbours
// and LINE_LOOP adds the closing segment last. Fewer than two elements make no segment.
std::vector<uint32_t> lineSegments(int mode, const std::vector<uint32_t>& sequence);

// ---- gltf_materials.cpp: samplers and texture transforms (and GltfFlattener's material members)
// A glTF sampler as TextureSampler; values the spec does not define fall back to its defaults
// (linear magnification, trilinear minification).
TextureSampler samplerOf(const tinygltf::Sampler& s);

// KHR_texture_transform of a textureInfo as T * R * S, column-major so that uv' = m * (u, v, 1). The
// rotation is counter-clockwise in UV space (v down): u' = cos u + sin v, v' = -sin u + cos v, the
// extension README's rows [cos, sin; -sin, cos] (its example, rotation pi/2 with offset (0, 1) and
// scale 0.5 selecting the lower left quadrant, pins the direction). `texCoord` is overridden when the
// extension gives one.
glm::mat3 textureTransform(const tinygltf::TextureInfo& info, int& texCoord);

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

}  // namespace sr::gltf

#endif  // RASTER_GLTF_INTERNAL_H
