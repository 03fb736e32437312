// scene.h - the flattened scene every backend draws.
//
// Loaders (glTF, OBJ, the built-in procedural scene) produce one flat triangle list in world space:
// node transforms are already applied, normals are always present (flat normals computed where the
// file has none), and the triangle order defines the triangle ids written to the `id` AOV
// (OBJ, PLY and STL faces in file order; glTF nodes depth-first in document order, primitives in
// order, triangles in index order).
#ifndef RASTER_SCENE_H
#define RASTER_SCENE_H

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "base/result.h"
#include "raster_shared.h"

namespace sr {

// A camera found in the scene file (glTF cameras), already placed by its node's world transform.
struct SceneCamera {
    std::string name;
    glm::mat4 worldFromView{1.0f};  // camera-to-world transform (view looks down -z, +y up)
    bool perspective = true;
    float yfov = 0.8f;         // radians, perspective only
    float aspectRatio = 0.0f;  // 0: use the framebuffer aspect
    float znear = 0.01f;
    float zfar = 0.0f;               // 0: infinite far plane (glTF), resolved from scene bounds
    float xmag = 1.0f, ymag = 1.0f;  // orthographic half extents
};

// How a texture is sampled: glTF sampler values mapped to raster_shared.h's WRAP_*, FILTER_*, MIPMAP_*.
// The defaults are glTF's for a texture without a sampler (repeat, trilinear).
struct TextureSampler {
    uint32_t wrapS = WRAP_REPEAT;
    uint32_t wrapT = WRAP_REPEAT;
    uint32_t magFilter = FILTER_LINEAR;
    uint32_t minFilter = FILTER_LINEAR;
    uint32_t mipmapMode = MIPMAP_LINEAR;
};

// A decoded image with its full mip chain, as GpuTexture describes it: level k is max(1, width >> k) x
// max(1, height >> k) RGBA8 texels (R in the low byte), row-major from the top row, levels concatenated.
// sRGB images keep their bytes at level 0; each further level is the 2x2 box average of the one above
// computed in linear space and encoded back (odd sizes: the last row/column averages with itself).
struct SceneTexture {
    std::string name;  // image URI or name, for messages
    uint32_t width = 0, height = 0, levels = 0;
    bool srgb = true;  // glTF base colour textures are sRGB
    std::vector<uint32_t> texels;
    TextureSampler sampler;
};

// A material as the pipeline uses it (glTF metallic-roughness base colour, alpha mode and emission;
// OBJ Kd/map_Kd and Ke/map_Ke).
struct SceneMaterial {
    std::string name;
    glm::vec4 baseColorFactor{1.0f};  // linear RGBA
    int32_t baseColorTexture = -1;    // index into Scene::textures, -1: none
    uint32_t texCoord = 0;            // 0 or 1: which of Scene::texcoords' two sets
    glm::mat3 uvTransform{1.0f};      // KHR_texture_transform T * R * S (column-major, last row 0 0 1)
    uint32_t alphaMode = ALPHA_OPAQUE;
    float alphaCutoff = 0.5f;
    glm::vec3 emissive{0.0f};       // linear emitted colour (glTF emissiveFactor x emissive strength, OBJ Ke)
    int32_t emissiveTexture = -1;   // index into Scene::textures (multiplies `emissive`), -1: none
    uint32_t emissiveTexCoord = 0;  // 0 or 1, as texCoord; the emissive texture has no transform
};

// The albedo of a surface whose file gives it no material (OBJ faces without `usemtl` or .mtl, PLY and
// STL meshes; glTF defines its own default material, base colour 1): a neutral grey of 0.8, the reflectance
// of matte white paint or plaster rather than an ideal reflector of 1. Under the default light
// (render_settings.h) it leaves a lit surface's brightest point at 83% of the display's white, so the
// shape reads from its shading instead of clipping to a flat white silhouette.
constexpr float kDefaultAlbedo = 0.8f;

// The material of those surfaces: named "default", base colour kDefaultAlbedo, opaque, no emission.
// Vertex colours multiply it, as they multiply any base colour factor.
SceneMaterial defaultMaterial();

struct DisplayForm;  // scene/primitive_mode.h

struct Scene {
    std::vector<glm::vec4> positions;  // world space, w = 1
    std::vector<glm::vec4> normals;    // world space, unit length, w = 0; same count as positions
    std::vector<glm::vec4> colors;     // linear RGBA per vertex; empty when every colour is white
    std::vector<uint32_t> indices;     // 3 per triangle, each < positions.size()
    std::vector<uint32_t> triFlags;    // one per triangle: TRI_FLAG_* from raster_shared.h
    // Materials: empty when the file has none that changes anything (every triangle white, opaque,
    // untextured); otherwise triMaterials has one index per triangle. texcoords is empty unless some
    // material has a texture; then it has one (u0, v0, u1, v1) per vertex (zeros for a missing set).
    std::vector<SceneMaterial> materials;
    std::vector<uint32_t> triMaterials;
    std::vector<glm::vec4> texcoords;
    std::vector<SceneTexture> textures;
    // Line segments (glTF LINES, LINE_STRIP, LINE_LOOP; OBJ `l` polylines): two vertex indices per
    // segment; a strip or loop is stored as its segments (a loop's closing segment last). Points (glTF
    // POINTS, OBJ `p`): one vertex index per point. Primitive ids are one space: triangles first
    // (0 .. triangleCount() - 1), then segments (segment k has id triangleCount() + k), then points
    // (point k has id triangleCount() + lineCount() + k), each in file order. lineMaterials and
    // pointMaterials hold one material index per segment / point when materials is not empty (else
    // they are empty too). A vertex used only by lines or points has a zero normal where the file gives
    // it none (lines and points are shaded unlit), the one exception to unit-length normals.
    std::vector<uint32_t> lines;
    std::vector<uint32_t> lineMaterials;
    std::vector<uint32_t> points;
    std::vector<uint32_t> pointMaterials;
    std::vector<SceneCamera> cameras;
    glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};  // of all referenced vertices
    // Primitives finalizeScene found broken (warned about once): kept in their places, drawn by nothing.
    uint64_t droppedTriangles = 0;
    uint64_t droppedLines = 0;
    uint64_t droppedPoints = 0;
    // Set on a scene displayScene derived (lines or points mode, the wireframe overlay): the scene it
    // came from and how, so that a tessellated frame draws the display form of the tessellated mesh
    // (tessellatedDisplay, render/renderer.h) rather than that of the scene's own triangles.
    std::shared_ptr<const DisplayForm> display;

