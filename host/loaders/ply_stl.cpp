// ply_stl.cpp - PLY and STL (the formats of scanned and 3D-printed meshes) through assimp.
//
// Why assimp: Debian 12 packages it (libassimp-dev 5.2.5), it is maintained, and it reads both formats
// in all their variants (PLY ASCII and binary of either endianness, with normals and colours as float
// or 8-bit properties; STL ASCII and binary, several solids, the binary colour extensions), where
// the small header-only readers (happly, tinyply) are not packaged. Only its PLY and STL readers are
// used, on bytes already in memory.
//
// assimp is handed bytes, never a path: the file is read through readRegularFile (safe_file.h), so the
// size limit and the refusal of directories, FIFOs and devices hold as for every other scene file. Its
// readers trust the counts a file declares (a PLY declaring 4e9 vertices is allocated before it is
// read, and a truncated binary PLY is read past its end), so the bytes are walked here first
// (checkPly, checkStl) and a file whose declared structure does not fit in it is one error naming
// what does not fit. No post-processing step runs: assimp's triangulation and vertex joining would
// decide the triangle order; here faces are taken in file order, polygons ear clipped like OBJ faces
// (triangulate.h), solids and meshes in file order.
//
// Every face corner becomes its own vertex, as in the OBJ loader, with the file's normal where it has
// one (unit length after normalising) and the face's otherwise; vertex colours (PLY red/green/blue
// [/alpha], STL's colour extensions) are used as given, like OBJ's. So a mesh written as OBJ, PLY and
// STL loads to the same scene: the same triangles in the same order (ids), positions and depth.
// Corners indexing past the vertex list, and NaN or infinite positions, are dropped with one warning
// by finalizeLoadedScene. A PLY with vertices but no faces (a scan's point cloud) is drawn as one point
// per vertex, and says so.
#include <assimp/Importer.hpp>
#include <assimp/scene.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "base/warnings.h"
#include "loaders/safe_file.h"
#include "scene/scene.h"
#include "loaders/triangulate.h"

