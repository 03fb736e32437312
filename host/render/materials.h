// materials.h - the scene's materials and textures in the GPU's layout (raster_shared.h's GpuMaterial
// and GpuTexture), shared by the compute renderer and the vulkan-graphics reference so that both read
// the very same records.
#ifndef RASTER_MATERIALS_H
#define RASTER_MATERIALS_H

#include <cstdint>
#include <vector>

#include "base/result.h"
#include "raster_shared.h"
#include "scene/scene.h"

namespace sr {

// One GpuMaterial per scene material, in order. The KHR_texture_transform matrix becomes its first two
// rows (uvTransformU, uvTransformV: u' = x u + y v + z); a material without a texture (base colour or
// emissive) gets NO_TEXTURE there.
std::vector<GpuMaterial> gpuMaterials(const Scene& scene);

// One GpuTexture per scene texture, in order, with every texture's texels (all levels) appended to
// `texels` (cleared first) at the GpuTexture's texelOffset. Fails, leaving `texels` empty, when the
// texels together pass the 2^32 that a uint offset can address.
Result<std::vector<GpuTexture>> gpuTextures(const Scene& scene, std::vector<uint32_t>& texels);

}  // namespace sr

#endif  // RASTER_MATERIALS_H
