// aov.cpp - see aov.h.
#include "render/aov.h"

#include <algorithm>
#include <vector>

#include "render/materials.h"

namespace sr {

void fillSurfaceAovs(const Scene& scene, const RasterParams& params, AovImage& aov)
{
    // The id and depth of output pixel (x, y) are those of sample 0 of raster pixel (x ssaa + ssaa / 2,
    // y ssaa + ssaa / 2) (aovSampleIndex), a covered sample: the surface is evaluated there, not at the
    // output pixel's centre, which under MSAA or SSAA need not lie on the triangle at all.
    const RasterParams output = outputParams(params);
    const size_t pixels = std::min(aov.id.size(), size_t(aov.width) * aov.height);
    for (std::vector<float>* plane :
         {&aov.baryU, &aov.baryV, &aov.uvU, &aov.uvV, &aov.normalX, &aov.normalY, &aov.normalZ})
        plane->assign(pixels, 0.0f);
    if (aov.width == 0) return;

    // The material lookup of materialBaseColor (compute_glsl/buffers.glsl): the scene's materials in
    // the GPU's layout, the last one for an out-of-range index, no coordinates without a texture.
    const std::vector<GpuMaterial> materials = gpuMaterials(scene);
    const bool haveUv = !materials.empty() && scene.triMaterials.size() == scene.triangleCount() &&
                        scene.texcoords.size() == scene.vertexCount();
    const auto textureCount = uint32_t(scene.textures.size());
    const size_t triangles = scene.triangleCount();

    for (size_t i = 0; i < pixels; ++i) {
        const uint32_t id = aov.id[i];
        if (id == EMPTY_ID || id >= triangles) continue;
        const uint32_t i0 = scene.indices[3 * size_t(id)];
        const uint32_t i1 = scene.indices[3 * size_t(id) + 1];
        const uint32_t i2 = scene.indices[3 * size_t(id) + 2];
        const auto px = uint32_t(i % aov.width), py = uint32_t(i / aov.width);
        const SurfacePoint s = surfaceAtNdc(output, aovSampleNdc(params, px, py), false, scene.positions[i0],
                                            scene.positions[i1], scene.positions[i2], scene.normals[i0],
                                            scene.normals[i1], scene.normals[i2]);
        aov.baryU[i] = s.bary.y;
        aov.baryV[i] = s.bary.z;

        if (haveUv) {
            const GpuMaterial& m = materials[std::min<size_t>(scene.triMaterials[id], materials.size() - 1)];
            if (m.baseColorTexture < textureCount) {
                vec2 dx, dy;
                vec2 uv = surfaceUvOfSet(s, scene.texcoords[i0], scene.texcoords[i1], scene.texcoords[i2],
                                         m.texCoord, dx, dy);
                uv = materialTransformUv(m, uv);
                aov.uvU[i] = uv.x;
                aov.uvV[i] = uv.y;
            }
        }

        const vec3 n =
            aovNormal(params, s.bary, scene.positions[i0], scene.positions[i1], scene.positions[i2],
                      scene.normals[i0], scene.normals[i1], scene.normals[i2]);
        aov.normalX[i] = n.x;
        aov.normalY[i] = n.y;
        aov.normalZ[i] = n.z;
    }
}

void fillSampleAovs(const SampleAovs& samples, uint32_t ssaa, AovImage& aov)
{
    const uint32_t perPixel = ssaa * ssaa * samples.samples;
    const uint64_t plane = uint64_t(samples.rasterWidth) * samples.rasterHeight;
    aov.sampleId.assign(perPixel, std::vector<uint32_t>(size_t(aov.width) * aov.height, EMPTY_ID));
    aov.sampleDepth.assign(perPixel, std::vector<float>(size_t(aov.width) * aov.height, 1.0f));
    for (uint32_t y = 0; y < aov.height; ++y)
        for (uint32_t x = 0; x < aov.width; ++x)
            for (uint32_t j = 0; j < ssaa; ++j)
                for (uint32_t i = 0; i < ssaa; ++i)
                    for (uint32_t s = 0; s < samples.samples; ++s) {
                        const uint64_t src =
                            s * plane + uint64_t(y * ssaa + j) * samples.rasterWidth + x * ssaa + i;
                        const size_t k = (size_t(j) * ssaa + i) * samples.samples + s;
                        if (src >= samples.id.size()) continue;
                        aov.sampleId[k][size_t(y) * aov.width + x] = samples.id[src];
                        aov.sampleDepth[k][size_t(y) * aov.width + x] = samples.depth[src];
                    }
}

}  // namespace sr
