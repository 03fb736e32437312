// test_util.cpp - see test_util.h.
#include "test_util.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "vulkan/vulkan_device_internal.h"
#include "vulkan/vulkan_graphics.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

namespace sr::test {

std::unique_ptr<ComputeDevice> openBackend(const std::string& backend, bool& skip)
{
    skip = false;
    setenv("SR_VULKAN_VALIDATION", "1", 0);
    auto device = backend == "cuda" ? makeCudaDevice(-1) : makeVulkanDevice(-1);
    if (device) return std::move(*device);
    const char* allowed = std::getenv("SR_ALLOW_MISSING_BACKENDS");
    std::string list = allowed ? std::string(",") + allowed + "," : "";
    if (list.find("," + backend + ",") != std::string::npos) {
        skip = true;
        return nullptr;
    }
    ADD_FAILURE() << "backend " << backend << " is required but unavailable: " << device.error().message
                  << " (set SR_ALLOW_MISSING_BACKENDS=" << backend << " to allow its absence)";
    return nullptr;
}

Scene clipSpaceScene(const std::vector<glm::vec4>& corners, const std::vector<uint32_t>& flags)
{
    Scene scene;
    for (size_t i = 0; i < corners.size(); ++i) {
        scene.positions.push_back(corners[i]);
        scene.normals.push_back(glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
        scene.indices.push_back(uint32_t(i));
    }
    scene.triFlags = flags.empty() ? std::vector<uint32_t>(corners.size() / 3, 0u) : flags;
    scene.boundsMin = glm::vec3(-1.0f);
    scene.boundsMax = glm::vec3(1.0f);
    return scene;
}

std::vector<glm::vec4> clipQuad(float x0, float y0, float x1, float y1, float z)
{
    return {{x0, y0, z, 1}, {x1, y0, z, 1}, {x1, y1, z, 1}, {x0, y0, z, 1}, {x1, y1, z, 1}, {x0, y1, z, 1}};
}

glm::vec4 windowVertex(double x, double y, uint32_t width, uint32_t height, float z)
{
    return {float(x * 2.0 / width - 1.0), float(y * 2.0 / height - 1.0), z, 1.0f};
}

std::vector<glm::vec4> windowQuadMesh(const std::vector<std::vector<glm::dvec2>>& grid, uint32_t width,
                                      uint32_t height, bool alternate, float z)
{
    std::vector<glm::vec4> corners;
    for (size_t j = 0; j + 1 < grid.size(); ++j)
        for (size_t i = 0; i + 1 < grid[j].size(); ++i) {
            glm::dvec2 a = grid[j][i], b = grid[j][i + 1], c = grid[j + 1][i + 1], d = grid[j + 1][i];
            const glm::dvec2 order[2][6] = {{a, b, c, a, c, d}, {a, b, d, b, c, d}};
            for (glm::dvec2 p : order[alternate && (i + j) % 2 == 0 ? 1 : 0])
                corners.push_back(windowVertex(p.x, p.y, width, height, z));
        }
    return corners;
}

CameraMatrices identityCamera()
{
    CameraMatrices camera;
    camera.znear = 0.0f;
    camera.zfar = 1.0f;
    return camera;
}

RenderSettings testSettings(uint32_t width, uint32_t height)
{
    RenderSettings s;
    s.width = width;
    s.height = height;
    s.warmup = 0;
    s.repeat = 1;
    s.cullMode = CULL_NONE;
    return s;
}

RenderSettings unlitSettings(uint32_t width, uint32_t height)
{
    RenderSettings s = testSettings(width, height);
    s.shadingMode = SHADING_LAMBERT;
    s.ambient = 1.0f;
    s.lightColor = glm::vec3(0.0f);
    return s;
}

Scene windowPointScene(const std::vector<WindowPoint>& points, uint32_t width, uint32_t height,
                       const std::vector<glm::vec4>& triangles)
{
    Scene scene = clipSpaceScene(triangles);
    for (const WindowPoint& p : points) {
        scene.points.push_back(uint32_t(scene.positions.size()));
        scene.positions.push_back(windowVertex(p.x, p.y, width, height, p.z));
        scene.normals.push_back(glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
    }
    return scene;
}

Scene windowLineScene(const std::vector<WindowLine>& lines, uint32_t width, uint32_t height,
                      const std::vector<glm::vec4>& triangles, const std::vector<WindowPoint>& points)
{
    Scene scene = windowPointScene(points, width, height, triangles);
    for (const WindowLine& l : lines) {
        scene.lines.push_back(uint32_t(scene.positions.size()));
        scene.positions.push_back(windowVertex(l.x0, l.y0, width, height, l.z0));
        scene.lines.push_back(uint32_t(scene.positions.size()));
        scene.positions.push_back(windowVertex(l.x1, l.y1, width, height, l.z1));
        scene.normals.insert(scene.normals.end(), 2, glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
    }
    return scene;
}

int lineCoversSample(const WindowLine& l, double width, double sx, double sy, double margin)
{
    const double dx = l.x1 - l.x0, dy = l.y1 - l.y0;
    const double length = std::sqrt(dx * dx + dy * dy);
    if (length == 0.0) return 0;
    const double qx = sx - l.x0, qy = sy - l.y0;
    // Along the segment from p0 (0) to p1 (length), and across it, in pixels.
    const double along = (qx * dx + qy * dy) / length;
    const double across = std::abs(qx * dy - qy * dx) / length;
    // An axis-aligned segment's rectangle has exact corners (half a width is whole subpixels), so every
    // tie follows the top-left rule: a sample on an edge is inside when that edge's inward normal points
    // right, or straight down for a horizontal edge (both edges at a corner).
    auto topLeft = [](double nx, double ny) { return nx > 0.0 || (nx == 0.0 && ny > 0.0); };
    if (dx == 0.0 || dy == 0.0) {
        const double ux = dx / length, uy = dy / length;  // unit direction, exact
        const double side = qx * -uy + qy * ux;           // signed distance to the left of the segment
        const double inward[4][3] = {{along, ux, uy},
                                     {length - along, -ux, -uy},
                                     {width / 2 - side, uy, -ux},
                                     {width / 2 + side, -uy, ux}};
        for (const auto& e : inward)
            if (e[0] < 0.0 || (e[0] == 0.0 && !topLeft(e[1], e[2]))) return 0;
        return 1;
    }
    if (across > width / 2 + margin || along < -margin || along > length + margin) return 0;
    if (across < width / 2 - margin && along > margin && along < length - margin) return 1;
    // Exactly an endpoint: on its cap, inside the sides; the top-left rule with the cap's inward normal.
    if (qx == 0.0 && qy == 0.0) return topLeft(dx, dy) ? 1 : 0;
    if (sx == l.x1 && sy == l.y1) return topLeft(-dx, -dy) ? 1 : 0;
    return -1;
}

int channelDifference(uint32_t a, uint32_t b)
{
    int worst = 0;
    for (int shift = 0; shift < 32; shift += 8)
        worst = std::max(worst, std::abs(int((a >> shift) & 0xffu) - int((b >> shift) & 0xffu)));
    return worst;
}

const std::vector<OutputMode> kOutputModes = {{1, 1, false}, {1, 1, true},  {4, 1, false},
                                              {4, 1, true},  {1, 2, false}, {4, 2, false}};

RenderSettings outputModeSettings(const OutputMode& mode, uint32_t width, uint32_t height)
{
    RenderSettings s = unlitSettings(width, height);
    s.msaa = mode.msaa;
    s.ssaa = mode.ssaa;
    s.visibilityOnly = mode.visibilityOnly;
    return s;
}

bool isOneLine(const std::string& message)
{
    return !message.empty() && message.find('\n') == std::string::npos;
}

SampleAgreement ComputeOracleTest::compareSamples(const Scene& scene, RenderSettings s,
                                                  const CameraMatrices& camera)
{
    SampleAgreement r;
    s.aovSamples = true;
    auto oracle = renderVulkanGraphics(scene, camera, s, -1);
    if (!oracle.ok() && oracle.error().message.find("does not offer") != std::string::npos) return r;
    r.offered = true;
    auto ours = renderScene(*compute_, scene, camera, s);
    EXPECT_TRUE(ours.ok()) << (ours.ok() ? "" : ours.error().message);
    EXPECT_TRUE(oracle.ok()) << (oracle.ok() ? "" : oracle.error().message);
    if (!ours.ok() || !oracle.ok()) return r;
    const SampleAovs &a = ours->samples, &b = oracle->samples;
    EXPECT_EQ(a.id.size(), b.id.size());
    for (size_t i = 0; i < std::min(a.id.size(), b.id.size()); ++i) {
        r.covered += a.id[i] != EMPTY_ID;
        r.differingCoverage += (a.id[i] != EMPTY_ID) != (b.id[i] != EMPTY_ID);
        if (a.id[i] != b.id[i])
            ++r.differingIds;
        else if (a.id[i] != EMPTY_ID)
            r.maxDepthDifference = std::max(r.maxDepthDifference, std::abs(a.depth[i] - b.depth[i]));
    }
    return r;
}

long ComputeOracleTest::differingSamples(const Scene& scene, RenderSettings s, const CameraMatrices& camera,
                                         size_t& covered, float depthTolerance)
{
    SampleAgreement r = compareSamples(scene, s, camera);
    covered = r.covered;
    if (!r.offered) return -1;
    EXPECT_LE(r.maxDepthDifference, depthTolerance);
    return r.differingIds;
}

RenderOutput GraphicsTest::render(const Scene& scene, const RenderSettings& settings,
                                  const CameraMatrices& camera)
{
    auto out = renderVulkanGraphics(scene, camera, settings, -1);
    EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().message);
    return out.ok() ? std::move(*out) : RenderOutput{};
}

void ComputeOracleTest::SetUp()
{
    bool skip = false;
    compute_ = openBackend("vulkan", skip);
    if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
    ASSERT_TRUE(compute_);
}

void GraphicsTest::SetUp()
{
    setenv("SR_VULKAN_VALIDATION", "1", 1);
    bool skip = false;
    const bool present = openBackend("vulkan", skip) != nullptr;
    if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
    ASSERT_TRUE(present);
    errorsBefore_ = vulkanValidationErrorCount();
}

void GraphicsTest::TearDown()
{
    if (!IsSkipped()) {
        EXPECT_EQ(vulkanValidationErrorCount(), errorsBefore_);
    }
}

ScratchDir::ScratchDir(const std::string& prefix)
{
    std::string pattern = ::testing::TempDir() + prefix + "_XXXXXX";
    if (mkdtemp(pattern.data())) path_ = pattern;
}

ScratchDir::~ScratchDir()
{
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
}

FramedScene framedBuiltin(uint32_t width, uint32_t height)
{
    FramedScene f{builtinScene(), {}, testSettings(width, height)};
    auto camera = resolveCamera(CameraSpec{}, f.scene, width, height);
    if (camera.ok())
        f.camera = *camera;
    else
        ADD_FAILURE() << camera.error().message;
    f.settings.cullMode = CULL_BACK;
    return f;
}

std::vector<glm::vec4> cullingTriangles()
{
    return {{-0.9f, -0.8f, 0.5f, 1}, {-0.9f, 0.8f, 0.5f, 1}, {-0.1f, -0.8f, 0.5f, 1},
            {0.1f, -0.8f, 0.5f, 1},  {0.9f, -0.8f, 0.5f, 1}, {0.1f, 0.8f, 0.5f, 1}};
}

size_t countId(const AovImage& aov, uint32_t id)
{
    size_t n = 0;
    for (uint32_t v : aov.id) n += v == id;
    return n;
}

namespace {
std::string readFile(const std::string& path)
{
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}
}  // namespace

std::string glmark2Model(const std::string& name)
{
    const char* root = std::getenv("SR_GLMARK2_MODELS");
    return std::string(root ? root : "/usr/share/glmark2/models") + "/" + name;
}

Scene namedScene(const std::string& name)
{
    auto scene = name.rfind("builtin", 0) == 0 ? builtinSceneNamed(name) : loadScene(glmark2Model(name));
    EXPECT_TRUE(scene.ok()) << name << ": " << (scene.ok() ? "" : scene.error().message);
    return scene.ok() ? std::move(*scene) : Scene{};
}

std::string rasterExe()
{
    // SR_RASTER_EXE in the environment points at a relocated binary (the GPU machine's bundle).
    const char* exe = std::getenv("SR_RASTER_EXE");
    return exe ? exe : SR_RASTER_EXE;
}

std::string sourceDir()
{
    const char* env = std::getenv("SR_SOURCE_DIR");
    return env && *env ? env : SR_SOURCE_DIR;
}

std::vector<unsigned char> fileBytes(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::vector<unsigned char>(std::istreambuf_iterator<char>(in), {});
}

std::string fullDisk(size_t bytes)
{
    const std::string exe = rasterExe();
    const std::string shim = exe.substr(0, exe.find_last_of('/') + 1) + "libsr_full_disk.so";
    // A sanitizer build's raster checks that its runtime comes first among the preloaded libraries.
    return "LD_PRELOAD='" + shim + "' SR_FULL_DISK_BYTES=" + std::to_string(bytes) +
           " ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}verify_asan_link_order=0\"";
}

ToolRun runTool(const std::string& args, const std::string& workDir, const std::string& wrapper)
{
    // ctest runs tests in parallel processes: name the capture files after this process and call.
    static int calls = 0;
    std::string stem =
        ::testing::TempDir() + "raster_tool_" + std::to_string(getpid()) + "_" + std::to_string(calls++);
    std::string out = stem + ".out";
    std::string err = stem + ".err";
    std::string cmd = (workDir.empty() ? "" : "cd '" + workDir + "' && ") + wrapper +
                      (wrapper.empty() ? "" : " ") + rasterExe() + " " + args + " >" + out + " 2>" + err;
    int status = std::system(cmd.c_str());
    ToolRun run;
    run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    run.stdoutText = readFile(out);
    run.stderrText = readFile(err);
    return run;
}

Scene pathologicalScene(const std::string& kind, uint32_t n)
{
    Scene scene;
    auto vertex = [&](float x, float y, float z) {
        scene.positions.emplace_back(x, y, z, 1.0f);
        scene.normals.emplace_back(0.0f, 0.0f, 1.0f, 0.0f);
        return uint32_t(scene.positions.size() - 1);
    };
    auto triangle = [&](uint32_t a, uint32_t b, uint32_t c) {
        for (uint32_t i : {a, b, c}) scene.indices.push_back(i);
    };
    if (kind == "degenerate copies" || kind == "copies") {
        const float y = kind == "copies" ? 1.0f : 0.0f;
        const uint32_t a = vertex(0, 0, 0), b = vertex(1, 0, 0), c = vertex(2, y, 0);
        for (uint32_t k = 0; k < n; ++k) triangle(a, b, c);
        triangle(vertex(0, 1, 1), vertex(1, 1, 1), vertex(0, 2, 1));
    } else if (kind == "fan") {
        const uint32_t centre = vertex(0, 0, 0);
        for (uint32_t k = 0; k <= n; ++k) {
            const double angle = 2.0 * M_PI * k / n;
            vertex(float(std::cos(angle)), float(std::sin(angle)), 0);
        }
        for (uint32_t k = 0; k < n; ++k) triangle(centre, 1 + k, 2 + k);
    } else {  // collapsed: every vertex at the origin
        for (uint32_t k = 0; k < n; ++k) triangle(vertex(0, 0, 0), vertex(0, 0, 0), vertex(0, 0, 0));
    }
    scene.triFlags.assign(scene.indices.size() / 3, 0u);
    return scene;
}

}  // namespace sr::test
