// tessellate_test.cpp - adaptive tessellation (--tessellate, common/shared/tessellate.h).
//
// The pattern is checked on its own against geometry (every factor triple tiles the triangle exactly,
// conforming: each edge cut into its factor's pieces, every inner edge shared by two triangles); each
// backend's generated mesh against the host's run of the same stages, bit for bit; and the rendered
// result against what rasterizers get wrong: cracks and overlaps (hit counts of closed meshes with
// neighbours of different factors), coverage that flat tessellation must not change, and pn's
// silhouette against the analytic sphere.
#include <cmath>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "study/study_runner.h"
#include "render/tessellate.h"
#include "camera/camera.h"
#include "study/scenes.h"
#include "shared/tess_emit.h"
#include "test_util.h"
#include "vulkan/vulkan_graphics.h"

namespace sr::test {
namespace {

// The orbit camera orbit:AZ,EL,DIST around `scene` at width x height.
CameraMatrices orbitCamera(const Scene& scene, const std::string& spec, uint32_t width, uint32_t height)
{
    auto parsed = parseCameraSpec(spec);
    EXPECT_TRUE(parsed.ok());
    auto camera = resolveCamera(*parsed, scene, width, height);
    EXPECT_TRUE(camera.ok()) << (camera.ok() ? "" : camera.error().message);
    return camera.ok() ? *camera : CameraMatrices{};
}

RenderSettings tessSettings(uint32_t mode, float edgePx, uint32_t maxLevel, uint32_t width = 128,
                            uint32_t height = 128)
{
    RenderSettings s = testSettings(width, height);
    s.tessellate = mode;
    s.tessEdgePx = edgePx;
    s.tessMaxLevel = maxLevel;
    return s;
}

// One triangle's generated mesh for the factor triple (f0, f1, f2), on the host, in barycentric
// coordinates: the triangle is (0,0), (1,0), (0,1) in the plane z = 0.
struct PatternMesh {
    std::vector<glm::vec4> positions;  // 3 corners, then the new vertices
    std::vector<uint32_t> indices;
};

PatternMesh pattern(uint32_t f0, uint32_t f1, uint32_t f2)
{
    Scene scene;
    scene.positions = {{0, 0, 0, 1}, {1, 0, 0, 1}, {0, 1, 0, 1}};
    scene.normals = {{0, 0, 1, 0}, {0, 0, 1, 0}, {0, 0, 1, 0}};
    scene.indices = {0, 1, 2};
    scene.triFlags = {0};
    RasterParams params{};
    params.tessMode = TESS_FLAT;
    params.tessSourceVertices = 3;
    TessSources sources = tessSources(scene);
    uint32_t factors = f0 | f1 << 8 | f2 << 16;
    uvec2 counts = tessCounts(TESS_FLAT, factors, 0);
    PatternMesh mesh;
    mesh.positions = scene.positions;
    mesh.positions.resize(3 + counts.x, glm::vec4(NAN));
    mesh.indices.assign(3 * counts.y, UINT32_MAX);
    std::vector<glm::vec4> normals(mesh.positions.size());
    std::vector<uint32_t> flags(counts.y), ids(counts.y);
    TessWriter w{};
    w.positions = mesh.positions.data();
    w.normals = normals.data();
    w.indices = mesh.indices.data();
    w.triFlags = flags.data();
    w.ids = ids.data();
    w.sources = sources.sources.data();
    w.sourceVertices = 3;
    TessVertex v0{scene.positions[0], scene.normals[0], glm::vec4(0), glm::vec4(1)};
    TessVertex v1{scene.positions[1], scene.normals[1], glm::vec4(0), glm::vec4(1)};
    TessVertex v2{scene.positions[2], scene.normals[2], glm::vec4(0), glm::vec4(1)};
    TessPatch patch = tessMakePatch(params.tessMode, v0, v1, v2, sources.sources[0].flags);
    uint32_t state = (f0 | f1 | f2) == 1 ? TESS_STATE_PASS : 0u;
    tessEmitTriangle(params, sources.sources[0], patch, 0, uvec4(0, 0, factors, state), 3, 0, w);
    return mesh;
}

double signedArea(const glm::vec4& a, const glm::vec4& b, const glm::vec4& c)
{
    return 0.5 * (double(b.x - a.x) * double(c.y - a.y) - double(b.y - a.y) * double(c.x - a.x));
}

// Every factor triple up to 7, and some larger: the counts match the formulas, every vertex is written,
// every triangle keeps the source's orientation (no fold; zero-area pieces would be a waste, there are
// none), the areas add up to the triangle's, and the mesh is conforming: each source edge is cut into
// exactly its factor's equal pieces and every other edge has two triangles, one on each side.
TEST(TessellationPattern, EveryFactorTripleTilesTheTriangleConformingly)
{
    std::vector<glm::uvec3> triples;
    for (uint32_t a = 1; a <= 7; ++a)
        for (uint32_t b = 1; b <= 7; ++b)
            for (uint32_t c = 1; c <= 7; ++c) triples.push_back({a, b, c});
    triples.push_back({64, 1, 1});
    triples.push_back({64, 64, 64});
    triples.push_back({13, 40, 2});
    for (const glm::uvec3& f : triples) {
        SCOPED_TRACE(testing::Message() << "factors " << f.x << " " << f.y << " " << f.z);
        PatternMesh mesh = pattern(f.x, f.y, f.z);
        uint32_t n = std::max({f.x, f.y, f.z});
        uint32_t m = n > 3 ? n - 3 : 0;
        size_t wantTris = n == 1 ? 1 : m * m + 3 * m + f.x + f.y + f.z;
        ASSERT_EQ(mesh.indices.size(), 3 * wantTris);
        for (const glm::vec4& p : mesh.positions) ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y));
        double area = 0.0;
        std::map<std::pair<uint32_t, uint32_t>, int> directed;
        for (size_t t = 0; t < wantTris; ++t) {
            uint32_t a = mesh.indices[3 * t], b = mesh.indices[3 * t + 1], c = mesh.indices[3 * t + 2];
            ASSERT_LT(std::max({a, b, c}), mesh.positions.size());
            double s = signedArea(mesh.positions[a], mesh.positions[b], mesh.positions[c]);
            ASSERT_GT(s, 1e-9) << "triangle " << t << " folds or collapses";
            area += s;
            for (auto e : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) ++directed[e];
        }
        EXPECT_NEAR(area, 0.5, 1e-5);
        // Boundary: the directed edges with no twin lie on the source edges and cut each into f pieces.
        uint32_t pieces[3] = {0, 0, 0};
        for (const auto& [e, count] : directed) {
            ASSERT_EQ(count, 1) << "edge used twice in one direction: overlapping triangles";
            if (directed.count({e.second, e.first})) continue;
            const glm::vec4 &p = mesh.positions[e.first], &q = mesh.positions[e.second];
            int edge = p.y == 0 && q.y == 0 ? 0 : p.x == 0 && q.x == 0 ? 2 : 1;
            if (edge == 1) {
                ASSERT_NEAR(p.x + p.y, 1.0f, 1e-6f) << "an unmatched edge inside the triangle";
            }
            double len = std::hypot(double(q.x - p.x), double(q.y - p.y));
            double full = edge == 1 ? std::sqrt(2.0) : 1.0;
            uint32_t fe = edge == 0 ? f.x : edge == 1 ? f.y : f.z;
            EXPECT_NEAR(len, full / fe, 1e-5);
            ++pieces[edge];
        }
        EXPECT_EQ(pieces[0], f.x);
        EXPECT_EQ(pieces[1], f.y);
        EXPECT_EQ(pieces[2], f.z);
    }
}

