// loader_test.cpp - glTF, OBJ and built-in scenes against hand-derived expectations.
//
// Every glTF here is written by the test itself (JSON plus a base64 data-URI buffer, or a GLB), so
// each expected world position, normal and triangle order below can be checked by hand.
#include <stdlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_util.h"
#include <nlohmann/json.hpp>

#include "raster_shared.h"
#include "scene/scene.h"

namespace sr {
namespace {

using Json = nlohmann::json;

constexpr int kU8 = 5121, kU16 = 5123, kU32 = 5125, kFloat = 5126;
constexpr int kPoints = 0, kLines = 1, kTriangleStrip = 5, kTriangleFan = 6;

void writeFile(const std::string& path, const std::string& bytes)
{
    std::ofstream(path, std::ios::binary) << bytes;
}

std::string base64(const std::vector<uint8_t>& data)
{
    static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < data.size(); i += 3) {
        uint32_t chunk = uint32_t(data[i]) << 16;
        if (i + 1 < data.size()) chunk |= uint32_t(data[i + 1]) << 8;
        if (i + 2 < data.size()) chunk |= data[i + 2];
        out += kAlphabet[(chunk >> 18) & 63];
        out += kAlphabet[(chunk >> 12) & 63];
        out += i + 1 < data.size() ? kAlphabet[(chunk >> 6) & 63] : '=';
        out += i + 2 < data.size() ? kAlphabet[chunk & 63] : '=';
    }
    return out;
}

size_t componentsOf(const std::string& type)
{
    return type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : 4;
}

// Builds a glTF document with a single buffer, appending data as accessors are added.
class GltfDoc {
public:
    GltfDoc() { json_["asset"] = {{"version", "2.0"}}; }

    Json& json() { return json_; }

    int addView(const void* data, size_t size, size_t stride = 0)
    {
        while (bin_.size() % 4 != 0) bin_.push_back(0);
        Json view = {{"buffer", 0}, {"byteOffset", bin_.size()}, {"byteLength", size}};
        if (stride != 0) view["byteStride"] = stride;
        const auto* bytes = static_cast<const uint8_t*>(data);
        bin_.insert(bin_.end(), bytes, bytes + size);
        json_["bufferViews"].push_back(view);
        return int(json_["bufferViews"].size()) - 1;
    }

    int addAccessor(int view, int componentType, size_t count, const std::string& type, size_t offset = 0,
                    bool normalized = false)
    {
        Json accessor = {
            {"bufferView", view}, {"componentType", componentType}, {"count", count}, {"type", type}};
        if (offset != 0) accessor["byteOffset"] = offset;
        if (normalized) accessor["normalized"] = true;
        json_["accessors"].push_back(accessor);
        return int(json_["accessors"].size()) - 1;
    }

    int floats(const std::vector<float>& values, const std::string& type)
    {
        int view = addView(values.data(), values.size() * sizeof(float));
        return addAccessor(view, kFloat, values.size() / componentsOf(type), type);
    }

    template <typename T>
    int integers(const std::vector<T>& values, const std::string& type = "SCALAR", bool normalized = false)
    {
        int componentType = sizeof(T) == 1 ? kU8 : sizeof(T) == 2 ? kU16 : kU32;
        int view = addView(values.data(), values.size() * sizeof(T));
        return addAccessor(view, componentType, values.size() / componentsOf(type), type, 0, normalized);
    }

    // A vector, not a Json: a braced list of one element would not become a JSON array.
    int addMesh(const std::vector<Json>& primitives)
    {
        json_["meshes"].push_back({{"primitives", primitives}});
        return int(json_["meshes"].size()) - 1;
    }

    int addNode(const Json& node)
    {
        json_["nodes"].push_back(node);
        return int(json_["nodes"].size()) - 1;
    }

    int addMaterial(const Json& material)
    {
        json_["materials"].push_back(material);
        return int(json_["materials"].size()) - 1;
    }

    void setRoots(const std::vector<int>& roots)
    {
        json_["scenes"] = Json::array({{{"nodes", roots}}});
        json_["scene"] = 0;
    }

    // .gltf text with the buffer embedded as a base64 data URI.
    std::string text() const
    {
        Json doc = json_;
        doc["buffers"] = Json::array(
            {{{"byteLength", bin_.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin_)}}});
        return doc.dump(1);
    }

    // .gltf text whose buffer is the external file `uri` (write bin() there).
    std::string textWithExternalBuffer(const std::string& uri) const
    {
        Json doc = json_;
        doc["buffers"] = Json::array({{{"byteLength", bin_.size()}, {"uri", uri}}});
        return doc.dump(1);
    }

    std::string bin() const { return std::string(bin_.begin(), bin_.end()); }

