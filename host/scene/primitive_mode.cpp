// primitive_mode.cpp - see primitive_mode.h.
#include "scene/primitive_mode.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <unordered_set>

namespace sr {
namespace {

// An undirected edge by the bit patterns of its endpoints' xyz, the smaller endpoint first so that
// both directions give one key. -0 is stored as +0, so that bit equality is float equality (NaN aside,
// which finalizeScene drops anyway).
using EdgeKey = std::array<uint32_t, 6>;
using PositionKey = std::array<uint32_t, 3>;

struct BitsHash {
    template <size_t N>
    size_t operator()(const std::array<uint32_t, N>& key) const
    {
        uint64_t h = 0x9e3779b97f4a7c15ull;
        for (uint32_t word : key) {
            h ^= word;
            h *= 0xff51afd7ed558ccdull;
            h ^= h >> 32;
        }
        return size_t(h);
    }
};

std::array<uint32_t, 3> positionBits(const glm::vec4& p)
{
    std::array<uint32_t, 3> bits;
    for (int c = 0; c < 3; ++c) {
        float value = p[c] + 0.0f;  // -0 + 0 is +0
        std::memcpy(&bits[size_t(c)], &value, sizeof value);
    }
    return bits;
}

// The unique edges of the scene's triangles as segments (two vertex indices each), with the triangle
// each one came from. Edges with an out-of-range vertex index have no position to compare and are left
// out, as meshAsPoints leaves such vertices out.
struct Edges {
    std::vector<uint32_t> lines;
    std::vector<size_t> triangles;
};

Edges uniqueEdges(const Scene& scene)
{
    Edges edges;
    std::unordered_set<EdgeKey, BitsHash> seen;
    seen.reserve(scene.indices.size());
    for (size_t t = 0; t < scene.triangleCount(); ++t) {
        const uint32_t* tri = &scene.indices[3 * t];
        for (size_t c = 0; c < 3; ++c) {
            uint32_t a = tri[c], b = tri[(c + 1) % 3];
            if (a >= scene.vertexCount() || b >= scene.vertexCount()) continue;
            std::array<uint32_t, 3> pa = positionBits(scene.positions[a]);
            std::array<uint32_t, 3> pb = positionBits(scene.positions[b]);
            if (pb < pa) std::swap(pa, pb);
            EdgeKey key = {pa[0], pa[1], pa[2], pb[0], pb[1], pb[2]};
            if (!seen.insert(key).second) continue;
            edges.lines.insert(edges.lines.end(), {a, b});
            edges.triangles.push_back(t);
        }
    }
    return edges;
}

// The scene without its triangles (a display mode replaced them).
void dropTriangles(Scene& scene)
{
    scene.indices.clear();
    scene.triFlags.clear();
    scene.triMaterials.clear();
}

}  // namespace

Scene meshAsPoints(Scene scene)
{
    const bool materials = !scene.materials.empty();
    constexpr uint32_t kUnused = 0xFFFFFFFFu;
    std::vector<uint32_t> material(scene.vertexCount(), kUnused);  // per vertex: first user's material
    for (size_t t = 0; t < scene.triangleCount(); ++t)
        for (size_t c = 0; c < 3; ++c) {
            uint32_t v = scene.indices[3 * t + c];
            if (v < material.size() && material[v] == kUnused)
                material[v] = materials ? scene.triMaterials[t] : 0u;
        }
    // One point per position: a mesh with split vertices (hard normals, texture seams) repeats a
    // corner's position in several vertices, which would draw the same square several times.
    std::unordered_set<PositionKey, BitsHash> seen;
    std::vector<uint32_t> points, pointMaterials;
    for (uint32_t v = 0; v < material.size(); ++v) {
        if (material[v] == kUnused || !seen.insert(positionBits(scene.positions[v])).second) continue;
        points.push_back(v);
        if (materials) pointMaterials.push_back(material[v]);
    }
    points.insert(points.end(), scene.points.begin(), scene.points.end());
    pointMaterials.insert(pointMaterials.end(), scene.pointMaterials.begin(), scene.pointMaterials.end());
    scene.points = std::move(points);
    scene.pointMaterials = std::move(pointMaterials);
    dropTriangles(scene);
    return scene;
}

Scene meshAsLines(Scene scene)
{
    Edges edges = uniqueEdges(scene);
    std::vector<uint32_t> lineMaterials;
    if (!scene.materials.empty()) {
        lineMaterials.reserve(edges.triangles.size() + scene.lineMaterials.size());
        for (size_t t : edges.triangles) lineMaterials.push_back(scene.triMaterials[t]);
    }
    edges.lines.insert(edges.lines.end(), scene.lines.begin(), scene.lines.end());
    lineMaterials.insert(lineMaterials.end(), scene.lineMaterials.begin(), scene.lineMaterials.end());
    scene.lines = std::move(edges.lines);
    scene.lineMaterials = std::move(lineMaterials);
    dropTriangles(scene);
    return scene;
}

Scene withWireframe(Scene scene)
{
    Edges edges = uniqueEdges(scene);
    if (scene.materials.empty()) {
        // Scene's emptiness rule: no materials means every primitive is white and opaque, which is
        // what this material says, so the scene looks the same with one index per primitive added.
        SceneMaterial white;
        white.name = "default";
        scene.materials.push_back(white);
        scene.triMaterials.assign(scene.triangleCount(), 0u);
        scene.lineMaterials.assign(scene.lineCount(), 0u);
        scene.pointMaterials.assign(scene.pointCount(), 0u);
    }
    SceneMaterial wireframe;
    wireframe.name = "wireframe";
    wireframe.baseColorFactor = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
    auto wireframeIndex = uint32_t(scene.materials.size());
    scene.materials.push_back(wireframe);
    scene.lines.insert(scene.lines.end(), edges.lines.begin(), edges.lines.end());
    scene.lineMaterials.insert(scene.lineMaterials.end(), edges.triangles.size(), wireframeIndex);
    return scene;
}

const char* primitiveModeName(PrimitiveMode mode)
{
    switch (mode) {
    case PrimitiveMode::Lines: return "lines";
    case PrimitiveMode::Points: return "points";
    case PrimitiveMode::Triangles: break;
    }
    return "triangles";
}

Result<PrimitiveMode> parsePrimitiveMode(const std::string& name)
{
    for (PrimitiveMode mode : {PrimitiveMode::Triangles, PrimitiveMode::Lines, PrimitiveMode::Points})
        if (name == primitiveModeName(mode)) return mode;
    return makeError(ExitCode::Usage, "invalid primitive mode '{}': expected triangles, lines or points",
                     name);
}

Scene displayScene(Scene scene, PrimitiveMode mode, bool wireframe)
{
    if (mode == PrimitiveMode::Triangles && !wireframe) return scene;
    scene.display.reset();
    auto form = std::make_shared<DisplayForm>(DisplayForm{scene, mode, wireframe});
    if (wireframe) scene = withWireframe(std::move(scene));
    if (mode == PrimitiveMode::Lines) scene = meshAsLines(std::move(scene));
    if (mode == PrimitiveMode::Points) scene = meshAsPoints(std::move(scene));
    scene.display = std::move(form);
    return scene;
}

}  // namespace sr
