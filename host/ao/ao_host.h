// ao_host.h - the GTAO stages (ao_gbuffer, ao, ao_denoise) run on the host through the same shared code
// as cuda/ao*.cuh and compute_glsl/ao*.comp (common/shared/ao.h is valid C++, and the host is built
// without contraction, so it computes the same bits). The vulkan-graphics reference backend runs them on
// the G-buffer its graphics pipeline drew (host/vulkan/vulkan_graphics.cpp), and the tests compare the
// devices with them.
#ifndef RASTER_AO_HOST_H
#define RASTER_AO_HOST_H

#include <cstdint>
#include <vector>

#include "raster_shared.h"

namespace sr {

struct Scene;

// ao_gbuffer's output as the host keeps it: four planes of params.samplePlane entries, the distance and
// the normal's x, y, z (BUF_AO's AO_PLANE_DISTANCE and AO_PLANE_NORMAL planes, in that order).
using AoGbufferPlanes = std::vector<float>;

// Stage ao_gbuffer from the frame's visibility keys (every sample plane) and the scene it drew.
AoGbufferPlanes aoGbufferOnHost(const Scene& scene, const RasterParams& params,
                                const std::vector<uint64_t>& visibility);
// Stage ao: plane 0 of BUF_AO.
std::vector<float> gtaoOnHost(const RasterParams& params, const AoGbufferPlanes& gbuffer);
// Stage ao_denoise: plane 1 of BUF_AO from plane 0.
std::vector<float> aoDenoiseOnHost(const RasterParams& params, const AoGbufferPlanes& gbuffer,
                                   const std::vector<float>& raw);

// The surface AO sees at raster pixel (x, y): its nearest sample's triangle (the smallest key, as
// ao_gbuffer takes it) at the pixel centre, its id, and what ao_gbuffer stores of it (aoGbufferOf);
// false where no triangle covers it.
bool aoSurfaceAt(const Scene& scene, const RasterParams& params, const std::vector<uint64_t>& visibility,
                 uint32_t x, uint32_t y, SurfacePoint& surface, uint32_t& triangle, glm::vec4& gbuffer);

}  // namespace sr

#endif  // RASTER_AO_HOST_H
