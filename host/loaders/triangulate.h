// triangulate.h - polygons of scene files (OBJ faces, PLY faces) as triangles.
//
// A polygon is triangulated by ear clipping in its best-fit plane (the plane of its Newell normal), so
// a concave polygon is filled exactly once, where a fan from its first corner covers parts twice and
// parts outside it. Ears are clipped in a fixed order, corner 1 first and then each following corner,
// which for a convex polygon gives exactly the fan (0, k, k + 1): files of convex faces keep their
// triangles and ids. Bridged polygons (a hole joined to the outline by an edge run both ways, as
// LightWave writes them) are simple in this sense and are clipped correctly.
#ifndef RASTER_TRIANGULATE_H
#define RASTER_TRIANGULATE_H

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace sr {

// Polygons with more corners than this are fanned: ear clipping costs O(n^2) per polygon (O(n^3) at
// worst), and a face of millions of corners in a hostile file must not stall the loader.
constexpr size_t kMaxEarClippedCorners = 4096;

struct PolygonTriangles {
    // Corner indices (0 .. n - 1), three per triangle, n - 2 triangles, each wound as the polygon is.
    std::vector<uint32_t> corners;
    // The polygon could not be ear clipped and was fanned from corner 0 instead: its edges cross, it
    // has no area (all corners on a line, or repeated), or it has more than kMaxEarClippedCorners.
    bool fanned = false;
};

// The triangles of the polygon with these corners, in order (at least 3).
PolygonTriangles triangulatePolygon(const std::vector<glm::dvec3>& corners);

}  // namespace sr

#endif  // RASTER_TRIANGULATE_H