// The centroid baseline: 3^N triangles, (3^N - 1) / 2 new vertices, areas adding up.
TEST(TessellationPattern, CentroidSplitsThreeWaysPerLevel)
{
    for (uint32_t level = 1; level <= 4; ++level) {
        uvec2 counts = tessCounts(TESS_CENTROID, 0, level);
        EXPECT_EQ(counts.y, uint32_t(std::pow(3, level)));
        EXPECT_EQ(counts.x, (counts.y - 1) / 2);
    }
}

// Per backend.
class TessellationTest : public BackendTest {
protected:
    // The device's generated mesh after a render: frame vertices and triangles, and the source ids.
    void expectMatchesHost(const Scene& scene, const CameraMatrices& camera, const RenderSettings& s)
    {
        auto session = RenderSession::create(*device_, scene);
        ASSERT_TRUE(session.ok());
        auto out = session->render(camera, s);
        ASSERT_TRUE(out.ok()) << out.error().message;
        TessellatedScene host = tessellateOnHost(scene, tessSources(scene), out->params);
        ASSERT_EQ(out->stats.tessTriangles, host.scene.triangleCount());
        ASSERT_EQ(out->stats.tessVertices, host.scene.vertexCount() - scene.vertexCount());
        ASSERT_EQ(out->stats.tessCulled, host.culled);
        ASSERT_GT(out->stats.tessTriangles, scene.triangleCount() / 2);
        std::vector<glm::vec4> positions(host.scene.vertexCount()), normals(host.scene.vertexCount());
        std::vector<uint32_t> indices(host.scene.indices.size()), ids(host.sourceIds.size());
        ASSERT_TRUE(device_->download(BUF_POSITIONS, positions.data(), positions.size() * 16).ok());
        ASSERT_TRUE(device_->download(BUF_NORMALS, normals.data(), normals.size() * 16).ok());
        ASSERT_TRUE(device_->download(BUF_INDICES, indices.data(), indices.size() * 4).ok());
        ASSERT_TRUE(device_->download(BUF_TESS_IDS, ids.data(), ids.size() * 4).ok());
        EXPECT_EQ(indices, host.scene.indices);
        EXPECT_EQ(ids, host.sourceIds);
        size_t positionMismatches = 0, normalMismatches = 0;
        for (size_t i = 0; i < positions.size(); ++i) {
            positionMismatches += std::memcmp(&positions[i], &host.scene.positions[i], 16) != 0;
            // Normals only shade (a driver's sqrt and division may differ in the last bits).
            normalMismatches += glm::length(glm::vec3(normals[i] - host.scene.normals[i])) > 1e-4f;
        }
        EXPECT_EQ(positionMismatches, 0u) << "positions must be bit-identical (watertightness, ids)";
        EXPECT_EQ(normalMismatches, 0u);
    }
};

