// render_test.cpp - the whole pipeline end to end on each backend (Vulkan on lavapipe here, CUDA
// where a GPU exists), checked against analytic coverage and depth, plus the `raster` command line.
// A missing backend fails these tests unless SR_ALLOW_MISSING_BACKENDS names it.
#include <cmath>
#include <fstream>
#include <random>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "raster_shared.h"
#include "test_util.h"

namespace sr::test {
namespace {

class RenderTest : public BackendTest {};

template <typename T>
std::vector<T> concat(std::vector<T> a, const std::vector<T>& b)
{
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

TEST_P(RenderTest, QuadCoversExactlyTheLeftHalf)
{
    const uint32_t w = 64, h = 48;
    RenderOutput out = render(clipSpaceScene(clipQuad(-1, -1, 0, 1, 0.5f)), testSettings(w, h));
    ASSERT_EQ(out.aov.id.size(), size_t(w) * h);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            uint32_t id = out.aov.id[y * w + x];
            if (x < w / 2) {
                ASSERT_TRUE(id == 0 || id == 1) << x << "," << y;
                ASSERT_EQ(out.aov.depth[y * w + x], 0.5f);
            } else {
                ASSERT_EQ(id, EMPTY_ID) << x << "," << y;
                ASSERT_EQ(out.aov.depth[y * w + x], 1.0f);
            }
        }
    EXPECT_EQ(out.stats.rasterized, 2u);
    EXPECT_EQ(out.stats.culled, 0u);
}

TEST_P(RenderTest, NearerSurfaceWinsWhateverTheOrder)
{
    const uint32_t w = 40, h = 40;
    for (bool nearFirst : {true, false}) {
        auto nearQuad = clipQuad(-1, -1, 1, 1, 0.3f), farQuad = clipQuad(-0.5f, -1, 1, 0.5f, 0.7f);
        Scene scene = clipSpaceScene(nearFirst ? concat(nearQuad, farQuad) : concat(farQuad, nearQuad));
        RenderOutput out = render(scene, testSettings(w, h));
        uint32_t nearBase = nearFirst ? 0 : 2;
        for (size_t i = 0; i < out.aov.id.size(); ++i) {
            ASSERT_TRUE(out.aov.id[i] == nearBase || out.aov.id[i] == nearBase + 1) << i;
            ASSERT_EQ(out.aov.depth[i], 0.3f);
        }
    }
}

TEST_P(RenderTest, EqualDepthsResolveToTheLowestTriangleId)
{
    Scene scene = clipSpaceScene(concat(clipQuad(-1, -1, 1, 1, 0.5f), clipQuad(-1, -1, 1, 1, 0.5f)));
    RenderOutput out = render(scene, testSettings(32, 32));
    for (uint32_t id : out.aov.id) ASSERT_TRUE(id == 0 || id == 1);
}

TEST_P(RenderTest, FrontBackAndDoubleSidedCulling)
{
    std::vector<glm::vec4> tris = cullingTriangles();  // 0: front-facing, 1: back-facing
    RenderSettings s = testSettings(64, 64);
    s.cullMode = CULL_BACK;
    RenderOutput back = render(clipSpaceScene(tris), s);
    EXPECT_GT(countId(back.aov, 0), 100u);
    EXPECT_EQ(countId(back.aov, 1), 0u);
    s.cullMode = CULL_FRONT;
    RenderOutput front = render(clipSpaceScene(tris), s);
    EXPECT_EQ(countId(front.aov, 0), 0u);
    EXPECT_EQ(countId(front.aov, 1), countId(back.aov, 0));  // mirror images: same pixel count
    RenderOutput twoSided = render(clipSpaceScene(tris, {TRI_FLAG_DOUBLE_SIDED, TRI_FLAG_DOUBLE_SIDED}), s);
    EXPECT_EQ(countId(twoSided.aov, 0), countId(back.aov, 0));
    EXPECT_EQ(countId(twoSided.aov, 1), countId(front.aov, 1));
}

// A ground plane y = -1 under a camera at the origin looking down -z, reaching far behind the
// camera (vertices with w < 0). With a 90-degree fov the horizon is the middle row: exactly the
// lower half of the image is covered, with no inside-out or exploding triangles.
TEST_P(RenderTest, GroundPlaneThroughTheNearPlaneCoversTheLowerHalf)
{
    Scene scene;
    const float e = 1e4f;
    for (glm::vec4 p : {glm::vec4(-e, -1, 10, 1), glm::vec4(e, -1, 10, 1), glm::vec4(e, -1, -e, 1),
                        glm::vec4(-e, -1, -e, 1)}) {
        scene.positions.push_back(p);
        scene.normals.push_back(glm::vec4(0, 1, 0, 0));
    }
    scene.indices = {0, 1, 2, 0, 2, 3};
    scene.triFlags = {0, 0};
    CameraMatrices camera;
    camera.znear = 0.1f;
    camera.zfar = 1e6f;
    camera.clipFromView = perspectiveVulkan(float(M_PI / 2), 1.0f, camera.znear, camera.zfar);
    camera.clipFromWorld = camera.clipFromView;
    const uint32_t n = 64;
    RenderSettings s = testSettings(n, n);
    s.cullMode = CULL_BACK;  // the plane faces up, towards the camera: front-facing
    RenderOutput out = render(scene, s, camera);
    EXPECT_EQ(out.stats.clipped, 2u);
    for (uint32_t y = 0; y < n; ++y)
        for (uint32_t x = 0; x < n; ++x) {
            bool below = y >= n / 2;
            ASSERT_EQ(out.aov.id[y * n + x] != EMPTY_ID, below) << x << "," << y;
            if (below) {
                // Analytic depth of the plane at this pixel centre: view distance d = 1 / ndcY. Vertices
                // snap to 1/256 pixel, which may shift the plane by up to that much: allow the depth
                // change over one subpixel on top of float rounding.
                auto planeDepth = [&](float row) {
                    float ndcY = (row + 0.5f) * 2.0f / float(n) - 1.0f;
                    glm::vec4 c = camera.clipFromView * glm::vec4(0, -1, -1.0f / ndcY, 1);
                    return c.z / c.w;
                };
                float expected = planeDepth(float(y));
                float tolerance = 1e-6f + std::abs(planeDepth(float(y) + 1.0f / 256.0f) - expected);
                ASSERT_NEAR(out.aov.depth[y * n + x], expected, tolerance) << x << "," << y;
            }
        }
}

TEST_P(RenderTest, HugeTriangleCoversEveryPixelOnce)
{
    for (float size : {1e3f, 1e5f, 1e7f}) {
        Scene scene = clipSpaceScene(
            {{-size, -size, 0.25f, 1}, {size * 2, -size, 0.25f, 1}, {-size, size * 2, 0.25f, 1}});
        RenderOutput out = render(scene, testSettings(48, 32));
        EXPECT_EQ(countId(out.aov, 0), 48u * 32u) << size;
        for (float d : out.aov.depth) ASSERT_EQ(d, 0.25f);
    }
}

// Small triangles whose corners lie far outside the viewport (a corner of the image cut off by a long
// sliver): their box in the image is a few pixels, but their corners spread over more than
// SMALL_EDGE_EXTENT subpixels, too far for setup's 32-bit pixel loop, so they take the big path
// (docs/architecture.md, setup). Ids and depth are those of the shared maths evaluated here on the host
// (setupTriangle and rasterPixel at every pixel, the nearest key kept), and the stats count them big, the
// others small.
TEST_P(RenderTest, SmallTrianglesWithFarCornersTakeTheBigPathExactly)
{
    const uint32_t size = 64;
    std::mt19937 rng(46);
    std::uniform_real_distribution<double> inside(0.3, 9.0), far(80.0, 3000.0), lean(0.0, 6.0),
        depth(0.05, 0.95), pos(4.0, 56.0), step(1.0, 6.0);
    auto grid = [](double v) { return std::round(v * 256.0) / 256.0; };
    std::vector<glm::vec4> corners;
    for (int i = 0; i < 48; ++i) {
        // A corner of the image cut off: the anchor a few pixels inside it, the other two corners far away
        // beyond its two sides; then mirrored onto one of the image's four corners.
        double ax = inside(rng), ay = inside(rng);
        glm::dvec2 p[3] = {{ax, ay}, {-far(rng), ay - lean(rng)}, {ax - lean(rng), -far(rng)}};
        float z = float(depth(rng));
        for (glm::dvec2 q : p) {
            double x = (i & 1) ? size - q.x : q.x, y = (i & 2) ? size - q.y : q.y;
            corners.push_back(windowVertex(grid(x), grid(y), size, size, z));
        }
    }
    for (int i = 0; i < 48; ++i) {  // ordinary small triangles, for the count of the other path
        double x = pos(rng), y = pos(rng);
        float z = float(depth(rng));
        for (glm::dvec2 q : {glm::dvec2(x, y), glm::dvec2(x + step(rng), y + lean(rng)),
                             glm::dvec2(x + lean(rng), y + step(rng))})
            corners.push_back(windowVertex(grid(q.x), grid(q.y), size, size, z));
    }
    std::vector<uint64_t> expected(size_t(size) * size, ~uint64_t(0));
    uint64_t small = 0, big = 0, farCorners = 0;
    for (uint32_t id = 0; id < corners.size() / 3; ++id) {
        TriSetup t;
        if (!setupTriangle(corners[3 * id], corners[3 * id + 1], corners[3 * id + 2], id, true, CULL_NONE,
                           size, size, PIXEL_CENTER_BOUNDS, t))
            continue;
        ivec4 b = setupPixelBounds(t, size, size, PIXEL_CENTER_BOUNDS);
        bool fits = smallEdgesFit(t);
        farCorners += isSmallTriangle(b) && !fits;
        (isSmallTriangle(b) && fits ? small : big) += 1;
        for (int y = b.y; y <= b.w; ++y)
            for (int x = b.x; x <= b.z; ++x) {
                float d;
                if (rasterPixel(t, x, y, d))
                    expected[size_t(y) * size + x] =
                        std::min(expected[size_t(y) * size + x], packVisibility(d, id));
            }
    }
    ASSERT_GE(farCorners, 40u);  // the scene exercises the path it is about
    ASSERT_GE(small, 40u);
    RenderOutput out = render(clipSpaceScene(corners), testSettings(size, size));
    ASSERT_EQ(out.aov.id.size(), expected.size());
    size_t covered = 0;
    for (size_t i = 0; i < expected.size(); ++i) {
        bool empty = expected[i] == ~uint64_t(0);
        covered += !empty;
        ASSERT_EQ(out.aov.id[i], empty ? EMPTY_ID : visibilityId(expected[i])) << "pixel " << i;
        ASSERT_EQ(out.aov.depth[i], empty ? 1.0f : visibilityDepth(expected[i])) << "pixel " << i;
    }
    EXPECT_GT(covered, 400u);
    EXPECT_EQ(out.stats.smallTris, small);
    EXPECT_EQ(out.stats.bigTris, big);
}

TEST_P(RenderTest, NonFiniteVerticesAreDroppedAndTheRestDrawn)
{
    auto tris = concat(clipQuad(-1, -1, 0, 1, 0.5f), std::vector<glm::vec4>{{NAN, 0, 0.5f, 1},
                                                                            {1, 0, 0.5f, 1},
                                                                            {1, 1, 0.5f, 1},
                                                                            {0, 0, 0.5f, 1},
                                                                            {INFINITY, 0, 0.5f, 1},
                                                                            {1, 1, 0.5f, 1}});
    RenderOutput out = render(clipSpaceScene(tris), testSettings(32, 32));
    EXPECT_EQ(out.stats.invalid, 2u);
    EXPECT_EQ(countId(out.aov, 0) + countId(out.aov, 1), 32u * 16u);
    EXPECT_EQ(countId(out.aov, EMPTY_ID), 32u * 16u);
}

TEST_P(RenderTest, OverflowingListsGrowAndRedrawIdentically)
{
    FramedScene f = framedBuiltin(96, 96);
    RenderSettings s = f.settings;
    RenderOutput normal = render(f.scene, s, f.camera);
    s.initialListCapacity = 1;
    RenderOutput tiny = render(f.scene, s, f.camera);
    EXPECT_EQ(normal.stats.redraws, 0u);
    EXPECT_GE(tiny.stats.redraws, 1u);
    EXPECT_EQ(tiny.aov.id, normal.aov.id);
    EXPECT_EQ(tiny.aov.depth, normal.aov.depth);
    EXPECT_EQ(tiny.color.pixels, normal.color.pixels);
}

// Clipped big triangles are the ones stored as records; with every list at capacity 1 the records, the
// pieces and the bins all overflow, grow and redraw, and the image is the same.
TEST_P(RenderTest, ClippedBigTrianglesUseRecordsAndGrowIdentically)
{
    // builtin:huge's ground plane reaches far past the guard band and behind the camera: its two
    // triangles are clipped into big sub-triangles, the ones stored as records.
    auto scene = builtinSceneNamed("builtin:huge");
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    auto spec =
        parseCameraSpec("orbit:35,4,1.5");  // as the near-plane golden: low, inside the plane's extent
    ASSERT_TRUE(spec.ok());
    auto camera = resolveCamera(*spec, *scene, 96, 96);
    ASSERT_TRUE(camera.ok()) << camera.error().message;
    RenderSettings s = testSettings(96, 96);
    RenderOutput normal = render(*scene, s, *camera);
    s.initialListCapacity = 1;
    RenderOutput tiny = render(*scene, s, *camera);
    EXPECT_GT(normal.stats.clipped, 0u);
    EXPECT_GT(normal.stats.records, 0u);
    EXPECT_GT(normal.stats.binEntries, normal.stats.pieces);
    EXPECT_GE(tiny.stats.redraws, 2u);  // records and pieces first, then the bins they fill
    EXPECT_EQ(tiny.aov.id, normal.aov.id);
    EXPECT_EQ(tiny.aov.depth, normal.aov.depth);
}

// Frames after the first skip the binning stages when the previous frame had no big triangle: a scene of
// small triangles renders the same over several frames, and a frame that skipped binning but met big
// triangles is drawn again with it, identical to a render that never skipped.
TEST_P(RenderTest, SkippedBinningFollowsThePreviousFrameAndRedrawsWhenNeeded)
{
    auto dense = builtinSceneNamed("builtin:dense");  // sub-pixel triangles at this size: no big one
    ASSERT_TRUE(dense.ok());
    auto camera = resolveCamera(CameraSpec{}, *dense, 64, 64);
    ASSERT_TRUE(camera.ok());
    RenderSettings one = testSettings(64, 64);
    RenderSettings three = one;
    three.warmup = 1;
    three.repeat = 3;
    RenderOutput a = render(*dense, one, *camera), b = render(*dense, three, *camera);
    EXPECT_EQ(a.stats.bigTris, 0u);
    EXPECT_EQ(b.stats.redraws, 0u);
    EXPECT_EQ(a.aov.id, b.aov.id);
    EXPECT_EQ(a.aov.depth, b.aov.depth);

    FramedScene f = framedBuiltin(96, 96);
    RenderOutput normal = render(f.scene, f.settings, f.camera);
    RenderSettings skipping = f.settings;
    skipping.firstFrameSkipsBinning = true;
    RenderOutput redrawn = render(f.scene, skipping, f.camera);
    EXPECT_GT(normal.stats.bigTris, 0u);
    EXPECT_EQ(normal.stats.redraws, 0u);
    EXPECT_GE(redrawn.stats.redraws, 1u);
    EXPECT_EQ(redrawn.aov.id, normal.aov.id);
    EXPECT_EQ(redrawn.aov.depth, normal.aov.depth);
}

TEST_P(RenderTest, BuiltinSceneIsNonTrivialAndDeterministic)
{
    FramedScene f = framedBuiltin(128, 96);
    RenderSettings s = f.settings;
    RenderOutput first = render(f.scene, s, f.camera);
    size_t covered = first.aov.id.size() - countId(first.aov, EMPTY_ID);
    EXPECT_GT(covered, first.aov.id.size() / 10);
    std::set<uint32_t> colours(first.color.pixels.begin(), first.color.pixels.end());
    EXPECT_GT(colours.size(), 100u);
    std::set<uint32_t> ids(first.aov.id.begin(), first.aov.id.end());
    EXPECT_GT(ids.size(), 200u);
    for (int run = 1; run < 20; ++run) {  // 20 renders in all
        RenderOutput again = render(f.scene, s, f.camera);
        ASSERT_EQ(again.aov.id, first.aov.id);
        ASSERT_EQ(again.aov.depth, first.aov.depth);
        ASSERT_EQ(again.color.pixels, first.color.pixels);
    }
}

// A triangle soup (no shared vertex) is transformed in setup instead of by the vertex stage; both paths
// must give the same image as the indexed scene.
TEST_P(RenderTest, TriangleSoupRendersLikeTheIndexedMesh)
{
    FramedScene f = framedBuiltin(96, 72);
    const Scene& indexed = f.scene;
    Scene soup = indexed;
    soup.positions.clear();
    soup.normals.clear();
    soup.colors.clear();
    for (uint32_t& index : soup.indices) {
        soup.positions.push_back(indexed.positions[index]);
        soup.normals.push_back(indexed.normals[index]);
        soup.colors.push_back(indexed.colors[index]);
        index = uint32_t(soup.positions.size() - 1);
    }
    RenderOutput a = render(indexed, f.settings, f.camera);
    RenderOutput b = render(soup, f.settings, f.camera);
    EXPECT_GT(a.aov.id.size() - countId(a.aov, EMPTY_ID), 1000u);
    EXPECT_EQ(b.aov.id, a.aov.id);
    EXPECT_EQ(b.aov.depth, a.aov.depth);
    EXPECT_EQ(b.color.pixels, a.color.pixels);
}

TEST_P(RenderTest, TimingsAndMemoryAreReported)
{
    RenderSettings s = testSettings(32, 32);
    s.warmup = 1;
    s.repeat = 3;
    RenderOutput out = render(clipSpaceScene(clipQuad(-1, -1, 1, 1, 0.5f)), s);
    // Every pipeline stage; the AO stages only with --ao gtao; the tess_* stages (numbered after them)
    // only in tessellated frames, first.
    constexpr size_t kAoStages = 3;
    ASSERT_EQ(out.stages.size(), size_t(STAGE_TESS_COUNT) - kAoStages);
    for (const StageTiming& t : out.stages) {
        EXPECT_LE(t.minMs, t.medianMs);
        EXPECT_LE(t.medianMs, t.maxMs);
        EXPECT_GE(t.minMs, 0.0);
    }
    EXPECT_GE(out.peakDeviceBytes, 32u * 32u * 12u);  // visibility + framebuffer at least
    s.tessellate = TESS_FLAT;
    RenderOutput tess = render(clipSpaceScene(clipQuad(-1, -1, 1, 1, 0.5f)), s);
    ASSERT_EQ(tess.stages.size(), size_t(STAGE_COUNT) - kAoStages);
    EXPECT_EQ(tess.stages[0].name, "tess_count");
    EXPECT_EQ(tess.stages[3].name, "tess_emit");
    EXPECT_EQ(tess.stages[4].name, "clear");
    s.tessellate = TESS_OFF;
    s.ao = AO_GTAO;
    RenderOutput ao = render(clipSpaceScene(clipQuad(-1, -1, 1, 1, 0.5f)), s);
    ASSERT_EQ(ao.stages.size(), size_t(STAGE_TESS_COUNT));
    EXPECT_EQ(ao.stages[STAGE_AO_GBUFFER].name, "ao_gbuffer");
    EXPECT_EQ(ao.stages[STAGE_AO_DENOISE].name, "ao_denoise");
    EXPECT_EQ(ao.stages[STAGE_SHADE].name, "shade");
}

INSTANTIATE_TEST_SUITE_P(Backends, RenderTest, ::testing::Values("vulkan", "cuda"),
                         [](const auto& info) { return info.param; });

// ---- the `raster` tool
// ---------------------------------------------------------------------------

TEST(RasterTool, RendersTheBuiltinSceneWithAllOutputs)
{
    std::string dir = ::testing::TempDir();
    ToolRun run = runTool("render --backend vulkan --width 96 --height 64 -o " + dir + "t.png --aov " + dir +
                          "t.exr --stats " + dir + "t.json --repeat 2");
    ASSERT_EQ(run.exitCode, 0) << run.stderrText;
    auto aov = readAovExr(dir + "t.exr");
    ASSERT_TRUE(aov.ok()) << aov.error().message;
    EXPECT_EQ(aov->width, 96u);
    auto png = readPng(dir + "t.png");
    ASSERT_TRUE(png.ok());
    EXPECT_EQ(png->height, 64u);
    std::ifstream in(dir + "t.json");
    nlohmann::json stats = nlohmann::json::parse(in);
    EXPECT_EQ(stats["backend"], "vulkan");
    EXPECT_EQ(stats["resolution"][0], 96);
    EXPECT_EQ(stats["clip_from_world"].size(), 16u);
    EXPECT_GT(stats["triangles"]["in"].get<int>(), 1000);
    EXPECT_TRUE(stats["stages_ms"].contains("raster_tiles"));
    EXPECT_GT(stats["peak_device_bytes"].get<int64_t>(), 0);
}

TEST(RasterTool, BadInputGivesOneLineAndExitCode2)
{
    std::string dir = ::testing::TempDir();
    std::ofstream(dir + "broken.gltf") << "{ \"asset\": {\"version\": \"2.0\"}, \"meshes\": [ {";
    std::ofstream(dir + "garbage.obj") << "v 1 2\nf 1 2 99999\nf a b c\n";
    for (std::string args : std::vector<std::string>{
             "render /nonexistent/scene.gltf", "render " + dir + "broken.gltf",
             "render " + dir + "garbage.obj", "render --width 0", "render --camera orbit:1,2",
             "render --backend metal", "render --light-dir 1,2"}) {
        ToolRun run = runTool(args + " -o " + dir + "never.png");
        EXPECT_EQ(run.exitCode, 2) << args << ": " << run.stderrText;
        EXPECT_EQ(std::count(run.stderrText.begin(), run.stderrText.end(), '\n'), 1)
            << args << ": " << run.stderrText;
        EXPECT_EQ(run.stderrText.rfind("raster: error: ", 0), 0u) << run.stderrText;
    }
}

}  // namespace
}  // namespace sr::test
