// primitive_mode_test.cpp - meshAsLines and withWireframe on hand-built meshes: each geometric edge
// once (by position, so split vertices do not double it), in triangle order with the first triangle's
// indices, orientation and material; the wireframe's black material and consistent material lists.
#include <array>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "scene/primitive_mode.h"
#include "scene/scene.h"

namespace sr {
namespace {

using PositionPair = std::array<float, 6>;

void addVertex(Scene& scene, glm::vec3 p, glm::vec3 n = glm::vec3(0, 0, 1))
{
    scene.positions.emplace_back(p, 1.0f);
    scene.normals.emplace_back(n, 0.0f);
}

// Corner i of the unit cube: x, y and z are bits 0, 1 and 2 of i.
glm::vec3 cubeCorner(int i)
{
    return glm::vec3(float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1));
}

// The cube's faces as quads of corner numbers, counter-clockwise seen from outside, with their normals.
const int kFaces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
const glm::vec3 kFaceNormals[6] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};

// 8 shared vertices, 12 triangles (each face split along its first corner's diagonal).
Scene sharedCube()
{
    Scene scene;
    for (int i = 0; i < 8; ++i) addVertex(scene, cubeCorner(i), glm::normalize(cubeCorner(i) - 0.5f));
    for (const auto& f : kFaces) {
        auto q = [&](int k) { return uint32_t(f[k]); };
        scene.indices.insert(scene.indices.end(), {q(0), q(1), q(2), q(0), q(2), q(3)});
    }
    scene.triFlags.assign(scene.triangleCount(), 0u);
    return scene;
}