TEST_P(TessellationTest, GeneratedMeshIsTheHostsBitForBit)
{
    Scene lowpoly = *builtinSceneNamed("builtin:lowpoly");
    for (uint32_t mode : {TESS_FLAT, TESS_PN}) {
        SCOPED_TRACE(mode == TESS_FLAT ? "flat" : "pn");
        expectMatchesHost(lowpoly, orbitCamera(lowpoly, "orbit:30,25,4", 160, 120),
                          tessSettings(mode, 6.0f, 16, 160, 120));
    }
    expectMatchesHost(lowpoly, orbitCamera(lowpoly, "orbit:30,25,4", 160, 120),
                      tessSettings(TESS_CENTROID, 8.0f, 2, 160, 120));
}

// Centroid tessellation at its deepest level: 3^8 triangles from each scene triangle, all emitted by one
// invocation of tess_emit, whose loops take about 48,000 turns (docs/benchmark.md, "Loops on a CPU
// device": llvmpipe 22.3 ends an invocation's loops after 65,535 turns in all; with 3^k computed in a
// loop, levels 7 and 8 went past that and lost vertices and triangles silently).
TEST_P(TessellationTest, CentroidAtItsDeepestLevelIsTheHostsBitForBit)
{
    Scene lowpoly = *builtinSceneNamed("builtin:lowpoly");
    expectMatchesHost(lowpoly, orbitCamera(lowpoly, "orbit:30,25,4", 96, 64),
                      tessSettings(TESS_CENTROID, 8.0f, TESS_MAX_CENTROID, 96, 64));
}

