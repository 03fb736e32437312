// primitive_mode.h - the display modes of the original course projects: a triangle mesh drawn as its
// vertices (`--primitive-mode points`), as its edges, or with its edges drawn over it.
#ifndef RASTER_PRIMITIVE_MODE_H
#define RASTER_PRIMITIVE_MODE_H

#include <string>

#include "base/result.h"
#include "scene/scene.h"

namespace sr {

// The scene's triangles replaced by one point per position their vertices take (compared exactly, so
// split vertices at one corner give one point), the position's first vertex in vertex order, with the
// material of the first triangle (in triangle order) that uses that vertex; the scene's own points
// follow. Everything else (vertices, materials, textures, cameras, bounds) is kept.
Scene meshAsPoints(Scene scene);

// The scene's triangles replaced by their edges, one segment per geometric edge: triangles in order,
// edges (i0, i1), (i1, i2), (i2, i0), the first occurrence of an edge (its two endpoint positions,
// compared exactly and in either order) kept with its triangle's vertex indices, orientation and
// material; the scene's own segments follow; points and everything else are kept.
Scene meshAsLines(Scene scene);

// The scene with meshAsLines's edges appended after its own segments, all with one added last material
// "wireframe" of linear black (lines are unlit), so they draw as black edges over the kept triangles; a
// scene without materials first gets a white opaque material 0 for all its primitives.
Scene withWireframe(Scene scene);

// What a triangle mesh is drawn as (`--primitive-mode`, the viewer's `p` key).
enum class PrimitiveMode { Triangles, Lines, Points };

// "triangles", "lines" or "points".
const char* primitiveModeName(PrimitiveMode mode);
// The mode of that name; any other name is a one-line usage error.
Result<PrimitiveMode> parsePrimitiveMode(const std::string& name);

// How displayScene derived a scene (Scene::display): from `source`, in `mode`, with or without the
// overlay.
struct DisplayForm {
    Scene source;
    PrimitiveMode mode = PrimitiveMode::Triangles;
    bool wireframe = false;
};

// The scene as `raster render --primitive-mode MODE [--wireframe]` draws it: with the wireframe
// overlay, whose edges are taken before a display mode replaces the triangles (so `lines` with the
// overlay keeps both the mesh's edges and the black overlay on them), then as points or lines. The
// overlay also needs RenderSettings::lineDepthBias = kWireframeDepthBias to show. A derived scene
// records its DisplayForm in Scene::display: tessellation changes the triangles per frame, and a
// tessellated frame derives its lines, points and overlay from the tessellated mesh.
Scene displayScene(Scene scene, PrimitiveMode mode, bool wireframe);

}  // namespace sr

#endif  // RASTER_PRIMITIVE_MODE_H
