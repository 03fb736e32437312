// primitive_mode.h - the display modes of the original course projects: a triangle mesh drawn as its
// vertices (`--primitive-mode points`).
#ifndef RASTER_PRIMITIVE_MODE_H
#define RASTER_PRIMITIVE_MODE_H

#include "scene/scene.h"

namespace sr {

// The scene's triangles replaced by one point per vertex they use, each vertex once, in vertex order,
// with the material of the first triangle (in triangle order) that uses it; the scene's own points
// follow. Everything else (vertices, materials, textures, cameras, bounds) is kept.
Scene meshAsPoints(Scene scene);

}  // namespace sr

#endif  // RASTER_PRIMITIVE_MODE_H
