// study_test.cpp - `raster study` (host/cli/study.h): its image metric against hand-computed values,
// two of the study's central claims against the supersampled reference (anti-aliasing error falls with
// every doubling of the sample count, trilinear filtering beats bilinear on a minified grazing
// texture), its synthetic scenes, its first-failure table, its oracle count (fixed8 draws what the
// conformant graphics pipeline draws), and its level-of-detail group: the subdivided bunny's
// construction, the coverage and depth comparison against --lod off, and the group run on lavapipe
// (fewer triangles for larger errors and farther cameras, the closed sphere's outline the only place
// its coverage moves). The stress cases themselves are in study_stress_test.cpp.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "study/study_runner.h"
#include "study/ao_study.h"
#include "study/scenes.h"
#include "test_util.h"

namespace sr::test {
namespace {

// PSNR of one channel off by d in one of n pixels: MSE = d^2 / (3 n) over R, G and B.
TEST(StudyMetrics, PsnrAndMaxErrorMatchTheirDefinitions)
{
    RgbaImage a{4, 2, std::vector<uint32_t>(8, 0xff204060u)};
    RgbaImage b = a;
    EXPECT_TRUE(std::isinf(imageError(a, b).psnr));
    EXPECT_EQ(imageError(a, b).maxError, 0);
    b.pixels[3] = 0xff20406au;  // R + 10
    ImageError e = imageError(b, a);
    EXPECT_EQ(e.maxError, 10);
    EXPECT_NEAR(e.psnr, 10.0 * std::log10(255.0 * 255.0 / (100.0 / 24.0)), 1e-9);
    b.pixels[5] = 0x00204060u;  // alpha is not compared
    EXPECT_EQ(imageError(b, a).maxError, 10);
}

class StudyClaimsTest : public BackendTest {
protected:
    // PSNR of `s` against the study's reference (SSAA 4 x MSAA 16, trilinear) of the same frame.
    double psnr(const FramedScene& f, RenderSettings s)
    {
        RenderSettings ref = f.settings;
        ref.msaa = 16;
        ref.ssaa = 4;
        ref.textureFilter = TEXTURE_FILTER_TRILINEAR;
        return imageError(render(f.scene, s, f.camera).color, render(f.scene, ref, f.camera).color).psnr;
    }
};

// Each doubling of the coverage samples brings the built-in scene's edges closer to the 64-sample
// reference: the box filter's estimate of a pixel's coverage has less error with more samples.
TEST_P(StudyClaimsTest, AntiAliasingErrorFallsWithTheSampleCount)
{
    FramedScene f = framedBuiltin(64, 48);
    double previous = 0.0;
    for (uint32_t msaa : {1u, 2u, 4u, 8u, 16u}) {
        RenderSettings s = f.settings;
        s.msaa = msaa;
        double p = psnr(f, s);
        EXPECT_GT(p, previous) << msaa << "x";
        previous = p;
    }
}

// The checkerboard plane seen at a grazing angle is minified far from the camera: bilinear filtering
// of the full-resolution texture aliases there, trilinear averages the texels a pixel covers, as the
// reference's 64 samples per pixel do.
TEST_P(StudyClaimsTest, TrilinearBeatsBilinearOnAGrazingPlane)
{
    auto scene = builtinSceneNamed("builtin:checker");
    ASSERT_TRUE(scene.ok());
    auto spec = parseCameraSpec("orbit:0,6,12");
    ASSERT_TRUE(spec.ok());
    auto camera = resolveCamera(*spec, *scene, 96, 72);
    ASSERT_TRUE(camera.ok());
    FramedScene f{std::move(*scene), *camera, testSettings(96, 72)};
    RenderSettings bilinear = f.settings, trilinear = f.settings;
    bilinear.textureFilter = TEXTURE_FILTER_BILINEAR;
    trilinear.textureFilter = TEXTURE_FILTER_TRILINEAR;
    EXPECT_GT(psnr(f, trilinear), psnr(f, bilinear) + 1.0);
}

// Doubled signed area of triangle t in window units (positions are clip coordinates, w = 1).
double doubledArea(const Scene& scene, size_t t)
{
    glm::dvec2 p[3];
    for (int k = 0; k < 3; ++k) p[k] = glm::dvec2(scene.positions[scene.indices[3 * t + k]]);
    return (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x);
}

// The synthetic accuracy scenes are what they claim: the stated triangle counts, the same scene on
// every build (fixed seed), no triangle folded over its neighbours (one winding throughout, so that
// no two triangles overlap), neighbouring colours different, and every triangle double-sided.
TEST(StudyScenes, SyntheticScenesAreDeterministicAndUnfolded)
{
    auto fan = sliverFanScene();
    auto grid = jitteredGridScene();
    ASSERT_TRUE(fan.ok() && grid.ok());
    EXPECT_EQ(fan->triangleCount(), size_t(kSliverFanTriangles));
    EXPECT_EQ(grid->triangleCount(), size_t(2 * kJitterCells * kJitterCells));
    auto again = jitteredGridScene();
    ASSERT_TRUE(again.ok());
    EXPECT_EQ(again->positions, grid->positions);
    EXPECT_EQ(again->triMaterials, grid->triMaterials);
    for (const Scene* scene : {&*fan, &*grid}) {
        ASSERT_EQ(scene->triMaterials.size(), scene->triangleCount());
        const double first = doubledArea(*scene, 0);
        for (size_t t = 0; t < scene->triangleCount(); ++t) {
            EXPECT_GT(doubledArea(*scene, t) * first, 0.0) << t;
            EXPECT_EQ(scene->triFlags[t], TRI_FLAG_DOUBLE_SIDED) << t;
            if (t > 0) {
                EXPECT_NE(scene->triMaterials[t], scene->triMaterials[t - 1]) << t;
            }
        }
    }
    for (const std::string& name : studySceneNames()) {
        if (name == "bunny") continue;
        auto s = makeStudyScene(name, 32, 24, "");
        ASSERT_TRUE(s.ok()) << name << ": " << s.error().message;
        EXPECT_EQ(s->textured, name == "checker-grazing") << name;
    }
    EXPECT_FALSE(makeStudyScene("teapot", 32, 24, "").ok());
    EXPECT_EQ(studySceneNameFor(""), "builtin");
    EXPECT_EQ(studySceneNameFor("builtin:dense"), "dense");
    EXPECT_EQ(studySceneNameFor("study:sliver-fan"), "sliver-fan");
    EXPECT_EQ(studySceneNameFor("/usr/share/glmark2/models/bunny.obj"), "bunny");
}

// The first failing x per axis and method, walking the rows in their (stress) order.
TEST(StudyMarkdown, FirstFailureTable)
{
    nlohmann::json study = {{"accuracy", nlohmann::json::array()}, {"stability", nlohmann::json::array()}};
    auto add = [&](const char* axis, const char* method, double x, int cracks, nlohmann::json oracle) {
        study["stability"].push_back({{"axis", axis},
                                      {"method", method},
                                      {"backend", "vulkan"},
                                      {"x", x},
                                      {"cracks", cracks},
                                      {"double_hits", 0},
                                      {"wrong_depth_order", 0},
                                      {"oracle_mismatches", oracle}});
    };
    for (double x : {1.0, 2.0, 4.0, 8.0}) {
        add("magnitude", "fixed8", x, 0, 0);
        add("magnitude", "float", x, 0, x >= 4.0 ? 3 : 0);
        add("magnitude", "scanline", x, x >= 2.0 ? 1 : 0, nullptr);
    }
    const std::string md = studyMarkdown(study);
    EXPECT_NE(md.find("| axis | backend | fixed8 | float | scanline |\n|---|---|---|---|---|\n"
                      "| magnitude | vulkan | none up to 8 | 4 | 2 |\n"),
              std::string::npos)
        << md;
}

// A study on lavapipe that runs no group until the test names the one it checks: every group the
// study gains would otherwise run in each test that does not empty it.
StudyOptions lavapipeStudy()
{
    StudyOptions o;
    o.backends = {"vulkan"};
    o.scenes = {};
    o.axes = {};
    o.lodScenes = {};
    o.aoScenes = {};
    return o;
}

// fixed8 snaps to 1/256 px and breaks ties by the top-left rule, as Vulkan requires and lavapipe's
// rasterizer does: on a magnitude case that needs no clipping (the fan's rim within the viewport, x <=
// size / 4) the two draw the same primitive at every pixel. Beyond, the graphics pipeline may clip
// (lavapipe clips to the viewport, in float) where fixed8 does not, and the test claims nothing there.
TEST(StudyOracle, Fixed8MatchesTheGraphicsPipelineOnUnclippedMagnitudeCases)
{
    bool skip = false;
    if (!openBackend("vulkan", skip)) {
        if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
        FAIL() << "no vulkan device";
    }
    StudyOptions o = lavapipeStudy();
    o.axes = {"magnitude"};
    o.methods = {"fixed8"};
    o.stressSize = 32;
    auto study = runStudy(o);
    ASSERT_TRUE(study.ok()) << study.error().message;
    EXPECT_TRUE((*study)["accuracy"].empty());
    EXPECT_TRUE((*study)["lod"].empty());
    const nlohmann::json& rows = (*study)["stability"];
    ASSERT_EQ(rows.size(), 15u);
    size_t checked = 0;
    for (const auto& r : rows) {
        std::printf("[ oracle   ] magnitude x=%g: %s oracle mismatches\n", r["x"].get<double>(),
                    r["oracle_mismatches"].dump().c_str());
        EXPECT_EQ(r["method"], "fixed8");
        EXPECT_EQ(r["cracks"], 0) << r.dump();
        EXPECT_EQ(r["double_hits"], 0) << r.dump();
        ASSERT_TRUE(r["oracle_mismatches"].is_number()) << r.dump();
        if (r["x"].get<double>() <= o.stressSize / 4.0) {
            EXPECT_EQ(r["oracle_mismatches"], 0) << r.dump();
            ++checked;
        }
    }
    EXPECT_EQ(checked, 4u);  // x = 1, 2, 4, 8
    // Unknown names are usage errors, not empty studies.
    o.methods = {"fixed2"};
    EXPECT_FALSE(runStudy(o).ok());
    o.methods = {"fixed8"};
    o.scenes = {"teapot"};
    EXPECT_FALSE(runStudy(o).ok());
}

// Undirected edges of the mesh by the positions of their ends (bit for bit, as the level-of-detail
// hierarchy welds them), with the number of triangles using each.
std::map<std::pair<std::array<float, 3>, std::array<float, 3>>, int> positionEdges(const Scene& scene)
{
    std::map<std::pair<std::array<float, 3>, std::array<float, 3>>, int> edges;
    for (size_t t = 0; t < scene.triangleCount(); ++t)
        for (int k = 0; k < 3; ++k) {
            const glm::vec4 a = scene.positions[scene.indices[3 * t + k]];
            const glm::vec4 b = scene.positions[scene.indices[3 * t + (k + 1) % 3]];
            std::array<float, 3> pa{a.x, a.y, a.z}, pb{b.x, b.y, b.z};
            ++edges[pa < pb ? std::make_pair(pa, pb) : std::make_pair(pb, pa)];
        }
    return edges;
}

double totalArea(const Scene& scene)
{
    double area = 0.0;
    for (size_t t = 0; t < scene.triangleCount(); ++t) {
        const glm::dvec3 a(scene.positions[scene.indices[3 * t]]),
            b(scene.positions[scene.indices[3 * t + 1]]), c(scene.positions[scene.indices[3 * t + 2]]);
        area += 0.5 * glm::length(glm::cross(b - a, c - a));
    }
    return area;
}

// bunny-fine's subdivision: 16 triangles per triangle with their parent's flags, the surface's area
// unchanged (the midpoints lie on the parent triangles), one new vertex per edge of an indexed mesh (the
// midpoint shared by the edge's two triangles), unit normals, and a closed mesh still closed: every edge,
// by its ends' positions, in exactly two triangles. The same holds of the sphere with one vertex per
// corner and flat normals, as the OBJ loader gives the bunny: the two sides' midpoints are two vertices
// at the same position.
TEST(StudyLod, SubdivisionSplitsEveryTriangleIntoSixteenAndStaysClosed)
{
    Scene sphere = tessellatedSphere(6);
    for (size_t t = 0; t < sphere.triangleCount(); ++t)
        sphere.triFlags[t] = t % 3 == 0 ? TRI_FLAG_DOUBLE_SIDED : 0u;
    Scene corners;  // one vertex per corner, the face's normal
    for (size_t t = 0; t < sphere.triangleCount(); ++t) {
        const glm::vec3 a(sphere.positions[sphere.indices[3 * t]]),
            b(sphere.positions[sphere.indices[3 * t + 1]]), c(sphere.positions[sphere.indices[3 * t + 2]]);
        const glm::vec4 n(glm::normalize(glm::cross(b - a, c - a)), 0.0f);
        for (int k = 0; k < 3; ++k) {
            corners.positions.push_back(sphere.positions[sphere.indices[3 * t + k]]);
            corners.normals.push_back(n);
            corners.indices.push_back(uint32_t(3 * t + k));
        }
    }
    corners.triFlags = sphere.triFlags;
    ASSERT_TRUE(finalizeScene(corners, "corner sphere").ok());
    for (const Scene* scene : {&sphere, &corners}) {
        for (const auto& [edge, uses] : positionEdges(*scene)) ASSERT_EQ(uses, 2) << "the source is closed";
        auto once = subdivideMidpoints(*scene, 1);
        auto fine = subdivideMidpoints(*scene, kLodFineSubdivisions);
        ASSERT_TRUE(once.ok() && fine.ok());
        ASSERT_EQ(fine->triangleCount(), 16 * scene->triangleCount());
        EXPECT_NEAR(totalArea(*fine), totalArea(*scene), 1e-5 * totalArea(*scene));
        for (size_t t = 0; t < fine->triangleCount(); ++t)
            ASSERT_EQ(fine->triFlags[t], scene->triFlags[t / 16]) << t;
        for (const glm::vec4& n : fine->normals) ASSERT_NEAR(glm::length(glm::vec3(n)), 1.0f, 1e-5f);
        for (const auto& [edge, uses] : positionEdges(*fine)) ASSERT_EQ(uses, 2) << "a crack or a T-junction";
        std::set<std::pair<uint32_t, uint32_t>> indexEdges;
        for (size_t t = 0; t < scene->triangleCount(); ++t)
            for (int k = 0; k < 3; ++k) {
                const uint32_t a = scene->indices[3 * t + k], b = scene->indices[3 * t + (k + 1) % 3];
                indexEdges.insert({std::min(a, b), std::max(a, b)});
            }
        EXPECT_EQ(once->vertexCount(), scene->vertexCount() + indexEdges.size());
    }
    EXPECT_FALSE(makeLodScene("teapot", 8, "").ok());
    EXPECT_FALSE(makeLodScene("bunny", 8, "/nonexistent/bunny.obj").ok());
    auto small = makeLodScene("sphere", 8, "");
    ASSERT_TRUE(small.ok());
    EXPECT_EQ(small->triangleCount(), tessellatedSphere(8).triangleCount());
}

// An AOV of w x h pixels, covered (id 0, depth 0.5) where `inside(x, y)`.
template <typename Inside>
AovImage squareAov(uint32_t w, uint32_t h, Inside inside)
{
    AovImage aov;
    aov.width = w;
    aov.height = h;
    aov.id.assign(size_t(w) * h, EMPTY_ID);
    aov.depth.assign(size_t(w) * h, 1.0f);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x)
            if (inside(int(x), int(y))) {
                aov.id[size_t(y) * w + x] = 0;
                aov.depth[size_t(y) * w + x] = 0.5f;
            }
    return aov;
}

// The comparison with --lod off on a hand-made pair: an 11 x 11 square moved one pixel right (both of
// its changed columns on the silhouette), a hole in its middle and a speck two pixels outside it (both
// beyond the 1-pixel band), and one pixel deeper.
TEST(StudyLod, ImageDiffCountsCoverageBeyondTheSilhouetteAndDepth)
{
    auto square = [](int x0) {
        return [x0](int x, int y) { return x >= x0 && x <= x0 + 10 && y >= 2 && y <= 12; };
    };
    const AovImage baseline = squareAov(16, 16, square(2));
    AovImage image = squareAov(16, 16, square(3));
    LodImageDiff same = lodImageDiff(baseline, baseline);
    EXPECT_EQ(same.coveragePx, 0u);
    EXPECT_EQ(same.bothCoveredPx, 121u);
    EXPECT_EQ(same.depthMaxError, 0.0);
    EXPECT_EQ(same.silhouettePx, 40u + 44u);  // the square's rim inside, and the pixels just outside
    LodImageDiff moved = lodImageDiff(image, baseline);
    EXPECT_EQ(moved.coveragePx, 22u);
    EXPECT_EQ(moved.beyondSilhouettePx, 0u);
    image.id[7 * 16 + 7] = EMPTY_ID;  // a hole
    image.id[15 * 16 + 0] = 0;        // a speck 2 rows below the rim's outer band
    image.depth[8 * 16 + 8] = 0.75f;
    LodImageDiff d = lodImageDiff(image, baseline);
    EXPECT_EQ(d.coveragePx, 24u);
    EXPECT_EQ(d.beyondSilhouettePx, 2u);
    EXPECT_EQ(d.bothCoveredPx, 109u);  // 10 columns x 11 rows, less the hole
    EXPECT_DOUBLE_EQ(d.depthMaxError, 0.25);
    EXPECT_DOUBLE_EQ(d.depthMeanError, 0.25 / 109.0);
}

TEST(StudyLod, ParseLodErrors)
{
    auto errors = parseLodErrors("0.25,0.5,1,2,4");
    ASSERT_TRUE(errors.ok());
    EXPECT_EQ(*errors, (std::vector<float>{0.25f, 0.5f, 1.0f, 2.0f, 4.0f}));
    auto none = parseLodErrors("");
    ASSERT_TRUE(none.ok());
    EXPECT_TRUE(none->empty());
    for (const char* bad : {"abc", "0", "1,-2", "4096"}) {
        auto e = parseLodErrors(bad);
        ASSERT_FALSE(e.ok()) << bad;
        EXPECT_TRUE(isOneLine(e.error().message)) << e.error().message;
    }
}

// The level-of-detail group on lavapipe at 128 x 96: a row per scene, camera and error after each
// camera's --lod off baseline, which matches itself exactly and has a finite PSNR against its SSAA
// reference (the floor the others compare with); larger errors and the far camera draw fewer
// triangles; and on the closed sphere every pixel whose coverage differs from --lod off lies within 1
// pixel of its silhouette (no hole or flap inside the outline). The bunny joins when its file is there.
TEST(StudyLod, GroupOnLavapipeDrawsFewerTrianglesAndKeepsTheSphereClosed)
{
    bool skip = false;
    if (!openBackend("vulkan", skip)) {
        if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
        FAIL() << "no vulkan device";
    }
    StudyOptions o = lavapipeStudy();
    o.width = 128;
    o.height = 96;
    o.warmup = 0;
    o.repeat = 1;
    o.lodScenes = {"sphere", "bunny"};
    o.lodRings = 24;
    o.lodErrors = {0.5f, 4.0f};
    auto study = runStudy(o);
    ASSERT_TRUE(study.ok()) << study.error().message;
    std::printf("%s", studyMarkdown(*study).c_str());
    std::vector<std::string> scenes = {"sphere"};
    if (std::filesystem::exists(o.bunnyPath)) scenes.push_back("bunny");
    const nlohmann::json& rows = (*study)["lod"];
    ASSERT_EQ(rows.size(), scenes.size() * 2 * (1 + o.lodErrors.size()));
    EXPECT_TRUE((*study)["lod_depth"].is_string());
    size_t i = 0;
    std::map<std::pair<std::string, std::string>, std::vector<uint64_t>> triangles;  // (scene, camera)
    for (const std::string& scene : scenes)
        for (const char* camera : {"near", "far"}) {
            const nlohmann::json& off = rows[i++];
            EXPECT_EQ(off["scene"], scene);
            EXPECT_EQ(off["camera"], camera);
            EXPECT_EQ(off["error_px"], "off");
            EXPECT_EQ(off["coverage_px"], 0) << off.dump();
            EXPECT_EQ(off["depth_max_error"], 0.0) << off.dump();
            EXPECT_EQ(off["psnr_vs_off"], "inf") << off.dump();
            EXPECT_TRUE(off["psnr_vs_reference"].is_number()) << off.dump();
            EXPECT_EQ(off["triangles"], off["scene_triangles"]) << off.dump();
            EXPECT_GT(off["baseline_silhouette_px"].get<uint64_t>(), 20u) << off.dump();
            std::vector<uint64_t>& drawn = triangles[{scene, camera}];
            drawn.push_back(off["triangles"].get<uint64_t>());
            for (float error : o.lodErrors) {
                const nlohmann::json& r = rows[i++];
                EXPECT_EQ(r["scene"], scene);
                EXPECT_EQ(r["camera"], camera);
                ASSERT_TRUE(r["error_px"].is_number()) << r.dump();
                EXPECT_EQ(r["error_px"].get<float>(), error);
                EXPECT_LE(r["triangles"].get<uint64_t>(), drawn.back())
                    << "a larger error drew more: " << r.dump();
                drawn.push_back(r["triangles"].get<uint64_t>());
                EXPECT_GE(r["visibility_ms"].get<double>(), 0.0) << r.dump();
                EXPECT_LE(r["visibility_ms"].get<double>(), r["ms"].get<double>()) << r.dump();
                EXPECT_LE(r["beyond_silhouette_px"].get<uint64_t>(), r["coverage_px"].get<uint64_t>());
                if (scene == "sphere") {
                    EXPECT_EQ(r["beyond_silhouette_px"], 0)
                        << "a hole or flap inside the sphere: " << r.dump();
                }
            }
        }
    for (const std::string& scene : scenes) {
        const std::vector<uint64_t>& nearer = triangles[{scene, "near"}];
        const std::vector<uint64_t>& farther = triangles[{scene, "far"}];
        EXPECT_EQ(nearer[0], farther[0]) << scene << ": --lod off draws every triangle from anywhere";
        for (size_t e = 1; e < nearer.size(); ++e)
            EXPECT_LT(farther[e], nearer[e]) << scene << " at " << o.lodErrors[e - 1] << " px";
    }
    const std::vector<uint64_t>& farSphere = triangles[{"sphere", "far"}];
    EXPECT_LT(farSphere.back(), farSphere.front() / 4) << "the far sphere at 4 px draws a coarse level";
    o.lodScenes = {"teapot"};
    EXPECT_FALSE(runStudy(o).ok());
}

// The ambient-occlusion group on lavapipe: a row per setting of the sweep and scene, each against the
// reference at its radius, and what docs/ambient-occlusion.md claims of it:
//   more slices and steps bring GTAO closer to the reference on the stress scene from both cameras (4 x 8
//   beats 1 x 2);
//   the denoise filter lowers the error at 1 and 2 slices, where the 4 x 4 pattern's noise is the larger
//   error (with 3 and 4 slices the noise is small and on the built-in scene's few-pixel objects the
//   filter's blur costs more than it removes: not asserted either way);
// and the stress scene's failure cases pinned (present, and no worse than measured):
//   thin objects and depth discontinuities: GTAO takes the thin plate and post, and the floating box, as
//   solid behind what it sees, so next to them it is off by over 0.2 somewhere at the default setting;
//   a larger radius reaches more of what the depth buffer hides: at twice the radius the grazing view's
//   mean error is over twice the default's.
TEST(StudyAo, TheGroupMeasuresGtaoAgainstTheReference)
{
    bool skip = false;
    if (!openBackend("vulkan", skip)) {
        if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
        FAIL() << "no vulkan device";
    }
    StudyOptions o = lavapipeStudy();
    o.aoScenes = {"builtin", "stress-grazing", "stress-near"};
    o.width = 96;
    o.height = 72;
    o.warmup = 0;
    o.repeat = 1;
    auto study = runStudy(o);
    ASSERT_TRUE(study.ok()) << study.error().message;
    std::printf("%s", studyMarkdown(*study).c_str());
    const nlohmann::json& rows = (*study)["ao"];
    ASSERT_EQ(rows.size(), o.aoScenes.size() * aoStudySettings().size());
    auto error = [&](const std::string& scene, int slices, int steps, bool denoise) {
        for (const auto& r : rows)
            if (r["scene"] == scene && r["slices"] == slices && r["steps"] == steps &&
                r["denoise"] == denoise && r["radius_scale"].get<double>() == 1.0)
                return r["mean_error"].get<double>();
        ADD_FAILURE() << "no row " << scene << " " << slices << "x" << steps;
        return 0.0;
    };
    for (const auto& r : rows) {
        EXPECT_GT(r["pixels"].get<uint64_t>(), 1000u) << r.dump();
        EXPECT_GE(r["psnr"].get<double>(), 10.0) << r.dump();
    }
    for (const char* scene : {"stress-grazing", "stress-near"})
        EXPECT_LT(error(scene, 4, 8, true), error(scene, 1, 2, true)) << scene;
    for (const std::string& scene : o.aoScenes)
        for (int slices : {1, 2})
            for (int steps : {2, 4, 8})
                EXPECT_LT(error(scene, slices, steps, true), error(scene, slices, steps, false))
                    << scene << " " << slices << "x" << steps;
    auto row = [&](const std::string& scene, double radiusScale) {
        for (const auto& r : rows)
            if (r["scene"] == scene && r["slices"] == RenderSettings{}.aoSlices &&
                r["steps"] == RenderSettings{}.aoSteps && r["denoise"] == true &&
                r["radius_scale"].get<double>() == radiusScale)
                return r;
        ADD_FAILURE() << "no default row " << scene;
        return nlohmann::json{};
    };
    const nlohmann::json grazing = row("stress-grazing", 1.0);
    EXPECT_GT(grazing["max_error"].get<double>(), 0.2);
    EXPECT_LT(grazing["mean_error"].get<double>(), 0.04);
    EXPECT_GT(row("stress-grazing", 2.0)["mean_error"].get<double>(),
              2.0 * grazing["mean_error"].get<double>());
    o.aoScenes = {"teapot"};
    EXPECT_FALSE(runStudy(o).ok());
}

INSTANTIATE_TEST_SUITE_P(Backends, StudyClaimsTest, ::testing::Values("vulkan", "cuda"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace sr::test
