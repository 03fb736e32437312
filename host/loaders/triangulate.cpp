// triangulate.cpp - see triangulate.h.
#include "loaders/triangulate.h"

#include <cmath>

namespace sr {
namespace {

// Twice the signed area of triangle (a, b, c): positive when it turns left (counter-clockwise).
double cross2(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c)
{
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// Segments ab and cd cross at one point inside both: touching at an end, or running along each other
// (a bridge edge taken there and back), is not a crossing.
bool properlyCross(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c, const glm::dvec2& d)
{
    double d1 = cross2(a, b, c), d2 = cross2(a, b, d), d3 = cross2(c, d, a), d4 = cross2(c, d, b);
    return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

bool selfIntersecting(const std::vector<glm::dvec2>& p)
{
    size_t n = p.size();
    for (size_t i = 0; i < n; ++i) {
        for (size_t j = i + 2; j < n; ++j) {
            if (i == 0 && j == n - 1) continue;  // adjacent through the closing edge
            if (properlyCross(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n])) return true;
        }
    }
    return false;
}

PolygonTriangles fan(size_t n)
{
    PolygonTriangles out;
    out.fanned = true;
    for (size_t k = 1; k + 1 < n; ++k)
        out.corners.insert(out.corners.end(), {0u, uint32_t(k), uint32_t(k + 1)});
    return out;
}

}  // namespace

PolygonTriangles triangulatePolygon(const std::vector<glm::dvec3>& corners)
{
    const size_t n = corners.size();
    if (n == 3) return PolygonTriangles{{0u, 1u, 2u}, false};
    if (n < 3 || n > kMaxEarClippedCorners) return fan(n);

    // Newell's method: the area-weighted normal, the best-fit plane's for a non-planar polygon.
    glm::dvec3 normal(0.0);
    for (size_t k = 0; k < n; ++k) {
        const glm::dvec3& a = corners[k];
        const glm::dvec3& b = corners[(k + 1) % n];
        normal += glm::dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
    }
    double length = glm::length(normal);
    if (!(length > 0.0) || !std::isfinite(length)) return fan(n);
    normal /= length;

    // An orthonormal basis (u, v) of the plane with u x v = normal: the polygon winds counter-clockwise
    // in (u, v), so ears are the corners that turn left.
    glm::dvec3 helper = std::abs(normal.x) < 0.5 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    glm::dvec3 u = glm::normalize(glm::cross(helper, normal));
    glm::dvec3 v = glm::cross(normal, u);
    std::vector<glm::dvec2> p(n);
    for (size_t k = 0; k < n; ++k) {
        glm::dvec3 d = corners[k] - corners[0];
        p[k] = glm::dvec2(glm::dot(d, u), glm::dot(d, v));
    }
    if (selfIntersecting(p)) return fan(n);

    // The remaining polygon as a circular list.
    std::vector<uint32_t> next(n), prev(n);
    for (size_t k = 0; k < n; ++k) {
        next[k] = uint32_t((k + 1) % n);
        prev[k] = uint32_t((k + n - 1) % n);
    }
    // An ear at corner i: it turns left, and no reflex corner of the rest lies in or on its triangle.
    // Corners at the same place as one of the triangle's (the two ends of a bridge) do not count: they
    // are on its boundary without entering it. Convex corners need no test: one inside would mean a
    // reflex one inside too.
    auto isEar = [&](uint32_t i) {
        uint32_t a = prev[i], c = next[i];
        const glm::dvec2 &pa = p[a], &pb = p[i], &pc = p[c];
        if (!(cross2(pa, pb, pc) > 0.0)) return false;
        for (uint32_t k = next[c]; k != a; k = next[k]) {
            const glm::dvec2& q = p[k];
            if (q == pa || q == pb || q == pc) continue;
            if (cross2(p[prev[k]], q, p[next[k]]) > 0.0) continue;  // convex
            if (cross2(pa, pb, q) >= 0.0 && cross2(pb, pc, q) >= 0.0 && cross2(pc, pa, q) >= 0.0)
                return false;
        }
        return true;
    };

    PolygonTriangles out;
    out.corners.reserve(3 * (n - 2));
    size_t remaining = n;
    uint32_t i = 1;
    // Steps since the last ear: a whole turn without one means only slivers of no area are left
    // (collinear corners) or rounding hides the ears; the rest is then fanned from corner `i`, which
    // keeps the count of triangles and the winding.
    size_t sinceEar = 0;
    while (remaining > 3) {
        if (isEar(i)) {
            out.corners.insert(out.corners.end(), {prev[i], i, next[i]});
            next[prev[i]] = next[i];
            prev[next[i]] = prev[i];
            i = next[i];
            --remaining;
            sinceEar = 0;
            continue;
        }
        i = next[i];
        if (++sinceEar > remaining) {
            out.fanned = true;
            for (uint32_t k = next[i]; next[k] != i; k = next[k])
                out.corners.insert(out.corners.end(), {i, k, next[k]});
            return out;
        }
    }
    out.corners.insert(out.corners.end(), {prev[i], i, next[i]});
    return out;
}

}  // namespace sr
