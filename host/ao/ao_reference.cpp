// ao_reference.cpp - the ground-truth ambient occlusion (ao_reference.h).
#include "ao/ao_reference.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "scene/scene.h"

namespace sr {

namespace {

// Triangles per leaf at most.
constexpr uint32_t kLeafTriangles = 4;

bool finite(const glm::dvec3& p)
{
    return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

// Whether the ray meets the slab box [lo, hi] within (tMin, tMax) (division by a zero component gives
// infinities, which the comparisons handle).
bool hitsBox(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& origin, const glm::dvec3& inv,
             double tMin, double tMax)
{
    for (int k = 0; k < 3; ++k) {
        double t0 = (lo[k] - origin[k]) * inv[k], t1 = (hi[k] - origin[k]) * inv[k];
        if (t0 > t1) std::swap(t0, t1);
        if (std::isnan(t0) || std::isnan(t1)) continue;  // origin on a slab plane of a flat box
        tMin = std::max(tMin, t0);
        tMax = std::min(tMax, t1);
        if (tMin > tMax) return false;
    }
    return true;
}

// Moller-Trumbore: whether the ray meets the triangle (either side) at t in (tMin, tMax).
bool hitsTriangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& origin,
                  const glm::dvec3& dir, double tMin, double tMax)
{
    const glm::dvec3 e1 = b - a, e2 = c - a;
    const glm::dvec3 q = glm::cross(dir, e2);
    const double det = glm::dot(e1, q);
    if (det == 0.0) return false;  // the ray is parallel to the triangle's plane
    const double inv = 1.0 / det;
    const glm::dvec3 s = origin - a;
    const double u = glm::dot(s, q) * inv;
    if (u < 0.0 || u > 1.0) return false;
    const glm::dvec3 r = glm::cross(s, e1);
    const double v = glm::dot(dir, r) * inv;
    if (v < 0.0 || u + v > 1.0) return false;
    const double t = glm::dot(e2, r) * inv;
    return t > tMin && t < tMax;
}

// A fixed hash of a cell, for its jitter: two values in [0, 1).
glm::dvec2 cellJitter(uint32_t i, uint32_t j)
{
    uint32_t h = i * 0x8da6b343u ^ j * 0xd8163841u ^ 0x9e3779b9u;
    auto next = [&h] {
        h ^= h >> 16;
        h *= 0x7feb352du;
        h ^= h >> 15;
        h *= 0x846ca68bu;
        h ^= h >> 16;
        return double(h) / 4294967296.0;
    };
    const double u = next();
    return {u, next()};
}

}  // namespace

AoBvh::AoBvh(const Scene& scene)
{
    const size_t count = scene.indices.size() / 3;
    for (size_t t = 0; t < count; ++t) {
        Triangle tri;
        glm::dvec3* corner[3] = {&tri.a, &tri.b, &tri.c};
        bool ok = true;
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = scene.indices[3 * t + k];
            ok = ok && v < scene.positions.size();
            if (!ok) break;
            *corner[k] = glm::dvec3(glm::vec3(scene.positions[v]));
            ok = finite(*corner[k]);
        }
        if (ok) triangles_.push_back(tri);
    }
    if (!triangles_.empty()) build(0, uint32_t(triangles_.size()));
}

// Builds the node over triangles_[first, first + count) (reordering them) and returns its index: split
// at the median of the centroids along the box's longest axis.
uint32_t AoBvh::build(uint32_t first, uint32_t count)
{
    Node node;
    node.lo = glm::dvec3(INFINITY);
    node.hi = glm::dvec3(-INFINITY);
    for (uint32_t t = first; t < first + count; ++t)
        for (const glm::dvec3& p : {triangles_[t].a, triangles_[t].b, triangles_[t].c}) {
            node.lo = glm::min(node.lo, p);
            node.hi = glm::max(node.hi, p);
        }
    const auto index = uint32_t(nodes_.size());
    nodes_.push_back(node);
    if (count <= kLeafTriangles) {
        nodes_[index].first = first;
        nodes_[index].count = count;
        return index;
    }
    const glm::dvec3 extent = node.hi - node.lo;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
    auto centroid = [axis](const Triangle& t) { return t.a[axis] + t.b[axis] + t.c[axis]; };
    const uint32_t half = count / 2;
    std::nth_element(triangles_.begin() + first, triangles_.begin() + first + half,
                     triangles_.begin() + first + count,
                     [&](const Triangle& x, const Triangle& y) { return centroid(x) < centroid(y); });
    const uint32_t left = build(first, half);
    const uint32_t right = build(first + half, count - half);
    nodes_[index].left = left;
    nodes_[index].right = right;
    return index;
}

bool AoBvh::occluded(const glm::dvec3& origin, const glm::dvec3& dir, double tMin, double tMax) const
{
    if (nodes_.empty()) return false;
    const glm::dvec3 inv(1.0 / dir.x, 1.0 / dir.y, 1.0 / dir.z);
    std::vector<uint32_t> stack{0u};
    while (!stack.empty()) {
        const Node& node = nodes_[stack.back()];
        stack.pop_back();
        if (!hitsBox(node.lo, node.hi, origin, inv, tMin, tMax)) continue;
        if (node.count > 0) {
            for (uint32_t t = node.first; t < node.first + node.count; ++t) {
                const Triangle& tri = triangles_[t];
                if (hitsTriangle(tri.a, tri.b, tri.c, origin, dir, tMin, tMax)) return true;
            }
            continue;
        }
        stack.push_back(node.left);
        stack.push_back(node.right);
    }
    return false;
}

double referenceAo(const AoBvh& bvh, const glm::dvec3& p, const glm::dvec3& n, double radius, uint32_t side,
                   double bias)
{
    // An orthonormal frame (t, b, n) about the normal.
    const glm::dvec3 helper = std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 t = glm::normalize(glm::cross(helper, n));
    const glm::dvec3 b = glm::cross(n, t);
    const glm::dvec3 origin = p + bias * n;
    uint32_t open = 0;
    for (uint32_t i = 0; i < side; ++i)
        for (uint32_t j = 0; j < side; ++j) {
            const glm::dvec2 jitter = cellJitter(i, j);
            const double u = (i + jitter.x) / side, v = (j + jitter.y) / side;
            // Malley: a uniform point of the unit disc (radius sqrt(u), angle 2 pi v), lifted onto the
            // hemisphere, has density cos(theta) / pi there.
            const double r = std::sqrt(u), phi = 2.0 * M_PI * v;
            const double x = r * std::cos(phi), y = r * std::sin(phi), z = std::sqrt(std::max(0.0, 1.0 - u));
            const glm::dvec3 dir = x * t + y * b + z * n;
            open += bvh.occluded(origin, dir, 0.0, radius) ? 0u : 1u;
        }
    return double(open) / (double(side) * side);
}

}  // namespace sr
