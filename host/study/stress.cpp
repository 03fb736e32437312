// stress.cpp - see stress.h. Every case's demand comes from the geometry alone, in double precision: the
// outline of the closed mesh in window coordinates decides, for each pixel centre, inside (kCoverOnce),
// outside (kEmpty) or too close to call (kFree). Nothing here renders.
#include "study/stress.h"

#include <algorithm>
#include <cmath>

#include "study/geometry.h"

namespace sr {
namespace {

// Pixels whose centre lies closer than this to a mesh's outline are kFree. Vertices are placed on the
// 1/256 grid (or, for the near axis, projected from float matrices), so the rasterized outline sits
// within a small fraction of a pixel of the exact one; one pixel is a generous bound.
constexpr double kOutlineMargin = 1.0;

// Settings of every case: unlit (a covered pixel is white), no culling (the fans and grids are drawn
// whichever way they face), one timed run, and the per-pixel hit count the failures are counted from.
RenderSettings stressSettings(uint32_t size)
{
    RenderSettings s;
    s.width = size;
    s.height = size;
    s.warmup = 0;
    s.repeat = 1;
    s.cullMode = CULL_NONE;
    s.shadingMode = SHADING_LAMBERT;
    s.ambient = 1.0f;
    s.lightColor = glm::vec3(0.0f);
    s.countHits = true;
    return s;
}

double segmentDistance(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b)
{
    glm::dvec2 ab = b - a;
    double len2 = glm::dot(ab, ab);
    double t = len2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    return glm::length(p - (a + t * ab));
}

// Demand of every pixel of a size x size viewport for the simple closed polygon `outline` (window
// coordinates, either orientation): kFree within kOutlineMargin of an edge, else kCoverOnce inside
// (even-odd along the pixel row through the centre) and kEmpty outside. The closeness test visits only
// the pixels of each edge's bounding box grown by the margin, so a 10^5-edge outline costs about as
// many distance evaluations as it has edges times a few pixels.
std::vector<PixelDemand> outlineDemand(const std::vector<glm::dvec2>& outline, uint32_t size)
{
    const size_t n = outline.size();
    std::vector<uint8_t> nearEdge(size_t(size) * size, 0);
    auto pixelRange = [&](double lo, double hi, int& first, int& last) {
        // Pixel i has its centre at i + 0.5; clamp in double before converting (coordinates may be huge).
        first = int(std::clamp(std::ceil(lo - 0.5), 0.0, double(size)));
        last = int(std::clamp(std::floor(hi - 0.5), -1.0, double(size) - 1.0));
    };
    for (size_t e = 0; e < n; ++e) {
        glm::dvec2 a = outline[e], b = outline[(e + 1) % n];
        int x0, x1, y0, y1;
        pixelRange(std::min(a.x, b.x) - kOutlineMargin, std::max(a.x, b.x) + kOutlineMargin, x0, x1);
        pixelRange(std::min(a.y, b.y) - kOutlineMargin, std::max(a.y, b.y) + kOutlineMargin, y0, y1);
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x)
                if (segmentDistance({x + 0.5, y + 0.5}, a, b) < kOutlineMargin)
                    nearEdge[size_t(y) * size + x] = 1;
    }
    std::vector<PixelDemand> demand(size_t(size) * size, PixelDemand::kEmpty);
    std::vector<double> crossings;
    for (uint32_t y = 0; y < size; ++y) {
        const double yc = y + 0.5;
        crossings.clear();
        for (size_t e = 0; e < n; ++e) {
            glm::dvec2 a = outline[e], b = outline[(e + 1) % n];
            // Half-open in y, so a vertex on the row is counted once by the two edges meeting there.
            if ((a.y <= yc) != (b.y <= yc)) crossings.push_back(a.x + (yc - a.y) * (b.x - a.x) / (b.y - a.y));
        }
        std::sort(crossings.begin(), crossings.end());
        for (uint32_t x = 0; x < size; ++x) {
            const size_t i = size_t(y) * size + x;
            const size_t left =
                size_t(std::lower_bound(crossings.begin(), crossings.end(), x + 0.5) - crossings.begin());
            if (nearEdge[i])
                demand[i] = PixelDemand::kFree;
            else if (left % 2 == 1)
                demand[i] = PixelDemand::kCoverOnce;
        }
    }
    return demand;
}

// A closed fan around `hub` through `rim` at window depth 0.5, with the demand of its outline.
StressCase fanCase(const std::string& axis, double x, glm::dvec2 hub, const std::vector<glm::dvec2>& rim,
                   uint32_t size)
{
    StressCase c;
    c.axis = axis;
    c.x = x;
    c.scene = fanScene(hub, rim, size, 0.5);
    c.camera = clipCamera();
    c.settings = stressSettings(size);
    c.demand = outlineDemand(rim, size);
    return c;
}

// Magnitude: a fan of 32 triangles around the viewport centre whose rim vertices lie on the circle of
// radius R = 2^k px, k = 0..14 (rounded to the 1/256 grid; the first at angle 0.1 rad so that no rim
// vertex sits on an axis). For k >= 6 the polygon holds the whole viewport: every pixel is kCoverOnce
// and is decided by the 32 spokes, edges from the centre to vertices 2^k px away, whose edge functions
// multiply coordinates of up to 2^14 * 256 = 2^22 subpixels. At k = 14 the rim touches the guard band
// (+-16384 px around the viewport centre) without crossing it: the rounded |x|, |y| never exceed R.
std::vector<StressCase> magnitudeCases(uint32_t size)
{
    std::vector<StressCase> cases;
    const int rimCount = 32;
    const glm::dvec2 hub(size / 2.0, size / 2.0);
    for (int k = 0; k <= 14; ++k) {
        const double radius = std::ldexp(1.0, k);
        std::vector<glm::dvec2> rim;
        for (int i = 0; i < rimCount; ++i) {
            double angle = 0.1 + 2.0 * M_PI * i / rimCount;
            rim.push_back(
                {onGrid(hub.x + radius * std::cos(angle)), onGrid(hub.y + radius * std::sin(angle))});
        }
        cases.push_back(fanCase("magnitude", radius, hub, rim, size));
    }
    return cases;
}

// Slivers: a fan of n triangles (n = 10 .. 10^5) around a hub placed exactly on a pixel centre, the
// disc of radius 0.4 size px, rim vertex i at angle 2 pi i / n. The hub is a vertex of every triangle
// and the spoke at angle 0 runs along the hub's pixel row, so the fill rule's ties decide pixel centres
// exactly on shared edges and on the shared vertex. Rim vertices are rounded to the 1/256 grid; where
// that would step the rim backwards (n above the rim's length in subpixels, 2 pi 0.4 size 256 = 41,000
// at size 64), the vertex repeats its predecessor instead, so the polygon stays star-shaped about the
// hub and the fan closed: such triangles have zero area and draw nothing, as their snapped selves would.
std::vector<StressCase> sliverCases(uint32_t size)
{
    std::vector<StressCase> cases;
    const glm::dvec2 hub(size / 2 + 0.5, size / 2 + 0.5);
    const double radius = 0.4 * size;
    for (int n : {10, 100, 1000, 10000, 100000})
        cases.push_back(fanCase("slivers", n, hub, fanRim(hub, radius, n), size));
    return cases;
}

// Near: a ground plane y = -1 below a camera at the origin looking down -z (90 degree field of view),
// a 5 x 5 grid of quads from view depth w0 to 10^4 and across x = +-10^4. Its nearest row of vertices
// sits at view depth, hence clip w, w0 = 1 .. 10^-6, with the near plane at w0 / 2 so that they are
// inside the view volume: they project up to 10^4 / w0 * size / 2 px off screen, and the guard-band
// clipper cuts the triangles that reach from them (the row from w0 to depth 4 covers the bottom rows,
// where the view depth is 1 .. 4) in clip space with w that small. The plane covers every pixel centre
// below the horizon whose view ray meets it inside the grid; the demand projects the grid's outline in
// double from the float matrix, so only the horizon rows (the far edge projects 32 / 10^4 px below it)
// are kFree.
std::vector<StressCase> nearCases(uint32_t size)
{
    std::vector<StressCase> cases;
    const double extent = 1e4, farDepth = 1e4;
    const std::vector<double> columns = {-extent, -2.5, -0.75, 0.25, 1.5, extent};
    for (double w0 : {1.0, 1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6}) {
        const std::vector<double> depths = {w0, 4.0, 16.0, 64.0, 512.0, farDepth};
        StressCase c;
        c.axis = "near";
        c.x = w0;
        c.camera.znear = float(w0 / 2);
        c.camera.zfar = float(2 * farDepth);
        c.camera.clipFromView = perspectiveVulkan(float(M_PI / 2), 1.0f, c.camera.znear, c.camera.zfar);
        c.camera.clipFromWorld = c.camera.clipFromView;
        Scene& scene = c.scene;
        const uint32_t cols = uint32_t(columns.size());
        for (double d : depths)
            for (double x : columns) {
                addVertex(scene, glm::vec4(float(x), -1.0f, float(-d), 1.0f));
                scene.normals.back() = glm::vec4(0.0f, 1.0f, 0.0f, 0.0f);
            }
        for (uint32_t j = 0; j + 1 < depths.size(); ++j)
            for (uint32_t i = 0; i + 1 < cols; ++i) {
                addGridCell(scene, j * cols + i, cols, (i + j) % 2 != 0);
            }
        computeBounds(scene);
        // The outline's corners projected in double with the camera's own (float) matrix entries.
        const glm::dmat4 m(c.camera.clipFromWorld);
        std::vector<glm::dvec2> outline;
        for (glm::dvec2 corner : {glm::dvec2(-extent, w0), glm::dvec2(extent, w0),
                                  glm::dvec2(extent, farDepth), glm::dvec2(-extent, farDepth)}) {
            glm::dvec4 clip = m * glm::dvec4(corner.x, -1.0, -corner.y, 1.0);
            outline.push_back({(clip.x / clip.w + 1.0) * size / 2.0, (clip.y / clip.w + 1.0) * size / 2.0});
        }
        c.settings = stressSettings(size);
        c.demand = outlineDemand(outline, size);
        cases.push_back(std::move(c));
    }
    return cases;
}

// Coplanar: two identical 4 x 4 grids of quads (alternating diagonals) over the window square
// [size / 8, 7 size / 8]^2, the farther at window depth z + d drawn first (ids 0 .. 31), the nearer at
// z = 0.75 drawn second (ids 32 .. 63), d = 2^-8 .. 2^-30 (x = d). With the identity camera a flat
// triangle's depth is its vertices' float z exactly, so the nearer surface wins while float(z + d) >
// z: up to d = ulp(0.75) = 2^-24. Below that the two depths are equal floats, the key's tie goes to the
// lowest id, the farther surface, and every overlapped pixel shows the wrong one.
std::vector<StressCase> coplanarCases(uint32_t size)
{
    std::vector<StressCase> cases;
    const int cells = 4;
    const double z = 0.75, lo = size / 8.0, step = (size * 0.75) / cells;
    for (int e = 8; e <= 30; ++e) {
        const double d = std::ldexp(1.0, -e);
        StressCase c;
        c.axis = "coplanar";
        c.x = d;
        Scene& scene = c.scene;
        std::vector<std::vector<glm::dvec2>> grid(cells + 1, std::vector<glm::dvec2>(cells + 1));
        for (int j = 0; j <= cells; ++j)
            for (int i = 0; i <= cells; ++i) grid[j][i] = {onGrid(lo + i * step), onGrid(lo + j * step)};
        for (double depth : {z + d, z}) addGrid(scene, grid, size, depth);
        computeBounds(scene);
        c.nearIdBegin = uint32_t(scene.triangleCount() / 2);
        c.nearIdEnd = uint32_t(scene.triangleCount());
        c.camera = clipCamera();
        c.settings = stressSettings(size);
        const double hi = onGrid(lo + cells * step), l0 = onGrid(lo);
        c.demand = outlineDemand({{l0, l0}, {hi, l0}, {hi, hi}, {l0, hi}}, size);
        for (PixelDemand& p : c.demand)
            if (p == PixelDemand::kCoverOnce) p = PixelDemand::kNearId;
        cases.push_back(std::move(c));
    }
    return cases;
}

}  // namespace

