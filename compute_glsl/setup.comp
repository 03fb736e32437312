// setup.comp - stage `setup`: per input primitive. A triangle is culled, clipped and snapped; a
// small (sub-)triangle (bbox at most SMALL_TRI_SPAN pixels wide and high) is rasterized right here by
// its thread, the one-thread fast path that needs no memory; a big one is cut into pieces of
// consecutive bbox tiles (pieceCount) for bin_count and bin_fill. Only a clipped big sub-triangle is
// stored (a TriSetup record); every other big triangle is named by its input index and set up again
// where it is needed. A line segment is clipped and snapped like a triangle and becomes its rectangle's
// two triangles (setupLine), which take the same two paths (a long line's pieces spread over many
// threads like a big triangle's), stored as records when big. A point is culled by its vertex, snapped
// and rasterized by its thread (every sample of its square).
// One invocation per primitive, triangles, then line segments, then points, from setupFirstPrimitive
// (with clusters the triangles are stage clusters' work); groups = ceil((triangleCount + lineCount +
// pointCount - setupFirstPrimitive) / GROUP_SIZE).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "raster_shared.h"
#include "buffers.glsl"
#include "bin.glsl"

layout(local_size_x = GROUP_SIZE) in;
#include "setup_triangle.glsl"

#if SETUP_LINES_POINTS
// Rasterizes point k (primitive triangleCount + lineCount + k) by its invocation: every sample of the pixels its
// square reaches, merged like a small triangle's. Points are opaque and have no facing.
void rasterPoint(uint k, inout ThreadCounts counts)
{
    uint v = points[k];
    if (v >= params.vertexCount) {
        countPrimitive(counts, COUNTER_INVALID);
        return;
    }
    vec4 c = setupClipPosition(params, positions[v], params.transformInSetup == 0u ? clipPos[v] : vec4(0.0f));
    if (!isFinite(c.x) || !isFinite(c.y) || !isFinite(c.z) || !isFinite(c.w)) {
        countPrimitive(counts, COUNTER_INVALID);
        return;
    }
    PointSetup pt;
    ivec4 r = ivec4(0, 0, -1, -1);
    if (setupPoint(c, params.pointSize, params.width, params.height, pt))
        r = pointPixelBounds(pt, params.width, params.height, params.sampleBounds);
    if (r.x > r.z || r.y > r.w) {
        countPrimitive(counts, COUNTER_CULLED);
        return;
    }
    countPrimitive(counts, COUNTER_POINTS);
    uint id = params.triangleCount + params.lineCount + k;
    for (int y = r.y; y <= r.w; ++y) {
        for (int x = r.x; x <= r.z; ++x) {
            uint pixel = uint(y) * params.width + uint(x);
            for (uint s = 0u; s < SAMPLES; ++s)
                if (pointCoversSample(pt, samplePosition(SAMPLES, s, x, y)))
                    mergeFragment(s * params.samplePlane + pixel, pt.depth, id);
        }
    }
}

// Sets up line segment k (primitive triangleCount + k): clipped like a triangle, snapped, and drawn as
// its rectangle's two triangles, which are never named by input index (they are not input triangles).
void setupLineSegment(uint k, inout ThreadCounts counts)
{
    vec4 c0, c1;
    if (!loadClipLine(k, c0, c1)) {
        countPrimitive(counts, COUNTER_INVALID);
        return;
    }
    vec4 a, b;
    vec2 u;
    uint kind = prepareLine(c0, c1, params.guardBand, a, b, u);
    if (kind == PREPARE_INVALID) {
        countPrimitive(counts, COUNTER_INVALID);
        return;
    }
    if (kind == PREPARE_CLIPPED) countPrimitive(counts, COUNTER_CLIPPED);
    LineQuad q;
    uint emitted = 0u;
    if (kind != PREPARE_CULLED &&
        setupLine(a, b, params.lineWidth, params.lineDepthBias, params.width, params.height, q)) {
        for (uint side = 0u; side < 2u; ++side) {
            TriSetup t;
            if (methodLineTriangle(q, side, params.triangleCount + k, params.width, params.height,
                                  params.sampleBounds, t)) {
                emitTriangle(t, true, counts);
                ++emitted;
            }
        }
    }
    countPrimitive(counts, emitted == 0u ? COUNTER_CULLED : COUNTER_LINES);
}
#endif

// Sets up primitive `primitive` (a triangle, a line segment or a point), counting into `counts`.
void setupPrimitive(uint primitive, inout ThreadCounts counts)
{
    if (primitive >= params.triangleCount) {
#if SETUP_LINES_POINTS
        uint k = primitive - params.triangleCount;
        if (k < params.lineCount)
            setupLineSegment(k, counts);
        else if (k < params.lineCount + params.pointCount)
            rasterPoint(k - params.lineCount, counts);
#endif
        return;
    }
    vec4 c0, c1, c2;
    if (!loadClipTriangle(primitive, c0, c1, c2)) {
        countPrimitive(counts, COUNTER_INVALID);
        return;
    }
    setupInputTriangle(primitive, c0, c1, c2, counts);
}

void main()
{
    ThreadCounts counts;
    counts.bits = 0u;
    uint primitive = gl_GlobalInvocationID.x;
#if SETUP_LINES_POINTS
    primitive += params.setupFirstPrimitive;
#endif
    setupPrimitive(primitive, counts);
    addThreadCounts(counts);  // every invocation of the subgroup is here
}
