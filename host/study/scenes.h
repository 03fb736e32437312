// scenes.h - the scene set of the accuracy half of `raster study` (issue 12: the built-in scene, the
// bunny, a textured grazing plane, a sliver fan, a jittered grid, a dense mesh), each with its camera.
//
// Two of them are built here rather than loaded, from the stress cases' builders (study/geometry.h):
// clip-space meshes for the identity camera, laid out in a nominal 256 x 256 window and stretched over
// whatever size the study renders at. Every triangle has a flat colour from a small palette, chosen to
// differ from its predecessor's, so that most shared edges are colour edges coverage has to get right.
//
//   sliver-fan     a closed fan of kSliverFanTriangles slivers around the image centre (the slivers
//                  stress axis at its 10^3 case), which converge to sub-pixel width at the hub.
//   jittered-grid  a grid of kJitterCells x kJitterCells cells whose interior vertices moved by up to
//                  0.15 cells (fixed seed), each cell split along alternating diagonals: edges of many
//                  slopes, each interior one shared by two triangles.
#ifndef RASTER_STUDY_SCENES_H
#define RASTER_STUDY_SCENES_H

#include <optional>
#include <string>
#include <vector>

#include "base/result.h"
#include "camera/camera.h"
#include "scene/scene.h"

namespace sr {

constexpr int kSliverFanTriangles = 1000;
constexpr int kJitterCells = 24;  // 2 x 24^2 = 1,152 triangles

struct StudyScene {
    std::string name;
    Scene scene;
    CameraMatrices camera;
    bool textured = false;  // the texture and UV groups apply
    // The tessellation group applies, and the reference is this smooth surface instead of the scene
    // itself (lowpoly-sphere: pn's silhouette and shading against the sphere it approximates).
    bool tessellation = false;
    std::optional<Scene> referenceScene;
};

// The scene names in the study's order: builtin, checker-grazing, dense, bunny, sliver-fan,
// jittered-grid, lowpoly-sphere.
const std::vector<std::string>& studySceneNames();

// The study scene `name` framed for width x height: builtin and dense under the auto camera, the
// checkerboard plane (builtin:checker) from orbit:0,6,12, the bunny from `bunnyPath` under the auto
// camera, the synthetic ones under the identity camera. An unknown name or a missing bunny file is a
// one-line Usage error.
Result<StudyScene> makeStudyScene(const std::string& name, unsigned width, unsigned height,
                                  const std::string& bunnyPath);

Result<Scene> sliverFanScene();
Result<Scene> jitteredGridScene();

// The prefix that names a study scene as `raster render`'s SCENE: "study:sliver-fan".
constexpr const char* kStudyScenePrefix = "study:";

// The study scene name a `raster render` SCENE argument stands for, to look its rows up in a study's
// JSON: "" and "builtin" -> builtin, "builtin:dense" -> dense, "study:NAME" -> NAME, and a file by its
// stem (glmark2's bunny.obj -> bunny).
std::string studySceneNameFor(const std::string& scenePath);

}  // namespace sr

#endif  // RASTER_STUDY_SCENES_H