std::vector<StressCase> stressCases(const std::string& axis, uint32_t size)
{
    if (axis == "magnitude") return magnitudeCases(size);
    if (axis == "slivers") return sliverCases(size);
    if (axis == "near") return nearCases(size);
    if (axis == "coplanar") return coplanarCases(size);
    return {};
}

StressFailures countFailures(const StressCase& c, const RenderOutput& out)
{
    StressFailures f;
    const bool haveHits = out.hitCount.size() >= c.demand.size();
    for (size_t i = 0; i < c.demand.size(); ++i) {
        const uint32_t id = i < out.aov.id.size() ? out.aov.id[i] : EMPTY_ID;
        // Hits at the pixel's first sample (the hit-count planes are sample-major); from the id alone
        // when there is no count, which sees coverage but not how often.
        const uint32_t hits = haveHits ? out.hitCount[i] : (id == EMPTY_ID ? 0u : 1u);
        switch (c.demand[i]) {
        case PixelDemand::kFree: break;
        case PixelDemand::kCoverOnce:
            f.cracks += hits == 0;
            f.doubleHits += hits >= 2;
            break;
        case PixelDemand::kEmpty: f.doubleHits += hits != 0; break;
        case PixelDemand::kNearId:
            if (id == EMPTY_ID)
                ++f.cracks;
            else if (id < c.nearIdBegin || id >= c.nearIdEnd)
                ++f.wrongDepthOrder;
            break;
        }
    }
    return f;
}

uint64_t oracleMismatches(const RenderOutput& out, const RenderOutput& oracle)
{
    const std::vector<uint32_t>&a = out.aov.id, &b = oracle.aov.id;
    uint64_t differing = 0;
    for (size_t i = 0; i < std::max(a.size(), b.size()); ++i)
        differing += (i < a.size() ? a[i] : EMPTY_ID) != (i < b.size() ? b[i] : EMPTY_ID);
    return differing;
}

}  // namespace sr
