// scene_obj.cpp - Wavefront OBJ to the flat triangle list, through tinyobjloader.
//
// tinyobjloader's own triangulation is off so that the triangle order (the ids in the `id` AOV) is
// defined here: polygons are fanned as (v0, vi, vi+1) in file order. Every face corner becomes its
// own vertex, because OBJ indexes positions, normals and colours separately.
#include <tiny_obj_loader.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "scene/scene.h"

namespace sr {
namespace {

// Stands for "no such vertex"; finalizeScene drops every triangle that uses it and counts it.
constexpr uint32_t kInvalidIndex = 0xffffffffu;
constexpr size_t kMaxVertices = size_t(1) << 31;

glm::vec3 unitOrZ(glm::dvec3 v)
{
    double len = glm::length(v);
    if (!(len > 0.0) || !std::isfinite(len)) return {0.0f, 0.0f, 1.0f};
    return glm::vec3(v / len);
}

}  // namespace

Result<Scene> loadObj(const std::string& path)
{
    // tinyobjloader reports a missing file without the reason; ask the OS first.
    std::FILE* file = std::fopen(path.c_str(), "rb");
    if (!file) return makeError(ExitCode::Usage, "cannot load '{}': {}", path, std::strerror(errno));
    std::fclose(file);

    tinyobj::ObjReaderConfig config;
    config.triangulate = false;
    config.vertex_color = true;
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(path, config)) {
        std::string reason = flattenMessage(reader.Error());
        if (reason.empty()) reason = "tinyobjloader could not parse the file";
        return makeError(ExitCode::Usage, "cannot load '{}': {}", path, reason);
    }
    if (!reader.Warning().empty())
        fmt::print(stderr, "warning: {}: {}\n", path, flattenMessage(reader.Warning()));

    const tinyobj::attrib_t& attrib = reader.GetAttrib();
    size_t positionCount = attrib.vertices.size() / 3;
    size_t normalCount = attrib.normals.size() / 3;
    bool hasColors = attrib.colors.size() == attrib.vertices.size();

    Scene scene;
    bool anyNonWhite = false;
    size_t shortFaces = 0;
    size_t linesAndPoints = 0;
    auto position = [&](int i) {
        const tinyobj::real_t* p = &attrib.vertices[3 * size_t(i)];
        return glm::dvec3(p[0], p[1], p[2]);
    };

    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
        linesAndPoints += shape.lines.num_line_vertices.size() + shape.points.indices.size();
        const tinyobj::mesh_t& mesh = shape.mesh;
        size_t offset = 0;
        for (unsigned char faceSize : mesh.num_face_vertices) {
            size_t n = faceSize;
            if (offset + n > mesh.indices.size()) break;  // inconsistent reader output: stop
            const tinyobj::index_t* corners = &mesh.indices[offset];
            offset += n;
            if (n < 3) {
                ++shortFaces;
                continue;
            }
            bool positionsValid = true;
            bool allNormals = true;
            for (size_t k = 0; k < n; ++k) {
                int v = corners[k].vertex_index;
                int vn = corners[k].normal_index;
                positionsValid = positionsValid && v >= 0 && size_t(v) < positionCount;
                allNormals = allNormals && vn >= 0 && size_t(vn) < normalCount;
            }
            if (!positionsValid) {
                // Kept as triangles of invalid indices so finalizeScene drops and counts them.
                scene.indices.insert(scene.indices.end(), 3 * (n - 2), kInvalidIndex);
                continue;
            }
            if (n > kMaxVertices - scene.positions.size())
                return makeError(ExitCode::Usage, "cannot load '{}': more than {} vertices", path,
                                 kMaxVertices);

            // Newell's method: the polygon's area-weighted normal, robust for non-planar faces.
            glm::dvec3 newell(0.0);
            for (size_t k = 0; k < n; ++k) {
                glm::dvec3 a = position(corners[k].vertex_index);
                glm::dvec3 b = position(corners[(k + 1) % n].vertex_index);
                newell += glm::dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x),
                                     (a.x - b.x) * (a.y + b.y));
            }
            glm::vec3 faceNormal = unitOrZ(newell);

            auto base = uint32_t(scene.positions.size());
            for (size_t k = 0; k < n; ++k) {
                size_t v = size_t(corners[k].vertex_index);
                scene.positions.emplace_back(glm::vec3(position(int(v))), 1.0f);
                glm::vec3 normal = faceNormal;
                if (allNormals) {
                    const tinyobj::real_t* vn = &attrib.normals[3 * size_t(corners[k].normal_index)];
                    glm::dvec3 given(vn[0], vn[1], vn[2]);
                    double len = glm::length(given);
                    if (len > 0.0 && std::isfinite(len)) normal = glm::vec3(given / len);
                }
                scene.normals.emplace_back(normal, 0.0f);
                glm::vec4 color(1.0f);
                if (hasColors) {
                    const tinyobj::real_t* c = &attrib.colors[3 * v];
                    color = glm::vec4(float(c[0]), float(c[1]), float(c[2]), 1.0f);
                }
                if (color != glm::vec4(1.0f)) anyNonWhite = true;
                scene.colors.push_back(color);
            }
            for (size_t k = 1; k + 1 < n; ++k) {
                scene.indices.insert(scene.indices.end(), {base, base + uint32_t(k), base + uint32_t(k + 1)});
            }
        }
    }
    if (!anyNonWhite) scene.colors.clear();
    if (shortFaces > 0) {
        fmt::print(stderr, "warning: {}: skipped {} face(s) with fewer than 3 vertices\n", path, shortFaces);
    }
    if (linesAndPoints > 0) {
        fmt::print(stderr, "warning: {}: skipping {} line/point element(s) (not supported yet)\n", path,
                   linesAndPoints);
    }
    SR_TRY(finalizeLoadedScene(scene, path));
    return scene;
}

}  // namespace sr
