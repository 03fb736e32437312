// ao_image.cpp - see ao_image.h.
#include "ao/ao_image.h"

#include <algorithm>
#include <atomic>
#include <thread>

#include <glm/gtc/matrix_inverse.hpp>

#include "ao/ao_host.h"
#include "ao/ao_reference.h"
#include "scene/scene.h"

namespace sr {

bool aoSurfaceWorld(const Scene& scene, const RasterParams& params, const std::vector<uint64_t>& visibility,
                    uint32_t x, uint32_t y, glm::dvec3& point, glm::dvec3& normal)
{
    SurfacePoint s{};
    uint32_t triangle = 0;
    glm::vec4 g(0.0f);
    if (!aoSurfaceAt(scene, params, visibility, x, y, s, triangle, g)) return false;
    const size_t t = 3 * size_t(triangle);
    // The point from the barycentrics and the world-space corners in double precision, so that it lies in
    // its triangle's plane far closer than the rays' offset (taken back from the float view-space point,
    // it was up to about 1e-6 off on curved meshes, as far as the offset, and some of its rays started
    // behind its own triangle: black speckles on the bunny and the torus). The normal goes back through
    // the transpose of the inverse transpose (normalFromWorld's inverse), renormalised.
    // With MSAA the pixel centre may lie outside the nearest sample's triangle, where surfaceAt
    // extrapolates its plane (as shading does); on a mesh of pixel-sized triangles that point is under
    // the neighbouring triangles, which then occlude it, so the rays start from the triangle's nearest
    // point instead: the barycentrics clamped to it.
    glm::dvec3 bary = glm::clamp(glm::dvec3(s.bary), 0.0, 1.0);
    bary /= bary.x + bary.y + bary.z;
    point = bary.x * glm::dvec3(scene.positions[scene.indices[t]]) +
            bary.y * glm::dvec3(scene.positions[scene.indices[t + 1]]) +
            bary.z * glm::dvec3(scene.positions[scene.indices[t + 2]]);
    const glm::dmat3 normalFromView = glm::transpose(glm::dmat3(glm::dmat4(params.viewFromWorld)));
    normal = glm::normalize(normalFromView * glm::dvec3(g.y, g.z, g.w));
    return true;
}

std::vector<float> referenceAoImage(const Scene& scene, const AoBvh& bvh, const RasterParams& params,
                                    const std::vector<uint64_t>& visibility, double radius, uint32_t side)
{
    const uint32_t width = params.width, height = params.height;
    std::vector<float> ao(uint64_t(width) * height, 1.0f);
    const glm::dvec3 extent = glm::dvec3(scene.boundsMax) - glm::dvec3(scene.boundsMin);
    const double bias = 1e-6 * std::max({extent.x, extent.y, extent.z, 1e-30});
    std::atomic<uint32_t> nextRow{0};
    auto work = [&] {
        for (uint32_t y = nextRow++; y < height; y = nextRow++)
            for (uint32_t x = 0; x < width; ++x) {
                glm::dvec3 p, n;
                if (aoSurfaceWorld(scene, params, visibility, x, y, p, n))
                    ao[uint64_t(y) * width + x] = float(referenceAo(bvh, p, n, radius, side, bias));
            }
    };
    const unsigned threads = std::max(1u, std::min(std::thread::hardware_concurrency(), 64u));
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
    return ao;
}

}  // namespace sr