    // Binary glTF: 12-byte header, a JSON chunk padded with spaces, a BIN chunk padded with zeros.
    std::string glb() const
    {
        Json doc = json_;
        doc["buffers"] = Json::array({{{"byteLength", bin_.size()}}});
        std::string jsonChunk = doc.dump();
        while (jsonChunk.size() % 4 != 0) jsonChunk += ' ';
        std::string binChunk = bin();
        while (binChunk.size() % 4 != 0) binChunk += '\0';
        std::string out;
        auto u32 = [&](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
        u32(0x46546C67u);  // "glTF"
        u32(2);
        u32(uint32_t(12 + 8 + jsonChunk.size() + 8 + binChunk.size()));
        u32(uint32_t(jsonChunk.size()));
        u32(0x4E4F534Au);  // "JSON"
        out += jsonChunk;
        u32(uint32_t(binChunk.size()));
        u32(0x004E4942u);  // "BIN\0"
        out += binChunk;
        return out;
    }

private:
    Json json_;
    std::vector<uint8_t> bin_;
};

Json primitive(int position, int normal = -1, int indices = -1, int mode = -1, int material = -1)
{
    Json p = {{"attributes", {{"POSITION", position}}}};
    if (normal >= 0) p["attributes"]["NORMAL"] = normal;
    if (indices >= 0) p["indices"] = indices;
    if (mode >= 0) p["mode"] = mode;
    if (material >= 0) p["material"] = material;
    return p;
}

// The unit right triangle (0,0,0), (1,0,0), (0,1,0), counter-clockwise seen from +z.
const std::vector<float> kTriangle = {0, 0, 0, 1, 0, 0, 0, 1, 0};
const std::vector<float> kUpNormals = {0, 0, 1, 0, 0, 1, 0, 0, 1};

// Document with one node holding the unit triangle: accessors 0 (positions), 1 (normals) and
// 2 (u16 indices), each in the buffer view of the same number.
GltfDoc singleTriangleDoc()
{
    GltfDoc doc;
    int pos = doc.floats(kTriangle, "VEC3");
    int nrm = doc.floats(kUpNormals, "VEC3");
    int idx = doc.integers<uint16_t>({0, 1, 2});
    doc.setRoots({doc.addNode({{"mesh", doc.addMesh({primitive(pos, nrm, idx)})}})});
    return doc;
}

glm::vec3 corner(const Scene& scene, size_t triangle, int k)
{
    return glm::vec3(scene.positions[scene.indices[3 * triangle + size_t(k)]]);
}

glm::vec3 cornerNormal(const Scene& scene, size_t triangle, int k)
{
    return glm::vec3(scene.normals[scene.indices[3 * triangle + size_t(k)]]);
}

glm::vec4 cornerColor(const Scene& scene, size_t triangle, int k)
{
    return scene.colors[scene.indices[3 * triangle + size_t(k)]];
}

// Unnormalised geometric normal of a triangle in index order.
glm::vec3 faceNormal(const Scene& scene, size_t t)
{
    return glm::cross(corner(scene, t, 1) - corner(scene, t, 0), corner(scene, t, 2) - corner(scene, t, 0));
}

template <typename V>
::testing::AssertionResult near(const V& actual, const V& expected, float eps = 1e-5f)
{
    for (int i = 0; i < V::length(); ++i) {
        if (!(std::fabs(actual[i] - expected[i]) <= eps)) {
            auto result = ::testing::AssertionFailure() << "got (";
            for (int j = 0; j < V::length(); ++j) result << (j ? ", " : "") << actual[j];
            result << "), expected (";
            for (int j = 0; j < V::length(); ++j) result << (j ? ", " : "") << expected[j];
            return result << ")";
        }
    }
    return ::testing::AssertionSuccess();
}

// Checks triangle t's corners, in index order.
::testing::AssertionResult triangleIs(const Scene& scene, size_t t, glm::vec3 a, glm::vec3 b, glm::vec3 c)
{
    if (3 * t + 2 >= scene.indices.size()) return ::testing::AssertionFailure() << "no triangle " << t;
    const glm::vec3 expected[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) {
        auto r = near(corner(scene, t, k), expected[k]);
        if (!r)
            return ::testing::AssertionFailure()
                   << "triangle " << t << " corner " << k << ": " << r.message();
    }
    return ::testing::AssertionSuccess();
}

Result<Scene> loadText(const test::ScratchDir& dir, const std::string& name, const std::string& text)
{
    writeFile(dir.file(name), text);
    return loadScene(dir.file(name));
}

// The error must be a single line that names the file.
void expectLoadError(const Result<Scene>& result, const std::string& path)
{
    ASSERT_FALSE(result.ok());
    const std::string& message = result.error().message;
    EXPECT_NE(message.find("cannot load '" + path + "'"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(result.error().code, ExitCode::Usage);
}

// ---- glTF -----------------------------------------------------------------------------------

TEST(GltfLoader, HierarchyWithTrsAndMatrixNodes)
{
    // Local normals: +z at corners 0 and 2, (0.6, 0.8, 0) at corner 1.
    GltfDoc doc;
    int mesh = doc.addMesh(
        {primitive(doc.floats(kTriangle, "VEC3"), doc.floats({0, 0, 1, 0.6f, 0.8f, 0, 0, 0, 1}, "VEC3"),
                   doc.integers<uint16_t>({0, 1, 2}))});
    int childTrs = doc.addNode({{"mesh", mesh}, {"translation", {0, 0, 1}}});
    // Column-major: translate (0, 1, 0) after scaling y by 3.
    int childMatrix =
        doc.addNode({{"mesh", mesh}, {"matrix", {1, 0, 0, 0, 0, 3, 0, 0, 0, 0, 1, 0, 0, 1, 0, 1}}});
    // 90 degrees about +y maps (x, y, z) to (z, y, -x).
    const double h = std::sqrt(0.5);
    int parent = doc.addNode({{"translation", {1, 2, 3}},
                              {"rotation", {0, h, 0, h}},
                              {"scale", {2, 2, 2}},
                              {"children", {childTrs, childMatrix}}});
    doc.setRoots({parent});
    test::ScratchDir dir("sr_loader");
    Result<Scene> scene = loadText(dir, "hierarchy.gltf", doc.text());
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    ASSERT_EQ(scene->triangleCount(), 2u);

    // Child 1: p + (0,0,1), then *2, rotate, + (1,2,3).
    // (0,0,0) -> (0,0,1) -> (0,0,2) -> (2,0,0) -> (3,2,3)
    // (1,0,0) -> (1,0,1) -> (2,0,2) -> (2,0,-2) -> (3,2,1)
    // (0,1,0) -> (0,1,1) -> (0,2,2) -> (2,2,0) -> (3,4,3)
    EXPECT_TRUE(triangleIs(*scene, 0, {3, 2, 3}, {3, 2, 1}, {3, 4, 3}));
    // Child 2: (x, 3y + 1, z), then *2, rotate, + (1,2,3).
    // (0,0,0) -> (0,1,0) -> (0,2,0) -> (0,2,0) -> (1,4,3)
    // (1,0,0) -> (1,1,0) -> (2,2,0) -> (0,2,-2) -> (1,4,1)
    // (0,1,0) -> (0,4,0) -> (0,8,0) -> (0,8,0) -> (1,10,3)
    EXPECT_TRUE(triangleIs(*scene, 1, {1, 4, 3}, {1, 4, 1}, {1, 10, 3}));

    // Normals: uniform scale leaves directions alone, the rotation takes +z to +x and
    // (0.6, 0.8, 0) to (0, 0.8, -0.6).
    EXPECT_TRUE(near(cornerNormal(*scene, 0, 0), glm::vec3(1, 0, 0)));
    EXPECT_TRUE(near(cornerNormal(*scene, 0, 1), glm::vec3(0, 0.8f, -0.6f)));
    // Under the y-scale of 3 the inverse transpose divides y by 3: (0.6, 0.26667, 0) / 0.65659
    // = (0.913812, 0.406138, 0), rotated to (0, 0.406138, -0.913812).
    EXPECT_TRUE(near(cornerNormal(*scene, 1, 1), glm::vec3(0, 0.406138f, -0.913812f)));
    EXPECT_TRUE(near(cornerNormal(*scene, 1, 2), glm::vec3(1, 0, 0)));

    EXPECT_TRUE(near(scene->boundsMin, glm::vec3(1, 2, 1)));
    EXPECT_TRUE(near(scene->boundsMax, glm::vec3(3, 10, 3)));
    EXPECT_TRUE(scene->colors.empty());
    EXPECT_EQ(scene->droppedTriangles, 0u);
    EXPECT_EQ(scene->triFlags, (std::vector<uint32_t>{0, 0}));
}

TEST(GltfLoader, IndexComponentTypesInPrimitiveOrder)
{
    GltfDoc doc;
    int pos = doc.floats({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, "VEC3");
    int nrm = doc.floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3");
    int mesh = doc.addMesh({primitive(pos, nrm, doc.integers<uint8_t>({0, 1, 2})),
                            primitive(pos, nrm, doc.integers<uint16_t>({0, 2, 3})),
                            primitive(pos, nrm, doc.integers<uint32_t>({3, 1, 2, 2, 0, 1}))});
    doc.setRoots({doc.addNode({{"mesh", mesh}})});
    test::ScratchDir dir("sr_loader");
    Result<Scene> scene = loadText(dir, "indices.gltf", doc.text());
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    ASSERT_EQ(scene->triangleCount(), 4u);
    EXPECT_TRUE(triangleIs(*scene, 0, {0, 0, 0}, {1, 0, 0}, {1, 1, 0}));
    EXPECT_TRUE(triangleIs(*scene, 1, {0, 0, 0}, {1, 1, 0}, {0, 1, 0}));
    EXPECT_TRUE(triangleIs(*scene, 2, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}));
    EXPECT_TRUE(triangleIs(*scene, 3, {1, 1, 0}, {0, 0, 0}, {1, 0, 0}));
}

TEST(GltfLoader, InterleavedAttributesUseStrideAndOffset)
{
    // One buffer view, 24 bytes per vertex: position then normal.
    std::vector<float> interleaved = {0, 0, 0, 0, 0, 1, 2, 0, 0, 0, 0, 1, 0, 2, 0, 0, 0, 1};
    GltfDoc doc;
    int view = doc.addView(interleaved.data(), interleaved.size() * 4, 24);
    int pos = doc.addAccessor(view, kFloat, 3, "VEC3", 0);
    int nrm = doc.addAccessor(view, kFloat, 3, "VEC3", 12);
    doc.setRoots({doc.addNode({{"mesh", doc.addMesh({primitive(pos, nrm)})}})});
    test::ScratchDir dir("sr_loader");
    Result<Scene> scene = loadText(dir, "interleaved.gltf", doc.text());
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    ASSERT_EQ(scene->triangleCount(), 1u);
    EXPECT_TRUE(triangleIs(*scene, 0, {0, 0, 0}, {2, 0, 0}, {0, 2, 0}));
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(near(cornerNormal(*scene, 0, k), glm::vec3(0, 0, 1)));
}

TEST(GltfLoader, NonIndexedWithoutNormalsGetsFlatNormals)
{
    GltfDoc doc;
    // Triangle 0 faces +z; triangle 1: (1,0,0) x (0,0,1)... edges e1 = (0,0,1), e2 = (1,0,0),
    // e1 x e2 = (0,1,0); triangle 2 is degenerate (collinear) and gets the fallback (0,0,1).
    int pos = doc.floats({0, 0, 0, 1, 0, 0, 0, 1, 0,  //
                          0, 0, 0, 0, 0, 1, 1, 0, 0,  //
                          0, 0, 0, 1, 1, 1, 2, 2, 2},
                         "VEC3");
    doc.setRoots({doc.addNode({{"mesh", doc.addMesh({primitive(pos)})}})});
    test::ScratchDir dir("sr_loader");
    Result<Scene> scene = loadText(dir, "flat.gltf", doc.text());
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    ASSERT_EQ(scene->triangleCount(), 3u);
    const glm::vec3 expected[3] = {{0, 0, 1}, {0, 1, 0}, {0, 0, 1}};
    for (size_t t = 0; t < 3; ++t)
        for (int k = 0; k < 3; ++k) EXPECT_TRUE(near(cornerNormal(*scene, t, k), expected[t]));
    EXPECT_TRUE(triangleIs(*scene, 1, {0, 0, 0}, {0, 0, 1}, {1, 0, 0}));
    EXPECT_EQ(scene->normals.size(), scene->positions.size());
}

TEST(GltfLoader, TriangleStripAndFanBecomeListsWithConsistentWinding)
{
    GltfDoc doc;
    // Strip v0..v4 zig-zagging up the y axis; every triangle is counter-clockwise from +z once odd
    // triangles swap their last two vertices: (v0,v1,v2), (v1,v3,v2), (v2,v3,v4).
    int strip = doc.floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 2, 0}, "VEC3");
    // Fan around (0,0,0) through (1,0), (1,1), (0,1), (-1,1): (v1,v2,v0), (v2,v3,v0), (v3,v4,v0).
    int fan = doc.floats({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, -1, 1, 0}, "VEC3");
    int mesh = doc.addMesh({primitive(strip, -1, -1, kTriangleStrip),
                            primitive(fan, -1, doc.integers<uint16_t>({0, 1, 2, 3, 4}), kTriangleFan)});
    doc.setRoots({doc.addNode({{"mesh", mesh}})});
    test::ScratchDir dir("sr_loader");
    Result<Scene> scene = loadText(dir, "strip.gltf", doc.text());
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    ASSERT_EQ(scene->triangleCount(), 6u);
    EXPECT_TRUE(triangleIs(*scene, 0, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}));
    EXPECT_TRUE(triangleIs(*scene, 1, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}));
    EXPECT_TRUE(triangleIs(*scene, 2, {0, 1, 0}, {1, 1, 0}, {0, 2, 0}));
    EXPECT_TRUE(triangleIs(*scene, 3, {1, 0, 0}, {1, 1, 0}, {0, 0, 0}));
    EXPECT_TRUE(triangleIs(*scene, 4, {1, 1, 0}, {0, 1, 0}, {0, 0, 0}));
    EXPECT_TRUE(triangleIs(*scene, 5, {0, 1, 0}, {-1, 1, 0}, {0, 0, 0}));
    for (size_t t = 0; t < 6; ++t) {
        EXPECT_GT(faceNormal(*scene, t).z, 0.0f) << "triangle " << t;
        EXPECT_TRUE(near(cornerNormal(*scene, t, 0), glm::vec3(0, 0, 1)));
    }
}

