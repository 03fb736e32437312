// stress.h - the stability half of `raster study`: scenes placed exactly where rasterizers fail, each with
// what a correct rasterizer must produce, so that failures can be counted rather than eyeballed.
//
// Four stress axes (issue 12): coordinate magnitude (the same closed mesh with its vertices 2^k px from
// the origin, k = 0..14), sliver aspect ratio (a closed fan of n slivers, n = 10..10^5), near-plane
// proximity (a closed mesh whose vertices' w approaches 0+), and the depth separation of two nearly
// coplanar surfaces (z-fighting). Every case is drawn with identityCamera-style clip coordinates or its
// own camera, at a small size (lavapipe runs the study in CI).
#ifndef RASTER_STUDY_STRESS_H
#define RASTER_STUDY_STRESS_H

#include <cstdint>
#include <string>
#include <vector>

#include "render/renderer.h"
#include "camera/camera.h"
#include "scene/scene.h"

namespace sr {

// What a pixel of a stress case must show. kCoverOnce: inside a closed surface (away from its
// silhouette), the pixel centre lies in exactly one of its triangles, so its hit count must be 1 (0 is a
// crack, 2 or more a double hit). kEmpty: outside, 0 hits. kFree: within a pixel of the silhouette or
// otherwise left to the rule's ties; not counted. kNearId: (coplanar axis) the pixel must show the
// nearer surface's triangles (ids in [StressCase::nearIdBegin, nearIdEnd)).
enum class PixelDemand : uint8_t { kFree = 0, kCoverOnce = 1, kEmpty = 2, kNearId = 3 };

struct StressCase {
    std::string axis;  // "magnitude", "slivers", "near" or "coplanar"
    double x = 0.0;    // the stress parameter: 2^k px, sliver count, min w, separation in depth units
    Scene scene;
    CameraMatrices camera;
    RenderSettings settings;          // width x height, countHits on, unlit
    std::vector<PixelDemand> demand;  // width * height, row-major from the top row
    // Coplanar axis: ids in [nearIdBegin, nearIdEnd) belong to the nearer surface. It is drawn second
    // (after the farther one), so a depth tie resolves to the farther surface's lower ids and shows.
    uint32_t nearIdBegin = 0;
    uint32_t nearIdEnd = 0;
};

// The cases of one axis, in increasing stress, at `size` x `size` pixels.
std::vector<StressCase> stressCases(const std::string& axis, uint32_t size);

// Failures of one render of a case: cracks (kCoverOnce pixels hit 0 times), double hits (kCoverOnce
// pixels hit 2+ times, or kEmpty pixels hit at all), wrong depth order (kNearId pixels showing another
// id). Needs RenderOutput::hitCount (countHits) except for the coplanar axis, which reads the ids; a
// kNearId pixel left empty counts as a crack. Without hitCount, coverage is read from the ids (double
// hits inside then go unseen). Pixels the output lacks (a failed render) read as empty.
struct StressFailures {
    uint64_t cracks = 0;
    uint64_t doubleHits = 0;
    uint64_t wrongDepthOrder = 0;
    uint64_t total() const { return cracks + doubleHits + wrongDepthOrder; }
};
StressFailures countFailures(const StressCase& c, const RenderOutput& out);

// Pixels whose visible primitive id (RenderOutput::aov.id) differs between a render and the conformant
// oracle's render of the same case (vulkan-graphics); pixels both leave empty agree. A pixel one output
// lacks (a failed render) reads as empty.
uint64_t oracleMismatches(const RenderOutput& out, const RenderOutput& oracle);

}  // namespace sr

#endif  // RASTER_STUDY_STRESS_H