    size_t vertexCount() const { return positions.size(); }
    size_t triangleCount() const { return indices.size() / 3; }
    size_t lineCount() const { return lines.size() / 2; }
    size_t pointCount() const { return points.size(); }
    size_t primitiveCount() const { return triangleCount() + lineCount() + pointCount(); }
};

// Loads a .gltf, .glb, .obj, .ply or .stl file, chosen by extension, or a procedural scene named
// "builtin...". Errors are one-line messages naming the file.
Result<Scene> loadScene(const std::string& path);
Result<Scene> loadGltf(const std::string& path);
Result<Scene> loadObj(const std::string& path);
Result<Scene> loadPly(const std::string& path);  // loaders/ply_stl.cpp, through assimp
Result<Scene> loadStl(const std::string& path);  // loaders/ply_stl.cpp, through assimp

// The built-in procedural scene used when no file is given: a few shaded solids on a ground plane,
// with vertex colours, sized to a few thousand triangles.
Scene builtinScene();
// A unit sphere of rings x 2 rings quads (about 4 rings^2 triangles, indexed, smooth normals).
Scene tessellatedSphere(int rings);
// The most rings tessellatedSphere takes: its 4 N^2 - 4 N triangles stay within the loaders' limit of
// 2^31 / 3 indices (every index, id and offset of the backends inside 31 bits): 238.6M triangles.
constexpr int kMaxSphereRings = 7723;
// Procedural scenes by name: "builtin" (the scene above), "builtin:dense" (a sphere of ~65k triangles,
// sub-pixel at small resolutions), "builtin:huge" (the built-in objects on a 200,000-unit ground plane),
// "builtin:checker", "builtin:cutout" (textures), "builtin:lowpoly" (the built-in objects with a 4-ring
// sphere and a 12 x 6 torus: what --tessellate pn smooths) and "builtin:ao" (ambient occlusion's stress
// scene: a thin plate and a thin post standing on a floor, a box floating above it, a low step).
Result<Scene> builtinSceneNamed(const std::string& name);

// The vertex index of a dropped segment's ends and of a dropped point: past every vertex, so that the
// devices count the primitive invalid (and the graphics reference draws it outside the view).
constexpr uint32_t kDroppedVertex = 0xffffffffu;

// Drops triangles, segments and points with out-of-range indices or non-finite positions, in place: each
// keeps its id and is drawn by nothing (a triangle's corners all become one vertex of a kept primitive, a
// segment's and a point's vertices kDroppedVertex), counted in droppedTriangles, droppedLines and
// droppedPoints with one warning of each kind. Drops materials, texture coordinates and textures that
// change nothing (the emptiness rules above), fills missing flags, recomputes bounds. Fails when nothing
// drawable is left.
Status finalizeScene(Scene& scene, const std::string& what);

// The bounds of every drawn primitive's vertices (Scene::boundsMin, boundsMax), as finalizeScene leaves
// them; for a scene whose positions changed in place.
void updateBounds(Scene& scene);

// finalizeScene for a scene read from `path`: warnings name the file and a failure reads
// "cannot load '<path>': <reason>", like every other loader error.
Status finalizeLoadedScene(Scene& scene, const std::string& path);

// Joins a multi-line library message (tinygltf, tinyobjloader) into one line.
std::string flattenMessage(const std::string& text);

}  // namespace sr

#endif  // RASTER_SCENE_H
