// scene.cpp - loader dispatch and the checks every loaded scene goes through.
#include "scene/scene.h"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <unordered_map>

#include "base/warnings.h"

namespace sr {
namespace {

// Limits that keep every index, primitive id and byte offset the backends compute inside 31 bits.
constexpr uint64_t kMaxIndices = (uint64_t(1) << 31) / 3;
constexpr uint64_t kMaxVertices = uint64_t(1) << 31;
// Segment indices and points get the index limit too, so triangle, segment and point ids together (at
// most kMaxIndices / 3 + kMaxIndices / 2 + kMaxIndices) stay below 2^31.
constexpr uint64_t kMaxLineIndices = kMaxIndices;
constexpr uint64_t kMaxPoints = kMaxIndices;

constexpr const char* kSceneExtensions = ".gltf, .glb, .obj, .ply or .stl";

std::string lowerExtension(const std::string& path)
{
    size_t slash = path.find_last_of("/\\");
    size_t dot = path.find_last_of('.');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    std::string ext = path.substr(dot);
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

bool finitePosition(const glm::vec4& p)
{
    return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && std::isfinite(p.w);
}

// Textures must be what GpuTexture promises (full chain, sizes in range); materials, per-triangle
// material indices and texture coordinates must be consistent, since the backends index with them
// without further checks.
Status checkMaterials(const Scene& scene, size_t triangles, const std::string& errorPrefix)
{
    for (size_t i = 0; i < scene.textures.size(); ++i) {
        const SceneTexture& t = scene.textures[i];
        bool sizeOk =
            t.width >= 1 && t.height >= 1 && t.width <= MAX_TEXTURE_DIM && t.height <= MAX_TEXTURE_DIM;
        uint32_t levels = 1;
        size_t texels = 0;
        if (sizeOk) {
            for (uint32_t m = std::max(t.width, t.height); m > 1; m >>= 1) ++levels;
            for (uint32_t k = 0; k < levels; ++k)
                texels += size_t(std::max(1u, t.width >> k)) * std::max(1u, t.height >> k);
        }
        if (!sizeOk || t.levels != levels || t.texels.size() != texels)
            return makeError(ExitCode::Usage,
                             "{}: texture {} ('{}', {}x{}, {} levels, {} texels) is malformed", errorPrefix,
                             i, t.name, t.width, t.height, t.levels, t.texels.size());
    }
    bool anyTexture = false;
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        const SceneMaterial& m = scene.materials[i];
        if (m.baseColorTexture < -1 ||
            (m.baseColorTexture >= 0 && size_t(m.baseColorTexture) >= scene.textures.size()))
            return makeError(ExitCode::Usage, "{}: material {} uses texture {}, but there are {} textures",
                             errorPrefix, i, m.baseColorTexture, scene.textures.size());
        if (m.emissiveTexture < -1 ||
            (m.emissiveTexture >= 0 && size_t(m.emissiveTexture) >= scene.textures.size()))
            return makeError(ExitCode::Usage,
                             "{}: material {} uses emissive texture {}, but there are {} textures",
                             errorPrefix, i, m.emissiveTexture, scene.textures.size());
        if (m.texCoord > 1 || m.emissiveTexCoord > 1)
            return makeError(ExitCode::Usage,
                             "{}: material {} uses texture coordinate set {} (0 or 1 expected)", errorPrefix,
                             i, std::max(m.texCoord, m.emissiveTexCoord));
        if (m.alphaMode != ALPHA_OPAQUE && m.alphaMode != ALPHA_MASK)
            return makeError(ExitCode::Usage, "{}: material {} has unknown alpha mode {}", errorPrefix, i,
                             m.alphaMode);
        anyTexture = anyTexture || m.baseColorTexture >= 0 || m.emissiveTexture >= 0;
    }
    // One material index per triangle, per segment and per point when there are materials, none
    // otherwise.
    bool haveMaterials = !scene.materials.empty();
    if (scene.triMaterials.size() != (haveMaterials ? triangles : 0))
        return makeError(ExitCode::Usage,
                         "{}: {} per-triangle material indices for {} triangles and {} materials",
                         errorPrefix, scene.triMaterials.size(), triangles, scene.materials.size());
    for (size_t t = 0; t < scene.triMaterials.size(); ++t) {
        if (scene.triMaterials[t] >= scene.materials.size())
            return makeError(ExitCode::Usage, "{}: triangle {} uses material {}, but there are {} materials",
                             errorPrefix, t, scene.triMaterials[t], scene.materials.size());
    }
    size_t segments = scene.lines.size() / 2;
    if (scene.lineMaterials.size() != (haveMaterials ? segments : 0))
        return makeError(ExitCode::Usage,
                         "{}: {} per-segment material indices for {} segments and {} materials", errorPrefix,
                         scene.lineMaterials.size(), segments, scene.materials.size());
    for (size_t k = 0; k < scene.lineMaterials.size(); ++k) {
        if (scene.lineMaterials[k] >= scene.materials.size())
            return makeError(ExitCode::Usage, "{}: segment {} uses material {}, but there are {} materials",
                             errorPrefix, k, scene.lineMaterials[k], scene.materials.size());
    }
    if (scene.pointMaterials.size() != (haveMaterials ? scene.points.size() : 0))
        return makeError(ExitCode::Usage, "{}: {} per-point material indices for {} points and {} materials",
                         errorPrefix, scene.pointMaterials.size(), scene.points.size(),
                         scene.materials.size());
    for (size_t k = 0; k < scene.pointMaterials.size(); ++k) {
        if (scene.pointMaterials[k] >= scene.materials.size())
            return makeError(ExitCode::Usage, "{}: point {} uses material {}, but there are {} materials",
                             errorPrefix, k, scene.pointMaterials[k], scene.materials.size());
    }
    if (!scene.texcoords.empty() && scene.texcoords.size() != scene.positions.size())
        return makeError(ExitCode::Usage, "{}: {} texture coordinates for {} vertices", errorPrefix,
                         scene.texcoords.size(), scene.positions.size());
    if (anyTexture && scene.texcoords.empty())
        return makeError(ExitCode::Usage,
                         "{}: a material has a texture but the scene has no texture coordinates",
                         errorPrefix);
    return okStatus();
}

// Scene's emptiness rules: no materials when none changes anything (white, untextured, opaque, not
// emissive), no
// texture coordinates and no textures when no material is textured, so that such a scene costs the
// pipeline nothing for them.
void dropUnusedMaterials(Scene& scene)
{
    bool anyTexture = false, allDefault = true;
    for (const SceneMaterial& m : scene.materials) {
        anyTexture = anyTexture || m.baseColorTexture >= 0 || m.emissiveTexture >= 0;
        allDefault = allDefault && m.baseColorFactor == glm::vec4(1.0f) && m.baseColorTexture < 0 &&
                     m.alphaMode == ALPHA_OPAQUE && m.emissive == glm::vec3(0.0f) && m.emissiveTexture < 0;
    }
    if (allDefault) {
        scene.materials.clear();
        scene.triMaterials.clear();
        scene.lineMaterials.clear();
        scene.pointMaterials.clear();
    }
    if (!anyTexture) {
        scene.texcoords.clear();
        scene.textures.clear();
    }
}

// `warnAs` names the scene in warnings and `errorPrefix` starts every error message, so that file
// loaders can report "cannot load '<path>': ..." while other callers get "<what>: ...".
Status finalizeImpl(Scene& scene, const std::string& warnAs, const std::string& errorPrefix)
{
    if (scene.indices.size() > kMaxIndices || scene.positions.size() > kMaxVertices) {
        return makeError(ExitCode::Usage, "{}: scene too large ({} vertices, {} triangles)", errorPrefix,
                         scene.positions.size(), scene.indices.size() / 3);
    }
    if (scene.lines.size() > kMaxLineIndices) {
        return makeError(ExitCode::Usage, "{}: scene too large ({} segments)", errorPrefix,
                         scene.lines.size() / 2);
    }
    if (scene.points.size() > kMaxPoints) {
        return makeError(ExitCode::Usage, "{}: scene too large ({} points)", errorPrefix,
                         scene.points.size());
    }
    if (scene.indices.size() % 3 != 0) {
        return makeError(ExitCode::Usage, "{}: index count {} is not a multiple of 3", errorPrefix,
                         scene.indices.size());
    }
    if (scene.lines.size() % 2 != 0) {
        return makeError(ExitCode::Usage, "{}: line index count {} is not a multiple of 2", errorPrefix,
                         scene.lines.size());
    }
    if (scene.normals.size() != scene.positions.size()) {
        return makeError(ExitCode::Usage, "{}: {} normals for {} vertices", errorPrefix, scene.normals.size(),
                         scene.positions.size());
    }
    if (!scene.colors.empty() && scene.colors.size() != scene.positions.size()) {
        return makeError(ExitCode::Usage, "{}: {} colours for {} vertices", errorPrefix, scene.colors.size(),
                         scene.positions.size());
    }

    size_t triangles = scene.indices.size() / 3;
    scene.triFlags.resize(triangles, 0u);
    SR_TRY(checkMaterials(scene, triangles, errorPrefix));
    dropUnusedMaterials(scene);

    auto usable = [&](uint32_t v) {
        return v < scene.positions.size() && finitePosition(scene.positions[v]);
    };

    // Ids name the caller's primitives, so a dropped one keeps its place as a primitive nothing draws,
    // and every later id still indexes the caller's arrays. A dropped triangle's corners all become one
    // vertex of a kept primitive: zero area, which no rasterizer covers a sample with and every host
    // pass takes as any degenerate triangle. A dropped segment's and point's vertices become
    // kDroppedVertex, past every vertex, which the devices count invalid and the graphics reference
    // draws outside the view.
    uint32_t anchor = kDroppedVertex;
    for (size_t t = 0; t < triangles && anchor == kDroppedVertex; ++t) {
        const uint32_t* tri = &scene.indices[3 * t];
        if (usable(tri[0]) && usable(tri[1]) && usable(tri[2])) anchor = tri[0];
    }
    for (size_t k = 0; k + 1 < scene.lines.size() && anchor == kDroppedVertex; k += 2)
        if (usable(scene.lines[k]) && usable(scene.lines[k + 1])) anchor = scene.lines[k];
    for (size_t k = 0; k < scene.points.size() && anchor == kDroppedVertex; ++k)
        if (usable(scene.points[k])) anchor = scene.points[k];
    if (anchor == kDroppedVertex)
        return makeError(ExitCode::Usage, "{}: no triangles, lines or points to draw", errorPrefix);

    // One warning for each kind of primitive dropped.
    auto report = [&](uint64_t dropped, uint64_t& total, const char* kind) {
        if (dropped == 0) return;
        total += dropped;
        warn(
            "{}: dropped {} {}(s) with out-of-range indices or non-finite positions (their ids stay "
            "reserved)",
            warnAs, dropped, kind);
    };
    uint64_t dropped = 0;
    for (size_t t = 0; t < triangles; ++t) {
        uint32_t* tri = &scene.indices[3 * t];
        if (usable(tri[0]) && usable(tri[1]) && usable(tri[2])) continue;
        tri[0] = tri[1] = tri[2] = anchor;
        ++dropped;
    }
    report(dropped, scene.droppedTriangles, "triangle");
    dropped = 0;
    for (size_t k = 0; k + 1 < scene.lines.size(); k += 2) {
        if (usable(scene.lines[k]) && usable(scene.lines[k + 1])) continue;
        scene.lines[k] = scene.lines[k + 1] = kDroppedVertex;
        ++dropped;
    }
    report(dropped, scene.droppedLines, "segment");
    dropped = 0;
    for (uint32_t& v : scene.points) {
        if (usable(v)) continue;
        v = kDroppedVertex;
        ++dropped;
    }
    report(dropped, scene.droppedPoints, "point");

    updateBounds(scene);
    return okStatus();
}

}  // namespace

void updateBounds(Scene& scene)
{
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    auto include = [&](uint32_t i) {
        glm::vec3 p(scene.positions[i]);
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    };
    for (uint32_t i : scene.indices) include(i);
    for (uint32_t i : scene.lines)
        if (i != kDroppedVertex) include(i);
    for (uint32_t i : scene.points)
        if (i != kDroppedVertex) include(i);
    scene.boundsMin = lo;
    scene.boundsMax = hi;
}

std::string flattenMessage(const std::string& text)
{
    // Library messages are newline-separated and may repeat a line per offending element
    // (tinyobjloader warns once per degenerate face, as "Degenerated face found\n."): keep each
    // distinct line once, with a count, and bound the length of the result.
    constexpr size_t kMaxLength = 400;
    auto isFiller = [](char c) {
        return std::isspace(static_cast<unsigned char>(c)) || c == '.' || c == ';';
    };
    std::vector<std::string> order;
    std::unordered_map<std::string, size_t> counts;
    size_t start = 0;
    while (start < text.size()) {
        size_t end = std::min(text.find_first_of("\r\n", start), text.size());
        size_t first = start, last = end;
        while (first < last && isFiller(text[first])) ++first;
        while (last > first && isFiller(text[last - 1])) --last;
        if (last > first) {
            std::string line = text.substr(first, last - first);
            if (counts[line]++ == 0) order.push_back(line);
        }
        start = end + 1;
    }
    std::string out;
    for (const std::string& line : order) {
        if (!out.empty()) out += "; ";
        out += line;
        if (counts[line] > 1) out += fmt::format(" ({} times)", counts[line]);
        if (out.size() > kMaxLength) {
            out.resize(kMaxLength - 3);
            out += "...";
            break;
        }
    }
    return out;
}

Result<Scene> loadScene(const std::string& path)
{
    if (path == "builtin" || path.rfind("builtin:", 0) == 0) return builtinSceneNamed(path);
    std::string ext = lowerExtension(path);
    if (ext == ".gltf" || ext == ".glb") return loadGltf(path);
    if (ext == ".obj") return loadObj(path);
    if (ext == ".ply") return loadPly(path);
    if (ext == ".stl") return loadStl(path);
    // The extension is only worth blaming when the path is a file: a folder (whose name has no
    // extension) or a missing path is said to be one.
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0)
        return makeError(ExitCode::Usage, "cannot load '{}': {}", path, std::strerror(errno));
    if (S_ISDIR(st.st_mode))
        return makeError(ExitCode::Usage, "cannot load '{}': it is a directory, not a scene file ({})", path,
                         kSceneExtensions);
    return makeError(ExitCode::Usage, "cannot load '{}': unknown file extension '{}' (expected {})", path,
                     ext, kSceneExtensions);
}

SceneMaterial defaultMaterial()
{
    SceneMaterial m;
    m.name = "default";
    m.baseColorFactor = glm::vec4(glm::vec3(kDefaultAlbedo), 1.0f);
    return m;
}

Status finalizeScene(Scene& scene, const std::string& what)
{
    return finalizeImpl(scene, what, what);
}

Status finalizeLoadedScene(Scene& scene, const std::string& path)
{
    return finalizeImpl(scene, path, fmt::format("cannot load '{}'", path));
}

}  // namespace sr
