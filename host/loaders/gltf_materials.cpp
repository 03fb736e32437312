// gltf_materials.cpp - glTF materials to the scene's: base colour factor and texture (its sampler and
// KHR_texture_transform), alpha mode, double-sidedness and emission; images decoded only when a used
// material needs them.
#include "loaders/gltf_internal.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "base/warnings.h"
#include "scene/texture.h"

namespace sr::gltf {

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

}  // namespace sr::gltf
