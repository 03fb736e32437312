// setup.comp - stage `setup`: per input primitive. A triangle is culled, clipped and snapped; a
// small (sub-)triangle (bbox at most SMALL_TRI_SPAN pixels wide and high) is rasterized right here by
// its thread, the one-thread fast path that needs no memory; a big one is cut into pieces of
// consecutive bbox tiles (pieceCount) for bin_count and bin_fill. Only a clipped big sub-triangle is
// stored (a TriSetup record); every other big triangle is named by its input index and set up again
// where it is needed. A line segment is clipped and snapped like a triangle and becomes its rectangle's
// two triangles (setupLine), which take the same two paths (a long line's pieces spread over many
// threads like a big triangle's), stored as records when big. A point is culled by its vertex, snapped
// and rasterized by its thread (every sample of its square).
// One thread per primitive, triangles, then line segments, then points; groups = ceil((triangleCount +
// lineCount + pointCount) / GROUP_SIZE).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"
#include "bin.glsl"

layout(local_size_x = GROUP_SIZE) in;
// Whether the alpha test of MASK materials is built in (SPEC_MATERIALS).
layout(constant_id = SPEC_MATERIALS) const bool MATERIALS = true;
// Samples per pixel (SPEC_SAMPLES, RasterParams.sampleCount): the one-sample build has no MSAA loop.
layout(constant_id = SPEC_SAMPLES) const uint SAMPLES = 1u;
// SETUP_LINES_POINTS (a preprocessor definition, 0 or 1): whether the line and point paths are built
// in. This shader is compiled twice (CMakeLists.txt), and scenes of triangles alone run the module
// without them: with the point code in the same module (behind a run-time branch) NVIDIA's compiler
// ran the triangle path 35-95% slower on the H100 (measured; docs/benchmark.md, performance log).
#ifndef SETUP_LINES_POINTS
#define SETUP_LINES_POINTS 0
#endif
// Whether a big triangle is stored as a record. On a GPU only a clipped one is (the others cost no
// memory and are set up again per tile); the CPU builds (SR_CPU_BUILD) store every big triangle, so that
// raster_tiles' CPU build fetches each with three texel gathers (VIEW_SETUP_TRIS) instead of setting it
// up from the scene in every tile, one lane at a time.
#if defined(SR_CPU_BUILD)
#define STORED_AS_RECORD(clipped) true
#else
#define STORED_AS_RECORD(clipped) (clipped)
#endif

// Rasterizes a small triangle (every sample of its bbox) or appends a big one's pieces: a record
// (BIN_REF_RECORD) when `clipped` (STORED_AS_RECORD: always in the CPU builds), else its input index. A full
// list still counts the appends, so the host sees the overflow, grows the lists and redraws; nothing is
// written past a capacity.
void emitTriangle(TriSetup t, bool clipped)
{
    ivec4 bounds = methodPixelBounds(t, params.width, params.height, params.sampleBounds);
    uint id = setupTriId(t);
    if (isSmallTriangle(bounds)) {
        atomicAdd(counters[COUNTER_SMALL], 1u);
        // Lines have no alpha test (and no triangle flags).
        bool masked = MATERIALS && params.materialCount != 0u &&
                      (SETUP_LINES_POINTS == 0 || id < params.triangleCount) &&
                      (triFlags[id] & TRI_FLAG_ALPHA_MASK) != 0u;
        if (SAMPLES == 1u) {
            for (int y = bounds.y; y <= bounds.w; ++y) {
                for (int x = bounds.x; x <= bounds.z; ++x) {
                    float depth;
                    if (methodPixel(t, x, y, depth) && (!masked || alphaMaskCovers(id, x, y)))
                        mergeFragment(uint(y) * params.width + uint(x), depth, id);
                }
            }
            return;
        }
        // MSAA, in a build of its own so that the one-sample loop compiles as it did without it: the alpha
        // test runs once per pixel, at its centre, as hardware shades a pixel.
        for (int y = bounds.y; y <= bounds.w; ++y) {
            for (int x = bounds.x; x <= bounds.z; ++x) {
                uint mask = methodCoverage(t, SAMPLES, x, y);
                if (mask == 0u || (masked && !alphaMaskCovers(id, x, y))) continue;
                uint pixel = uint(y) * params.width + uint(x);
                for (uint s = 0u; s < SAMPLES; ++s) {
                    float depth;
                    if ((mask & (1u << s)) != 0u && methodSample(t, samplePosition(SAMPLES, s, x, y), depth))
                        mergeFragment(s * params.samplePlane + pixel, depth, id);
                }
            }
        }
        return;
    }
    atomicAdd(counters[COUNTER_BIG], 1u);
    uint ref = id;
    if (clipped) {
        uint slot = atomicAdd(counters[COUNTER_SETUP], 1u);
        if (slot >= params.setupCapacity) return;
        setupTris[slot] = t;
        ref = slot | BIN_REF_RECORD;
    }
    uint tiles = tileCount(bounds);
    uint n = pieceCount(tiles);
    uint base = atomicAdd(counters[COUNTER_PIECES], n);
    // Piece indices are uint: a frame that needs 2^31 of them is reported, never wrapped.
    if (base >= 0x80000000u) counters[COUNTER_WORK_OVERFLOW] = 1u;
    if (n == 1u) {  // counted here, while the triangle is at hand; bin_count skips the piece
        if (base >= params.pieceCapacity) return;  // counts must match what bin_fill will find
        pieces[base] = uvec2(ref, PIECE_COUNTED);
        binTiles(t, bounds, ref, 0u, tiles, false);
        return;
    }
    atomicAdd(counters[COUNTER_SPLIT], 1u);
    for (uint k = 0u; k < n && base + k < params.pieceCapacity; ++k)
        pieces[base + k] = uvec2(ref, k * pieceTiles(tiles));
}