// A closed low-poly sphere filling most of the view, back faces culled: every pixel of it is covered
// exactly once (no overlap) and no uncovered pixel is enclosed by it (no crack), with triangles whose
// three edges chose different factors.
TEST_P(TessellationTest, ClosedMeshStaysWatertightAcrossDifferentFactors)
{
    Scene sphere = tessellatedSphere(5);
    const uint32_t w = 128, h = 128;
    CameraMatrices camera = orbitCamera(sphere, "orbit:20,30,3", w, h);
    for (uint32_t mode : {TESS_OFF, TESS_FLAT, TESS_PN}) {
        SCOPED_TRACE(mode == TESS_FLAT ? "flat" : mode == TESS_OFF ? "off" : "pn");
        RenderSettings s = tessSettings(mode, 5.0f, 16, w, h);
        s.cullMode = CULL_BACK;
        s.countHits = true;
        RenderOutput out = render(sphere, s, camera);
        ASSERT_EQ(out.hitCount.size(), size_t(w) * h);
        // Mixed factors within triangles (so neighbours differ), from the host's decisions.
        RasterParams p = out.params;
        TessSources src = tessSources(sphere);
        size_t mixed = 0;
        std::set<uint32_t> levels;
        for (const TessSource& t : src.sources) {
            TessVertex v[3];
            uint32_t corner[3] = {t.i0, t.i1, t.i2};
            for (int k = 0; k < 3; ++k)
                v[k] = {sphere.positions[corner[k]], sphere.normals[corner[k]], {}, {1, 1, 1, 1}};
            uvec4 e = tessCountTriangle(p, tessMakePatch(p.tessMode, v[0], v[1], v[2], t.flags));
            if (e.w != 0) continue;
            uint32_t f0 = tessFactor(e.z, 0), f1 = tessFactor(e.z, 1), f2 = tessFactor(e.z, 2);
            mixed += f0 != f1 || f1 != f2;
            levels.insert(f0);
        }
        EXPECT_GT(mixed, 20u);
        EXPECT_GE(levels.size(), 3u);
        // Overlaps, then enclosed holes: flood the uncovered pixels from the border.
        // pn may cover a pixel twice where its cubic patch folds over at the silhouette (a ray entering
        // the surface twice), never inside it; flat never.
        auto nearSilhouette = [&](uint32_t x, uint32_t y) {
            for (int dy = -2; dy <= 2; ++dy)
                for (int dx = -2; dx <= 2; ++dx) {
                    int nx = int(x) + dx, ny = int(y) + dy;
                    if (nx >= 0 && ny >= 0 && nx < int(w) && ny < int(h) &&
                        out.hitCount[size_t(ny) * w + nx] == 0)
                        return true;
                }
            return false;
        };
        size_t covered = 0, folds = 0;
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                uint32_t c = out.hitCount[size_t(y) * w + x];
                covered += c > 0;
                if (c <= 1) continue;
                ++folds;
                EXPECT_TRUE(mode == TESS_PN && nearSilhouette(x, y))
                    << "pixel (" << x << ", " << y << ") covered " << c << " times: overlapping triangles";
            }
        std::printf("[ watertight ] mode %u: %zu pixels covered, %zu covered twice at the silhouette\n", mode,
                    covered, folds);
        EXPECT_GT(covered, size_t(w) * h / 3);
        std::vector<uint8_t> outside(size_t(w) * h, 0);
        std::vector<std::pair<uint32_t, uint32_t>> stack;
        for (uint32_t x = 0; x < w; ++x) stack.push_back({x, 0}), stack.push_back({x, h - 1});
        for (uint32_t y = 0; y < h; ++y) stack.push_back({0, y}), stack.push_back({w - 1, y});
        while (!stack.empty()) {
            auto [x, y] = stack.back();
            stack.pop_back();
            size_t i = size_t(y) * w + x;
            if (out.hitCount[i] != 0 || outside[i]) continue;
            outside[i] = 1;
            if (x > 0) stack.push_back({x - 1, y});
            if (x + 1 < w) stack.push_back({x + 1, y});
            if (y > 0) stack.push_back({x, y - 1});
            if (y + 1 < h) stack.push_back({x, y + 1});
        }
        size_t holes = 0;
        for (size_t i = 0; i < outside.size(); ++i) holes += out.hitCount[i] == 0 && !outside[i];
        EXPECT_EQ(holes, 0u) << "uncovered pixels inside the sphere: cracks";
    }
}

