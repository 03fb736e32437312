// obj.cpp - Wavefront OBJ to the flat triangle, segment and point lists, through tinyobjloader.
//
// tinyobjloader's own triangulation is off (it fans polygons, which overlaps itself on concave ones) so
// that the triangle order (the ids in the `id` AOV) is defined here: polygons are ear clipped in their
// best-fit plane (triangulate.h; a convex polygon gives the fan (v0, vi, vi+1)), faces in file order.
// A self-intersecting or degenerate polygon is fanned, with one warning per file. Every face corner becomes
// its own vertex, because OBJ indexes positions, normals, texture coordinates and colours separately.
//
// Points: every vertex of every `p` statement, in file order, with the material of the `usemtl` in
// force and its own vertex (a zero normal unless it names a `vn`: points are shaded unlit). Lines: every
// `l` statement is a polyline, stored as the segments between its consecutive vertices in file order,
// with vertices made like the points'; one with fewer than two vertices is skipped with one warning. A
// file with vertices but no `f`, `l` or `p` statement at all (Meshlab's point clouds) is drawn as one
// point per vertex, as assimp does.
//
// Materials come from the .mtl files: Kd is the base colour factor, map_Kd the base colour texture
// (sRGB, repeat, trilinear), Ke the emitted colour and map_Ke its texture (map_Ke counts only with a
// non-zero Ke, as glTF multiplies the two), images resolved relative to the folder of the .mtl that
// names them. Faces without a material get defaultMaterial(). A missing .mtl
// or texture image is a warning; the faces keep their geometry.
//
// tinyobjloader is handed streams, never paths: the .obj, each .mtl and each image are read through
// readRegularFile (safe_file.h), so a directory, a FIFO or a device named there is one message.
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <istream>
#include <map>
#include <streambuf>
#include <string_view>

#include "base/warnings.h"
#include "loaders/safe_file.h"
#include "scene/scene.h"
#include "scene/texture.h"
#include "loaders/triangulate.h"

namespace sr {
namespace {

// Stands for "no such vertex"; finalizeScene drops every triangle, segment or point that uses it and
// counts it.
constexpr uint32_t kInvalidIndex = 0xffffffffu;
constexpr size_t kMaxVertices = size_t(1) << 31;

glm::vec3 unitOrZ(glm::dvec3 v)
{
    double len = glm::length(v);
    if (!(len > 0.0) || !std::isfinite(len)) return {0.0f, 0.0f, 1.0f};
    return glm::vec3(v / len);
}

// A read-only stream over bytes in memory, without copying them (an .obj may be gigabytes).
class MemoryStreamBuf : public std::streambuf {
public:
    explicit MemoryStreamBuf(std::vector<unsigned char>& bytes)
    {
        char* begin = reinterpret_cast<char*>(bytes.data());
        setg(begin, begin, begin + bytes.size());
    }
};

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
        Result<std::vector<unsigned char>> bytes =
            readRegularFile(path, kMaxSceneFileBytes, "read material file");
        if (!bytes) {
            if (warn) *warn += bytes.error().message + "\n";
            return false;
        }
        MemoryStreamBuf buffer(*bytes);
        std::istream in(&buffer);
        size_t before = materials->size();
        tinyobj::LoadMtl(matMap, materials, &in, warn, err);
        folders.resize(before);
        folders.resize(materials->size(), folderOf(path));
        materialIds = *matMap;
        return true;
    }