TEST(GltfLoader, DoubleSidedMaterialSetsTriangleFlag)
{
    GltfDoc doc;
    int pos = doc.floats(kTriangle, "VEC3");
    int twoSided = doc.addMaterial({{"doubleSided", true}});
    int oneSided = doc.addMaterial({{"name", "plain"}});
    int mesh = doc.addMesh(
        {primitive(pos, -1, -1, -1, twoSided), primitive(pos, -1, -1, -1, oneSided), primitive(pos)});
    doc.setRoots({doc.addNode({{"mesh", mesh}})});
    test::ScratchDir dir("sr_loader");
    Result<Scene> scene = loadText(dir, "sided.gltf", doc.text());
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    EXPECT_EQ(scene->triFlags, (std::vector<uint32_t>{TRI_FLAG_DOUBLE_SIDED, 0u, 0u}));
}

TEST(GltfLoader, NegativeScaleReversesWinding)
{
    GltfDoc doc;
    int pos = doc.floats(kTriangle, "VEC3");
    int mesh = doc.addMesh({primitive(pos, doc.floats(kUpNormals, "VEC3")), primitive(pos)});
    doc.setRoots({doc.addNode({{"mesh", mesh}, {"scale", {-1, 1, 1}}})});
    test::ScratchDir dir("sr_loader");
    Result<Scene> scene = loadText(dir, "mirror.gltf", doc.text());
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    ASSERT_EQ(scene->triangleCount(), 2u);
    // Mirrored corners (0,0,0), (-1,0,0), (0,1,0) are clockwise from +z; reversing the last two
    // makes the triangle counter-clockwise again, and the surface still faces +z.
    for (size_t t = 0; t < 2; ++t) {
        EXPECT_TRUE(triangleIs(*scene, t, {0, 0, 0}, {0, 1, 0}, {-1, 0, 0}));
        EXPECT_GT(faceNormal(*scene, t).z, 0.0f);
        for (int k = 0; k < 3; ++k) EXPECT_TRUE(near(cornerNormal(*scene, t, k), glm::vec3(0, 0, 1)));
    }
}

