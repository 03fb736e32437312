// test_util.h - helpers shared by the test files: backend selection with the explicit
// missing-backend switch, scenes built straight from clip-space triangles, and small image queries.
#ifndef RASTER_TEST_UTIL_H
#define RASTER_TEST_UTIL_H

#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "render/compute_device.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace sr::test {

// The backend named `backend` ("vulkan" or "cuda"). When it cannot be created the test FAILS, unless
// the environment variable SR_ALLOW_MISSING_BACKENDS lists it (comma-separated, e.g. "cuda"); then
// `skip` is set and the caller must GTEST_SKIP(). Vulkan runs with validation (errors fail the call).
std::unique_ptr<ComputeDevice> openBackend(const std::string& backend, bool& skip);

CameraMatrices identityCamera();  // clip space is world space (below)

// A test run once per backend (the parameter names it): device_ is open, or the test was skipped under
// SR_ALLOW_MISSING_BACKENDS, or it failed.
class BackendTest : public ::testing::TestWithParam<std::string> {
protected:
    void SetUp() override
    {
        bool skip = false;
        device_ = openBackend(GetParam(), skip);
        if (skip) GTEST_SKIP() << GetParam() << " absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
        ASSERT_TRUE(device_);
    }

    // The scene rendered on device_, or an empty output after a failure that the test reports.
    RenderOutput render(const Scene& scene, const RenderSettings& settings,
                        const CameraMatrices& camera = identityCamera())
    {
        auto out = renderScene(*device_, scene, camera, settings);
        EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
        return out.ok() ? std::move(*out) : RenderOutput{};
    }

    std::unique_ptr<ComputeDevice> device_;
};

// A scene whose vertex positions are clip coordinates: render it with identityCamera().
// Each triangle is given as 3 clip-space vec4s; normals face +z, no colours.
Scene clipSpaceScene(const std::vector<glm::vec4>& corners, const std::vector<uint32_t>& flags = {});
CameraMatrices identityCamera();

RenderSettings testSettings(uint32_t width, uint32_t height);
// testSettings with Lambert shading, ambient 1 and no directional light: a covered pixel's colour is its
// base colour itself (white without vertex colours or materials).
RenderSettings unlitSettings(uint32_t width, uint32_t height);

// The built-in scene under the auto camera at width x height, with back-face culling.
struct FramedScene {
    Scene scene;
    CameraMatrices camera;
    RenderSettings settings;
};
FramedScene framedBuiltin(uint32_t width, uint32_t height);

// Two triangles forming an axis-aligned rectangle in NDC at depth z.
std::vector<glm::vec4> clipQuad(float x0, float y0, float x1, float y1, float z);

// Window position (x, y) in pixels of a width x height viewport at depth z, as a clip-space vertex with
// w = 1 (exact for power-of-two sizes and positions on the 1/256 grid).
glm::vec4 windowVertex(double x, double y, uint32_t width, uint32_t height, float z);

// A grid of window positions (grid[j][i]) whose interior vertices move by `jitter` (a draw per
// coordinate, in pixels) and whose border stays on the regular grid origin + k * step.
template <typename Jitter>
std::vector<std::vector<glm::dvec2>> jitteredGrid(int cells, double origin, double step, Jitter jitter)
{
    std::vector<std::vector<glm::dvec2>> grid(cells + 1, std::vector<glm::dvec2>(cells + 1));
    for (int j = 0; j <= cells; ++j)
        for (int i = 0; i <= cells; ++i) {
            bool inner = i > 0 && i < cells && j > 0 && j < cells;
            double dx = inner ? jitter() : 0.0, dy = inner ? jitter() : 0.0;
            grid[j][i] = {origin + i * step + dx, origin + j * step + dy};
        }
    return grid;
}

// Two triangles per cell of a grid of window positions (grid[j][i]) of a width x height viewport, at
// depth z; with `alternate`, neighbouring cells split along opposite diagonals, so shared edges occur in
// both orientations.
std::vector<glm::vec4> windowQuadMesh(const std::vector<std::vector<glm::dvec2>>& grid, uint32_t width,
                                      uint32_t height, bool alternate, float z = 0.5f);

// Two triangles in clip space: the left one counter-clockwise on screen (front-facing), the right one
// clockwise, mirror images of each other. NDC y = -1 is the top row.
std::vector<glm::vec4> cullingTriangles();

// A fresh directory per test under the gtest temp dir, removed with everything in it at the end.
class ScratchDir {
public:
    explicit ScratchDir(const std::string& prefix = "sr");
    ~ScratchDir();
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;
    std::string file(const std::string& name) const { return path_ + "/" + name; }

private:
    std::string path_;
};

// A point at window position (x, y) in pixels, at window depth z.
struct WindowPoint {
    double x, y;
    float z;
};

// The triangles (clip space, as clipSpaceScene builds them) followed by one vertex (normal +z) and one
// point per entry of `points`, window positions of a width x height viewport: point k has id
// triangleCount + k.
Scene windowPointScene(const std::vector<WindowPoint>& points, uint32_t width, uint32_t height,
                       const std::vector<glm::vec4>& triangles = {});

// A line segment between window positions (x0, y0) and (x1, y1) in pixels, at window depths z0 and z1.
struct WindowLine {
    double x0, y0;
    float z0;
    double x1, y1;
    float z1;
};

// windowPointScene with line segments too: the triangles, then two vertices (normal +z) and one segment
// per entry of `lines` (segment k has id triangleCount + k), then the points (ids after the segments).
Scene windowLineScene(const std::vector<WindowLine>& lines, uint32_t width, uint32_t height,
                      const std::vector<glm::vec4>& triangles = {},
                      const std::vector<WindowPoint>& points = {});

