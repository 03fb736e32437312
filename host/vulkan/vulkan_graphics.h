// vulkan_graphics.h - the `vulkan-graphics` reference backend: the same scene drawn through the real
// Vulkan graphics pipeline (hardware rasterizer on a GPU, Mesa's conformant rasterizer on lavapipe).
//
// One indexed draw of the whole flattened triangle list, so gl_PrimitiveID is the triangle id of the
// compute backends. Attachments: R32_UINT colour (the same packed sRGB RGBA8 word the compute `shade`
// stage writes, computed by the same shared-header shading code), R32_UINT id (gl_PrimitiveID, cleared
// to EMPTY_ID) and D32_SFLOAT depth (LESS, cleared to 1.0). Facing culling happens in the fragment
// shader so that glTF doubleSided triangles are never culled within the single draw. Base colour
// textures are real images (all mip levels, sRGB or UNORM) sampled through real samplers with the
// hardware's derivatives, so the compute path's software sampling is checked against the hardware's.
//
// Anti-aliasing (RenderSettings::msaa, ssaa) draws the raster grid (the output size times ssaa per
// side) with msaa rasterization samples at the standard sample locations, without sample shading: the
// fragment shader runs once per pixel and triangle, at the pixel centre, as the compute pipeline
// shades. The attachments are then R32G32B32A32_SFLOAT linear colour (clamped to [0, 1]), R32_SFLOAT
// id (exact below 2^24 triangles; larger scenes are refused) and D32_SFLOAT depth, multisampled ones
// read back sample by sample by a compute shader; the host averages each output pixel's samples in
// linear space and sRGB-encodes the mean. A sample count the device does not offer for these
// attachments (lavapipe: only 1 and 4) is a one-line Usage error naming the counts it offers.
//
// Lines (Scene::lines) are a second draw in the same pass, after the triangles and before the points, so
// that LESS with this draw order resolves equal depths to the lower id as the compute visibility key
// does: LINE_LIST of 2 * lineCount vertices, each segment's ends fetched through the line list, width
// RenderSettings::lineWidth raster pixels, id = triangleCount + gl_PrimitiveID, colour unlit (shadeUnlit
// of lineBaseColor: the two vertex colours mixed at the hardware's perspective-correct parameter along
// the segment, times the material factor), no facing culling. Coverage is Vulkan's rectangular line
// rasterization (the samples inside the rectangle of the line's width centred on the segment, its ends
// cut square at the endpoints): VK_LINE_RASTERIZATION_MODE_RECTANGULAR_EXT where the device offers
// VK_KHR_ or VK_EXT_line_rasterization with rectangularLines (lavapipe does), else DEFAULT mode where
// limits.strictLines makes that rectangular; a device with neither, or that cannot draw the width
// exactly (lineWidthRange, lineWidthGranularity, wideLines), is a one-line Usage error. The depth bias
// b (RenderSettings::lineDepthBias) draws window depth z as z - b (1 - z), applied to the clip-space
// vertices, so the hardware clips a segment at the near plane where its biased depth reaches 0 (at
// unbiased z = b / (1 + b)); without a bias, at z = 0. Segments are clipped as segments: on lavapipe
// (Mesa 22.3) also at the side planes, so a wide line leaving the view volume at a slant ends in a
// square cap through the point where its centre line leaves, and the corner of its rectangle beyond
// that cap is not drawn, though it lies in the viewport. Samples on a side of the rectangle, which the
// spec leaves open, lavapipe gives to its top and left sides. Under MSAA lavapipe interpolates a line's
// depth and its parameter half a pixel right of and below each sample and pixel centre (coverage is
// right; triangles are not affected), so its multisampled line depths and colours are off by half a
// pixel's gradient (tests/lines_graphics_test.cpp).
//
// Points (Scene::points) are a third draw after the lines: POINT_LIST, each point's vertex fetched
// through the point list, gl_PointSize = RenderSettings::pointSize, id = triangleCount + lineCount +
// gl_PrimitiveID, colour unlit (shadeUnlit: vertex colour x material factor), depth the vertex's. The
// device decides coverage by Vulkan's basic point rasterization (the samples inside the square of side
// pointSize centred on the vertex); a point whose vertex is outside the view volume is discarded whole
// by the vertex shader itself, since devices differ there (reference_point.vert). A size the device
// cannot draw exactly is a one-line Usage error.
#ifndef RASTER_VULKAN_GRAPHICS_H
#define RASTER_VULKAN_GRAPHICS_H

#include "camera/camera.h"
#include "render/renderer.h"
#include "base/result.h"
#include "scene/scene.h"

namespace sr {

// Renders `settings.warmup + settings.repeat` frames on Vulkan device `deviceIndex` (same ordering and
// validation rules as makeVulkanDevice) and returns the last one. stages holds one entry, "draw" (GPU
// time of the render pass; the readback is not timed); stats has trianglesIn, linesIn and pointsIn only;
// samples is filled when settings.aovSamples asks for it; hitCount stays empty.
Result<RenderOutput> renderVulkanGraphics(const Scene& scene, const CameraMatrices& camera,
                                          const RenderSettings& settings, int deviceIndex);

}  // namespace sr

#endif  // RASTER_VULKAN_GRAPHICS_H