    std::vector<std::string> folders;  // per material: folder of its .mtl, ending in '/' (or empty)
    // tinyobjloader's name -> material id map (the first material of a name wins), which `usemtl`
    // statements are resolved with.
    std::map<std::string, int> materialIds;

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

// One vertex of a `p` or `l` statement: 0-based indices as tinyobjloader resolves them (-1: not given
// or invalid, negative ones relative to the vertices read so far), and the tinyobjloader material id in
// force (-1: none).
struct ObjPointRef {
    int v = -1, vt = -1, vn = -1;
    int material = -1;
};

struct ObjElements {
    std::vector<ObjPointRef> points;
    std::vector<std::vector<ObjPointRef>> polylines;  // one per `l` statement, short ones included
    size_t faces = 0;                                 // `f` statements
};

// One index of tinyobjloader's parseTriple: atoi, 1-based or negative (relative to `count`), 0 invalid.
int objIndex(const char*& token, int count)
{
    int i = std::atoi(token);
    token += std::strcspn(token, "/ \t\r");
    if (i > 0) return i - 1;
    if (i < 0 && count + i >= 0) return count + i;
    return -1;
}

// The "v", "v/vt", "v//vn" or "v/vt/vn" references after a `p` or `l` keyword, up to the line's end.
std::vector<ObjPointRef> readObjRefs(const char* token, int vertices, int texcoords, int normals,
                                     int material)
{
    std::vector<ObjPointRef> refs;
    while (token[0] != '\0' && token[0] != '\r' && token[0] != '\n') {
        ObjPointRef ref;
        ref.material = material;
        ref.v = objIndex(token, vertices);
        if (token[0] == '/') {
            ++token;
            if (token[0] == '/') {
                ++token;
                ref.vn = objIndex(token, normals);
            } else {
                ref.vt = objIndex(token, texcoords);
                if (token[0] == '/') {
                    ++token;
                    ref.vn = objIndex(token, normals);
                }
            }
        }
        refs.push_back(ref);
        token += std::strspn(token, " \t\r");
    }
    return refs;
}

// Reads the `p`, `l` and `f` statements of an OBJ file that tinyobjloader has already accepted.
// tinyobjloader 2.0.0rc10 keeps points and lines badly: a `usemtl` between `p` statements exports the
// pending points a second time, a `g` line loses the points of a group without faces, and neither
// carries a material. So they are read here, line by line with tinyobjloader's own tokenisation (its
// line ends, leading blanks, a keyword followed by a blank, "v/vt/vn" triples read with atoi, negative
// indices relative to the lines read so far), and `usemtl` is resolved with tinyobjloader's material
// map, as it does for faces.
// The numbers after a `v`, `vn` or `vt` keyword: how many there are, or -1 with `bad` set to the first
// word that is not a number as a whole (tinyobjloader reads "0f" as 0 and goes on).
int countNumbers(const char* token, std::string& bad)
{
    int count = 0;
    for (;;) {
        token += std::strspn(token, " \t\r");
        if (token[0] == '\0' || token[0] == '#') return count;
        size_t length = std::strcspn(token, " \t\r");
        std::string word(token, length);
        char* end = nullptr;
        std::strtod(word.c_str(), &end);
        if (end != word.c_str() + word.size()) {
            bad = word;
            return -1;
        }
        ++count;
        token += length;
    }
}

// The first `f` corner of a line that names no vertex: its index as written, or empty. Positive indices
// may name any of the file's `total` vertices (tinyobjloader resolves them after the whole file),
// negative ones count back from the `seen` read so far.
std::string missingFaceVertex(const char* token, int total, int seen)
{
    while (token[0] != '\0' && token[0] != '\r' && token[0] != '#') {
        token += std::strspn(token, " \t\r");
        if (token[0] == '\0' || token[0] == '#') break;
        size_t length = std::strcspn(token, "/ \t\r");
        std::string word(token, length);
        char* end = nullptr;
        long i = std::strtol(word.c_str(), &end, 10);
        if (end != word.c_str() + word.size() || i == 0 || i > total || -i > seen) return word;
        token += std::strcspn(token, " \t\r");
    }
    return "";
}

// Checks the lines tinyobjloader reads leniently, with the file's line numbers: a `v`, `vn` or `vt` line
// with a word that is not a number (or too few numbers) is an error, since the rest of the file's
// indices would silently shift or read a wrong value; a face corner naming a vertex that does not exist
// is dropped with the face by finalizeScene, and the first such line is named in one warning here.
Status checkObjLines(std::string_view text, const std::string& path)
{
    int vertices = 0;
    size_t firstMissingLine = 0, missingFaces = 0;
    std::string firstMissing;
    // Positive indices may name vertices defined further on, as tinyobjloader resolves them after the
    // whole file: count the vertices first.
    for (int pass = 0; pass < 2; ++pass) {
        size_t start = 0, lineNo = 0;
        int seen = 0;
        while (start < text.size()) {
            size_t end = std::min(text.find_first_of("\r\n", start), text.size());
            std::string line(text.substr(start, end - start));
            start = end + (text.compare(end, 2, "\r\n") == 0 ? 2 : 1);
            ++lineNo;
            const char* token = line.c_str() + std::strspn(line.c_str(), " \t");
            auto isSpace = [](char c) { return c == ' ' || c == '\t'; };
            // Vertices are x y z [w] or x y z r g b [a]; normals x y z; texture coordinates u [v [w]].
            int least = 0, most = 0, keyword = 2;
            const char* what = "";
            if (token[0] == 'v' && isSpace(token[1])) {
                least = 3, most = 7, keyword = 1, what = "vertex";
                ++seen;
            } else if (token[0] == 'v' && token[1] == 'n' && isSpace(token[2])) {
                least = 3, most = 3, what = "normal";
            } else if (token[0] == 'v' && token[1] == 't' && isSpace(token[2])) {
                least = 1, most = 3, what = "texture coordinate";
            } else if (pass == 1 && token[0] == 'f' && isSpace(token[1])) {
                std::string missing = missingFaceVertex(token + 2, vertices, seen);
                if (!missing.empty() && missingFaces++ == 0) {
                    firstMissing = missing;
                    firstMissingLine = lineNo;
                }
                continue;
            } else {
                continue;
            }
            if (pass == 1) continue;
            std::string bad;
            int n = countNumbers(token + keyword, bad);
            if (n < 0)
                return makeError(ExitCode::Usage,
                                 "cannot load '{}': line {}: '{}' is not a number in the {} '{}'", path,
                                 lineNo, printableText(bad.c_str()), what, printableText(line.c_str()));
            if (n < least || n > most)
                return makeError(ExitCode::Usage,
                                 "cannot load '{}': line {}: a {} has {} to {} numbers, not {}: '{}'", path,
                                 lineNo, what, least, most, n, printableText(line.c_str()));
        }
        vertices = seen;
    }
    if (missingFaces > 0)
        warn(
            "{}:{}: face corner '{}' names no vertex (the file has {}); {} face(s) naming "
            "missing vertices are dropped",
            path, firstMissingLine, printableText(firstMissing.c_str()), vertices, missingFaces);
    return okStatus();
}

ObjElements readObjElements(std::string_view text, const std::map<std::string, int>& materialIds)
{
    ObjElements out;
    int vertices = 0, normals = 0, texcoords = 0;
    int material = -1;
    size_t start = 0;
    while (start < text.size()) {
        // Lines end at "\n", "\r\n" or a lone "\r", as tinyobjloader's safeGetline reads them.
        size_t end = std::min(text.find_first_of("\r\n", start), text.size());
        std::string line(text.substr(start, end - start));
        start = end + (text.compare(end, 2, "\r\n") == 0 ? 2 : 1);
        const char* token = line.c_str() + std::strspn(line.c_str(), " \t");
        auto isSpace = [](char c) { return c == ' ' || c == '\t'; };
        if (token[0] == 'v' && isSpace(token[1])) {
            ++vertices;
        } else if (token[0] == 'v' && token[1] == 'n' && isSpace(token[2])) {
            ++normals;
        } else if (token[0] == 'v' && token[1] == 't' && isSpace(token[2])) {
            ++texcoords;
        } else if (token[0] == 'f' && isSpace(token[1])) {
            ++out.faces;
        } else if (token[0] == 'l' && isSpace(token[1])) {
            out.polylines.push_back(readObjRefs(token + 2, vertices, texcoords, normals, material));
        } else if (token[0] == 'p' && isSpace(token[1])) {
            std::vector<ObjPointRef> refs = readObjRefs(token + 2, vertices, texcoords, normals, material);
            out.points.insert(out.points.end(), refs.begin(), refs.end());
        } else if (std::strncmp(token, "usemtl", 6) == 0) {
            token += 6;
            token += std::strspn(token, " \t");
            std::string name(token, std::strcspn(token, " \t\r"));
            auto it = materialIds.find(name);
            material = it == materialIds.end() ? -1 : it->second;
        }
    }
    return out;
}

}  // namespace