#if SETUP_LINES_POINTS
// Rasterizes point k (primitive triangleCount + lineCount + k) by its invocation: every sample of the pixels its
// square reaches, merged like a small triangle's. Points are opaque and have no facing.
void rasterPoint(uint k)
{
    uint v = points[k];
    if (v >= params.vertexCount) {
        atomicAdd(counters[COUNTER_INVALID], 1u);
        return;
    }
    vec4 c = setupClipPosition(params, positions[v], params.transformInSetup == 0u ? clipPos[v] : vec4(0.0f));
    if (!isFinite(c.x) || !isFinite(c.y) || !isFinite(c.z) || !isFinite(c.w)) {
        atomicAdd(counters[COUNTER_INVALID], 1u);
        return;
    }
    PointSetup pt;
    ivec4 r = ivec4(0, 0, -1, -1);
    if (setupPoint(c, params.pointSize, params.width, params.height, pt))
        r = pointPixelBounds(pt, params.width, params.height, params.sampleBounds);
    if (r.x > r.z || r.y > r.w) {
        atomicAdd(counters[COUNTER_CULLED], 1u);
        return;
    }
    atomicAdd(counters[COUNTER_POINTS], 1u);
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
void setupLineSegment(uint k)
{
    vec4 c0, c1;
    if (!loadClipLine(k, c0, c1)) {
        atomicAdd(counters[COUNTER_INVALID], 1u);
        return;
    }
    vec4 a, b;
    vec2 u;
    uint kind = prepareLine(c0, c1, params.guardBand, a, b, u);
    if (kind == PREPARE_INVALID) {
        atomicAdd(counters[COUNTER_INVALID], 1u);
        return;
    }
    if (kind == PREPARE_CLIPPED) atomicAdd(counters[COUNTER_CLIPPED], 1u);
    LineQuad q;
    uint emitted = 0u;
    if (kind != PREPARE_CULLED &&
        setupLine(a, b, params.lineWidth, params.lineDepthBias, params.width, params.height, q)) {
        for (uint side = 0u; side < 2u; ++side) {
            TriSetup t;
            if (methodLineTriangle(q, side, params.triangleCount + k, params.width, params.height,
                                  params.sampleBounds, t)) {
                emitTriangle(t, true);
                ++emitted;
            }
        }
    }
    atomicAdd(counters[emitted == 0u ? COUNTER_CULLED : COUNTER_LINES], 1u);
}
#endif

void main()
{
    uint tri = gl_GlobalInvocationID.x;
    if (tri >= params.triangleCount) {
#if SETUP_LINES_POINTS
        uint k = tri - params.triangleCount;
        if (k < params.lineCount)
            setupLineSegment(k);
        else if (k < params.lineCount + params.pointCount)
            rasterPoint(k - params.lineCount);
#endif
        return;
    }
    vec4 c0, c1, c2;
    if (!loadClipTriangle(tri, c0, c1, c2)) {
        atomicAdd(counters[COUNTER_INVALID], 1u);
        return;
    }
    vec4 poly[MAX_CLIP_VERTS];
    uint count;
    uint kind = prepareTriangle(c0, c1, c2, params.guardBand, poly, count);
    if (kind == PREPARE_INVALID) {
        atomicAdd(counters[COUNTER_INVALID], 1u);
        return;
    }
    if (kind == PREPARE_CLIPPED) atomicAdd(counters[COUNTER_CLIPPED], 1u);
    bool doubleSided = (triFlags[tri] & TRI_FLAG_DOUBLE_SIDED) != 0u;
    uint emitted = 0u;
    for (uint k = 1u; k + 1u < count; ++k) {
        TriSetup t;
        if (methodSetupTriangle(poly[0], poly[k], poly[k + 1u], tri, doubleSided, params.cullMode, params.width,
                                params.height, params.sampleBounds, t)) {
            emitTriangle(t, STORED_AS_RECORD(kind == PREPARE_CLIPPED));
            ++emitted;
        }
    }
    if (emitted == 0u) atomicAdd(counters[COUNTER_CULLED], 1u);
}
