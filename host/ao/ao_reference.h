// ao_reference.h - ground-truth ambient occlusion (issue 30): the cosine-weighted visibility of a
// surface point's hemisphere within a radius, by casting rays against the scene's triangles on the host.
//
// Ambient occlusion at a point p with unit normal n is
//   AO(p) = 1/pi * integral over the hemisphere of V(p, w) (n . w) dw,
// V = 1 where the ray from p along w meets no triangle closer than the radius R. With directions drawn
// with density (n . w) / pi the integral is the mean of V, so the estimate is the fraction of unoccluded
// cosine-weighted rays. The directions are a stratified k x k grid on the unit square (cell centres,
// jittered by a fixed hash of the cell, so the same point always gets the same rays) mapped to the
// hemisphere by Malley's method: a uniform point of the unit disc, lifted onto the hemisphere. This is
// what the screen-space estimate (GTAO) will be measured against: it sees every triangle, not a depth
// buffer, and it is slow (a BVH on the host), which is fine for a reference.
#ifndef RASTER_AO_REFERENCE_H
#define RASTER_AO_REFERENCE_H

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace sr {

struct Scene;

// A bounding volume hierarchy over a scene's triangles (those whose corners are finite), built once.
class AoBvh {
public:
    explicit AoBvh(const Scene& scene);

    // Whether a triangle lies along the ray origin + t dir for some t in (tMin, tMax); dir need not be
    // unit length (t is in its units).
    bool occluded(const glm::dvec3& origin, const glm::dvec3& dir, double tMin, double tMax) const;

    size_t triangleCount() const { return triangles_.size(); }

private:
    struct Node {
        glm::dvec3 lo, hi;
        uint32_t first = 0, count = 0;  // a leaf: triangles_[first, first + count)
        uint32_t left = 0, right = 0;   // an inner node (count == 0): its children
    };
    struct Triangle {
        glm::dvec3 a, b, c;
    };
    uint32_t build(uint32_t first, uint32_t count);

    std::vector<Triangle> triangles_;
    std::vector<Node> nodes_;
};

// The reference ambient occlusion at p (world space) with unit normal n: the fraction of `side` x
// `side` stratified cosine-weighted rays that meet no triangle within `radius`. Rays start a relative
// 1e-6 of the scene's extent (`bias`, world units) off the surface along n, so that the point's own
// triangle does not occlude it.
double referenceAo(const AoBvh& bvh, const glm::dvec3& p, const glm::dvec3& n, double radius, uint32_t side,
                   double bias);

}  // namespace sr

#endif  // RASTER_AO_REFERENCE_H