// flat keeps the surface: the id AOV (mapped back to the scene's triangles) and the coverage equal the
// untessellated render's, except at pixels next to a scene triangle's edge, where the split edges'
// points (interpolated in world space, then projected and snapped on their own) may move a sample
// across by a rounding step. Depth differs by float rounding only.
TEST_P(TessellationTest, FlatKeepsCoverageExceptAlongSceneEdges)
{
    FramedScene f = framedBuiltin(160, 120);
    RenderOutput plain = render(f.scene, f.settings, f.camera);
    RenderSettings s = f.settings;
    s.tessellate = TESS_FLAT;
    s.tessEdgePx = 4.0f;
    RenderOutput tess = render(f.scene, s, f.camera);
    ASSERT_GT(tess.stats.tessTriangles, 2 * f.scene.triangleCount() / 3);
    const uint32_t w = 160, h = 120;
    size_t edgePixels = 0, mismatches = 0;
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            size_t i = size_t(y) * w + x;
            bool nearEdge = false;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    int nx = int(x) + dx, ny = int(y) + dy;
                    if (nx < 0 || ny < 0 || nx >= int(w) || ny >= int(h)) continue;
                    nearEdge = nearEdge || plain.aov.id[size_t(ny) * w + nx] != plain.aov.id[i];
                }
            edgePixels += nearEdge;
            if (tess.aov.id[i] != plain.aov.id[i]) {
                ++mismatches;
                EXPECT_TRUE(nearEdge) << "id changed at (" << x << ", " << y << ") away from any edge";
            } else if (plain.aov.id[i] != EMPTY_ID) {
                // Depth interpolates from the snapped vertices: the pieces' planes shift by up to a
                // subpixel's worth of the depth gradient (2e-4 covers the grazing ground at 160 px).
                EXPECT_NEAR(tess.aov.depth[i], plain.aov.depth[i], 2e-4f);
            }
        }
    EXPECT_LT(mismatches, edgePixels / 20 + 1) << mismatches << " of " << edgePixels << " edge pixels";
}

// pn on a coarse sphere with its exact normals: the silhouette approaches the sphere's as the target
// edge length falls, from the polygon's error to the cubic patch's own. The sphere of radius 1 seen from
// distance D covers the disc of radius tan(asin(1 / D)) * P11 * H / 2 pixels about the centre (P11 the
// projection's y scale).
TEST_P(TessellationTest, PnSilhouetteConvergesToTheSphere)
{
    Scene sphere = tessellatedSphere(3);
    const uint32_t w = 128, h = 128;
    const float D = 3.0f;
    CameraMatrices camera = orbitCamera(sphere, "orbit:10,20,3", w, h);
    const double r = std::tan(std::asin(1.0 / D)) * camera.clipFromView[1][1] * h / 2.0;
    const double disc = M_PI * r * r;
    auto coverageError = [&](uint32_t mode, float edgePx) {
        RenderOutput out = render(sphere, tessSettings(mode, edgePx, 64, w, h), camera);
        size_t covered = 0;
        for (uint32_t id : out.aov.id) covered += id != EMPTY_ID;
        return std::abs(double(covered) - disc) / disc;
    };
    const double untessellated = coverageError(TESS_OFF, 8.0f);
    double previous = untessellated;
    for (float edgePx : {32.0f, 8.0f, 2.0f}) {
        double e = coverageError(TESS_PN, edgePx);
        std::printf("[ pn silhouette ] L = %g: relative area error %.4f (untessellated %.4f)\n", edgePx, e,
                    untessellated);
        EXPECT_LT(e, previous);
        previous = e;
    }
    // The limit is the pn surface's own silhouette, not the sphere: on this sphere of 60-degree facets
    // each edge's cubic dips 2.6% below the circle at its middle (computed from the control points of
    // a 60-degree arc), so the area keeps a few percent of error; the polygon's is 23%.
    EXPECT_GT(untessellated, 0.15);
    EXPECT_LT(previous, untessellated / 3.0);
    // flat only splits: the polygon's silhouette stays.
    EXPECT_NEAR(coverageError(TESS_FLAT, 2.0f), untessellated, 0.01);
}

// A triangle with a zero normal and one with a NaN normal fall back to flat (their generated vertices
// stay in their planes), with a warning; the smooth neighbour keeps its shared edges straight.
TEST_P(TessellationTest, BadNormalsFallBackToFlat)
{
    Scene scene = tessellatedSphere(3);
    scene.normals[scene.indices[0]] = glm::vec4(0.0f);
    scene.normals[scene.indices[30]] = glm::vec4(NAN, 0.0f, 1.0f, 0.0f);
    TessSources src = tessSources(scene);
    EXPECT_GE(src.flatPatches, 2u);
    EXPECT_NE(src.sources[0].flags & TESS_FLAT_PATCH, 0u);
    CameraMatrices camera = orbitCamera(scene, "orbit:10,20,3", 128, 128);
    RenderSettings s = tessSettings(TESS_PN, 4.0f, 16);
    testing::internal::CaptureStderr();
    RenderOutput out = render(scene, s, camera);
    std::string err = testing::internal::GetCapturedStderr();
    EXPECT_NE(err.find("pn tessellation keeps them flat"), std::string::npos) << err;
    TessellatedScene host = tessellateOnHost(scene, src, out.params);
    for (size_t t = 0; t < host.sourceIds.size(); ++t) {
        uint32_t source = host.sourceIds[t];
        if ((src.sources[source].flags & TESS_FLAT_PATCH) == 0) continue;
        glm::vec3 a(scene.positions[src.sources[source].i0]), b(scene.positions[src.sources[source].i1]),
            c(scene.positions[src.sources[source].i2]);
        glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
        for (int k = 0; k < 3; ++k) {
            glm::vec3 p(host.scene.positions[host.scene.indices[3 * t + k]]);
            EXPECT_NEAR(glm::dot(p - a, n), 0.0f, 1e-5f);
        }
    }
}

