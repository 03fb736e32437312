// aov.h - the surface AOVs (barycentrics, texture coordinates, shading normal) of a rendered frame.
//
// Computed on the host from the frame's triangle ids, with the shade stage's own shared-header code
// (surfaceAt, surfaceUv, materialTransformUv), so every backend's EXR carries the same values for the
// same ids without any backend storing more than its visibility buffer.
#ifndef RASTER_AOV_H
#define RASTER_AOV_H

#include "io/image_io.h"
#include "render/renderer.h"
#include "raster_shared.h"
#include "scene/scene.h"

namespace sr {

// Fills aov's bary, uv and normal channels (see AovImage) from aov.id, for the scene and the
// RasterParams the frame was drawn with (RenderOutput::params, at the raster resolution); aov.width x
// aov.height must be the output size (params.width x params.height / params.ssaa) and aov.id one id per
// pixel. Each pixel's channels describe the sample its id and depth come from (aovSampleIndex). Background pixels, and ids outside the
// scene (which no backend writes), get 0 in every channel.
void fillSurfaceAovs(const Scene& scene, const RasterParams& params, AovImage& aov);

// Fills aov's per-sample channels (AovImage::sampleId, sampleDepth) from every sample of the frame, for
// an output of aov.width x aov.height pixels rendered with SSAA factor `ssaa`.
void fillSampleAovs(const SampleAovs& samples, uint32_t ssaa, AovImage& aov);

}  // namespace sr

#endif  // RASTER_AOV_H
