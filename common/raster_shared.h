// raster_shared.h - the one header shared by host C++, CUDA and GLSL.
//
// Holds everything both ports must agree on bit for bit: buffer bindings, stage ids, constants, the
// parameter and record structs, and the maths of every stage (clipping, snapping to n.8 fixed point,
// integer edge functions with the top-left rule, depth interpolation, the visibility key, perspective-
// correct barycentrics and shading). The CUDA kernels and the GLSL compute shaders are thin shells that
// index threads, load buffers, call these functions and do the atomics.
//
// Rules that keep one file valid in three languages (see ../shared/notes/style-and-ecosystem.md):
// include guards (glslang has no '#pragma once'), GLSL type names, no swizzles, no constructors or
// aggregate initialisers for structs, arrays passed through SR_ARRAY_INOUT, and every float expression
// whose bits matter across backends stored in a `precise` variable (GLSL NoContraction; CUDA is built
// with --fmad=false and the host with -ffp-contract=off, so no backend fuses a*b+c). Float literals
// carry an 'f' so that C++ and CUDA never widen an expression to double where GLSL stays in float.
#ifndef RASTER_SHARED_H
#define RASTER_SHARED_H

#if defined(__cplusplus)
#include <cmath>
#include <cstdint>
#include <cstring>

#include <glm/glm.hpp>
#if defined(__CUDACC__)
#define SR_FN __host__ __device__ inline
#else
#define SR_FN inline
#endif
#define SR_OUT(T) T&
#define SR_INOUT(T) T&
#define SR_ARRAY_INOUT(T, name, N) T(&name)[N]
#define SR_PRECISE
namespace sr {
using glm::abs;
using glm::clamp;
using glm::cross;
using glm::dot;
using glm::ivec2;
using glm::ivec4;
using glm::mat4;
using glm::max;
using glm::min;
using glm::mix;
using glm::normalize;
using glm::pow;
using glm::sqrt;
using glm::uvec4;
using glm::vec2;
using glm::vec3;
using glm::vec4;
using uint = std::uint32_t;
using std::int64_t;
using std::uint64_t;

// GLSL built-ins that GLM lacks on the device or spells differently.
SR_FN uint floatBitsToUint(float f)
{
#if defined(__CUDA_ARCH__)
    return __float_as_uint(f);
#else
    uint u;
    std::memcpy(&u, &f, sizeof u);
    return u;
#endif
}
SR_FN float uintBitsToFloat(uint u)
{
#if defined(__CUDA_ARCH__)
    return __uint_as_float(u);
#else
    float f;
    std::memcpy(&f, &u, sizeof f);
    return f;
#endif
}
// Round half to even, the rounding of GLSL roundEven and of the x86 default mode.
SR_FN float roundEven(float x)
{
#if defined(__CUDA_ARCH__)
    return rintf(x);
#else
    return std::nearbyint(x);
#endif
}
SR_FN bool isFinite(float x)
{
    return (floatBitsToUint(x) & 0x7f800000u) != 0x7f800000u;
}
#else  // GLSL
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#define SR_FN
#define SR_OUT(T) out T
#define SR_INOUT(T) inout T
#define SR_ARRAY_INOUT(T, name, N) inout T name[N]
#define SR_PRECISE precise
bool isFinite(float x)
{
    return (floatBitsToUint(x) & 0x7f800000u) != 0x7f800000u;
}
#endif

// ---------------------------------------------------------------------------------------------------
// Buffer bindings. Vulkan: descriptor binding numbers of set 0. CUDA and host: indices of the device
// buffer table. Same numbers, same names everywhere.
#define BUF_PARAMS 0        // RasterParams (uniform buffer in Vulkan, kernel argument in CUDA)
#define BUF_POSITIONS 1     // vec4 per vertex: world-space position, w = 1
#define BUF_NORMALS 2       // vec4 per vertex: world-space normal, w = 0
#define BUF_COLORS 3        // vec4 per vertex: linear RGBA (only read when RasterParams.hasColors)
#define BUF_INDICES 4       // uint, 3 per triangle, already validated on the host
#define BUF_TRI_FLAGS 5     // uint per triangle: TRI_FLAG_* bits
#define BUF_CLIP_POS 6      // vec4 per vertex: clip-space position (vertex stage output, read by setup)
#define BUF_SETUP_TRIS 7    // TriSetup per big (sub-)triangle, appended by setup
#define BUF_BIG_TRIS 8      // uint: indices into BUF_SETUP_TRIS, in the order raster_tiles walks them
#define BUF_BIG_OFFSETS 9   // uint per big triangle: its tile count, scanned in place to an offset
#define BUF_SCAN_SUMS 10    // uint per scan block: block total, scanned in place to a block offset
#define BUF_COUNTERS 11     // uint[COUNTER_COUNT]: list lengths and statistics
#define BUF_VISIBILITY 12   // uint64 per pixel: depth bits << 32 | triangle id, ~0 = empty
#define BUF_FRAMEBUFFER 13  // uint per pixel: RGBA8, sRGB-encoded colour
#define BUF_HIT_COUNT 14    // uint per pixel: covering triangles (written only with DEBUG_COUNT_HITS)
#define BUF_COUNT 15

// Counters in BUF_COUNTERS, cleared by the clear stage every frame.
#define COUNTER_SETUP 0          // TriSetup records appended (may exceed capacity: overflow)
#define COUNTER_SMALL 1          // small (sub-)triangles rasterized by setup itself, without a record
#define COUNTER_BIG 2            // entries appended to BUF_BIG_TRIS
#define COUNTER_TILES 3          // total (big triangle, tile) work items, written by scan_sums
#define COUNTER_CULLED 4         // input triangles that produced no TriSetup at all
#define COUNTER_CLIPPED 5        // input triangles that went through the polygon clipper
#define COUNTER_INVALID 6        // input triangles dropped for NaN/Inf positions
#define COUNTER_WORK_OVERFLOW 7  // non-zero when the tile work total does not fit in 31 bits
#define COUNTER_COUNT 8

// Stages, in dispatch order. Each is one CUDA kernel (cuda/<name>.cuh) and one compute shader
// (compute_glsl/<name>.comp).
#define STAGE_CLEAR 0         // visibility := empty, counters := 0
#define STAGE_VERTEX 1        // per vertex: clip position
#define STAGE_SETUP 2         // per triangle: cull, clip, snap; rasterize small ones, append big ones
#define STAGE_SCAN_BLOCKS 3   // per 256 big triangles: local exclusive scan of tile counts
#define STAGE_SCAN_SUMS 4     // one group: exclusive scan of the block totals
#define STAGE_SCAN_ADD 5      // per 256 big triangles: add block offsets
#define STAGE_RASTER_TILES 6  // one group per (big triangle, 8x8 tile), one thread per pixel
#define STAGE_SHADE 7         // per pixel: resolve the visibility key and shade
#define STAGE_COUNT 8

#define GROUP_SIZE 128       // threads per group of the 1D stages
#define SCAN_GROUP_SIZE 256  // elements per scan block (one per thread)
#define TILE_SIZE 8          // raster_tiles tile edge in pixels; its group has TILE_SIZE^2 threads
#define SMALL_TRI_SPAN 8     // triangles whose pixel bbox is at most this wide and high are small
#define SUBPIXEL_BITS 8      // vertices snap to 1/256 pixel, as Vulkan on NVIDIA, lavapipe and D3D
#define SUBPIXEL_SCALE 256
#define MAX_CLIP_VERTS 9    // a triangle clipped by the 6 planes below has at most 3 + 6 vertices
#define CLIP_PLANE_COUNT 6  // near, far, and the four guard-band planes
// Window coordinates are clipped to +-GUARD_BAND_PX around the viewport centre, so |window x| stays
// below 8192 + 16384 < 2^15 pixels. There a float still resolves half a subpixel (a wider guard band
// lets float rounding of clipped vertices move edges by more than the 1/256 snap), snapped coordinates
// stay below 2^23 subpixels and edge-function products below 2^48, comfortably inside int64.
#define GUARD_BAND_PX 16384.0f
#define MAX_FRAMEBUFFER_DIM 16384
#define EMPTY_ID 0xFFFFFFFFu

#define TRI_FLAG_DOUBLE_SIDED 1u  // never culled by facing (glTF doubleSided materials)

#define CULL_NONE 0u
#define CULL_BACK 1u
#define CULL_FRONT 2u

#define SHADING_LAMBERT 0u
#define SHADING_PHONG 1u
#define SHADING_BLINN_PHONG 2u
#define SHADING_FLAT 3u
#define SHADING_NORMALS 4u
#define SHADING_DEPTH 5u
#define SHADING_PRIMITIVE_ID 6u
#define SHADING_HIT_COUNT 7u  // debug: how many triangles covered each pixel (needs DEBUG_COUNT_HITS)

// RasterParams.debugFlags bits.
#define DEBUG_COUNT_HITS 1u  // raster stages also count every covered pixel in BUF_HIT_COUNT

// Per-frame constants. std140 in Vulkan: mat4/vec4 first, then 4-byte scalars, 16-byte total multiple.
struct RasterParams {
    mat4 clipFromWorld;     // world -> clip; Vulkan conventions: depth 0..1, NDC y = -1 is the top row
    mat4 viewFromWorld;     // world -> view space (camera at the origin looking down -z)
    mat4 normalFromWorld;   // inverse transpose of viewFromWorld; only its 3x3 part is used
    vec4 lightDirView;      // xyz: unit vector towards the light, view space
    vec4 lightColor;        // rgb: directional light colour; a: ambient intensity
    vec4 background;        // rgb: linear background colour
    vec4 shadeExtra;        // x: specular exponent; y, z: view distances mapped to white/black in depth view
    vec4 guardBand;         // x, y: guard-band half-extent in NDC units (|x| <= x * w); zw unused
    uint width;             // framebuffer width in pixels, 1..MAX_FRAMEBUFFER_DIM
    uint height;            // framebuffer height in pixels
    uint vertexCount;       // entries in the per-vertex buffers
    uint triangleCount;     // entries in BUF_TRI_FLAGS; BUF_INDICES has 3x as many
    uint cullMode;          // CULL_*
    uint shadingMode;       // SHADING_*
    uint hasColors;         // 1 when BUF_COLORS holds vertexCount colours, else colours are white
    uint setupCapacity;     // capacity of BUF_SETUP_TRIS, BUF_BIG_TRIS, BUF_BIG_OFFSETS
    uint rasterGroups;      // groups launched for raster_tiles (grid-stride loop)
    uint debugFlags;        // DEBUG_* bits
    uint transformInSetup;  // 1: no vertex is shared, setup transforms positions itself (no vertex stage)
    uint reserved1;
};

// One rasterizable triangle after clipping and snapping, positively oriented (edge functions are
// positive inside). 48 bytes.
struct TriSetup {
    ivec4 xy01;       // x0, y0, x1, y1: snapped window coordinates in 1/256 pixel
    ivec4 xy2Id;      // x2, y2, triangle id (uint bits), pixel bbox packed as minX | minY << 16
    vec4 depthPlane;  // z0, z1 - z0, z2 - z0 (window depth at the snapped vertices), 1 / area
};

#if defined(__cplusplus)
static_assert(sizeof(RasterParams) == 3 * 64 + 5 * 16 + 12 * 4, "RasterParams must match std140");
static_assert(sizeof(TriSetup) == 48, "TriSetup must match std430");
#endif

// ---------------------------------------------------------------------------------------------------
// Deterministic reciprocal. Vulkan only promises 2.5 ulp for OpFDiv while CUDA divides correctly
// rounded, so a plain '/' would let the backends disagree on snapped vertices and depth. This builds
// 1/b from integer operations on the float's bits, which every backend executes identically:
// b = m * 2^(E-150) with a 24-bit mantissa m, so 1/b = floor(2^47 / m) * 2^(103-E) up to < 1 ulp.
// Returns +-0 for |b| >= 2^126 and +-inf for zero or denormal b.
SR_FN float recipDet(float b)
{
    uint bits = floatBitsToUint(b);
    uint sign = bits & 0x80000000u;
    uint e = (bits >> 23) & 0xffu;
    if (e == 0u) return uintBitsToFloat(sign | 0x7f800000u);
    if (e >= 253u) return uintBitsToFloat(sign);
    uint64_t m = uint64_t((bits & 0x7fffffu) | 0x800000u);
    uint64_t q = (uint64_t(1) << 47) / m;  // in (2^23, 2^24]
    if (q == (uint64_t(1) << 24)) return uintBitsToFloat(sign | ((254u - e) << 23));
    return uintBitsToFloat(sign | ((253u - e) << 23) | (uint(q) & 0x7fffffu));
}

SR_FN float divDet(float a, float b)
{
    SR_PRECISE float r = a * recipDet(b);
    return r;
}

// ---------------------------------------------------------------------------------------------------
// Vertex stage.

// m * v with a fixed summation order and no contraction. GLSL's built-in matrix product leaves the
// order to the driver, which would let clip positions (and so snapped vertices) differ by an ulp.
SR_FN vec4 mulPoint(mat4 m, vec4 v)
{
    SR_PRECISE vec4 r = ((m[0] * v.x + m[1] * v.y) + m[2] * v.z) + m[3] * v.w;
    return r;
}

// World-space vertex to clip position, view position and unit view-space normal.
SR_FN void transformVertex(RasterParams params, vec4 position, vec4 normal, SR_OUT(vec4) clip,
                           SR_OUT(vec4) viewPos, SR_OUT(vec4) viewNormal)
{
    clip = mulPoint(params.clipFromWorld, position);
    viewPos = mulPoint(params.viewFromWorld, position);
    vec4 n = mulPoint(params.normalFromWorld, vec4(normal.x, normal.y, normal.z, 0.0f));
    vec3 n3 = vec3(n.x, n.y, n.z);
    float len2 = dot(n3, n3);
    n3 = len2 > 0.0f ? n3 / sqrt(len2) : n3;
    viewNormal = vec4(n3.x, n3.y, n3.z, 0.0f);
}

// ---------------------------------------------------------------------------------------------------
// Clipping. Signed distance of a clip-space vertex to clip plane `plane`, >= 0 inside. Near z >= 0 and
// far z <= w are Vulkan's depth range; the guard-band planes only keep fixed point in range (pixels
// outside the viewport are never visited, so x/y need no exact clipping).
SR_FN float planeDistance(vec4 c, uint plane, vec4 guardBand)
{
    SR_PRECISE float d;
    if (plane == 0u)
        d = c.z;
    else if (plane == 1u)
        d = c.w - c.z;
    else if (plane == 2u)
        d = guardBand.x * c.w - c.x;
    else if (plane == 3u)
        d = guardBand.x * c.w + c.x;
    else if (plane == 4u)
        d = guardBand.y * c.w - c.y;
    else
        d = guardBand.y * c.w + c.y;
    return d;
}

// Bit p set when the vertex is outside plane p.
SR_FN uint clipOutcode(vec4 c, vec4 guardBand)
{
    uint code = 0u;
    for (uint p = 0u; p < uint(CLIP_PLANE_COUNT); ++p)
        if (planeDistance(c, p, guardBand) < 0.0f) code |= 1u << p;
    return code;
}

// Bit p set when the vertex is outside viewport plane p (0: x < -w, 1: x > w, 2: y < -w, 3: y > w,
// 4: z < 0, 5: z > w). A triangle whose three vertices share a bit covers no pixel: frustum cull.
SR_FN uint frustumOutcode(vec4 c)
{
    uint code = 0u;
    if (c.x < -c.w) code |= 1u;
    if (c.x > c.w) code |= 2u;
    if (c.y < -c.w) code |= 4u;
    if (c.y > c.w) code |= 8u;
    if (c.z < 0.0f) code |= 16u;
    if (c.z > c.w) code |= 32u;
    return code;
}

SR_FN vec4 lerpClip(vec4 a, vec4 b, float t)
{
    SR_PRECISE vec4 r = a + t * (b - a);
    return r;
}

// Puts a clipper-generated vertex exactly on `plane`, removing the rounding of the interpolation in
// the coordinate that the plane constrains.
SR_FN vec4 projectOntoPlane(vec4 v, uint plane, vec4 guardBand)
{
    SR_PRECISE vec4 r = v;
    if (plane == 0u)
        r.z = 0.0f;
    else if (plane == 1u)
        r.z = r.w;
    else if (plane == 2u)
        r.x = guardBand.x * r.w;
    else if (plane == 3u)
        r.x = -(guardBand.x * r.w);
    else if (plane == 4u)
        r.y = guardBand.y * r.w;
    else
        r.y = -(guardBand.y * r.w);
    return r;
}

// One Sutherland-Hodgman pass against `plane`; returns the new vertex count.
// The intersection on an edge is interpolated from the endpoint nearer to the plane: t is then at most
// 1/2 and the result keeps the precision of the small quantities (interpolating from a far endpoint
// cancels catastrophically, e.g. w = 10000 - 9999.9 near the near plane). The choice depends only on
// the two endpoints, not on the edge's direction, so two triangles sharing the edge produce
// bit-identical points and stay watertight after clipping.
SR_FN uint clipPolygonAgainstPlane(SR_ARRAY_INOUT(vec4, poly, MAX_CLIP_VERTS), uint count, uint plane,
                                   vec4 guardBand)
{
    vec4 result[MAX_CLIP_VERTS];
    uint n = 0u;
    for (uint i = 0u; i < count; ++i) {
        vec4 a = poly[i];
        vec4 b = poly[(i + 1u) % count];
        float da = planeDistance(a, plane, guardBand);
        float db = planeDistance(b, plane, guardBand);
        bool aIn = da >= 0.0f;
        bool bIn = db >= 0.0f;
        if (aIn && n < uint(MAX_CLIP_VERTS)) result[n++] = a;
        if (aIn != bIn && n < uint(MAX_CLIP_VERTS)) {
            bool fromA = abs(da) < abs(db) || (abs(da) == abs(db) && aIn);
            vec4 near = fromA ? a : b;
            vec4 far = fromA ? b : a;
            float dNear = fromA ? da : db;
            float dFar = fromA ? db : da;
            SR_PRECISE float denom = dNear - dFar;
            result[n++] = projectOntoPlane(lerpClip(near, far, divDet(dNear, denom)), plane, guardBand);
        }
    }
    for (uint i = 0u; i < n; ++i) poly[i] = result[i];
    return n;
}

// Clips the triangle against every plane in `planes` (a clipOutcode mask); returns the vertex count of
// the resulting convex polygon (0 when nothing is left).
SR_FN uint clipTriangle(vec4 c0, vec4 c1, vec4 c2, uint planes, vec4 guardBand,
                        SR_ARRAY_INOUT(vec4, poly, MAX_CLIP_VERTS))
{
    poly[0] = c0;
    poly[1] = c1;
    poly[2] = c2;
    uint count = 3u;
    for (uint p = 0u; p < uint(CLIP_PLANE_COUNT); ++p)
        if ((planes & (1u << p)) != 0u && count >= 3u)
            count = clipPolygonAgainstPlane(poly, count, p, guardBand);
    return count >= 3u ? count : 0u;
}

// Clip position of a vertex as setup sees it: from the vertex stage's buffer, or, when no vertex is
// shared (RasterParams.transformInSetup), computed here by the same function the vertex stage uses, so
// the bits are the same either way.
SR_FN vec4 setupClipPosition(RasterParams params, vec4 worldPosition, vec4 storedClip)
{
    return params.transformInSetup != 0u ? mulPoint(params.clipFromWorld, worldPosition) : storedClip;
}

// What setup does with one input triangle before snapping.
#define PREPARE_INVALID 0u  // a NaN or Inf clip coordinate: dropped and counted
#define PREPARE_CULLED 1u   // all vertices outside one viewport plane: no pixel can be covered
#define PREPARE_DIRECT 2u   // inside the depth range and guard band: poly holds the 3 vertices
#define PREPARE_CLIPPED 3u  // went through the clipper: poly holds `count` vertices (0 = nothing left)

// Classifies the triangle and fills `poly`/`count` with the convex polygon to set up as a fan
// (poly[0], poly[k], poly[k + 1]).
SR_FN uint prepareTriangle(vec4 c0, vec4 c1, vec4 c2, vec4 guardBand,
                           SR_ARRAY_INOUT(vec4, poly, MAX_CLIP_VERTS), SR_OUT(uint) count)
{
    count = 0u;
    bool finite = true;
    for (int k = 0; k < 4; ++k) finite = finite && isFinite(c0[k]) && isFinite(c1[k]) && isFinite(c2[k]);
    if (!finite) return PREPARE_INVALID;
    if ((frustumOutcode(c0) & frustumOutcode(c1) & frustumOutcode(c2)) != 0u) return PREPARE_CULLED;
    uint planes = clipOutcode(c0, guardBand) | clipOutcode(c1, guardBand) | clipOutcode(c2, guardBand);
    if (planes == 0u) {
        poly[0] = c0;
        poly[1] = c1;
        poly[2] = c2;
        count = 3u;
        return PREPARE_DIRECT;
    }
    count = clipTriangle(c0, c1, c2, planes, guardBand, poly);
    return PREPARE_CLIPPED;
}

// ---------------------------------------------------------------------------------------------------
// Viewport transform and snapping. Window x = (ndc.x + 1) * width / 2, pixel centres at i + 0.5, and
// the result rounded half-to-even to 1/256 pixel. Returns false when w <= 0 or the vertex left the
// guard band (only possible for degenerate clipper output).
SR_FN bool snapVertex(vec4 c, uint width, uint height, SR_OUT(ivec2) xy, SR_OUT(float) z)
{
    xy = ivec2(0, 0);
    z = 0.0f;
    if (!(c.w > 0.0f)) return false;
    float invW = recipDet(c.w);
    SR_PRECISE float halfW = 0.5f * float(width);
    SR_PRECISE float halfH = 0.5f * float(height);
    SR_PRECISE float wx = (c.x * invW) * halfW + halfW;
    SR_PRECISE float wy = (c.y * invW) * halfH + halfH;
    SR_PRECISE float wz = c.z * invW;
    float limit = float(GUARD_BAND_PX) * 2.0f;
    if (!(abs(wx) < limit && abs(wy) < limit && isFinite(wz))) return false;
    SR_PRECISE float sx = wx * float(SUBPIXEL_SCALE);
    SR_PRECISE float sy = wy * float(SUBPIXEL_SCALE);
    xy = ivec2(int(roundEven(sx)), int(roundEven(sy)));
    z = clamp(wz, 0.0f, 1.0f);
    return true;
}

// Twice the signed area of the snapped triangle, in subpixel^2. In Vulkan's y-down framebuffer a
// triangle that is counter-clockwise on screen has a negative value.
SR_FN int64_t signedArea2(ivec2 v0, ivec2 v1, ivec2 v2)
{
    return int64_t(v1.x - v0.x) * int64_t(v2.y - v0.y) - int64_t(v1.y - v0.y) * int64_t(v2.x - v0.x);
}

// Edge function of the directed edge a->b at p: positive when p lies on the interior side of a
// positively oriented triangle. Exact in int64 for coordinates below 2^30.
SR_FN int64_t edgeFunction(ivec2 a, ivec2 b, ivec2 p)
{
    return int64_t(b.x - a.x) * int64_t(p.y - a.y) - int64_t(b.y - a.y) * int64_t(p.x - a.x);
}

// Top-left rule in the y-down framebuffer (D3D and lavapipe): a sample exactly on an edge belongs to
// the triangle only if the edge is a top edge (horizontal, interior below) or a left edge (interior to
// its right). For a positively oriented triangle those are dy == 0 && dx > 0, and dy < 0.
SR_FN bool isTopLeftEdge(ivec2 a, ivec2 b)
{
    int dx = b.x - a.x;
    int dy = b.y - a.y;
    return (dy == 0 && dx > 0) || dy < 0;
}

// Bias subtracted from an edge function so that `e - bias >= 0` implements the fill rule.
SR_FN int64_t edgeBias(ivec2 a, ivec2 b)
{
    return isTopLeftEdge(a, b) ? int64_t(0) : int64_t(1);
}

// First and last pixel index whose centre (256 i + 128 subpixels) lies in [lo, hi], clamped to
// [0, size - 1]. Empty when first > last. Arithmetic shift is floor division for negative values.
SR_FN ivec2 pixelSpan(int lo, int hi, uint size)
{
    int first = (lo - SUBPIXEL_SCALE / 2 + SUBPIXEL_SCALE - 1) >> SUBPIXEL_BITS;
    int last = (hi - SUBPIXEL_SCALE / 2) >> SUBPIXEL_BITS;
    return ivec2(max(first, 0), min(last, int(size) - 1));
}

// Deterministic 1 / area for a positive int64 area: floor(2^p / area) is an exact integer quotient
// below 2^24, so the float built from it is identical on every backend.
SR_FN float recipArea(int64_t area)
{
    uint64_t a = uint64_t(area);
    int shift = 0;
    while ((a >> shift) >= (uint64_t(1) << 24)) ++shift;  // a >> shift < 2^24
    uint64_t q = (uint64_t(1) << 47) / (a >> shift);      // in (2^23, 2^24]
    // 1/area ~= q * 2^-(47 + shift); build the float directly from the exact q.
    SR_PRECISE float r = float(q) * uintBitsToFloat(uint(127 - 47 - shift) << 23);
    return r;
}

// Everything raster needs from one (sub-)triangle. Returns false (and leaves `t` undefined) when the
// snapped triangle has zero area, faces the culled way, or covers no pixel centre of the viewport.
SR_FN bool setupTriangle(vec4 c0, vec4 c1, vec4 c2, uint triId, bool doubleSided, uint cullMode, uint width,
                         uint height, SR_OUT(TriSetup) t)
{
    ivec2 v0, v1, v2;
    float z0, z1, z2;
    if (!snapVertex(c0, width, height, v0, z0)) return false;
    if (!snapVertex(c1, width, height, v1, z1)) return false;
    if (!snapVertex(c2, width, height, v2, z2)) return false;
    int64_t area = signedArea2(v0, v1, v2);
    if (area == int64_t(0)) return false;
    bool frontFacing = area < int64_t(0);  // counter-clockwise on screen, glTF's front face
    if (!doubleSided && ((cullMode == CULL_BACK && !frontFacing) || (cullMode == CULL_FRONT && frontFacing)))
        return false;
    if (area < int64_t(0)) {  // make the edge functions positive inside
        ivec2 tv = v1;
        v1 = v2;
        v2 = tv;
        float tz = z1;
        z1 = z2;
        z2 = tz;
        area = -area;
    }
    ivec2 spanX = pixelSpan(min(v0.x, min(v1.x, v2.x)), max(v0.x, max(v1.x, v2.x)), width);
    ivec2 spanY = pixelSpan(min(v0.y, min(v1.y, v2.y)), max(v0.y, max(v1.y, v2.y)), height);
    if (spanX.x > spanX.y || spanY.x > spanY.y) return false;
    t.xy01 = ivec4(v0.x, v0.y, v1.x, v1.y);
    t.xy2Id = ivec4(v2.x, v2.y, int(triId), spanX.x | (spanY.x << 16));
    SR_PRECISE float dz10 = z1 - z0;
    SR_PRECISE float dz20 = z2 - z0;
    t.depthPlane = vec4(z0, dz10, dz20, recipArea(area));
    return true;
}

SR_FN ivec2 setupV0(TriSetup t)
{
    return ivec2(t.xy01.x, t.xy01.y);
}
SR_FN ivec2 setupV1(TriSetup t)
{
    return ivec2(t.xy01.z, t.xy01.w);
}
SR_FN ivec2 setupV2(TriSetup t)
{
    return ivec2(t.xy2Id.x, t.xy2Id.y);
}
SR_FN uint setupTriId(TriSetup t)
{
    return uint(t.xy2Id.z);
}

// Inclusive pixel bbox (minX, minY, maxX, maxY), already clamped to the viewport.
SR_FN ivec4 setupPixelBounds(TriSetup t, uint width, uint height)
{
    ivec2 v0 = setupV0(t), v1 = setupV1(t), v2 = setupV2(t);
    int maxX = pixelSpan(0, max(v0.x, max(v1.x, v2.x)), width).y;
    int maxY = pixelSpan(0, max(v0.y, max(v1.y, v2.y)), height).y;
    return ivec4(t.xy2Id.w & 0xffff, (t.xy2Id.w >> 16) & 0xffff, maxX, maxY);
}

SR_FN bool isSmallTriangle(ivec4 bounds)
{
    return bounds.z - bounds.x < SMALL_TRI_SPAN && bounds.w - bounds.y < SMALL_TRI_SPAN;
}

// Number of TILE_SIZE x TILE_SIZE screen tiles the bbox touches.
SR_FN uint tileCount(ivec4 bounds)
{
    uint tilesX = uint((bounds.z / TILE_SIZE) - (bounds.x / TILE_SIZE) + 1);
    uint tilesY = uint((bounds.w / TILE_SIZE) - (bounds.y / TILE_SIZE) + 1);
    return tilesX * tilesY;
}

// Pixel (px, py) of the tile with linear index `tileIndex` inside the bbox's tile rectangle, for the
// thread `lane` of a TILE_SIZE^2 group.
SR_FN ivec2 tilePixel(ivec4 bounds, uint tileIndex, uint lane)
{
    uint tilesX = uint((bounds.z / TILE_SIZE) - (bounds.x / TILE_SIZE) + 1);
    int tx = bounds.x / TILE_SIZE + int(tileIndex % tilesX);
    int ty = bounds.y / TILE_SIZE + int(tileIndex / tilesX);
    return ivec2(tx * TILE_SIZE + int(lane % uint(TILE_SIZE)), ty * TILE_SIZE + int(lane / uint(TILE_SIZE)));
}

// Work items a raster_tiles group takes at once: enough to keep every group busy, at most one per thread.
SR_FN uint rasterBatchSize(uint items, uint groups)
{
    return clamp((items + groups - 1u) / max(groups, 1u), 1u, uint(TILE_SIZE * TILE_SIZE));
}

// Coverage of pixel (px, py) and, when covered, its window depth. Depth is linear in screen space
// (Vulkan's rule) and evaluated from the exact edge functions with correctly rounded float steps, so
// CUDA and GLSL produce the same bits.
SR_FN bool rasterPixel(TriSetup t, int px, int py, SR_OUT(float) depth)
{
    depth = 1.0f;
    ivec2 v0 = setupV0(t), v1 = setupV1(t), v2 = setupV2(t);
    ivec2 p = ivec2(px * SUBPIXEL_SCALE + SUBPIXEL_SCALE / 2, py * SUBPIXEL_SCALE + SUBPIXEL_SCALE / 2);
    int64_t e0 = edgeFunction(v1, v2, p);  // weight of v0
    int64_t e1 = edgeFunction(v2, v0, p);  // weight of v1
    int64_t e2 = edgeFunction(v0, v1, p);  // weight of v2
    if (e0 - edgeBias(v1, v2) < int64_t(0)) return false;
    if (e1 - edgeBias(v2, v0) < int64_t(0)) return false;
    if (e2 - edgeBias(v0, v1) < int64_t(0)) return false;
    SR_PRECISE float b1 = float(e1) * t.depthPlane.w;
    SR_PRECISE float b2 = float(e2) * t.depthPlane.w;
    SR_PRECISE float z = t.depthPlane.x + b1 * t.depthPlane.y + b2 * t.depthPlane.z;
    // Clamp to the depth range; written so that -0.0 and NaN become +0.0 and keys stay ordered.
    depth = z > 0.0f ? min(z, 1.0f) : 0.0f;
    return true;
}

// 64-bit visibility key: non-negative float bits order like the floats, so one atomicMin does the depth
// test and the id write together; equal depths resolve to the lowest triangle id on every backend.
SR_FN uint64_t packVisibility(float depth, uint triId)
{
    return (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(triId);
}
SR_FN uint visibilityId(uint64_t key)
{
    return uint(key & uint64_t(0xffffffffu));
}
SR_FN float visibilityDepth(uint64_t key)
{
    return uint(key >> 32) == 0xffffffffu ? 1.0f : uintBitsToFloat(uint(key >> 32));
}

// ---------------------------------------------------------------------------------------------------
// Shading.

// Perspective-correct barycentrics of NDC point `ndc` straight from clip space (no division per
// vertex): p_i = xy_i - ndc * w_i, and the sub-areas of p_i are proportional to b_i / w_i.
// Works for vertices with w <= 0 because the covered point itself always has w > 0.
SR_FN vec3 perspectiveBarycentrics(vec4 c0, vec4 c1, vec4 c2, vec2 ndc)
{
    vec2 p0 = vec2(c0.x - ndc.x * c0.w, c0.y - ndc.y * c0.w);
    vec2 p1 = vec2(c1.x - ndc.x * c1.w, c1.y - ndc.y * c1.w);
    vec2 p2 = vec2(c2.x - ndc.x * c2.w, c2.y - ndc.y * c2.w);
    float a0 = p1.x * p2.y - p1.y * p2.x;
    float a1 = p2.x * p0.y - p2.y * p0.x;
    float a2 = p0.x * p1.y - p0.y * p1.x;
    float sum = a0 + a1 + a2;
    if (sum == 0.0f) return vec3(1.0f / 3.0f, 1.0f / 3.0f, 1.0f / 3.0f);
    vec3 b = vec3(a0, a1, a2) / sum;
    return clamp(b, vec3(0.0f), vec3(1.0f));  // clamped against rounding at grazing angles
}

// NDC of the centre of pixel (px, py).
SR_FN vec2 pixelCenterNdc(int px, int py, uint width, uint height)
{
    return vec2((float(px) + 0.5f) * 2.0f / float(width) - 1.0f,
                (float(py) + 0.5f) * 2.0f / float(height) - 1.0f);
}

SR_FN float linearToSrgb(float c)
{
    c = clamp(c, 0.0f, 1.0f);
    return c <= 0.0031308f ? 12.92f * c : 1.055f * pow(c, 1.0f / 2.4f) - 0.055f;
}

SR_FN uint packRgba8(vec3 linearRgb)
{
    uint r = uint(linearToSrgb(linearRgb.x) * 255.0f + 0.5f);
    uint g = uint(linearToSrgb(linearRgb.y) * 255.0f + 0.5f);
    uint b = uint(linearToSrgb(linearRgb.z) * 255.0f + 0.5f);
    return r | (g << 8) | (b << 16) | (255u << 24);
}

// A stable, well-spread colour per triangle id (integer hash, then 3 bytes).
SR_FN vec3 idColor(uint id)
{
    uint h = id * 0x9E3779B1u;
    h ^= h >> 16;
    h *= 0x85EBCA6Bu;
    h ^= h >> 13;
    return vec3(float(h & 255u), float((h >> 8) & 255u), float((h >> 16) & 255u)) / 255.0f;
}

// Lambert, Phong and Blinn-Phong with one directional light plus ambient, in view space.
// n: unit normal facing the viewer; v: unit vector towards the eye; l: unit vector towards the light.
SR_FN vec3 shadeLight(uint mode, vec3 albedo, vec3 n, vec3 v, vec3 l, vec4 lightColor, float specPower)
{
    vec3 light = vec3(lightColor.x, lightColor.y, lightColor.z);
    float ndotl = max(dot(n, l), 0.0f);
    vec3 color = albedo * (lightColor.w + ndotl * light);
    if (ndotl > 0.0f && mode == SHADING_PHONG) {
        vec3 r = 2.0f * dot(n, l) * n - l;
        color += light * pow(max(dot(r, v), 0.0f), specPower) * 0.5f;
    } else if (ndotl > 0.0f && mode == SHADING_BLINN_PHONG) {
        vec3 h = normalize(l + v);
        color += light * pow(max(dot(n, h), 0.0f), specPower) * 0.5f;
    }
    return color;
}

// Full shading of one covered pixel from its interpolated attributes.
// viewPos/viewNormal/color: perspective-correct interpolations; faceNormal: geometric normal of the
// triangle in view space (unnormalised); albedo: linear base colour.
SR_FN vec3 shadePixel(RasterParams params, uint triId, vec3 viewPos, vec3 viewNormal, vec3 faceNormal,
                      vec3 albedo)
{
    uint mode = params.shadingMode;
    if (mode == SHADING_PRIMITIVE_ID) return idColor(triId);
    vec3 v = normalize(vec3(0.0f) - viewPos);
    vec3 fn = dot(faceNormal, faceNormal) > 0.0f ? normalize(faceNormal) : vec3(0.0f, 0.0f, 1.0f);
    if (dot(fn, v) < 0.0f) fn = vec3(0.0f) - fn;  // face the viewer (double-sided or culling off)
    vec3 n = dot(viewNormal, viewNormal) > 0.0f ? normalize(viewNormal) : fn;
    if (dot(n, fn) < 0.0f) n = vec3(0.0f) - n;  // back faces are lit like front faces
    if (mode == SHADING_NORMALS) return n * 0.5f + vec3(0.5f);
    if (mode == SHADING_DEPTH) {
        float d = -viewPos.z;
        float s = clamp((params.shadeExtra.z - d) / max(params.shadeExtra.z - params.shadeExtra.y, 1e-20f),
                        0.0f, 1.0f);
        return vec3(s * s);
    }
    vec3 l = vec3(params.lightDirView.x, params.lightDirView.y, params.lightDirView.z);
    if (mode == SHADING_FLAT) return shadeLight(SHADING_LAMBERT, albedo, fn, v, l, params.lightColor, 1.0f);
    return shadeLight(mode, albedo, n, v, l, params.lightColor, params.shadeExtra.x);
}

// SHADING_HIT_COUNT: background where nothing covered the pixel, green for exactly one triangle (what a
// watertight mesh gives), red for two, white for more.
SR_FN vec3 hitCountColor(uint hits, vec3 background)
{
    if (hits == 0u) return background;
    if (hits == 1u) return vec3(0.1f, 0.6f, 0.1f);
    if (hits == 2u) return vec3(0.9f, 0.05f, 0.05f);
    return vec3(1.0f);
}

SR_FN vec3 interpolate3(vec3 b, vec4 a0, vec4 a1, vec4 a2)
{
    return vec3(a0.x, a0.y, a0.z) * b.x + vec3(a1.x, a1.y, a1.z) * b.y + vec3(a2.x, a2.y, a2.z) * b.z;
}

// Colour of pixel (px, py) covered by triangle `triId`, from its world-space vertex positions, normals
// and linear colours. Shading re-derives each vertex's clip position, view position and view normal
// with transformVertex instead of reading them from per-vertex buffers: three small matrix products per
// pixel cost less than storing and re-reading 48 bytes per vertex, and the clip positions come out
// bit-identical to the vertex stage's, so the barycentrics match the rasterized triangle exactly.
SR_FN vec3 shadeTriangleAt(RasterParams params, uint triId, int px, int py, vec4 pos0, vec4 pos1, vec4 pos2,
                           vec4 nrm0, vec4 nrm1, vec4 nrm2, vec4 col0, vec4 col1, vec4 col2)
{
    vec4 c0, c1, c2, p0, p1, p2, n0, n1, n2;
    transformVertex(params, pos0, nrm0, c0, p0, n0);
    transformVertex(params, pos1, nrm1, c1, p1, n1);
    transformVertex(params, pos2, nrm2, c2, p2, n2);
    vec3 b = perspectiveBarycentrics(c0, c1, c2, pixelCenterNdc(px, py, params.width, params.height));
    vec3 viewPos = interpolate3(b, p0, p1, p2);
    vec3 viewNormal = interpolate3(b, n0, n1, n2);
    vec3 albedo = interpolate3(b, col0, col1, col2);
    vec3 e1 = vec3(p1.x - p0.x, p1.y - p0.y, p1.z - p0.z);
    vec3 e2 = vec3(p2.x - p0.x, p2.y - p0.y, p2.z - p0.z);
    return shadePixel(params, triId, viewPos, viewNormal, cross(e1, e2), albedo);
}

#if defined(__cplusplus)
}  // namespace sr
#endif
#endif  // RASTER_SHARED_H
