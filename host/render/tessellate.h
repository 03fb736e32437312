// tessellate.h - the host's half of tessellation (--tessellate, common/shared/tessellate.h): the scene
// triangles' records with the edges pn must keep straight, the host's run of the tess_* stages (the
// oracle the tests hold both backends to, and what vulkan-graphics draws), and the map from generated
// triangles back to the scene's primitives.
#ifndef RASTER_TESSELLATE_H
#define RASTER_TESSELLATE_H

#include <cstdint>
#include <vector>

#include "raster_shared.h"
#include "scene/scene.h"

namespace sr {

// The scene's triangles as tessellation reads them (BUF_TESS_SOURCE). An edge is kept straight under pn
// unless exactly two triangles share it (by position) and both see the same normals at its ends; a
// triangle with a zero or non-finite corner normal is a flat patch, and its edges are straight.
struct TessSources {
    std::vector<TessSource> sources;
    uint64_t flatPatches = 0;  // triangles with a bad normal
};
// The records, and the one warning line on stderr when some triangle is a flat patch.
TessSources tessSources(const Scene& scene);

// The frame's generated mesh: the scene's vertices followed by the generated ones, the generated
// triangles in place of the scene's (lines and points unchanged, their ids after the new triangles).
struct TessellatedScene {
    Scene scene;
    std::vector<uint32_t> sourceIds;  // per generated triangle: its scene triangle (BUF_TESS_IDS)
    uint64_t culled = 0;              // scene triangles that generated nothing
};

// Stages tess_count, the scans and tess_emit on the host, with the same shared functions in the same
// order: the mesh a device generates for `params` (frameParams with settings.tessellate), bit for bit.
TessellatedScene tessellateOnHost(const Scene& scene, const TessSources& sources, const RasterParams& params);

// The scene primitive a tessellated frame's id names: its scene triangle for a generated triangle, the
// same segment or point for the rest (shifted back by the change in triangle count); EMPTY_ID stays.
uint32_t sourcePrimitiveId(uint32_t id, const std::vector<uint32_t>& sourceIds, uint32_t sceneTriangles);
void mapToSourceIds(std::vector<uint32_t>& ids, const std::vector<uint32_t>& sourceIds,
                    uint32_t sceneTriangles);

}  // namespace sr

#endif  // RASTER_TESSELLATE_H