// The same cube with hard edges: 4 vertices per face carrying the face normal, 24 in all.
Scene splitCube()
{
    Scene scene;
    for (int face = 0; face < 6; ++face) {
        auto base = uint32_t(scene.positions.size());
        for (int k = 0; k < 4; ++k) addVertex(scene, cubeCorner(kFaces[face][k]), kFaceNormals[face]);
        scene.indices.insert(scene.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
    scene.triFlags.assign(scene.triangleCount(), 0u);
    return scene;
}

// The unit square in z = 0 as two triangles (0 1 2) and (0 2 3), sharing the diagonal 0-2.
Scene openQuad()
{
    Scene scene;
    for (glm::vec3 p : {glm::vec3(0, 0, 0), glm::vec3(1, 0, 0), glm::vec3(1, 1, 0), glm::vec3(0, 1, 0)})
        addVertex(scene, p);
    scene.indices = {0, 1, 2, 0, 2, 3};
    scene.triFlags = {0, 0};
    return scene;
}

// Segment k's endpoint positions, the smaller first, so that either direction gives one pair.
PositionPair positionPair(const Scene& scene, size_t k)
{
    glm::vec3 a(scene.positions[scene.lines[2 * k]]), b(scene.positions[scene.lines[2 * k + 1]]);
    PositionPair first = {a.x, a.y, a.z, b.x, b.y, b.z};
    PositionPair second = {b.x, b.y, b.z, a.x, a.y, a.z};
    return std::min(first, second);
}

// The cube's segments cover each geometric edge exactly once: the 12 cube edges (corners that differ
// in one coordinate) and the 6 face diagonals the triangulation adds.
void expectCubeEdgesOnce(const Scene& lines)
{
    std::set<PositionPair> seen;
    for (size_t k = 0; k < lines.lineCount(); ++k)
        EXPECT_TRUE(seen.insert(positionPair(lines, k)).second) << "segment " << k << " repeats an edge";
    auto pair = [](int i, int j) {
        glm::vec3 a = cubeCorner(i), b = cubeCorner(j);
        return std::min(PositionPair{a.x, a.y, a.z, b.x, b.y, b.z},
                        PositionPair{b.x, b.y, b.z, a.x, a.y, a.z});
    };
    std::set<PositionPair> expected;
    for (int i = 0; i < 8; ++i)
        for (int bit = 0; bit < 3; ++bit)
            if ((i & (1 << bit)) == 0) expected.insert(pair(i, i | (1 << bit)));
    EXPECT_EQ(expected.size(), 12u);
    for (const auto& f : kFaces) expected.insert(pair(f[0], f[2]));
    EXPECT_EQ(seen, expected);
}
// meshAsPoints on a cube with hard edges: its 24 vertices sit on 8 corners, drawn once each.
TEST(PrimitiveMode, MeshAsPointsDrawsEachCornerOnce)
{
    Scene points = meshAsPoints(splitCube());
    ASSERT_EQ(points.pointCount(), 8u);
    std::set<std::array<float, 3>> corners;
    for (uint32_t v : points.points)
        corners.insert({points.positions[v].x, points.positions[v].y, points.positions[v].z});
    EXPECT_EQ(corners.size(), 8u);
    EXPECT_EQ(meshAsPoints(sharedCube()).pointCount(), 8u);
}

TEST(PrimitiveMode, MeshAsLinesDrawsEachCubeEdgeOnce)
{
    for (const Scene& cube : {sharedCube(), splitCube()}) {
        ASSERT_EQ(cube.triangleCount(), 12u);
        Scene lines = meshAsLines(cube);
        EXPECT_EQ(lines.lineCount(), 18u) << cube.vertexCount() << " vertices";
        expectCubeEdgesOnce(lines);
        EXPECT_EQ(lines.triangleCount(), 0u);
        EXPECT_TRUE(lines.triFlags.empty());
        EXPECT_TRUE(lines.lineMaterials.empty());
        EXPECT_EQ(lines.positions, cube.positions);
        Scene finalized = lines;
        EXPECT_TRUE(finalizeScene(finalized, "cube").ok());
        EXPECT_EQ(finalized.lineCount(), 18u);
    }
}

// Triangle order, edges (i0 i1) (i1 i2) (i2 i0), the first occurrence kept with its triangle's indices,
// orientation and material: the shared diagonal is (2 0) from triangle 0, not (0 2) from triangle 1.
// The scene's own segments follow, its points are kept.
TEST(PrimitiveMode, MeshAsLinesKeepsTheFirstOccurrenceAndTheSceneLinesAndPoints)
{
    Scene quad = openQuad();
    Scene plain = meshAsLines(quad);
    EXPECT_EQ(plain.lines, (std::vector<uint32_t>{0, 1, 1, 2, 2, 0, 2, 3, 3, 0}));
    EXPECT_TRUE(plain.lineMaterials.empty());

    quad.materials.resize(3);
    quad.materials[1].baseColorFactor = glm::vec4(1, 0, 0, 1);
    quad.materials[2].baseColorFactor = glm::vec4(0, 1, 0, 1);
    quad.triMaterials = {1, 2};
    quad.lines = {1, 3};
    quad.lineMaterials = {0};
    quad.points = {2};
    quad.pointMaterials = {1};
    Scene lines = meshAsLines(quad);
    EXPECT_EQ(lines.lines, (std::vector<uint32_t>{0, 1, 1, 2, 2, 0, 2, 3, 3, 0, 1, 3}));
    EXPECT_EQ(lines.lineMaterials, (std::vector<uint32_t>{1, 1, 1, 2, 2, 0}));
    EXPECT_EQ(lines.points, quad.points);
    EXPECT_EQ(lines.pointMaterials, quad.pointMaterials);
    EXPECT_EQ(lines.materials.size(), 3u);
    EXPECT_TRUE(lines.indices.empty());
    EXPECT_TRUE(lines.triFlags.empty());
    EXPECT_TRUE(lines.triMaterials.empty());
    EXPECT_TRUE(finalizeScene(lines, "quad").ok());
    EXPECT_EQ(lines.lineCount(), 6u);
}

// Positions are compared as floats: -0 and +0 are one point, so the two copies of the edge from
// (0, 0, 0) to (1, 0, 0) are one segment.
TEST(PrimitiveMode, MeshAsLinesTreatsSignedZerosAsEqual)
{
    Scene scene;
    for (glm::vec3 p : {glm::vec3(0, 0, 0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(-0.0f, 0, 0),
                        glm::vec3(0, -1, 0), glm::vec3(1, -0.0f, 0)})
        addVertex(scene, p);
    scene.indices = {0, 1, 2, 3, 4, 5};
    Scene lines = meshAsLines(scene);
    EXPECT_EQ(lines.lines, (std::vector<uint32_t>{0, 1, 1, 2, 2, 0, 3, 4, 4, 5}));
}

// Triangles kept; the edges appended after the scene's own segments with an added black material; a
// scene without materials first gets a white opaque material 0 for every primitive.
TEST(PrimitiveMode, WithWireframeAppendsBlackEdgesAfterTheSceneLines)
{
    Scene quad = openQuad();
    quad.lines = {1, 3};
    quad.points = {2};
    Scene wire = withWireframe(quad);
    EXPECT_EQ(wire.indices, quad.indices);
    EXPECT_EQ(wire.triFlags, quad.triFlags);
    EXPECT_EQ(wire.points, quad.points);
    EXPECT_EQ(wire.lines, (std::vector<uint32_t>{1, 3, 0, 1, 1, 2, 2, 0, 2, 3, 3, 0}));
    ASSERT_EQ(wire.materials.size(), 2u);
    EXPECT_EQ(wire.materials[0].baseColorFactor, glm::vec4(1.0f));
    EXPECT_EQ(wire.materials[0].baseColorTexture, -1);
    EXPECT_EQ(wire.materials[0].alphaMode, uint32_t(ALPHA_OPAQUE));
    EXPECT_EQ(wire.materials[1].name, "wireframe");
    EXPECT_EQ(wire.materials[1].baseColorFactor, glm::vec4(0, 0, 0, 1));
    EXPECT_EQ(wire.materials[1].baseColorTexture, -1);
    EXPECT_EQ(wire.triMaterials, (std::vector<uint32_t>{0, 0}));
    EXPECT_EQ(wire.lineMaterials, (std::vector<uint32_t>{0, 1, 1, 1, 1, 1}));
    EXPECT_EQ(wire.pointMaterials, (std::vector<uint32_t>{0}));
    // The black material changes something, so finalizeScene keeps every list.
    Scene finalized = wire;
    ASSERT_TRUE(finalizeScene(finalized, "wire").ok());
    EXPECT_EQ(finalized.materials.size(), 2u);
    EXPECT_EQ(finalized.lineMaterials, wire.lineMaterials);
    EXPECT_EQ(finalized.triMaterials, wire.triMaterials);
    EXPECT_EQ(finalized.pointMaterials, wire.pointMaterials);

    // With materials: "wireframe" is added last and the existing indices are kept.
    Scene coloured = quad;
    coloured.materials.resize(2);
    coloured.materials[1].baseColorFactor = glm::vec4(1, 0, 0, 1);
    coloured.triMaterials = {1, 0};
    coloured.lineMaterials = {1};
    coloured.pointMaterials = {0};
    Scene colouredWire = withWireframe(coloured);
    ASSERT_EQ(colouredWire.materials.size(), 3u);
    EXPECT_EQ(colouredWire.materials[2].name, "wireframe");
    EXPECT_EQ(colouredWire.materials[2].baseColorFactor, glm::vec4(0, 0, 0, 1));
    EXPECT_EQ(colouredWire.triMaterials, coloured.triMaterials);
    EXPECT_EQ(colouredWire.lineMaterials, (std::vector<uint32_t>{1, 2, 2, 2, 2, 2}));
    EXPECT_EQ(colouredWire.pointMaterials, coloured.pointMaterials);
    EXPECT_TRUE(finalizeScene(colouredWire, "coloured").ok());
}

TEST(PrimitiveMode, WithWireframeOnASplitCube)
{
    Scene cube = splitCube();
    Scene wire = withWireframe(cube);
    EXPECT_EQ(wire.indices, cube.indices);
    EXPECT_EQ(wire.lineCount(), 18u);
    expectCubeEdgesOnce(wire);
    ASSERT_EQ(wire.materials.size(), 2u);
    EXPECT_EQ(wire.triMaterials, std::vector<uint32_t>(12, 0u));
    EXPECT_EQ(wire.lineMaterials, std::vector<uint32_t>(18, 1u));
    EXPECT_TRUE(wire.pointMaterials.empty());
    EXPECT_TRUE(finalizeScene(wire, "cube").ok());
}

}  // namespace
}  // namespace sr
