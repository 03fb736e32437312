// ao_host.cpp - see ao_host.h. The loops are the stages' (cuda/ao*.cuh), line for line.
#include "ao/ao_host.h"

#include <algorithm>
#include <cmath>

#include "scene/scene.h"

namespace sr {

bool aoSurfaceAt(const Scene& scene, const RasterParams& params, const std::vector<uint64_t>& visibility,
                 uint32_t x, uint32_t y, SurfacePoint& surface, uint32_t& triangle, glm::vec4& gbuffer)
{
    const uint64_t pixel = uint64_t(y) * params.width + x;
    uint64_t key = visibility[pixel];
    for (uint32_t s = 1; s < params.sampleCount; ++s)
        key = std::min(key, visibility[uint64_t(s) * params.samplePlane + pixel]);
    const uint32_t id = visibilityId(key);
    if (id >= params.triangleCount || id >= scene.triangleCount()) return false;
    triangle = id;
    const uint32_t i0 = scene.indices[3 * size_t(id)], i1 = scene.indices[3 * size_t(id) + 1],
                   i2 = scene.indices[3 * size_t(id) + 2];
    surface = surfaceAt(params, int(x), int(y), scene.positions[i0], scene.positions[i1], scene.positions[i2],
                        scene.normals[i0], scene.normals[i1], scene.normals[i2]);
    gbuffer = aoGbufferOf(params, surface.bary, scene.positions[i0], scene.positions[i1], scene.positions[i2],
                          scene.normals[i0], scene.normals[i1], scene.normals[i2]);
    return true;
}

AoGbufferPlanes aoGbufferOnHost(const Scene& scene, const RasterParams& params,
                                const std::vector<uint64_t>& visibility)
{
    const uint64_t plane = params.samplePlane;
    AoGbufferPlanes g(4 * plane, 0.0f);
    for (uint32_t y = 0; y < params.height; ++y)
        for (uint32_t x = 0; x < params.width; ++x) {
            SurfacePoint s{};
            uint32_t triangle = 0;
            glm::vec4 v(0.0f);
            if (!aoSurfaceAt(scene, params, visibility, x, y, s, triangle, v)) continue;
            const uint64_t i = uint64_t(y) * params.width + x;
            g[i] = v.x;
            g[plane + i] = v.y;
            g[2 * plane + i] = v.z;
            g[3 * plane + i] = v.w;
        }
    return g;
}

namespace {

glm::vec3 normalAt(const AoGbufferPlanes& g, uint64_t plane, uint64_t i)
{
    return glm::vec3(g[plane + i], g[2 * plane + i], g[3 * plane + i]);
}

}  // namespace

std::vector<float> gtaoOnHost(const RasterParams& params, const AoGbufferPlanes& g)
{
    const uint64_t plane = params.samplePlane;
    std::vector<float> ao(plane, 1.0f);
    for (uint64_t i = 0; i < plane; ++i) {
        const float dist = g[i];
        const int x = int(i % params.width), y = int(i / params.width);
        const AoPixel a = aoPixelAt(params, x, y, dist, normalAt(g, plane, i));
        if (dist == 0.0f || !(a.radiusPx >= 1.0f)) continue;
        float sum = 0.0f;
        for (uint32_t k = 0; k < params.aoSlices; ++k) {
            AoSlice s = aoSliceBegin(params, a, k);
            for (uint32_t j = 0; j < params.aoSteps; ++j) {
                const float offset = aoStepOffset(params, a, j);
                for (uint32_t side = 0; side < 2; ++side) {
                    const glm::vec2 position = aoSamplePosition(x, y, s.dir, offset, side == 1);
                    const int qx = int(std::floor(position.x)), qy = int(std::floor(position.y));
                    if (qx < 0 || qy < 0 || qx >= int(params.width) || qy >= int(params.height)) continue;
                    const uint64_t q = uint64_t(qy) * params.width + uint64_t(qx);
                    const float d = g[q];
                    if (d == 0.0f) continue;
                    aoSample(params, a, s, aoSurfaceAt(params, position, qx, qy, d, normalAt(g, plane, q)),
                             side == 1);
                }
            }
            sum += aoSliceVisibility(s);
        }
        ao[i] = aoResolve(params, sum);
    }
    return ao;
}

std::vector<float> aoDenoiseOnHost(const RasterParams& params, const AoGbufferPlanes& g,
                                   const std::vector<float>& raw)
{
    const uint64_t plane = params.samplePlane;
    std::vector<float> out(plane, 1.0f);
    for (uint64_t i = 0; i < plane; ++i) {
        const float dist = g[i];
        if (dist == 0.0f) continue;
        const int x = int(i % params.width), y = int(i / params.width);
        const AoPixel a = aoPixelAt(params, x, y, dist, normalAt(g, plane, i));
        float sum = 0.0f, weights = 0.0f;
        for (int dy = -2; dy <= 2; ++dy)
            for (int dx = -2; dx <= 2; ++dx) {
                const int qx = aoDenoiseNeighbour(x + dx, params.width);
                const int qy = aoDenoiseNeighbour(y + dy, params.height);
                if (qx < 0 || qy < 0) continue;
                const uint64_t q = uint64_t(qy) * params.width + uint64_t(qx);
                const float d = g[q];
                if (d == 0.0f) continue;
                const float w = aoDenoiseWeight(a, dist, aoViewPoint(params, qx, qy, d), dx, dy);
                sum += w * raw[q];
                weights += w;
            }
        out[i] = aoDenoiseResolve(sum, weights);
    }
    return out;
}

}  // namespace sr