// A session alternating tessellated and plain frames, with the generated buffers growing as the camera
// comes closer, draws every frame as a fresh render does.
TEST_P(TessellationTest, SessionFramesEqualFreshRenders)
{
    Scene lowpoly = *builtinSceneNamed("builtin:lowpoly");
    auto session = RenderSession::create(*device_, lowpoly);
    ASSERT_TRUE(session.ok());
    struct Frame {
        const char* camera;
        uint32_t mode;
    };
    const Frame frames[] = {{"orbit:30,25,8", TESS_PN},
                            {"orbit:30,25,3", TESS_PN},
                            {"orbit:30,25,3", TESS_OFF},
                            {"orbit:50,15,2.5", TESS_FLAT},
                            {"orbit:30,25,3", TESS_OFF}};
    std::vector<RenderOutput> fromSession;
    for (const Frame& f : frames) {
        auto out =
            session->render(orbitCamera(lowpoly, f.camera, 96, 96), tessSettings(f.mode, 6.0f, 16, 96, 96));
        ASSERT_TRUE(out.ok()) << out.error().message;
        fromSession.push_back(std::move(*out));
    }
    EXPECT_GT(fromSession[1].stats.tessTriangles, fromSession[0].stats.tessTriangles);
    for (size_t k = 0; k < std::size(frames); ++k) {
        SCOPED_TRACE(frames[k].camera);
        RenderOutput fresh = render(lowpoly, tessSettings(frames[k].mode, 6.0f, 16, 96, 96),
                                    orbitCamera(lowpoly, frames[k].camera, 96, 96));
        EXPECT_EQ(fromSession[k].aov.id, fresh.aov.id);
        EXPECT_EQ(fromSession[k].aov.depth, fresh.aov.depth);
        EXPECT_EQ(fromSession[k].color.pixels, fresh.color.pixels);
    }
}

// The study's tessellation group on lowpoly-sphere (what its Pareto chart plots): against the smooth
// sphere, pn's silhouette error and PSNR improve as the edge length falls, and beat no tessellation,
// flat and the centroid baseline, which keep the polygon's silhouette.
TEST_P(TessellationTest, StudyShowsPnErrorFallingWithEdgeLength)
{
    auto scene = makeStudyScene("lowpoly-sphere", 96, 96, "");
    ASSERT_TRUE(scene.ok());
    RenderSettings base = testSettings(96, 96);
    base.cullMode = CULL_BACK;
    // The study renders through the library: a device of the library's own, on the same backend.
    auto device =
        raster::Device::open(GetParam() == "cuda" ? raster::Backend::Cuda : raster::Backend::Vulkan);
    ASSERT_TRUE(device.ok()) << device.error().message;
    auto rows = measureAccuracy(*device, *scene, base, {"fixed8"});
    ASSERT_TRUE(rows.ok()) << rows.error().message;
    std::map<std::string, nlohmann::json> byLabel;
    for (const nlohmann::json& row : *rows)
        if (row["group"] == "tessellation") byLabel[row["setting"]] = row;
    ASSERT_EQ(byLabel.size(), 10u);
    auto silhouette = [&](const char* label) { return byLabel.at(label)["silhouette_px"].get<double>(); };
    auto psnr = [&](const char* label) { return byLabel.at(label)["psnr"].get<double>(); };
    EXPECT_GT(silhouette("tess-off"), 50.0);
    // At 96 px no facet edge reaches 32 px: pn-32px draws the polygon.
    EXPECT_LE(silhouette("pn-32px"), silhouette("tess-off"));
    EXPECT_LT(silhouette("pn-16px"), silhouette("pn-32px"));
    EXPECT_LE(silhouette("pn-8px"), silhouette("pn-16px"));
    EXPECT_LE(silhouette("pn-2px"), silhouette("pn-8px"));
    EXPECT_LT(silhouette("pn-2px"), silhouette("tess-off") / 3.0);
    EXPECT_GT(psnr("pn-2px"), psnr("tess-off") + 3.0);
    for (const char* polygon : {"flat-8px", "centroid-3"})
        EXPECT_NEAR(silhouette(polygon), silhouette("tess-off"), silhouette("tess-off") / 10.0) << polygon;
    std::printf(
        "[ study lowpoly-sphere ] silhouette px: off %g, pn 32/16/8/4/2 px %g %g %g %g %g; PSNR off %.2f, "
        "pn-2px %.2f dB\n",
        silhouette("tess-off"), silhouette("pn-32px"), silhouette("pn-16px"), silhouette("pn-8px"),
        silhouette("pn-4px"), silhouette("pn-2px"), psnr("tess-off"), psnr("pn-2px"));
}

