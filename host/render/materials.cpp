// materials.cpp - see materials.h.
#include "render/materials.h"

namespace sr {

std::vector<GpuMaterial> gpuMaterials(const Scene& scene)
{
    std::vector<GpuMaterial> out;
    out.reserve(scene.materials.size());
    for (const SceneMaterial& m : scene.materials) {
        GpuMaterial g{};
        g.baseColorFactor = m.baseColorFactor;
        // glm is column-major: M[c][r]. Row r of the affine map is (M[0][r], M[1][r], M[2][r]).
        const glm::mat3& t = m.uvTransform;
        g.uvTransformU = glm::vec4(t[0][0], t[1][0], t[2][0], 0.0f);
        g.uvTransformV = glm::vec4(t[0][1], t[1][1], t[2][1], 0.0f);
        g.baseColorTexture = m.baseColorTexture < 0 ? NO_TEXTURE : uint32_t(m.baseColorTexture);
        g.texCoord = m.texCoord;
        g.alphaMode = m.alphaMode;
        g.alphaCutoff = m.alphaCutoff;
        g.emissive = glm::vec4(m.emissive, 0.0f);
        g.emissiveTexture = m.emissiveTexture < 0 ? NO_TEXTURE : uint32_t(m.emissiveTexture);
        g.emissiveTexCoord = m.emissiveTexCoord;
        out.push_back(g);
    }
    return out;
}

Result<std::vector<GpuTexture>> gpuTextures(const Scene& scene, std::vector<uint32_t>& texels)
{
    texels.clear();
    uint64_t total = 0;
    for (const SceneTexture& t : scene.textures) total += t.texels.size();
    if (total > (uint64_t(1) << 32))
        return makeError(ExitCode::Usage,
                         "the scene's textures hold {} texels, more than the 2^32 the GPU buffers address",
                         total);
    std::vector<GpuTexture> out;
    out.reserve(scene.textures.size());
    texels.reserve(size_t(total));
    for (const SceneTexture& t : scene.textures) {
        GpuTexture g{};
        g.texelOffset = uint32_t(texels.size());
        g.width = t.width;
        g.height = t.height;
        g.levels = t.levels;
        g.wrapS = t.sampler.wrapS;
        g.wrapT = t.sampler.wrapT;
        g.filters = t.sampler.magFilter | (t.sampler.minFilter << 8) | (t.sampler.mipmapMode << 16);
        g.srgb = t.srgb ? 1u : 0u;
        texels.insert(texels.end(), t.texels.begin(), t.texels.end());
        out.push_back(g);
    }
    return out;
}

}  // namespace sr