TEST(GltfLoader, CamerasArePlacedByTheirNodes)
{
    GltfDoc doc = singleTriangleDoc();
    Json& j = doc.json();
    j["cameras"] =
        Json::array({{{"type", "perspective"},
                      {"name", "persp"},
                      {"perspective", {{"yfov", 0.7}, {"aspectRatio", 1.5}, {"znear", 0.1}, {"zfar", 100}}}},
                     {{"type", "orthographic"},
                      {"orthographic", {{"xmag", 2}, {"ymag", 1.5}, {"znear", 0.5}, {"zfar", 50}}}}});
    const double h = std::sqrt(0.5);
    // Scale 2 is stripped; the 90-degree turn about +y sends view x to -z and view z to +x.
    int persp = doc.addNode(
        {{"camera", 0}, {"translation", {0, 1, 5}}, {"rotation", {0, h, 0, h}}, {"scale", {2, 2, 2}}});
    int orthoChild = doc.addNode({{"camera", 1}, {"name", "orthoNode"}, {"translation", {1, 0, 0}}});
    int orthoParent = doc.addNode({{"translation", {0, 0, 10}}, {"children", {orthoChild}}});
    j["scenes"][0]["nodes"].push_back(persp);
    j["scenes"][0]["nodes"].push_back(orthoParent);
    test::ScratchDir dir("sr_loader");
    Result<Scene> scene = loadText(dir, "cameras.gltf", doc.text());
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    ASSERT_EQ(scene->cameras.size(), 2u);

    const SceneCamera& p = scene->cameras[0];
    EXPECT_EQ(p.name, "persp");
    EXPECT_TRUE(p.perspective);
    EXPECT_FLOAT_EQ(p.yfov, 0.7f);
    EXPECT_FLOAT_EQ(p.aspectRatio, 1.5f);
    EXPECT_FLOAT_EQ(p.znear, 0.1f);
    EXPECT_FLOAT_EQ(p.zfar, 100.0f);
    EXPECT_TRUE(near(p.worldFromView[0], glm::vec4(0, 0, -1, 0)));
    EXPECT_TRUE(near(p.worldFromView[1], glm::vec4(0, 1, 0, 0)));
    EXPECT_TRUE(near(p.worldFromView[2], glm::vec4(1, 0, 0, 0)));
    EXPECT_TRUE(near(p.worldFromView[3], glm::vec4(0, 1, 5, 1)));

    const SceneCamera& o = scene->cameras[1];
    EXPECT_EQ(o.name, "orthoNode");  // the camera has no name, the node does
    EXPECT_FALSE(o.perspective);
    EXPECT_FLOAT_EQ(o.xmag, 2.0f);
    EXPECT_FLOAT_EQ(o.ymag, 1.5f);
    EXPECT_FLOAT_EQ(o.znear, 0.5f);
    EXPECT_FLOAT_EQ(o.zfar, 50.0f);
    EXPECT_TRUE(near(o.worldFromView[3], glm::vec4(1, 0, 10, 1)));
}

TEST(GltfLoader, VertexColoursTimesBaseColorFactor)
{
    GltfDoc doc;
    int pos = doc.floats(kTriangle, "VEC3");
    int halfRed = doc.addMaterial({{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 1, 1, 1}}}}});
    int tint = doc.addMaterial({{"pbrMetallicRoughness", {{"baseColorFactor", {0.2, 0.4, 0.6, 1}}}}});
    Json rgba8 = primitive(pos, -1, -1, -1, halfRed);
    rgba8["attributes"]["COLOR_0"] =
        doc.integers<uint8_t>({255, 0, 0, 255, 0, 255, 0, 51, 0, 0, 255, 255}, "VEC4", true);
    Json rgb16 = primitive(pos);
    rgb16["attributes"]["COLOR_0"] =
        doc.integers<uint16_t>({65535, 0, 0, 0, 65535, 0, 0, 0, 65535}, "VEC3", true);
    Json rgbFloat = primitive(pos);
    rgbFloat["attributes"]["COLOR_0"] = doc.floats({0.25f, 0.5f, 0.75f, 1, 1, 1, 0, 0, 0}, "VEC3");
    doc.setRoots(
        {doc.addNode({{"mesh", doc.addMesh({rgba8, rgb16, rgbFloat, primitive(pos, -1, -1, -1, tint)})}})});
    test::ScratchDir dir("sr_loader");
    Result<Scene> scene = loadText(dir, "colors.gltf", doc.text());
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    ASSERT_EQ(scene->triangleCount(), 4u);
    ASSERT_EQ(scene->colors.size(), scene->positions.size());
    EXPECT_TRUE(near(cornerColor(*scene, 0, 0), glm::vec4(0.5f, 0, 0, 1)));
    EXPECT_TRUE(near(cornerColor(*scene, 0, 1), glm::vec4(0, 1, 0, 0.2f)));
    EXPECT_TRUE(near(cornerColor(*scene, 0, 2), glm::vec4(0, 0, 1, 1)));
    EXPECT_TRUE(near(cornerColor(*scene, 1, 1), glm::vec4(0, 1, 0, 1)));
    EXPECT_TRUE(near(cornerColor(*scene, 2, 0), glm::vec4(0.25f, 0.5f, 0.75f, 1)));
    EXPECT_TRUE(near(cornerColor(*scene, 2, 1), glm::vec4(1, 1, 1, 1)));
    // No COLOR_0: the factor is the vertex colour.
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(near(cornerColor(*scene, 3, k), glm::vec4(0.2f, 0.4f, 0.6f, 1)));
}