INSTANTIATE_TEST_SUITE_P(Backends, TessellationTest, ::testing::Values("vulkan", "cuda"));

// Bad tessellation options: one line, exit 2, nothing rendered.
TEST(TessellationTool, BadOptionsAreOneLineUsageErrors)
{
    ScratchDir dir("tess");
    for (const char* options : {"--tessellate pn --tess-edge-px 0", "--tessellate flat --tess-edge-px nan",
                                "--tessellate pn --tess-max-level 65",
                                "--tessellate centroid --tess-max-level 9", "--tessellate sometimes"}) {
        ToolRun run = runTool(std::string("render --backend vulkan --width 16 --height 16 -o ") +
                              dir.file("t.png") + " " + options);
        EXPECT_EQ(run.exitCode, 2) << options;
        EXPECT_EQ(std::count(run.stderrText.begin(), run.stderrText.end(), '\n'), 1) << run.stderrText;
        EXPECT_FALSE(std::filesystem::exists(dir.file("t.png"))) << options;
    }
}

// lavapipe's graphics pipeline drawing the host's generated mesh (what `--backend vulkan-graphics
// --tessellate` does) against the compute backend's frame: ids identical (mapped back to the scene's
// triangles), depth within the graphics pipeline's interpolation.
TEST(TessellationGraphics, ComputeMatchesTheGraphicsPipeline)
{
    bool skip = false;
    auto device = openBackend("vulkan", skip);
    ASSERT_TRUE(device);
    Scene lowpoly = *builtinSceneNamed("builtin:lowpoly");
    CameraMatrices camera = orbitCamera(lowpoly, "orbit:30,25,4", 160, 120);
    for (uint32_t mode : {TESS_FLAT, TESS_PN}) {
        SCOPED_TRACE(mode == TESS_FLAT ? "flat" : "pn");
        RenderSettings s = tessSettings(mode, 6.0f, 16, 160, 120);
        auto compute = renderScene(*device, lowpoly, camera, s);
        ASSERT_TRUE(compute.ok()) << compute.error().message;
        TessellatedScene host = tessellateOnHost(lowpoly, tessSources(lowpoly), compute->params);
        RenderSettings plain = s;
        plain.tessellate = TESS_OFF;
        auto graphics = renderVulkanGraphics(host.scene, camera, plain, -1);
        ASSERT_TRUE(graphics.ok()) << graphics.error().message;
        mapToSourceIds(graphics->aov.id, host.sourceIds, uint32_t(lowpoly.triangleCount()));
        size_t idMismatches = 0, covered = 0;
        for (size_t i = 0; i < compute->aov.id.size(); ++i) {
            idMismatches += compute->aov.id[i] != graphics->aov.id[i];
            covered += compute->aov.id[i] != EMPTY_ID;
        }
        EXPECT_GT(covered, 4000u);
        // The bound of docs/validation.md for vertices made by a perspective divide: each pipeline
        // divides in its own float arithmetic and may round a vertex to the neighbouring subpixel.
        EXPECT_LE(idMismatches, 64u);
        std::printf("[ tessellation vs vulkan-graphics ] %s: %zu of %zu covered pixels differ\n",
                    mode == TESS_FLAT ? "flat" : "pn", idMismatches, covered);
    }
}

}  // namespace
}  // namespace sr::test