namespace sr {
namespace {

constexpr uint32_t kInvalidIndex = 0xffffffffu;

// ---- PLY: the header and the body's structure --------------------------------------------------

struct PlyProperty {
    std::string name;
    bool list = false;
    int size = 0;       // bytes of the value (of each item, for a list)
    int countSize = 0;  // lists: bytes of the count
};

struct PlyElement {
    std::string name;
    uint64_t count = 0;
    std::vector<PlyProperty> properties;
};

// Bytes of a PLY scalar type, 0 when the name is none.
int plyTypeSize(const std::string& type)
{
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" ||
        type == "float32")
        return 4;
    if (type == "double" || type == "float64") return 8;
    return 0;
}

// An unsigned integer of `size` bytes at `p` in the file's byte order.
uint64_t readCount(const unsigned char* p, int size, bool bigEndian)
{
    uint64_t value = 0;
    for (int k = 0; k < size; ++k) value |= uint64_t(p[bigEndian ? size - 1 - k : k]) << (8 * k);
    return value;
}

// The declared structure of a PLY file checked against its bytes: the header is complete and names
// known types, and every element the header declares is there (ASCII: its line has every value a list
// count asks for; binary: its bytes lie inside the file). Errors name the element and its index.
Status checkPly(const std::vector<unsigned char>& bytes, const std::string& path)
{
    auto fail = [&](const std::string& why) {
        return makeError(ExitCode::Usage, "cannot load '{}': {}", path, why);
    };
    const std::string text(reinterpret_cast<const char*>(bytes.data()),
                           std::min<size_t>(bytes.size(), 1 << 20));
    if (text.compare(0, 4, "ply\n") != 0 && text.compare(0, 5, "ply\r\n") != 0)
        return fail("not a PLY file (it does not start with a 'ply' line)");
    // `end_header` as a line of its own (ending in "\n" or "\r\n"): assimp's header reader loops without
    // end when the word only ends a line ("endsoend_header", from a fuzzed cube.ply).
    size_t end = text.find("\nend_header");
    while (end != std::string::npos && text.compare(end + 11, 1, "\n") != 0 &&
           text.compare(end + 11, 2, "\r\n") != 0)
        end = text.find("\nend_header", end + 1);
    if (end == std::string::npos) return fail("the PLY header has no 'end_header' line in its first MiB");
    size_t bodyStart = text.find('\n', end + 1) + 1;

    // `format`, `element` and `property` lines have no word missing or left over. Other lines are
    // skipped, as assimp does: some writers put free text there without `comment` (Blender 2.47's
    // "Created by Blender3D ..." in assimp-testmodels' Wuson.ply).
    std::istringstream header(text.substr(0, end));
    std::string line, format;
    std::vector<PlyElement> elements;
    std::getline(header, line);  // "ply"
    for (int lineNo = 2; std::getline(header, line); ++lineNo) {
        std::istringstream words(line);
        std::string keyword, extra;
        words >> keyword;
        if (keyword == "comment" || keyword == "obj_info") continue;
        auto leftOver = [&]() { return static_cast<bool>(words >> extra); };
        if (keyword == "format") {
            std::string version;
            words >> format >> version;
            if (version.empty() || leftOver())
                return fail(fmt::format("PLY header line {}: expected 'format TYPE VERSION'", lineNo));
        } else if (keyword == "element") {
            PlyElement e;
            std::string count;
            words >> e.name >> count;
            char* stop = nullptr;
            e.count = std::strtoull(count.c_str(), &stop, 10);
            if (count.empty() || *stop != '\0' || count[0] == '-' || leftOver())
                return fail(fmt::format("PLY header line {}: expected 'element NAME COUNT'", lineNo));
            elements.push_back(e);
        } else if (keyword == "property") {
            if (elements.empty())
                return fail(fmt::format("PLY header line {}: a property before any element", lineNo));
            PlyProperty p;
            std::string type;
            words >> type;
            if (type == "list") {
                std::string countType, itemType;
                words >> countType >> itemType >> p.name;
                p.list = true;
                p.countSize = plyTypeSize(countType);
                p.size = plyTypeSize(itemType);
                if (p.countSize == 0 || p.countSize == 8 || p.size == 0)
                    return fail(fmt::format("PLY header line {}: unknown list types '{} {}'", lineNo,
                                            countType, itemType));
            } else {
                words >> p.name;
                p.size = plyTypeSize(type);
                if (p.size == 0)
                    return fail(fmt::format("PLY header line {}: unknown type '{}'", lineNo, type));
            }
            if (p.name.empty() || leftOver())
                return fail(
                    fmt::format("PLY header line {}: expected 'property TYPE NAME' or 'property list "
                                "COUNT_TYPE ITEM_TYPE NAME'",
                                lineNo));
            elements.back().properties.push_back(p);
        }
    }
    for (const PlyElement& e : elements)
        if (e.properties.empty() && e.count > 0)
            return fail(fmt::format("PLY element '{}' has no properties", e.name));
    const bool ascii = format == "ascii";
    const bool bigEndian = format == "binary_big_endian";
    if (!ascii && !bigEndian && format != "binary_little_endian")
        return fail(fmt::format("unknown PLY format '{}' (ascii, binary_little_endian or binary_big_endian)",
                                format));

    size_t at = bodyStart;
    if (!ascii) {
        for (const PlyElement& e : elements) {
            // The smallest an instance can be (lists empty), so that a huge count fails at once.
            uint64_t least = 0;
            for (const PlyProperty& p : e.properties) least += uint64_t(p.list ? p.countSize : p.size);
            if (e.count > 0 && (bytes.size() - at) / std::max<uint64_t>(least, 1) < e.count)
                return fail(
                    fmt::format("element '{}' declares {} instances, more than the file's {} remaining "
                                "bytes hold (truncated?)",
                                e.name, e.count, bytes.size() - at));
            for (uint64_t k = 0; k < e.count; ++k) {
                for (const PlyProperty& p : e.properties) {
                    uint64_t need = uint64_t(p.list ? p.countSize : p.size);
                    if (p.list && at + p.countSize <= bytes.size())
                        need += readCount(&bytes[at], p.countSize, bigEndian) * uint64_t(p.size);
                    if (need > bytes.size() - at)
                        return fail(fmt::format("{} {} of {} ends past the end of the file (truncated?)",
                                                e.name, k, e.count));
                    at += size_t(need);
                }
            }
        }
        return okStatus();
    }
    // ASCII: one instance per line, values separated by blanks.
    const char* body = reinterpret_cast<const char*>(bytes.data());
    auto nextLine = [&](std::vector<std::string>& values) {
        while (at < bytes.size()) {
            size_t stop = at;
            while (stop < bytes.size() && body[stop] != '\n') ++stop;
            std::istringstream words(std::string(body + at, stop - at));
            at = stop + 1;
            values.clear();
            for (std::string w; words >> w;) values.push_back(w);
            if (!values.empty()) return true;
        }
        return false;
    };
    std::vector<std::string> values;
    for (const PlyElement& e : elements) {
        if (e.count > bytes.size() - std::min(at, bytes.size()))
            return fail(
                fmt::format("element '{}' declares {} instances, more than the file's remaining lines "
                            "hold (truncated?)",
                            e.name, e.count));
        for (uint64_t k = 0; k < e.count; ++k) {
            if (!nextLine(values))
                return fail(fmt::format("{} {} of {} is missing: the file ends first (truncated?)", e.name, k,
                                        e.count));
            size_t used = 0;
            bool complete = true;
            for (const PlyProperty& p : e.properties) {
                if (used >= values.size()) {
                    complete = false;
                    break;
                }
                if (!p.list) {
                    ++used;
                    continue;
                }
                char* stop = nullptr;
                unsigned long long n = std::strtoull(values[used].c_str(), &stop, 10);
                if (*stop != '\0' || values[used][0] == '-' || n > values.size() - used - 1) {
                    complete = false;
                    break;
                }
                used += 1 + size_t(n);
            }
            if (!complete)
                return fail(fmt::format("{} {} of {} has fewer values than its properties need: '{}'", e.name,
                                        k, e.count, fmt::join(values, " ")));
        }
    }
    return okStatus();
}

// ---- STL ---------------------------------------------------------------------------------------

// Binary STL is an 80-byte header, a 32-bit triangle count and 50 bytes per triangle; ASCII STL starts
// with "solid". (Some binary files start with "solid" too: a binary file is recognised by its size.)
Status checkStl(const std::vector<unsigned char>& bytes, const std::string& path)
{
    if (bytes.size() >= 84) {
        uint64_t count = readCount(&bytes[80], 4, false);
        if (84 + 50 * count == bytes.size()) return okStatus();
    }
    size_t first = 0;
    while (first < bytes.size() && std::isspace(bytes[first])) ++first;
    if (bytes.size() - first >= 5 && std::memcmp(&bytes[first], "solid", 5) == 0) return okStatus();
    if (bytes.size() < 84)
        return makeError(ExitCode::Usage,
                         "cannot load '{}': not an STL file (shorter than a binary STL's 84-byte header, and "
                         "not ASCII STL's 'solid')",
                         path);
    uint64_t count = readCount(&bytes[80], 4, false);
    return makeError(
        ExitCode::Usage,
        "cannot load '{}': binary STL header declares {} triangles ({} bytes), but the file has {} "
        "bytes (truncated?)",
        path, count, 84 + 50 * count, bytes.size());
}

// ---- the scene ---------------------------------------------------------------------------------

glm::vec3 unitOrZero(const aiVector3D& n)
{
    glm::dvec3 v(n.x, n.y, n.z);
    double len = glm::length(v);
    return len > 0.0 && std::isfinite(len) ? glm::vec3(v / len) : glm::vec3(0.0f);
}

Result<Scene> loadWithAssimp(const std::string& path, const char* format)
{
    Result<std::vector<unsigned char>> bytes = readRegularFile(path, kMaxSceneFileBytes, "load");
    if (!bytes) return bytes.error();
    const bool ply = std::strcmp(format, "ply") == 0;
    SR_TRY(ply ? checkPly(*bytes, path) : checkStl(*bytes, path));

    Assimp::Importer importer;
    const aiScene* ai = importer.ReadFileFromMemory(bytes->data(), bytes->size(), 0, format);
    if (!ai || !ai->mRootNode) {
        std::string why = printableText(importer.GetErrorString());
        return makeError(ExitCode::Usage, "cannot load '{}': {}", path,
                         why.empty() ? "assimp could not read it" : flattenMessage(why));
    }

    Scene scene;
    bool anyColor = false;
    size_t shortFaces = 0, fannedPolygons = 0;
    // Meshes in file order (PLY has one; STL one per solid). Both readers place them under identity
    // transforms; the node tree is not consulted.
    for (unsigned m = 0; m < ai->mNumMeshes; ++m) {
        const aiMesh* mesh = ai->mMeshes[m];
        auto position = [&](unsigned v) {
            const aiVector3D& p = mesh->mVertices[v];
            return glm::dvec3(p.x, p.y, p.z);
        };
        auto pushVertex = [&](unsigned v, const glm::vec3& fallbackNormal) {
            scene.positions.emplace_back(glm::vec3(position(v)), 1.0f);
            glm::vec3 n = mesh->mNormals ? unitOrZero(mesh->mNormals[v]) : glm::vec3(0.0f);
            scene.normals.emplace_back(n == glm::vec3(0.0f) ? fallbackNormal : n, 0.0f);
            glm::vec4 c(1.0f);
            if (mesh->mColors[0]) {
                const aiColor4D& k = mesh->mColors[0][v];
                c = glm::vec4(k.r, k.g, k.b, k.a);
            }
            anyColor = anyColor || c != glm::vec4(1.0f);
            scene.colors.push_back(c);
        };
        if (mesh->mNumFaces == 0) {
            if (mesh->mNumVertices > 0)
                warn("{}: no faces: its {} vertices are drawn as points", path, mesh->mNumVertices);
            for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
                scene.points.push_back(uint32_t(scene.positions.size()));
                pushVertex(v, glm::vec3(0.0f));
            }
            continue;
        }
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const aiFace& face = mesh->mFaces[f];
            const unsigned n = face.mNumIndices;
            if (n < 3) {
                ++shortFaces;
                continue;
            }
            bool valid = true;
            for (unsigned k = 0; k < n; ++k) valid = valid && face.mIndices[k] < mesh->mNumVertices;
            if (!valid) {
                // Kept as triangles of invalid indices so finalizeLoadedScene drops and counts them.
                scene.indices.insert(scene.indices.end(), 3 * size_t(n - 2), kInvalidIndex);
                continue;
            }
            std::vector<glm::dvec3> polygon(n);
            for (unsigned k = 0; k < n; ++k) polygon[k] = position(face.mIndices[k]);
            // Newell's normal, as the OBJ loader computes a face's (a triangle's is its cross product).
            glm::dvec3 newell(0.0);
            for (unsigned k = 0; k < n; ++k) {
                const glm::dvec3 &a = polygon[k], &b = polygon[(k + 1) % n];
                newell += glm::dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x),
                                     (a.x - b.x) * (a.y + b.y));
            }
            double len = glm::length(newell);
            glm::vec3 faceNormal =
                len > 0.0 && std::isfinite(len) ? glm::vec3(newell / len) : glm::vec3(0, 0, 1);
            auto base = uint32_t(scene.positions.size());
            for (unsigned k = 0; k < n; ++k) pushVertex(face.mIndices[k], faceNormal);
            PolygonTriangles triangles = triangulatePolygon(polygon);
            fannedPolygons += triangles.fanned ? 1 : 0;
            for (uint32_t corner : triangles.corners) scene.indices.push_back(base + corner);
        }
    }
    if (!anyColor) scene.colors.clear();
    // PLY and STL carry no material: every primitive gets the default one.
    scene.materials.push_back(defaultMaterial());
    scene.triMaterials.assign(scene.indices.size() / 3, 0u);
    scene.pointMaterials.assign(scene.points.size(), 0u);
    if (shortFaces > 0) warn("{}: skipped {} face(s) with fewer than 3 vertices", path, shortFaces);
    if (fannedPolygons > 0)
        warn(
            "{}: {} polygon(s) self-intersecting, without area or of over {} corners: "
            "fanned from their first corner, which may cover parts twice",
            path, fannedPolygons, kMaxEarClippedCorners);
    SR_TRY(finalizeLoadedScene(scene, path));
    return scene;
}

}  // namespace

Result<Scene> loadPly(const std::string& path)
{
    return loadWithAssimp(path, "ply");
}

Result<Scene> loadStl(const std::string& path)
{
    return loadWithAssimp(path, "stl");
}

}  // namespace sr