TEST(GltfLoader, AllWhiteColoursLeaveColorsEmpty)
{
    GltfDoc doc;
    Json p = primitive(doc.floats(kTriangle, "VEC3"));
    p["attributes"]["COLOR_0"] = doc.floats({1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1}, "VEC4");
    int white = doc.addMaterial({{"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 1}}}}});
    p["material"] = white;
    doc.setRoots({doc.addNode({{"mesh", doc.addMesh({p})}})});
    test::ScratchDir dir("sr_loader");
    Result<Scene> scene = loadText(dir, "white.gltf", doc.text());
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    EXPECT_TRUE(scene->colors.empty());
}

TEST(GltfLoader, BinaryGlbAndExternalBuffer)
{
    GltfDoc doc = singleTriangleDoc();
    test::ScratchDir dir("sr_loader");
    Result<Scene> glb = loadText(dir, "triangle.GLB", doc.glb());
    ASSERT_TRUE(glb.ok()) << glb.error().message;
    ASSERT_EQ(glb->triangleCount(), 1u);
    EXPECT_TRUE(triangleIs(*glb, 0, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}));

    // The GLB magic number wins over a misleading extension.
    Result<Scene> disguised = loadText(dir, "disguised.gltf", doc.glb());
    ASSERT_TRUE(disguised.ok()) << disguised.error().message;
    EXPECT_EQ(disguised->triangleCount(), 1u);

    writeFile(dir.file("triangle.bin"), doc.bin());
    Result<Scene> external = loadText(dir, "external.gltf", doc.textWithExternalBuffer("triangle.bin"));
    ASSERT_TRUE(external.ok()) << external.error().message;
    EXPECT_TRUE(triangleIs(*external, 0, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}));
}

TEST(GltfLoader, SceneSelection)
{
    GltfDoc doc;
    int pos = doc.floats(kTriangle, "VEC3");
    int mesh = doc.addMesh({primitive(pos)});
    int child = doc.addNode({{"mesh", mesh}, {"translation", {0, 0, 2}}});
    int a = doc.addNode({{"mesh", mesh}, {"translation", {0, 0, 1}}, {"children", {child}}});
    int b = doc.addNode({{"mesh", mesh}, {"translation", {0, 0, 5}}});
    test::ScratchDir dir("sr_loader");

    // "scene": 1 picks the second scene only.
    doc.json()["scenes"] = Json::array({{{"nodes", {a}}}, {{"nodes", {b}}}});
    doc.json()["scene"] = 1;
    Result<Scene> second = loadText(dir, "second.gltf", doc.text());
    ASSERT_TRUE(second.ok()) << second.error().message;
    ASSERT_EQ(second->triangleCount(), 1u);
    EXPECT_FLOAT_EQ(corner(*second, 0, 0).z, 5.0f);

    // No default scene: scene 0, depth first (a, then its child at z = 1 + 2).
    doc.json().erase("scene");
    Result<Scene> first = loadText(dir, "first.gltf", doc.text());
    ASSERT_TRUE(first.ok()) << first.error().message;
    ASSERT_EQ(first->triangleCount(), 2u);
    EXPECT_FLOAT_EQ(corner(*first, 0, 0).z, 1.0f);
    EXPECT_FLOAT_EQ(corner(*first, 1, 0).z, 3.0f);

    // No scenes at all: every root node in document order, children right after their parent.
    doc.json().erase("scenes");
    Result<Scene> roots = loadText(dir, "roots.gltf", doc.text());
    ASSERT_TRUE(roots.ok()) << roots.error().message;
    ASSERT_EQ(roots->triangleCount(), 3u);
    EXPECT_FLOAT_EQ(corner(*roots, 0, 0).z, 1.0f);
    EXPECT_FLOAT_EQ(corner(*roots, 1, 0).z, 3.0f);
    EXPECT_FLOAT_EQ(corner(*roots, 2, 0).z, 5.0f);
}

TEST(GltfLoader, OutOfRangeIndicesAndNanPositionsAreDropped)
{
    GltfDoc doc;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    int pos = doc.floats({0, 0, 0, 1, 0, 0, 0, 1, 0, nan, 0, 0}, "VEC3");
    int nrm = doc.floats({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3");
    // Triangles: valid, index 7 out of range, uses the NaN vertex, valid again.
    int indices = doc.integers<uint16_t>({0, 1, 2, 0, 1, 7, 3, 1, 2, 2, 1, 0});
    // The same without normals takes the flat path, which must drop the same way.
    int flatIndices = doc.integers<uint8_t>({0, 1, 9, 0, 1, 2});
    int mesh = doc.addMesh({primitive(pos, nrm, indices), primitive(pos, -1, flatIndices)});
    doc.setRoots({doc.addNode({{"mesh", mesh}})});
    test::ScratchDir dir("sr_loader");
    std::string path = dir.file("bad_indices.gltf");
    writeFile(path, doc.text());
    ::testing::internal::CaptureStderr();
    Result<Scene> scene = loadScene(path);
    std::string warnings = ::testing::internal::GetCapturedStderr();
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    EXPECT_EQ(scene->droppedTriangles, 3u);
    ASSERT_EQ(scene->triangleCount(), 3u);
    EXPECT_EQ(scene->triFlags.size(), 3u);
    EXPECT_TRUE(triangleIs(*scene, 0, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}));
    EXPECT_TRUE(triangleIs(*scene, 1, {0, 1, 0}, {1, 0, 0}, {0, 0, 0}));
    EXPECT_TRUE(triangleIs(*scene, 2, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}));
    EXPECT_EQ(warnings, "warning: " + path +
                            ": dropped 3 triangle(s) with out-of-range indices or non-finite "
                            "positions\n");
    // Bounds ignore the unreferenced NaN vertex.
    EXPECT_TRUE(near(scene->boundsMin, glm::vec3(0, 0, 0)));
    EXPECT_TRUE(near(scene->boundsMax, glm::vec3(1, 1, 0)));
}

TEST(GltfLoader, LinesAndPointsAreSkippedWithOneWarningPerMode)
{
    GltfDoc doc;
    int pos = doc.floats(kTriangle, "VEC3");
    int mesh = doc.addMesh({primitive(pos, -1, -1, kLines), primitive(pos), primitive(pos, -1, -1, kLines),
                            primitive(pos, -1, -1, kPoints)});
    doc.setRoots({doc.addNode({{"mesh", mesh}})});
    test::ScratchDir dir("sr_loader");
    std::string path = dir.file("lines.gltf");
    writeFile(path, doc.text());
    ::testing::internal::CaptureStderr();
    Result<Scene> scene = loadScene(path);
    std::string warnings = ::testing::internal::GetCapturedStderr();
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    EXPECT_EQ(scene->triangleCount(), 1u);
    EXPECT_EQ(warnings, "warning: " + path +
                            ": skipping 1 primitive(s) with mode POINTS (lines/points not supported yet)\n"
                            "warning: " +
                            path +
                            ": skipping 2 primitive(s) with mode LINES (lines/points not supported yet)\n");
}

TEST(GltfLoader, MalformedInputsAreOneLineErrors)
{
    test::ScratchDir dir("sr_loader");
    std::string valid = singleTriangleDoc().text();

    std::string missing = dir.file("missing.gltf");
    expectLoadError(loadScene(missing), missing);

    std::string truncated = dir.file("truncated.gltf");
    writeFile(truncated, valid.substr(0, valid.size() / 2));
    expectLoadError(loadScene(truncated), truncated);

    std::string truncatedGlb = dir.file("truncated.glb");
    std::string glb = singleTriangleDoc().glb();
    writeFile(truncatedGlb, glb.substr(0, glb.size() - 20));
    expectLoadError(loadScene(truncatedGlb), truncatedGlb);

    std::string noBin = dir.file("no_bin.gltf");
    writeFile(noBin, singleTriangleDoc().textWithExternalBuffer("does_not_exist.bin"));
    expectLoadError(loadScene(noBin), noBin);

    // Accessor 0 (positions) claims 4 elements in a 36-byte view.
    {
        GltfDoc doc = singleTriangleDoc();
        doc.json()["accessors"][0]["count"] = 4;
        std::string path = dir.file("accessor_bounds.gltf");
        writeFile(path, doc.text());
        Result<Scene> r = loadScene(path);
        expectLoadError(r, path);
        if (!r.ok()) {
            EXPECT_NE(r.error().message.find("accessor 0"), std::string::npos) << r.error().message;
        }
    }
    // A buffer view that runs past the end of its buffer.
    {
        GltfDoc doc = singleTriangleDoc();
        doc.json()["bufferViews"][1]["byteLength"] = 4000;
        std::string path = dir.file("view_bounds.gltf");
        writeFile(path, doc.text());
        expectLoadError(loadScene(path), path);
    }
    // Sparse accessors are not supported.
    {
        GltfDoc doc = singleTriangleDoc();
        doc.json()["accessors"][0]["sparse"] = {{"count", 1},
                                                {"indices", {{"bufferView", 2}, {"componentType", kU16}}},
                                                {"values", {{"bufferView", 1}}}};
        std::string path = dir.file("sparse.gltf");
        writeFile(path, doc.text());
        Result<Scene> r = loadScene(path);
        expectLoadError(r, path);
        if (!r.ok()) {
            EXPECT_NE(r.error().message.find("sparse"), std::string::npos);
        }
    }
    // Positions must be VEC3 float.
    {
        GltfDoc doc = singleTriangleDoc();
        doc.json()["accessors"][0]["type"] = "VEC2";
        std::string path = dir.file("vec2.gltf");
        writeFile(path, doc.text());
        expectLoadError(loadScene(path), path);
    }
    // A node that references a missing mesh, and a node that is its own child.
    {
        GltfDoc doc = singleTriangleDoc();
        doc.json()["nodes"][0]["mesh"] = 5;
        std::string path = dir.file("no_mesh.gltf");
        writeFile(path, doc.text());
        expectLoadError(loadScene(path), path);
    }
    {
        GltfDoc doc = singleTriangleDoc();
        doc.json()["nodes"][0]["children"] = {0};
        std::string path = dir.file("cycle.gltf");
        writeFile(path, doc.text());
        expectLoadError(loadScene(path), path);
    }
    // Nothing drawable at all.
    {
        GltfDoc doc;
        doc.setRoots({doc.addNode({{"name", "empty"}})});
        doc.floats(kTriangle, "VEC3");
        std::string path = dir.file("empty.gltf");
        writeFile(path, doc.text());
        Result<Scene> r = loadScene(path);
        expectLoadError(r, path);
        if (!r.ok()) {
            EXPECT_NE(r.error().message.find("no triangles"), std::string::npos);
        }
    }
}

TEST(SceneLoader, DispatchesOnExtensionCaseInsensitively)
{
    test::ScratchDir dir("sr_loader");
    std::string unknown = dir.file("model.ply");
    writeFile(unknown, "ply\n");
    Result<Scene> r = loadScene(unknown);
    expectLoadError(r, unknown);

    std::string obj = dir.file("tri.OBJ");
    writeFile(obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    Result<Scene> scene = loadScene(obj);
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    EXPECT_EQ(scene->triangleCount(), 1u);
}

TEST(SceneLoader, FlattenMessageMakesOneLine)
{
    EXPECT_EQ(flattenMessage("first\n\nsecond\r\nsecond\n.\n  third.  \n"), "first; second (2 times); third");
    EXPECT_EQ(flattenMessage(""), "");
    std::string many;
    for (int i = 0; i < 1000; ++i) many += "line " + std::to_string(i) + "\n";
    std::string flat = flattenMessage(many);
    EXPECT_LE(flat.size(), 400u);
    EXPECT_EQ(flat.find('\n'), std::string::npos);
}

// ---- finalizeScene --------------------------------------------------------------------------

Scene twoTriangleScene()
{
    Scene scene;
    for (glm::vec3 p : {glm::vec3(0, 0, 0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(-2, 3, 4)}) {
        scene.positions.emplace_back(p, 1.0f);
        scene.normals.emplace_back(0.0f, 0.0f, 1.0f, 0.0f);
    }
    scene.indices = {0, 1, 2, 2, 1, 3};
    return scene;
}

TEST(FinalizeScene, FillsFlagsAndBounds)
{
    Scene scene = twoTriangleScene();
    ASSERT_TRUE(finalizeScene(scene, "test").ok());
    EXPECT_EQ(scene.triFlags, (std::vector<uint32_t>{0, 0}));
    EXPECT_TRUE(near(scene.boundsMin, glm::vec3(-2, 0, 0)));
    EXPECT_TRUE(near(scene.boundsMax, glm::vec3(1, 3, 4)));
}

TEST(FinalizeScene, DropsBadTrianglesKeepingOrderAndFlags)
{
    Scene scene = twoTriangleScene();
    scene.positions.emplace_back(std::numeric_limits<float>::infinity(), 0.0f, 0.0f, 1.0f);
    scene.normals.emplace_back(0.0f, 0.0f, 1.0f, 0.0f);
    // Triangle 1 uses index 99, triangle 2 the infinite vertex 4.
    scene.indices = {0, 1, 2, 0, 1, 99, 4, 1, 2, 2, 1, 3};
    scene.triFlags = {1, 0, 1, 1};
    ::testing::internal::CaptureStderr();
    ASSERT_TRUE(finalizeScene(scene, "unit").ok());
    EXPECT_EQ(::testing::internal::GetCapturedStderr(),
              "warning: unit: dropped 2 triangle(s) with out-of-range indices or non-finite "
              "positions\n");
    EXPECT_EQ(scene.indices, (std::vector<uint32_t>{0, 1, 2, 2, 1, 3}));
    EXPECT_EQ(scene.triFlags, (std::vector<uint32_t>{1, 1}));
    EXPECT_EQ(scene.droppedTriangles, 2u);
}

TEST(FinalizeScene, Errors)
{
    Scene empty;
    Status noTriangles = finalizeScene(empty, "nothing");
    ASSERT_FALSE(noTriangles.ok());
    EXPECT_EQ(noTriangles.error().message, "nothing: no triangles to draw");

    Scene allBad = twoTriangleScene();
    allBad.indices = {0, 1, 7};
    ::testing::internal::CaptureStderr();
    EXPECT_FALSE(finalizeScene(allBad, "bad").ok());
    ::testing::internal::GetCapturedStderr();
    EXPECT_EQ(allBad.droppedTriangles, 1u);

    Scene missingNormals = twoTriangleScene();
    missingNormals.normals.pop_back();
    EXPECT_FALSE(finalizeScene(missingNormals, "normals").ok());
}

// ---- OBJ ------------------------------------------------------------------------------------

TEST(ObjLoader, PolygonsAreFanTriangulatedInFileOrder)
{
    test::ScratchDir dir("sr_loader");
    std::string path = dir.file("polygons.obj");
    writeFile(path,
              "# two objects: a quad and a triangle, then a pentagon\n"
              "o first\n"
              "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
              "v 2 0 0\nv 3 0 0\nv 3.5 1 0\nv 2.5 2 0\nv 1.5 1 0\n"
              "f 1 2 3 4\n"
              "f 1 2 4\n"
              "o second\n"
              "f 5 6 7 8 9\n");
    Result<Scene> scene = loadScene(path);
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    ASSERT_EQ(scene->triangleCount(), 6u);
    EXPECT_TRUE(triangleIs(*scene, 0, {0, 0, 0}, {1, 0, 0}, {1, 1, 0}));
    EXPECT_TRUE(triangleIs(*scene, 1, {0, 0, 0}, {1, 1, 0}, {0, 1, 0}));
    EXPECT_TRUE(triangleIs(*scene, 2, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}));
    EXPECT_TRUE(triangleIs(*scene, 3, {2, 0, 0}, {3, 0, 0}, {3.5f, 1, 0}));
    EXPECT_TRUE(triangleIs(*scene, 4, {2, 0, 0}, {3.5f, 1, 0}, {2.5f, 2, 0}));
    EXPECT_TRUE(triangleIs(*scene, 5, {2, 0, 0}, {2.5f, 2, 0}, {1.5f, 1, 0}));
    // No vn lines: flat normals, +z for these counter-clockwise faces.
    for (size_t t = 0; t < 6; ++t)
        for (int k = 0; k < 3; ++k) EXPECT_TRUE(near(cornerNormal(*scene, t, k), glm::vec3(0, 0, 1)));
    EXPECT_TRUE(scene->colors.empty());
    EXPECT_EQ(scene->triFlags, std::vector<uint32_t>(6, 0u));
}

TEST(ObjLoader, NormalsAndVertexColours)
{
    test::ScratchDir dir("sr_loader");
    std::string path = dir.file("attributes.obj");
    writeFile(path,
              "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 1 1 1\n"
              "vn 0 0 2\nvn 0 3 4\n"
              "f 1//1 2//2 3//1 4//1\n"
              "f 1 3 2\n");
    Result<Scene> scene = loadScene(path);
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    ASSERT_EQ(scene->triangleCount(), 3u);
    // Given normals are normalised: (0,0,2) -> +z, (0,3,4) -> (0, 0.6, 0.8).
    EXPECT_TRUE(near(cornerNormal(*scene, 0, 0), glm::vec3(0, 0, 1)));
    EXPECT_TRUE(near(cornerNormal(*scene, 0, 1), glm::vec3(0, 0.6f, 0.8f)));
    EXPECT_TRUE(near(cornerNormal(*scene, 1, 2), glm::vec3(0, 0, 1)));
    // The second face has no normals and is clockwise from +z: its flat normal is -z.
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(near(cornerNormal(*scene, 2, k), glm::vec3(0, 0, -1)));
    ASSERT_EQ(scene->colors.size(), scene->positions.size());
    EXPECT_TRUE(near(cornerColor(*scene, 0, 0), glm::vec4(1, 0, 0, 1)));
    EXPECT_TRUE(near(cornerColor(*scene, 0, 1), glm::vec4(0, 1, 0, 1)));
    EXPECT_TRUE(near(cornerColor(*scene, 1, 2), glm::vec4(1, 1, 1, 1)));
    EXPECT_TRUE(near(cornerColor(*scene, 2, 1), glm::vec4(0, 0, 1, 1)));
}

TEST(ObjLoader, ShortFacesAndBadIndicesDoNotCrash)
{
    test::ScratchDir dir("sr_loader");
    std::string path = dir.file("short.obj");
    writeFile(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nf 1 2 3\n");
    ::testing::internal::CaptureStderr();
    Result<Scene> scene = loadScene(path);
    std::string warnings = ::testing::internal::GetCapturedStderr();
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    EXPECT_EQ(scene->triangleCount(), 1u);
    // tinyobjloader drops the 2-vertex face itself; its warning is passed on, naming the file.
    EXPECT_EQ(warnings.rfind("warning: " + path + ": ", 0), 0u) << warnings;

    // Index 9 does not exist: either tinyobjloader rejects the file or the face is dropped.
    std::string badIndex = dir.file("bad_index.obj");
    writeFile(badIndex, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\nf 1 2 3\n");
    ::testing::internal::CaptureStderr();
    Result<Scene> bad = loadScene(badIndex);
    ::testing::internal::GetCapturedStderr();
    if (bad.ok()) {
        EXPECT_EQ(bad->triangleCount(), 1u);
        EXPECT_EQ(bad->droppedTriangles, 1u);
    } else {
        expectLoadError(bad, badIndex);
    }
}

TEST(ObjLoader, MissingAndGarbageFilesAreErrors)
{
    test::ScratchDir dir("sr_loader");
    std::string missing = dir.file("missing.obj");
    expectLoadError(loadScene(missing), missing);

    std::string garbage = dir.file("garbage.obj");
    std::string bytes =
        "\x7f"
        "ELF\x01\x02 not an obj file\n\xff\xfe f f f\n";
    for (int i = 0; i < 256; ++i) bytes += char(i * 37 + 11);
    writeFile(garbage, bytes);
    ::testing::internal::CaptureStderr();
    Result<Scene> r = loadScene(garbage);
    ::testing::internal::GetCapturedStderr();
    expectLoadError(r, garbage);
}

// ---- built-in scene -------------------------------------------------------------------------

TEST(BuiltinScene, SaneGeometry)
{
    Scene scene = builtinScene();
    ASSERT_GE(scene.triangleCount(), 2000u);
    ASSERT_LE(scene.triangleCount(), 5000u);
    ASSERT_EQ(scene.normals.size(), scene.positions.size());
    ASSERT_EQ(scene.colors.size(), scene.positions.size());
    EXPECT_EQ(scene.triFlags.size(), scene.triangleCount());
    EXPECT_EQ(scene.droppedTriangles, 0u);
    for (uint32_t i : scene.indices) ASSERT_LT(i, scene.positions.size());
    for (size_t v = 0; v < scene.positions.size(); ++v) {
        const glm::vec4& p = scene.positions[v];
        ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) << v;
        EXPECT_EQ(p.w, 1.0f);
        EXPECT_NEAR(glm::length(glm::vec3(scene.normals[v])), 1.0f, 1e-5f) << v;
        EXPECT_EQ(scene.normals[v].w, 0.0f);
    }
    // Resting on y = 0, about 4 units across.
    EXPECT_NEAR(scene.boundsMin.y, 0.0f, 1e-6f);
    glm::vec3 extent = scene.boundsMax - scene.boundsMin;
    EXPECT_GT(extent.x, 3.0f);
    EXPECT_LT(extent.x, 5.0f);
    EXPECT_GT(extent.z, 3.0f);
    EXPECT_LT(extent.z, 5.0f);
    EXPECT_GT(extent.y, 0.5f);
    EXPECT_LT(extent.y, 3.0f);

    // Counter-clockwise from outside: the geometric normal agrees with the vertex normals.
    std::vector<glm::vec4> distinct;
    for (size_t t = 0; t < scene.triangleCount(); ++t) {
        glm::vec3 n = faceNormal(scene, t);
        ASSERT_GT(glm::length(n), 0.0f) << "degenerate triangle " << t;
        for (int k = 0; k < 3; ++k)
            ASSERT_GT(glm::dot(n, cornerNormal(scene, t, k)), 0.0f) << "triangle " << t;
        glm::vec4 c = cornerColor(scene, t, 0);
        if (std::find(distinct.begin(), distinct.end(), c) == distinct.end()) distinct.push_back(c);
    }
    EXPECT_GE(distinct.size(), 4u);  // one colour per object
}

TEST(BuiltinScene, Deterministic)
{
    Scene a = builtinScene();
    Scene b = builtinScene();
    EXPECT_EQ(a.positions, b.positions);
    EXPECT_EQ(a.normals, b.normals);
    EXPECT_EQ(a.colors, b.colors);
    EXPECT_EQ(a.indices, b.indices);
}

// ---- shipped assets -------------------------------------------------------------------------

#ifdef SR_SOURCE_DIR
// The checkout's root; SR_SOURCE_DIR in the environment wins for a relocated test binary.
std::string sourceDir()
{
    const char* env = std::getenv("SR_SOURCE_DIR");
    return env ? env : SR_SOURCE_DIR;
}

// The hand-written files are consistent: every triangle's winding agrees with its normals.
void expectWindingMatchesNormals(const Scene& scene)
{
    for (size_t t = 0; t < scene.triangleCount(); ++t)
        for (int k = 0; k < 3; ++k)
            EXPECT_GT(glm::dot(faceNormal(scene, t), cornerNormal(scene, t, k)), 0.0f) << t;
}

TEST(Assets, HierarchyGltf)
{
    Result<Scene> scene = loadScene(sourceDir() + "/assets/hierarchy.gltf");
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    EXPECT_EQ(scene->droppedTriangles, 0u);
    EXPECT_EQ(scene->cameras.size(), 1u);
    EXPECT_FALSE(scene->colors.empty());
    bool anyDoubleSided = false, anySingleSided = false;
    for (uint32_t f : scene->triFlags) {
        anyDoubleSided |= (f & TRI_FLAG_DOUBLE_SIDED) != 0;
        anySingleSided |= (f & TRI_FLAG_DOUBLE_SIDED) == 0;
    }
    EXPECT_TRUE(anyDoubleSided);
    EXPECT_TRUE(anySingleSided);
    EXPECT_EQ(scene->triangleCount(), 8u);  // pyramid 6, banner 2
    expectWindingMatchesNormals(*scene);
    EXPECT_NEAR(scene->boundsMin.y, 0.0f, 1e-5f);
    EXPECT_NEAR(scene->boundsMax.y, 1.2f, 1e-5f);
}

TEST(Assets, ShapesObj)
{
    Result<Scene> scene = loadScene(sourceDir() + "/assets/shapes.obj");
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    EXPECT_EQ(scene->droppedTriangles, 0u);
    EXPECT_FALSE(scene->colors.empty());
    EXPECT_EQ(scene->triangleCount(), 28u);  // cube 6 x 2, prism 3 + 3 + 5 x 2
    expectWindingMatchesNormals(*scene);
    EXPECT_NEAR(scene->boundsMin.y, 0.0f, 1e-6f);
}
#endif

}  // namespace
}  // namespace sr