Result<Scene> loadObj(const std::string& path)
{
    // No triangulation (the fan order is defined below); vertex colours on "v x y z r g b" lines.
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    MtlReader mtlReader(folderOf(path));
    ObjElements elements;
    {
        Result<std::vector<unsigned char>> bytes = readRegularFile(path, kMaxSceneFileBytes, "load");
        if (!bytes) return bytes.error();
        MemoryStreamBuf buffer(*bytes);
        std::istream in(&buffer);
        std::string warn, err;
        if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, &mtlReader, false, true)) {
            std::string reason = flattenMessage(err);
            if (reason.empty()) reason = "tinyobjloader could not parse the file";
            return makeError(ExitCode::Usage, "cannot load '{}': {}", path, reason);
        }
        if (!warn.empty()) sr::warn("{}: {}", path, flattenMessage(warn));
        std::string_view text(reinterpret_cast<const char*>(bytes->data()), bytes->size());
        SR_TRY(checkObjLines(text, path));
        elements = readObjElements(text, mtlReader.materialIds);
    }

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
                scene.materials.push_back(sr::defaultMaterial());
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
        // Ke / map_Ke: the emitted colour (linear, as Kd) and its texture (sRGB, as map_Kd).
        m.emissive = glm::vec3(float(src.emission[0]), float(src.emission[1]), float(src.emission[2]));
        std::string folder =
            size_t(id) < mtlReader.folders.size() ? mtlReader.folders[size_t(id)] : folderOf(path);
        // Scene::textures index of the image `name` names (-1 when it cannot be read: a warning).
        auto useTexture = [&](const std::string& name, const char* without) -> Result<int32_t> {
            std::string file = texturePath(folder, name);
            auto it = textureIndex.find(file);
            if (it != textureIndex.end()) return it->second;
            Result<SceneTexture> texture = loadTextureFile(file, true, TextureSampler{});
            int32_t index = -1;
            if (texture) {
                index = int32_t(scene.textures.size());
                scene.textures.push_back(std::move(*texture));
            } else if (isTextureSizeError(texture.error())) {
                return makeError(ExitCode::Usage, "cannot load '{}': {}", path, texture.error().message);
            } else {
                warn("{}: material '{}': {}; drawn without its {}", path, src.name, texture.error().message,
                     without);
            }
            textureIndex.emplace(file, index);
            return index;
        };
        if (!src.diffuse_texname.empty()) {
            Result<int32_t> texture = useTexture(src.diffuse_texname, "map_Kd");
            if (!texture) return texture.error();
            m.baseColorTexture = *texture;
        }
        if (!src.emissive_texname.empty() && m.emissive != glm::vec3(0.0f)) {
            Result<int32_t> texture = useTexture(src.emissive_texname, "map_Ke");
            if (!texture) return texture.error();
            m.emissiveTexture = *texture;
        }
        materialIndex[size_t(id)] = int32_t(scene.materials.size());
        scene.materials.push_back(m);
        return uint32_t(materialIndex[size_t(id)]);
    };
    size_t shortFaces = 0;
    size_t fannedPolygons = 0;
    auto position = [&](int i) {
        const tinyobj::real_t* p = &attrib.vertices[3 * size_t(i)];
        return glm::dvec3(p[0], p[1], p[2]);
    };
    // OBJ's v points up; glTF's v = 0 (which the samplers follow) is the image's top row.
    auto texcoord = [&](int vt) {
        glm::vec4 uv(0.0f);
        if (vt >= 0 && size_t(vt) < texcoordCount) {
            const tinyobj::real_t* t = &attrib.texcoords[2 * size_t(vt)];
            uv.x = float(t[0]);
            uv.y = float(1.0 - double(t[1]));
        }
        return uv;
    };
    // The vertex colour of position v, noting whether any is not white.
    auto color = [&](size_t v) {
        glm::vec4 c(1.0f);
        if (hasColors) {
            const tinyobj::real_t* rgb = &attrib.colors[3 * v];
            c = glm::vec4(float(rgb[0]), float(rgb[1]), float(rgb[2]), 1.0f);
        }
        if (c != glm::vec4(1.0f)) anyNonWhite = true;
        return c;
    };

    for (const tinyobj::shape_t& shape : shapes) {
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
                scene.texcoords.push_back(texcoord(corners[k].texcoord_index));
                scene.colors.push_back(color(size_t(v)));
            }
            if (n == 3) {
                scene.indices.insert(scene.indices.end(), {base, base + 1, base + 2});
            } else {
                std::vector<glm::dvec3> polygon(n);
                for (size_t k = 0; k < n; ++k) polygon[k] = position(corners[k].vertex_index);
                PolygonTriangles triangles = triangulatePolygon(polygon);
                fannedPolygons += triangles.fanned ? 1 : 0;
                for (uint32_t corner : triangles.corners) scene.indices.push_back(base + corner);
            }
        }
    }

    // Every point and every polyline vertex gets its own vertex, like every face corner; kInvalidIndex
    // for a position that does not exist.
    auto pushUnlitVertex = [&](int v, int vt, int vn) -> Result<uint32_t> {
        if (v < 0 || size_t(v) >= positionCount) return kInvalidIndex;
        if (scene.positions.size() >= kMaxVertices)
            return makeError(ExitCode::Usage, "cannot load '{}': more than {} vertices", path, kMaxVertices);
        auto index = uint32_t(scene.positions.size());
        scene.positions.emplace_back(glm::vec3(position(v)), 1.0f);
        glm::vec3 normal(0.0f);
        if (vn >= 0 && size_t(vn) < normalCount) {
            const tinyobj::real_t* n = &attrib.normals[3 * size_t(vn)];
            glm::dvec3 given(n[0], n[1], n[2]);
            double len = glm::length(given);
            if (len > 0.0 && std::isfinite(len)) normal = glm::vec3(given / len);
        }
        scene.normals.emplace_back(normal, 0.0f);
        scene.texcoords.push_back(texcoord(vt));
        scene.colors.push_back(color(size_t(v)));
        return index;
    };
    auto pushPoint = [&](int v, int vt, int vn, uint32_t material) -> Status {
        Result<uint32_t> vertex = pushUnlitVertex(v, vt, vn);
        if (!vertex) return vertex.error();
        scene.points.push_back(*vertex);
        scene.pointMaterials.push_back(material);
        return okStatus();
    };

    size_t shortLines = 0;
    for (const std::vector<ObjPointRef>& polyline : elements.polylines) {
        if (polyline.size() < 2) {
            ++shortLines;
            continue;
        }
        Result<uint32_t> materialId = useMaterial(polyline[0].material);
        if (!materialId) return materialId.error();
        Result<uint32_t> previous = pushUnlitVertex(polyline[0].v, polyline[0].vt, polyline[0].vn);
        if (!previous) return previous.error();
        for (size_t k = 1; k < polyline.size(); ++k) {
            Result<uint32_t> vertex = pushUnlitVertex(polyline[k].v, polyline[k].vt, polyline[k].vn);
            if (!vertex) return vertex.error();
            scene.lines.insert(scene.lines.end(), {*previous, *vertex});
            scene.lineMaterials.push_back(*materialId);
            previous = vertex;
        }
    }
    for (const ObjPointRef& ref : elements.points) {
        Result<uint32_t> materialId = useMaterial(ref.material);
        if (!materialId) return materialId.error();
        SR_TRY(pushPoint(ref.v, ref.vt, ref.vn, *materialId));
    }
    if (elements.faces == 0 && elements.polylines.empty() && elements.points.empty() && positionCount > 0) {
        // A bare vertex list is a point cloud. Meshlab writes a `vn` before each `v`, so equal counts
        // pair them by position in the file.
        warn("{}: no faces, lines or points: its {} vertices are drawn as points", path, positionCount);
        Result<uint32_t> materialId = useMaterial(-1);
        if (!materialId) return materialId.error();
        bool pairedNormals = normalCount == positionCount;
        for (size_t v = 0; v < positionCount; ++v)
            SR_TRY(pushPoint(int(v), -1, pairedNormals ? int(v) : -1, *materialId));
    }

    if (!anyNonWhite) scene.colors.clear();
    if (shortFaces > 0) {
        warn("{}: skipped {} face(s) with fewer than 3 vertices", path, shortFaces);
    }
    if (fannedPolygons > 0) {
        warn(
            "{}: {} polygon(s) self-intersecting, without area or of over {} corners: "
            "fanned from their first corner, which may cover parts twice",
            path, fannedPolygons, kMaxEarClippedCorners);
    }
    if (shortLines > 0) {
        warn("{}: skipped {} line element(s) with fewer than 2 vertices", path, shortLines);
    }
    SR_TRY(finalizeLoadedScene(scene, path));
    return scene;
}

}  // namespace sr
