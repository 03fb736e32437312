// tessellate.cpp - tessellation records, the host's oracle of the tess_* stages, id mapping.
#include "render/tessellate.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <unordered_map>

#include <fmt/format.h>

#include "base/warnings.h"
#include "shared/tess_emit.h"

namespace sr {
namespace {

// Bits of a float with -0 taken as +0 (tessPrecedes compares values, not bits).
uint32_t keyBits(float v)
{
    if (v == 0.0f) return 0u;
    uint32_t b;
    std::memcpy(&b, &v, sizeof b);
    return b;
}

using EdgeKey = std::array<uint32_t, 6>;
struct EdgeKeyHash {
    size_t operator()(const EdgeKey& k) const
    {
        uint64_t h = 1469598103934665603ull;
        for (uint32_t v : k) h = (h ^ v) * 1099511628211ull;
        return size_t(h);
    }
};

// One triangle's view of an edge: which triangle and edge, and its normals at the canonical ends.
struct EdgeSide {
    uint32_t tri;
    uint32_t edge;
    glm::vec4 na, nb;
};

bool goodNormal(const glm::vec4& n)
{
    float l2 = n.x * n.x + n.y * n.y + n.z * n.z;
    return std::isfinite(l2) && l2 > 0.0f;
}

bool sameNormal(const glm::vec4& a, const glm::vec4& b)
{
    return a.x == b.x && a.y == b.y && a.z == b.z;
}

TessVertex hostVertex(const Scene& scene, const RasterParams& params, uint32_t i)
{
    TessVertex v;
    v.position = scene.positions[i];
    v.normal = scene.normals[i];
    v.texcoord = params.textureCount > 0u ? scene.texcoords[i] : glm::vec4(0.0f);
    v.color = params.hasColors != 0u ? scene.colors[i] : glm::vec4(1.0f);
    return v;
}

TessPatch hostPatch(const Scene& scene, const RasterParams& params, const TessSource& s)
{
    return tessMakePatch(params.tessMode, hostVertex(scene, params, s.i0), hostVertex(scene, params, s.i1),
                         hostVertex(scene, params, s.i2), s.flags);
}

}  // namespace

TessSources tessSources(const Scene& scene)
{
    TessSources out;
    const size_t triangles = scene.triangleCount();
    out.sources.resize(triangles);
    std::unordered_map<EdgeKey, std::vector<EdgeSide>, EdgeKeyHash> edges;
    edges.reserve(triangles * 2);
    for (size_t t = 0; t < triangles; ++t) {
        TessSource& s = out.sources[t];
        s.i0 = scene.indices[3 * t];
        s.i1 = scene.indices[3 * t + 1];
        s.i2 = scene.indices[3 * t + 2];
        s.flags = (scene.triFlags[t] & 255u) << TESS_TRI_FLAGS_SHIFT;
        const uint32_t corners[3] = {s.i0, s.i1, s.i2};
        bool flat = false;
        for (uint32_t c : corners) flat = flat || !goodNormal(scene.normals[c]);
        if (flat) {
            s.flags |= TESS_FLAT_PATCH;
            ++out.flatPatches;
        }
        for (uint32_t e = 0; e < 3; ++e) {
            uint32_t a = corners[e], b = corners[(e + 1) % 3];
            if (!tessPrecedes(scene.positions[a], scene.positions[b])) std::swap(a, b);
            const glm::vec4& pa = scene.positions[a];
            const glm::vec4& pb = scene.positions[b];
            EdgeKey key = {keyBits(pa.x), keyBits(pa.y), keyBits(pa.z),
                           keyBits(pb.x), keyBits(pb.y), keyBits(pb.z)};
            edges[key].push_back({uint32_t(t), e, scene.normals[a], scene.normals[b]});
        }
    }
    for (const auto& [key, sides] : edges) {
        bool straight = sides.size() > 2;
        for (const EdgeSide& side : sides)
            straight = straight || (out.sources[side.tri].flags & TESS_FLAT_PATCH) != 0u;
        if (sides.size() == 2)
            straight =
                straight || !sameNormal(sides[0].na, sides[1].na) || !sameNormal(sides[0].nb, sides[1].nb);
        if (!straight) continue;
        for (const EdgeSide& side : sides) out.sources[side.tri].flags |= 1u << side.edge;
    }
    if (out.flatPatches > 0)
        warn("{} triangle(s) have a zero or non-finite normal: pn tessellation keeps them flat",
             out.flatPatches);
    return out;
}

TessellatedScene tessellateOnHost(const Scene& scene, const TessSources& sources, const RasterParams& params)
{
    TessellatedScene out;
    const auto triangles = uint32_t(sources.sources.size());
    std::vector<uvec4> entries(triangles);
    uint64_t vertices = 0, generated = 0;
    for (uint32_t t = 0; t < triangles; ++t) {
        uvec4 e = tessCountTriangle(params, hostPatch(scene, params, sources.sources[t]));
        if ((e.w & TESS_STATE_CULLED) != 0u) ++out.culled;
        entries[t] = uvec4(uint32_t(vertices), uint32_t(generated), e.z, e.w);
        vertices += e.x;
        generated += e.y;
    }

    Scene& g = out.scene;
    g = scene;
    const size_t v = scene.vertexCount();
    g.positions.resize(v + vertices);
    g.normals.resize(v + vertices);
    if (params.hasColors != 0u) g.colors.resize(v + vertices);
    if (params.textureCount > 0u) g.texcoords.resize(v + vertices);
    g.indices.assign(3 * generated, 0u);
    g.triFlags.assign(generated, 0u);
    const bool materials = params.materialCount > 0u;
    if (materials) g.triMaterials.assign(generated, 0u);
    out.sourceIds.assign(generated, 0u);

    TessWriter w{};
    w.positions = g.positions.data();
    w.normals = g.normals.data();
    w.texcoords = g.texcoords.data();
    w.colors = g.colors.data();
    w.indices = g.indices.data();
    w.triFlags = g.triFlags.data();
    w.triMaterials = g.triMaterials.data();
    w.ids = out.sourceIds.data();
    w.materials = materials ? scene.triMaterials.data() : nullptr;
    w.sources = sources.sources.data();
    w.sourceVertices = params.tessSourceVertices;
    w.hasTexcoords = params.textureCount > 0u;
    w.hasColors = params.hasColors != 0u;
    for (uint32_t t = 0; t < triangles; ++t) {
        const uvec4& e = entries[t];
        tessEmitTriangle(params, sources.sources[t], hostPatch(scene, params, sources.sources[t]), t, e,
                         params.tessSourceVertices + e.x, e.y, w);
    }
    return out;
}

uint32_t sourcePrimitiveId(uint32_t id, const std::vector<uint32_t>& sourceIds, uint32_t sceneTriangles)
{
    if (id == EMPTY_ID) return id;
    if (id < sourceIds.size()) return sourceIds[id];
    return id - uint32_t(sourceIds.size()) + sceneTriangles;
}

void mapToSourceIds(std::vector<uint32_t>& ids, const std::vector<uint32_t>& sourceIds,
                    uint32_t sceneTriangles)
{
    for (uint32_t& id : ids) id = sourcePrimitiveId(id, sourceIds, sceneTriangles);
}

}  // namespace sr
