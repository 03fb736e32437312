// ao_image.h - the ground-truth ambient occlusion of a whole frame (--ao reference, issue 30): for every
// raster pixel, the surface the GPU's ao_gbuffer stage sees there (the nearest sample's triangle at the
// pixel centre, through the same shared code), its reference AO by rays against the scene's triangles
// (ao_reference.h).
#ifndef RASTER_AO_IMAGE_H
#define RASTER_AO_IMAGE_H

#include <cstdint>
#include <vector>

#include "raster_shared.h"

namespace sr {

struct Scene;
class AoBvh;

// The reference AO of each raster pixel (params.width x params.height, row-major) of the frame drawn
// with `params` from its visibility keys (every sample plane), `radius` in world units, side x side rays
// a pixel; 1 where no triangle covers the pixel (empty, a line or a point). The scene is the one the
// frame drew (no generated triangles). Runs on every core of the host.
std::vector<float> referenceAoImage(const Scene& scene, const AoBvh& bvh, const RasterParams& params,
                                    const std::vector<uint64_t>& visibility, double radius, uint32_t side);

// The world-space point and unit normal of a pixel's AO surface (aoGbufferOf's view-space point and
// normal taken back through viewFromWorld); false where the pixel has no triangle.
bool aoSurfaceWorld(const Scene& scene, const RasterParams& params, const std::vector<uint64_t>& visibility,
                    uint32_t x, uint32_t y, glm::dvec3& point, glm::dvec3& normal);

}  // namespace sr

#endif  // RASTER_AO_IMAGE_H