// Whether sample position (sx, sy) (pixels) is inside the rectangle Vulkan's rectangular line rule draws
// for segment `l` of width `width`, computed exactly in double: 1 inside, 0 outside. Ties follow the
// top-left rule (a sample on an edge is inside when the edge's inward normal points right, or straight
// down): on every edge of an axis-aligned segment's rectangle, whose snapped corners are exact, and at
// the endpoints of any other. Otherwise -1 within `margin` pixels of a side or an end cap, where the
// rounding of the snapped rectangle decides, so a test must not insist.
int lineCoversSample(const WindowLine& l, double width, double sx, double sy, double margin = 1.0 / 128.0);

// Largest difference of the R, G, B and A bytes of two packed RGBA8 words.
int channelDifference(uint32_t a, uint32_t b);

bool isOneLine(const std::string& message);

// A test comparing the Vulkan compute backend (compute_) with the vulkan-graphics reference, skipped
// under SR_ALLOW_MISSING_BACKENDS=vulkan without a Vulkan device.
// How two renders of the same scene agree, sample by sample.
struct SampleAgreement {
    bool offered = false;          // the reference offers the sample count (else nothing was compared)
    long differingIds = 0;         // samples whose ids differ
    long differingCoverage = 0;    // samples covered in one render and empty in the other
    size_t covered = 0;            // samples the compute render covers
    float maxDepthDifference = 0;  // largest depth difference where the ids agree
};

class ComputeOracleTest : public ::testing::Test {
protected:
    void SetUp() override;

    // compute_ against vulkan-graphics rendering `scene` with `s`, every sample (aovSamples is set).
    SampleAgreement compareSamples(const Scene& scene, RenderSettings s, const CameraMatrices& camera);

    // Samples whose ids differ between compute_ and vulkan-graphics rendering `scene` with `s` (every
    // sample: aovSamples is set); where the ids agree, depth must agree within depthTolerance. `covered`
    // counts the compute side's covered samples. -1 when the device does not offer the sample count.
    long differingSamples(const Scene& scene, RenderSettings s, const CameraMatrices& camera, size_t& covered,
                          float depthTolerance = 0.0f);

    std::unique_ptr<ComputeDevice> compute_;
};

// A test of the vulkan-graphics reference: validation on (also when the binary runs by hand), skipped
// under SR_ALLOW_MISSING_BACKENDS=vulkan without a Vulkan device, and failing on any validation error
// its renders report (each creates and destroys its own device, so leaks are reported too).
class GraphicsTest : public ::testing::Test {
protected:
    void SetUp() override;
    void TearDown() override;

    // The scene through vulkan-graphics on the default device, or an empty output after a failure that
    // the test reports.
    RenderOutput render(const Scene& scene, const RenderSettings& settings,
                        const CameraMatrices& camera = identityCamera());

private:
    size_t errorsBefore_ = 0;
};

// The output modes a renderer must serve alike: 1x and MSAA 4x, each with colour and depth + ids only
// (RenderSettings::visibilityOnly), and SSAA 2 at 1x and MSAA 4x.
struct OutputMode {
    uint32_t msaa, ssaa;
    bool visibilityOnly;
};
extern const std::vector<OutputMode> kOutputModes;
// unlitSettings(width, height) in output mode `mode`.
RenderSettings outputModeSettings(const OutputMode& mode, uint32_t width, uint32_t height);

// Number of pixels whose id equals `id`.
size_t countId(const AovImage& aov, uint32_t id);

// Command line of the `raster` tool built next to the tests, with its exit code and stderr.
// A model of Debian's glmark2-data (/usr/share/glmark2/models/NAME); SR_GLMARK2_MODELS names another
// folder (the GPU machine has no Debian packages: ci/gpu-bundle carries the bunny).
std::string glmark2Model(const std::string& name);
// A built-in scene by name ("builtin...", builtinSceneNamed) or a glmark2 model by file name; an empty
// scene after a failure that the test reports.
Scene namedScene(const std::string& name);

// Meshes that many triangles share a vertex or a centroid of, n triangles each: "degenerate copies" (n
// copies of one zero-area triangle, and one real triangle), "copies" (of one real triangle), "fan" (n
// triangles around one vertex) and "collapsed" (n triangles at one point, through distinct vertices).
Scene pathologicalScene(const std::string& kind, uint32_t n);

struct ToolRun {
    int exitCode = -1;
    std::string stdoutText;
    std::string stderrText;
};
// Runs in `workDir` when given, else in the current directory; `wrapper` goes before the binary (a
// command that runs it, e.g. `xvfb-run -a` or `env -u DISPLAY`).
ToolRun runTool(const std::string& args, const std::string& workDir = "", const std::string& wrapper = "");
// The raster binary runTool runs: SR_RASTER_EXE from the environment (a relocated bundle) or the build's.
std::string rasterExe();
// The checkout's root, where the tests read assets, goldens, the README and the sources: SR_SOURCE_DIR
// from the environment (a test binary relocated to another machine) or the one it was built from.
std::string sourceDir();
// A file's bytes (none when it cannot be read).
std::vector<unsigned char> fileBytes(const std::string& path);
// runTool's wrapper for a disk that holds `bytes` per file in the run's working folder: writes past that
// fail with ENOSPC (tests/support/full_disk.c, the library beside the raster binary).
std::string fullDisk(size_t bytes);

}  // namespace sr::test

#endif  // RASTER_TEST_UTIL_H
