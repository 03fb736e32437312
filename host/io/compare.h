// compare.h - `raster compare`: image and AOV differences with an idiff-style report.
#ifndef RASTER_COMPARE_H
#define RASTER_COMPARE_H

#include <cstdint>
#include <string>

#include "io/image_io.h"
#include "base/result.h"

namespace sr {

struct CompareTolerance {
    int colorLsb = 0;              // largest allowed per-channel difference of 8-bit colour
    uint64_t maxIdMismatches = 0;  // AOVs: pixels whose triangle id may differ
    float depthTolerance = 0.0f;   // AOVs: largest allowed |Z_a - Z_b| where both are covered
    // AOVs: largest allowed difference of any surface channel (bary, uv, N) where both files have its
    // group and the pixel shows the same triangle in both; negative: reported, never failed on.
    double surfaceTolerance = -1.0;
    // Fraction of the pixels (of the samples, for the sample channels) that may exceed the colour, depth
    // and surface tolerances; the id and coverage mismatches have their own count.
    double maxFraction = 0.0;
};

// The tolerance the project documents for two outputs of the named backends (docs/building-and-testing.md
// "Goldens", docs/validation.md "What raster compare applies"), which `raster compare` applies when no flag
// sets one:
//   - cuda and vulkan (any devices, and the goldens, which are CUDA's): ids, coverage and depth exact,
//     colour within 1/255, the goldens' criterion;
//   - one backend on one device (both origins name the same device): exact, as the determinism tests
//     require;
//   - cuda or vulkan against vulkan-graphics: at most kGraphicsIdMismatches pixels (and samples) whose id
//     or coverage differs, depth within kGraphicsDepthTolerance and colour within kGraphicsColorLsb on
//     all but kGraphicsDepthFraction / kGraphicsColorFraction of the pixels (the oracle tests' bounds and
//     the measured share of textured pixels whose mip level the graphics pipeline's quad derivatives
//     choose otherwise);
//   - anything else (no origin, an unknown backend, two graphics pipelines on different devices):
//     exact, the behaviour before outputs named their backend.
constexpr uint64_t kGraphicsIdMismatches = 64;
constexpr float kGraphicsDepthTolerance = 1e-3f;
constexpr double kGraphicsDepthFraction = 0.001;
constexpr int kGraphicsColorLsb = 2;
constexpr double kGraphicsColorFraction = 0.10;

struct PairTolerance {
    CompareTolerance tolerance;
    std::string rule;  // one line: the rule applied and where it is documented, or why none was
};
PairTolerance documentedTolerance(const ImageOrigin& a, const ImageOrigin& b, bool aov);

// Who made a file: its own metadata (ImageOrigin), else the "backend" and "device" of a JSON file with
// the same stem beside it (the goldens' provenance, `raster render --stats` and a viewer save's JSON
// under the image's name), else nothing. `source` says which, for the report ("" when none).
struct FileOrigin {
    ImageOrigin origin;
    std::string source;
};
Result<FileOrigin> fileOrigin(const std::string& path);

struct CompareReport {
    uint32_t width = 0, height = 0;
    // Colour (PNG): per-channel differences in 8-bit units over R, G, B.
    double meanError = 0.0, rmsError = 0.0, psnr = 0.0;
    int maxError = 0;
    uint32_t maxX = 0, maxY = 0;
    uint64_t pixelsOverTolerance = 0;
    // AOV (EXR).
    uint64_t idMismatches = 0;        // both covered, different triangle
    uint64_t coverageMismatches = 0;  // covered in one, background in the other
    double maxDepthDiff = 0.0, meanDepthDiff = 0.0;
    // Surface channel groups, compared only where both files have the group: the largest |a - b| over
    // the group's channels and the pixels covered by the same triangle in both; -1: not compared.
    double maxBaryDiff = -1.0, maxUvDiff = -1.0, maxNormalDiff = -1.0;
    uint64_t surfaceOverTolerance = 0;  // such pixels over surfaceTolerance (when it is set)
    // The ambient occlusion channel (AovImage::ao), where both files have it: the largest |a - b| over
    // the pixels covered by the same triangle in both (the device's own output, unlike the groups above,
    // so a cross-backend comparison of it means something); -1: not compared.
    double maxAoDiff = -1.0;
    // Sample channels (AovImage::sampleId, both files must have the same number): samples whose id or
    // coverage differs (allowed: maxIdMismatches), and samples of the same triangle whose depth differs by
    // more than depthTolerance.
    uint32_t samplesPerPixel = 0;
    uint64_t sampleIdMismatches = 0;
    uint64_t sampleDepthOverTolerance = 0;
    bool isAov = false;
    bool pass = false;
    RgbaImage heatmap;  // per-pixel difference, black (none) through red and yellow to white
};

Result<CompareReport> compareColor(const RgbaImage& a, const RgbaImage& b, const CompareTolerance& tol);
Result<CompareReport> compareAov(const AovImage& a, const AovImage& b, const CompareTolerance& tol);
// Whether `path` names an EXR (AOV) file rather than a PNG, by its extension.
bool isExrPath(const std::string& path);
// Reads both files (.png colour or .exr AOV, by extension) and compares them.
Result<CompareReport> compareFiles(const std::string& a, const std::string& b, const CompareTolerance& tol);
// The report as printed by `raster compare`, ending in PASS or FAILURE. An AOV report with surface
// channels says that they are derived from the ids on the host (render/aov.h), the same code for every
// backend, so that where the ids match they match by construction and prove nothing more.
std::string formatReport(const CompareReport& report, const CompareTolerance& tol);

}  // namespace sr

#endif  // RASTER_COMPARE_H
