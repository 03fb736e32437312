// scene.h - the flattened scene every backend draws.
//
// Loaders (glTF, OBJ, the built-in procedural scene) produce one flat triangle list in world space:
// node transforms are already applied, normals are always present (flat normals computed where the
// file has none), and the triangle order defines the triangle ids written to the `id` AOV
// (OBJ faces in file order; glTF nodes depth-first in document order, primitives in order, triangles
// in index order).
#ifndef RASTER_SCENE_H
#define RASTER_SCENE_H

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "base/result.h"

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

struct Scene {
    std::vector<glm::vec4> positions;  // world space, w = 1
    std::vector<glm::vec4> normals;    // world space, unit length, w = 0; same count as positions
    std::vector<glm::vec4> colors;     // linear RGBA per vertex; empty when every colour is white
    std::vector<uint32_t> indices;     // 3 per triangle, each < positions.size()
    std::vector<uint32_t> triFlags;    // one per triangle: TRI_FLAG_* from raster_shared.h
    std::vector<SceneCamera> cameras;
    glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};  // of all referenced vertices
    uint64_t droppedTriangles = 0;               // triangles dropped by the loader (warned about once)

    size_t vertexCount() const { return positions.size(); }
    size_t triangleCount() const { return indices.size() / 3; }
};

// Loads a .gltf, .glb or .obj file, chosen by extension, or a procedural scene named "builtin...".
// Errors are one-line messages naming the file.
Result<Scene> loadScene(const std::string& path);
Result<Scene> loadGltf(const std::string& path);
Result<Scene> loadObj(const std::string& path);

// The built-in procedural scene used when no file is given: a few shaded solids on a ground plane,
// with vertex colours, sized to a few thousand triangles.
Scene builtinScene();
// A unit sphere of rings x 2 rings quads (about 4 rings^2 triangles, indexed, smooth normals).
Scene tessellatedSphere(int rings);
// Procedural scenes by name: "builtin" (the scene above), "builtin:dense" (a sphere of ~65k triangles,
// sub-pixel at small resolutions) and "builtin:huge" (the built-in objects on a 200,000-unit ground plane).
Result<Scene> builtinSceneNamed(const std::string& name);

// Drops triangles with out-of-range indices or non-finite positions (counting them in
// droppedTriangles), fills missing flags, recomputes bounds. Fails when nothing drawable is left.
Status finalizeScene(Scene& scene, const std::string& what);

// finalizeScene for a scene read from `path`: warnings name the file and a failure reads
// "cannot load '<path>': <reason>", like every other loader error.
Status finalizeLoadedScene(Scene& scene, const std::string& path);

// Joins a multi-line library message (tinygltf, tinyobjloader) into one line.
std::string flattenMessage(const std::string& text);

}  // namespace sr

#endif  // RASTER_SCENE_H
