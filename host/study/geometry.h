// geometry.h - the mesh builders `raster study` shares between its stress cases (study/stress.h) and
// its synthetic accuracy scenes (study/scenes.h): meshes laid out in window coordinates of a square
// viewport and stored as clip coordinates (w = 1) for the identity camera, so that the vertex the
// rasterizer snaps is exactly the one the geometry was computed from.
#ifndef RASTER_STUDY_GEOMETRY_H
#define RASTER_STUDY_GEOMETRY_H

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "camera/camera.h"
#include "scene/scene.h"

namespace sr {

// The identity camera: scene positions are clip coordinates, depth range [0, 1].
CameraMatrices clipCamera();

// Rounds a window coordinate to the 1/256 pixel grid the rasterizer snaps to.
double onGrid(double v);

// Clip coordinates (w = 1) of window position p in a size x size viewport. For a power-of-two size and
// p on the 1/256 grid with |p| < 2^15 the float is exact and the rasterizer snaps it back to p.
glm::vec4 windowToClip(glm::dvec2 p, uint32_t size, double z);

// Appends a vertex (normal +z) and returns its index.
uint32_t addVertex(Scene& scene, glm::vec4 position);

// Appends a triangle with no flags.
void addTriangle(Scene& scene, uint32_t a, uint32_t b, uint32_t c);

// Sets the scene's bounds from its positions.
void computeBounds(Scene& scene);

// The rim of a closed fan of n triangles around `hub`: vertex i at angle 2 pi i / n on the circle of
// `radius` px, rounded to the 1/256 grid. Where rounding would step the rim backwards (n above the
// rim's length in subpixels), the vertex repeats its predecessor instead, so the polygon stays
// star-shaped about the hub and the fan closed: such triangles have zero area and draw nothing, as
// their snapped selves would.
std::vector<glm::dvec2> fanRim(glm::dvec2 hub, double radius, int n);

// A closed fan: triangles (hub, rim[i], rim[i + 1]) around the hub, the last one closing back to
// rim[0], window coordinates of a size x size viewport at window depth z. Consecutive triangles share a
// rim vertex index, so every spoke is one edge drawn twice from the same two vertices.
Scene fanScene(glm::dvec2 hub, const std::vector<glm::dvec2>& rim, uint32_t size, double z);

// The two triangles of the grid cell whose top-left vertex is `a` in a grid `cols` vertices wide, split
// along one diagonal or (`flip`) the other: alternating them makes shared edges run both ways across
// the screen.
void addGridCell(Scene& scene, uint32_t a, uint32_t cols, bool flip);

// Appends a grid mesh: one vertex per grid[j][i] (window coordinates of a size x size viewport, depth
// z) and two triangles per cell, neighbouring cells split along opposite diagonals (addGridCell).
void addGrid(Scene& scene, const std::vector<std::vector<glm::dvec2>>& grid, uint32_t size, double z);

}  // namespace sr

#endif  // RASTER_STUDY_GEOMETRY_H
