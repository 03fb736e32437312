// scene_obj.cpp - Wavefront OBJ to the flat triangle list, through tinyobjloader.
//
// tinyobjloader's own triangulation is off so that the triangle order (the ids in the `id` AOV) is
// defined here: polygons are fanned as (v0, vi, vi+1) in file order. Every face corner becomes its
// own vertex, because OBJ indexes positions, normals, texture coordinates and colours separately.
//
// Materials come from the .mtl files: Kd is the base colour factor, map_Kd the base colour texture
// (sRGB, repeat, trilinear), resolved relative to the folder of the .mtl that names it. A missing .mtl
// or texture image is a warning; the faces keep their geometry.
#include <tiny_obj_loader.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>

#include "scene/scene.h"
#include "scene/texture.h"

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

std::string folderOf(const std::string& path)
{
    size_t slash = path.find_last_of('/');
    return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

// Reads each `mtllib` relative to the .obj's folder, like tinyobjloader's MaterialFileReader, but also
// remembers which file every material came from: map_Kd paths are relative to their .mtl, which may lie
// in a subfolder. (tinyobjloader's own reader also splits its search path at ':', which breaks paths
// that contain one.)
class MtlReader : public tinyobj::MaterialReader {
public:
    explicit MtlReader(std::string objFolder) : objFolder_(std::move(objFolder)) {}

    bool operator()(const std::string& matId, std::vector<tinyobj::material_t>* materials,
                    std::map<std::string, int>* matMap, std::string* warn, std::string* err) override
    {
        std::string path = !matId.empty() && matId[0] == '/' ? matId : objFolder_ + matId;
        std::ifstream in(path);
        if (!in) {
            if (warn) *warn += "material file '" + path + "' not found\n";
            return false;
        }
        size_t before = materials->size();
        tinyobj::LoadMtl(matMap, materials, &in, warn, err);
        folders.resize(before);
        folders.resize(materials->size(), folderOf(path));
        return true;
    }

    std::vector<std::string> folders;  // per material: folder of its .mtl, ending in '/' (or empty)

private:
    std::string objFolder_;
};

// OBJ files written on Windows use backslashes (spider.mtl: "map_Kd .\\SpiderTex.jpg").
std::string texturePath(const std::string& folder, std::string name)
{
    for (char& c : name)
        if (c == '\\') c = '/';
    // Normalised, so that "./a.png" and "a.png" are one texture, loaded once.
    std::string path = !name.empty() && name[0] == '/' ? name : folder + name;
    return std::filesystem::path(path).lexically_normal().string();
}

}  // namespace

Result<Scene> loadObj(const std::string& path)
{
    // tinyobjloader reports a missing file without the reason; ask the OS first.
    std::FILE* file = std::fopen(path.c_str(), "rb");
    if (!file) return makeError(ExitCode::Usage, "cannot load '{}': {}", path, std::strerror(errno));
    std::fclose(file);

    // No triangulation (the fan order is defined below); vertex colours on "v x y z r g b" lines.
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warn, err;
    std::ifstream in(path);
    MtlReader mtlReader(folderOf(path));
    if (!in || !tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, &mtlReader, false, true)) {
        std::string reason = flattenMessage(in ? err : std::string("cannot open the file"));
        if (reason.empty()) reason = "tinyobjloader could not parse the file";
        return makeError(ExitCode::Usage, "cannot load '{}': {}", path, reason);
    }
    if (!warn.empty()) fmt::print(stderr, "warning: {}: {}\n", path, flattenMessage(warn));

    size_t positionCount = attrib.vertices.size() / 3;
    size_t normalCount = attrib.normals.size() / 3;
    size_t texcoordCount = attrib.texcoords.size() / 2;
    bool hasColors = attrib.colors.size() == attrib.vertices.size();

    Scene scene;
    bool anyNonWhite = false;

    // OBJ material -> Scene::materials index, created on first use; textures loaded once per path.
    std::vector<int32_t> materialIndex(materials.size(), -1);
    int32_t defaultMaterial = -1;
    std::map<std::string, int32_t> textureIndex;
    auto useMaterial = [&](int id) -> Result<uint32_t> {
        if (id < 0 || size_t(id) >= materials.size()) {
            if (defaultMaterial < 0) {
                defaultMaterial = int32_t(scene.materials.size());
                SceneMaterial m;
                m.name = "default";
                scene.materials.push_back(m);
            }
            return uint32_t(defaultMaterial);
        }
        if (materialIndex[size_t(id)] >= 0) return uint32_t(materialIndex[size_t(id)]);
        const tinyobj::material_t& src = materials[size_t(id)];
        SceneMaterial m;
        m.name = src.name;
        // Kd is used as linear as it stands; d / Tr (dissolve) are not an alpha mode we draw.
        m.baseColorFactor =
            glm::vec4(float(src.diffuse[0]), float(src.diffuse[1]), float(src.diffuse[2]), 1.0f);
        if (!src.diffuse_texname.empty()) {
            std::string folder =
                size_t(id) < mtlReader.folders.size() ? mtlReader.folders[size_t(id)] : folderOf(path);
            std::string file = texturePath(folder, src.diffuse_texname);
            auto it = textureIndex.find(file);
            if (it == textureIndex.end()) {
                Result<SceneTexture> texture = loadTextureFile(file, true, TextureSampler{});
                int32_t index = -1;
                if (texture) {
                    index = int32_t(scene.textures.size());
                    scene.textures.push_back(std::move(*texture));
                } else if (isTextureSizeError(texture.error())) {
                    return makeError(ExitCode::Usage, "cannot load '{}': {}", path, texture.error().message);
                } else {
                    fmt::print(stderr, "warning: {}: material '{}': {}; drawn with its Kd colour only\n",
                               path, src.name, texture.error().message);
                }
                it = textureIndex.emplace(file, index).first;
            }
            m.baseColorTexture = it->second;
        }
        materialIndex[size_t(id)] = int32_t(scene.materials.size());
        scene.materials.push_back(m);
        return uint32_t(materialIndex[size_t(id)]);
    };
    size_t shortFaces = 0;
    size_t linesAndPoints = 0;
    auto position = [&](int i) {
        const tinyobj::real_t* p = &attrib.vertices[3 * size_t(i)];
        return glm::dvec3(p[0], p[1], p[2]);
    };

    for (const tinyobj::shape_t& shape : shapes) {
        linesAndPoints += shape.lines.num_line_vertices.size() + shape.points.indices.size();
        const tinyobj::mesh_t& mesh = shape.mesh;
        size_t offset = 0;
        for (size_t face = 0; face < mesh.num_face_vertices.size(); ++face) {
            size_t n = mesh.num_face_vertices[face];
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
            Result<uint32_t> materialId =
                useMaterial(face < mesh.material_ids.size() ? mesh.material_ids[face] : -1);
            if (!materialId) return materialId.error();
            scene.triMaterials.insert(scene.triMaterials.end(), n - 2, *materialId);
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
                // OBJ's v points up; glTF's v = 0 (which the samplers follow) is the image's top row.
                glm::vec4 uv(0.0f);
                int vt = corners[k].texcoord_index;
                if (vt >= 0 && size_t(vt) < texcoordCount) {
                    const tinyobj::real_t* t = &attrib.texcoords[2 * size_t(vt)];
                    uv.x = float(t[0]);
                    uv.y = float(1.0 - double(t[1]));
                }
                scene.texcoords.push_back(uv);
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
