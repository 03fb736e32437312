// lod_study.h - the level-of-detail group of `raster study` (issue 29, item 5): its scenes, its two cameras,
// and what a frame drawn with --lod on is compared with --lod off by.
//
// Scenes: "sphere", the built-in sphere builtin:dense:N (about 4 N^2 triangles: N = 5000 is the 100M
// sphere of the issue, a few hundred suit lavapipe); "bunny", the Stanford bunny OBJ (69,666
// triangles); "bunny-fine", the bunny with every triangle split into 4 by its edge midpoints twice
// (1.1M triangles). bunny-fine is the "large real mesh": Debian ships no real mesh larger than
// the bunny (glmark2-data's other models and assimp-testmodels' are smaller; the largest file of the
// latter, PLY/pond.0.ply, is 70k points without faces), so the larger one is made from it by subdivision.
// Splitting at midpoints leaves the surface where it is, so every level of its hierarchy has the bunny's
// shape to simplify towards, with 16 times the triangles to drop.
//
// Cameras: "near", the orbit camera the study's other scenes use (the auto camera: the bounding sphere
// touching the narrower half-angle of the frustum), and "far", the same direction at kLodFarFactor
// times the distance, where the hierarchy's coarse levels take over.
#ifndef RASTER_STUDY_LOD_H
#define RASTER_STUDY_LOD_H

#include <cstdint>
#include <string>
#include <vector>

#include "base/result.h"
#include "io/image_io.h"
#include "camera/camera.h"
#include "scene/scene.h"

namespace sr {

constexpr float kLodFarFactor = 8.0f;    // the far camera's distance over the near one's
constexpr int kLodFineSubdivisions = 2;  // bunny-fine: 4^2 = 16 triangles per bunny triangle

// The LOD group's scene names in the study's order: sphere, bunny, bunny-fine.
const std::vector<std::string>& lodSceneNames();

// The LOD scene `name`: the sphere of `rings` rings, or the bunny read from `bunnyPath`, as it is or
// subdivided (bunny-fine). An unknown name, a ring count builtinSceneNamed refuses or a bunny that does
// not load is a one-line Usage error.
Result<Scene> makeLodScene(const std::string& name, int rings, const std::string& bunnyPath);

// `scene` with every triangle split into four by its edge midpoints, `times` times over: triangle
// (a, b, c) becomes (a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca), in that order, each with its
// parent's flags and material, so the winding (culling) and the materials stay. A midpoint is one vertex
// per edge of the index graph, shared by both triangles of the edge, with the mean of its ends' colours
// and texture coordinates and their normals' normalised sum (the first end's normal where that sum is
// zero). Where the scene gives each corner a vertex of its own (an OBJ without normals, such as the
// bunny: flat normals, one vertex per corner), the two sides' midpoints are two vertices at the same
// position bit for bit (the mean of the same two floats), with each side's normal: the mesh stays
// connected by position, which is what the rasterizer's snapping and the hierarchy's weld join on, and
// a flat face stays flat. Lines and points keep their vertices (the new vertices come after the old).
// More triangles than the loaders allow is a one-line Usage error.
Result<Scene> subdivideMidpoints(const Scene& scene, int times);

// The near and far cameras of a scene for a width x height frame, in that order.
struct LodCamera {
    std::string name;  // "near" or "far"
    OrbitPose pose;    // its orbit pose: orbitSpecString gives the --camera that draws the same frame
    CameraMatrices camera;
};
std::vector<LodCamera> lodCameras(const Scene& scene, unsigned width, unsigned height);

// A frame's AOVs against the --lod off frame's, output pixel by output pixel (AovImage::id and depth,
// sample 0 of each pixel).
//
// Coverage: pixels covered (id not EMPTY_ID) in one frame only. A silhouette pixel of the baseline is a
// covered pixel with an uncovered 4-neighbour, or an uncovered one with a covered 4-neighbour (the
// image's border is no neighbour: the frame ends there); a differing pixel within 1 pixel of the
// silhouette has one at Chebyshev distance at most 1. A simplified surface may move its outline by up
// to the error asked for; a differing pixel beyond that 1-pixel band is a hole or a flap inside the
// outline, which a watertight cut never leaves at the errors the study asks for.
//
// Depth: over the pixels both frames cover, the largest and the mean |depth - baseline depth| of the
// depth AOV, which holds window depth z / w: 0 at the camera's near plane, 1 at its far plane, the
// planes enclosing the scene's bounding sphere (orbitCameraMatrices), so a difference is a fraction of
// that range, non-linear in distance (perspective).
struct LodImageDiff {
    uint64_t coveragePx = 0;          // covered in one frame only
    uint64_t beyondSilhouettePx = 0;  // of which farther than 1 pixel from the baseline's silhouette
    uint64_t silhouettePx = 0;        // the baseline's silhouette pixels
    uint64_t bothCoveredPx = 0;       // covered in both: the depth error's pixels
    double depthMaxError = 0.0;
    double depthMeanError = 0.0;  // 0 when no pixel is covered in both
};
// The AOVs must have the same size; pixels one of them lacks read as uncovered.
LodImageDiff lodImageDiff(const AovImage& image, const AovImage& baseline);

// The --lod-errors list: comma-separated --lod-error-px values (each checked as the setting is), empty
// entries skipped; a bad entry is a one-line Usage error naming it.
Result<std::vector<float>> parseLodErrors(const std::string& text);

}  // namespace sr

#endif  // RASTER_STUDY_LOD_H
