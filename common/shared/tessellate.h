// shared/tessellate.h - stages tess_*: adaptive tessellation to the screen size of each edge.
//
// The wish of the course project whose geometry stage split every triangle at its centroid 3^N times:
// refine a triangle only as much as its size on screen asks, and keep the mesh watertight.
//
// Edge factors. Edge k of a triangle runs from corner k to corner k + 1 (mod 3). Its factor
// f = clamp(ceil(projected length / tessEdgePx), 1, tessMaxLevel) is computed from the edge's two
// endpoints alone, taken in a canonical order (tessPrecedes: by position, not by index or by the
// triangle's winding), with exact comparisons instead of a square root whose bits the backends would not
// share. The two triangles that share an edge therefore choose the same factor and put its f - 1 new
// points at the same bits (tessEdgePoint, again from the canonical endpoints), which is all it takes
// for the refined mesh to be crack-free: nothing else of either triangle touches the edge.
//
// Pattern. With n = max(f0, f1, f2): n = 1 draws the triangle as it is. Otherwise the inside is a
// regular lattice of level m = max(n - 3, 0) whose corners sit one step of 1/max(n, 3) in from the
// triangle's corners (its points have barycentric coordinates (a + 1, b + 1, c + 1) / (m + 3), a + b + c =
// m), and each edge is zipped to the lattice side parallel to it: a strip between two parallel rows of
// points, f on the edge and m + 1 on the lattice side, walked in order of their position along the edge.
// Every triangle of a strip has an edge on one row and its apex on the other, so the strips cannot
// fold, whatever the three factors (unlike snapping a uniform lattice to the edge points). Counts per
// triangle: vertices (f0 - 1) + (f1 - 1) + (f2 - 1) + (m + 1)(m + 2) / 2, triangles m^2 + 3m + f0 + f1 + f2.
//
// Surfaces. flat keeps every new vertex in the triangle's plane (attributes interpolated linearly). pn
// puts it on the Curved PN triangle of Vlachos, Peters, Boyd and Mitchell (I3D 2001): a cubic Bezier
// triangle from the three positions and normals, whose edges depend on their two endpoints only; its
// normals come from their quadratic normal patch. An edge whose two triangles disagree on the normals at
// its ends (a hard edge), or that has more than two triangles, would open a crack under pn, so the host
// marks it straight (TESS_STRAIGHT_EDGES) and the patch keeps that edge's control points on the chord; a
// triangle with a zero or non-finite corner normal stays flat (TESS_FLAT_PATCH), with a warning.
//
// Culling before refining: a triangle whose control points (its corners for flat, the ten Bezier
// points for pn, whose convex hull holds the patch) all lie outside one plane of the view volume
// generates nothing, and under flat so does one that setup would cull for its facing (same snapped
// area, same rule). A pn patch can turn towards the camera where its flat triangle does not, so pn
// culls by the view volume only and leaves facing to setup. An edge with an endpoint in front of the
// near plane has no meaningful projected length and takes the largest factor (both sides agree).
//
// centroid is the course project's baseline for comparison: each triangle split at its centroid into
// three, tessMaxLevel times (3^N triangles, (3^N - 1) / 2 new vertices), whatever its size on screen.
//
// Part of raster_shared.h (included from there, not on its own); same three-language rules. The
// writing half, with its hooks for the buffers of each backend, is shared/tess_emit.h.
#ifndef RASTER_SHARED_TESSELLATE_H
#define RASTER_SHARED_TESSELLATE_H

SR_NAMESPACE_BEGIN

// One vertex with everything the later stages read of it.
struct TessVertex {
    vec4 position;  // world space, w = 1
    vec4 normal;    // world space, w = 0 (not normalised: shade normalises after interpolating)
    vec4 texcoord;  // (u0, v0, u1, v1)
    vec4 color;     // linear RGBA
};

// A scene triangle and its pn control points (b300 = corner 0, b030 = corner 1, b003 = corner 2; bIJK
// weighs corner 0 by I, corner 1 by J, corner 2 by K) and quadratic normal coefficients.
struct TessPatch {
    TessVertex v0;
    TessVertex v1;
    TessVertex v2;
    vec4 b210;
    vec4 b120;
    vec4 b021;
    vec4 b012;
    vec4 b102;
    vec4 b201;
    vec4 b111;
    vec4 n110;
    vec4 n011;
    vec4 n101;
    uint flags;  // TessSource.flags
};

// Dot product of the xyz parts in a fixed order (GLSL's dot leaves the order to the driver).
SR_FN float tessDot3(vec4 a, vec4 b)
{
    SR_PRECISE float r = (a.x * b.x + a.y * b.y) + a.z * b.z;
    return r;
}

// The canonical order of an edge's endpoints: lexicographic by world position. Both triangles of an
// edge see the same two positions, whatever their indices (seams duplicate vertices) and winding.
SR_FN bool tessPrecedes(vec4 a, vec4 b)
{
    if (a.x != b.x) return a.x < b.x;
    if (a.y != b.y) return a.y < b.y;
    return a.z < b.z;
}

// Factor of the edge between clip positions ca and cb, given in canonical order: the smallest f with
// f * edgePx >= its projected length in output pixels, within 1..maxLevel. Decided by exact comparisons
// of squares; the square root only guesses where to start.
SR_FN uint tessEdgeFactor(vec4 ca, vec4 cb, float halfWidth, float halfHeight, float edgePx, uint maxLevel)
{
    if (!(ca.w > 0.0f) || !(cb.w > 0.0f) || ca.z < 0.0f || cb.z < 0.0f) return maxLevel;
    SR_PRECISE float dx = (ca.x * recipDet(ca.w) - cb.x * recipDet(cb.w)) * halfWidth;
    SR_PRECISE float dy = (ca.y * recipDet(ca.w) - cb.y * recipDet(cb.w)) * halfHeight;
    SR_PRECISE float len2 = dx * dx + dy * dy;
    if (!isFinite(len2)) return maxLevel;
    float guess = min(ceil(sqrt(len2) / edgePx), float(maxLevel));
    uint f = uint(max(guess, 1.0f));
    for (uint i = 0u; i < TESS_MAX_LEVEL && f > 1u; ++i) {
        SR_PRECISE float shorter = float(f - 1u) * edgePx;
        SR_PRECISE float shorter2 = shorter * shorter;
        if (shorter2 < len2) break;
        --f;
    }
    for (uint i = 0u; i < TESS_MAX_LEVEL && f < maxLevel; ++i) {
        SR_PRECISE float reach = float(f) * edgePx;
        SR_PRECISE float reach2 = reach * reach;
        if (reach2 >= len2) break;
        ++f;
    }
    return f;
}

// A pn edge control point: (2 p + q - ((q - p) . n) n) / 3, the projection of the chord's third point
// onto the tangent plane at p. On the chord ((2 p + q) / 3) for a straight edge.
SR_FN vec4 tessEdgeControl(vec4 p, vec4 q, vec4 n, bool straight)
{
    SR_PRECISE vec4 d = q - p;
    SR_PRECISE float w = straight ? 0.0f : tessDot3(d, n);
    SR_PRECISE vec4 r = ((p + p) + q - w * n) * 0.333333343f;
    r.w = 1.0f;
    return r;
}

// The quadratic normal patch's mid-edge coefficient: n_p + n_q reflected in the plane normal to the
// edge, normalised (Vlachos et al.: v = 2 (q - p).(n_p + n_q) / |q - p|^2).
SR_FN vec4 tessEdgeNormal(vec4 p, vec4 q, vec4 np, vec4 nq)
{
    vec4 d = q - p;
    vec4 s = np + nq;
    float len2 = tessDot3(d, d);
    float v = len2 > 0.0f ? 2.0f * tessDot3(d, s) / len2 : 0.0f;
    vec4 n = s - v * d;
    float nn = tessDot3(n, n);
    n = nn > 0.0f ? n / sqrt(nn) : s;
    n.w = 0.0f;
    return n;
}

SR_FN bool tessUsesPn(uint mode, uint flags)
{
    return mode == TESS_PN && (flags & TESS_FLAT_PATCH) == 0u;
}

// A scene triangle for tessellation mode `mode`, with its pn control points when it is a pn patch
// (tessUsesPn; otherwise they are zero and nothing reads them). Edge k's controls stay on its chord when
// TESS_STRAIGHT_EDGES says so, so that the patch meets the straight edge points tessEdgePoint puts there.
SR_FN TessPatch tessMakePatch(uint mode, TessVertex v0, TessVertex v1, TessVertex v2, uint flags)
{
    TessPatch t;
    t.v0 = v0;
    t.v1 = v1;
    t.v2 = v2;
    t.flags = flags;
    vec4 zero = vec4(0.0f);
    t.b210 = t.b120 = t.b021 = t.b012 = t.b102 = t.b201 = t.b111 = zero;
    t.n110 = t.n011 = t.n101 = zero;
    if (!tessUsesPn(mode, flags)) return t;
    bool s0 = (flags & 1u) != 0u, s1 = (flags & 2u) != 0u, s2 = (flags & 4u) != 0u;
    vec4 p0 = v0.position, p1 = v1.position, p2 = v2.position;
    t.b210 = tessEdgeControl(p0, p1, v0.normal, s0);
    t.b120 = tessEdgeControl(p1, p0, v1.normal, s0);
    t.b021 = tessEdgeControl(p1, p2, v1.normal, s1);
    t.b012 = tessEdgeControl(p2, p1, v2.normal, s1);
    t.b102 = tessEdgeControl(p2, p0, v2.normal, s2);
    t.b201 = tessEdgeControl(p0, p2, v0.normal, s2);
    // Centre: E + (E - V) / 2, E the mean of the six edge points, V the mean of the corners.
    SR_PRECISE vec4 e = (((t.b210 + t.b120) + (t.b021 + t.b012)) + (t.b102 + t.b201)) * 0.166666672f;
    SR_PRECISE vec4 c = ((p0 + p1) + p2) * 0.333333343f;
    SR_PRECISE vec4 b111 = e + (e - c) * 0.5f;
    t.b111 = b111;
    t.b111.w = 1.0f;
    t.n110 = tessEdgeNormal(p0, p1, v0.normal, v1.normal);
    t.n011 = tessEdgeNormal(p1, p2, v1.normal, v2.normal);
    t.n101 = tessEdgeNormal(p2, p0, v2.normal, v0.normal);
    return t;
}

// Clip position of a world position (the vertex stage's transform, same bits).
SR_FN uint tessOutcode(RasterParams params, vec4 world)
{
    return frustumOutcode(mulPoint(params.clipFromWorld, world));
}

// Whether nothing of the triangle can be visible: every control point outside one plane of the view
// volume, or (flat) facing the culled way as setup decides it from the snapped corners.
SR_FN bool tessCulled(RasterParams params, TessPatch t, vec4 c0, vec4 c1, vec4 c2)
{
    uint code = frustumOutcode(c0) & frustumOutcode(c1) & frustumOutcode(c2);
    if (code == 0u) return false;
    if (!tessUsesPn(params.tessMode, t.flags)) return true;
    code &= tessOutcode(params, t.b210) & tessOutcode(params, t.b120) & tessOutcode(params, t.b021);
    code &= tessOutcode(params, t.b012) & tessOutcode(params, t.b102) & tessOutcode(params, t.b201);
    return (code & tessOutcode(params, t.b111)) != 0u;
}

SR_FN bool tessFacingCulled(RasterParams params, uint flags, vec4 c0, vec4 c1, vec4 c2)
{
    if (tessUsesPn(params.tessMode, flags)) return false;
    bool doubleSided = ((flags >> TESS_TRI_FLAGS_SHIFT) & TRI_FLAG_DOUBLE_SIDED) != 0u;
    if (doubleSided || params.cullMode == CULL_NONE) return false;
    ivec2 v0, v1, v2;
    float z0, z1, z2;
    // Only a triangle setup would draw unclipped has a snapped area to decide by.
    if ((clipOutcode(c0, params.guardBand) | clipOutcode(c1, params.guardBand) |
         clipOutcode(c2, params.guardBand)) != 0u)
        return false;
    if (!snapVertex(c0, params.width, params.height, v0, z0) ||
        !snapVertex(c1, params.width, params.height, v1, z1) ||
        !snapVertex(c2, params.width, params.height, v2, z2))
        return false;
    int64_t area = signedArea2(v0, v1, v2);
    if (area == int64_t(0)) return true;  // no sample of it or of its flat pieces
    bool frontFacing = area < int64_t(0);
    return (params.cullMode == CULL_BACK && !frontFacing) || (params.cullMode == CULL_FRONT && frontFacing);
}

// 3^level for level <= 15, without a loop: the product of 3^(2^k) over the set bits of `level`.
// (tess_emit calls it in its innermost loops; on a CPU device every turn of a loop counts towards
// llvmpipe's limit of 65,535 per invocation, docs/benchmark.md "Loops on a CPU device".)
SR_FN uint tessPow3(uint level)
{
    uint r = (level & 1u) != 0u ? 3u : 1u;
    if ((level & 2u) != 0u) r *= 9u;
    if ((level & 4u) != 0u) r *= 81u;
    if ((level & 8u) != 0u) r *= 6561u;
    return r;
}

// Edge factors (f0 | f1 << 8 | f2 << 16) of a triangle with clip corners c0..c2 and world corners p0..p2.
SR_FN uint tessFactors(RasterParams params, vec4 p0, vec4 p1, vec4 p2, vec4 c0, vec4 c1, vec4 c2)
{
    float halfW = 0.5f * float(params.width / params.ssaa);
    float halfH = 0.5f * float(params.height / params.ssaa);
    float L = params.tessEdgePx;
    uint m = params.tessMaxLevel;
    uint f0 = tessPrecedes(p0, p1) ? tessEdgeFactor(c0, c1, halfW, halfH, L, m)
                                   : tessEdgeFactor(c1, c0, halfW, halfH, L, m);
    uint f1 = tessPrecedes(p1, p2) ? tessEdgeFactor(c1, c2, halfW, halfH, L, m)
                                   : tessEdgeFactor(c2, c1, halfW, halfH, L, m);
    uint f2 = tessPrecedes(p2, p0) ? tessEdgeFactor(c2, c0, halfW, halfH, L, m)
                                   : tessEdgeFactor(c0, c2, halfW, halfH, L, m);
    return f0 | (f1 << 8) | (f2 << 16);
}

SR_FN uint tessFactor(uint factors, uint edge)
{
    return (factors >> (8u * edge)) & 255u;
}

// Inner lattice level m of a triangle whose largest factor is n >= 2.
SR_FN uint tessInnerLevel(uint n)
{
    return n > 3u ? n - 3u : 0u;
}

// New vertices (x) and triangles (y) of a triangle with these factors (mode flat or pn), or of a
// centroid split of `level` rounds.
SR_FN uvec2 tessCounts(uint mode, uint factors, uint level)
{
    if (mode == TESS_CENTROID) return uvec2((tessPow3(level) - 1u) / 2u, tessPow3(level));
    uint f0 = tessFactor(factors, 0u), f1 = tessFactor(factors, 1u), f2 = tessFactor(factors, 2u);
    uint n = max(f0, max(f1, f2));
    if (n <= 1u) return uvec2(0u, 1u);
    uint m = tessInnerLevel(n);
    return uvec2((f0 - 1u) + (f1 - 1u) + (f2 - 1u) + (m + 1u) * (m + 2u) / 2u, m * m + 3u * m + f0 + f1 + f2);
}

// The per-triangle decision of stage tess_count: BUF_TESS_COUNTS's entry (new vertices, new triangles,
// factors, TESS_STATE_*).
SR_FN uvec4 tessCountTriangle(RasterParams params, TessPatch t)
{
    vec4 c0 = mulPoint(params.clipFromWorld, t.v0.position);
    vec4 c1 = mulPoint(params.clipFromWorld, t.v1.position);
    vec4 c2 = mulPoint(params.clipFromWorld, t.v2.position);
    bool finite = true;
    for (int k = 0; k < 4; ++k) finite = finite && isFinite(c0[k]) && isFinite(c1[k]) && isFinite(c2[k]);
    // Non-finite corners go on as they are: setup drops them and counts them as invalid.
    if (!finite) return uvec4(0u, 1u, 0x010101u, TESS_STATE_PASS);
    if (tessCulled(params, t, c0, c1, c2) || tessFacingCulled(params, t.flags, c0, c1, c2))
        return uvec4(0u, 0u, 0u, TESS_STATE_CULLED);
    if (params.tessMode == TESS_CENTROID) {
        uvec2 n = tessCounts(TESS_CENTROID, 0u, params.tessMaxLevel);
        return uvec4(n.x, n.y, 0u, params.tessMaxLevel == 0u ? TESS_STATE_PASS : 0u);
    }
    uint factors = tessFactors(params, t.v0.position, t.v1.position, t.v2.position, c0, c1, c2);
    uvec2 n = tessCounts(params.tessMode, factors, 0u);
    return uvec4(n.x, n.y, factors, n.y == 1u ? TESS_STATE_PASS : 0u);
}

// Linear interpolation of a vertex along an edge, parameter t from a.
SR_FN TessVertex tessLerpVertex(TessVertex a, TessVertex b, float t)
{
    TessVertex r;
    SR_PRECISE vec4 p = a.position + t * (b.position - a.position);
    r.position = p;
    r.position.w = 1.0f;
    r.normal = a.normal + t * (b.normal - a.normal);
    r.texcoord = a.texcoord + t * (b.texcoord - a.texcoord);
    r.color = a.color + t * (b.color - a.color);
    return r;
}

// Point j of f along the edge from a to b, given in canonical order (tessPrecedes), straight (flat, or
// a straight pn edge) or on the pn patch's boundary cubic (which depends on a and b alone).
SR_FN TessVertex tessEdgePoint(TessVertex a, TessVertex b, uint j, uint f, bool pn)
{
    float t = divDet(float(j), float(f));
    TessVertex r = tessLerpVertex(a, b, t);
    if (!pn) return r;
    vec4 ca = tessEdgeControl(a.position, b.position, a.normal, false);
    vec4 cb = tessEdgeControl(b.position, a.position, b.normal, false);
    SR_PRECISE float s = 1.0f - t;
    SR_PRECISE float w0 = (s * s) * s;
    SR_PRECISE float w1 = (3.0f * (s * s)) * t;
    SR_PRECISE float w2 = (3.0f * s) * (t * t);
    SR_PRECISE float w3 = (t * t) * t;
    SR_PRECISE vec4 p = ((w0 * a.position + w1 * ca) + w2 * cb) + w3 * b.position;
    r.position = p;
    r.position.w = 1.0f;
    vec4 nab = tessEdgeNormal(a.position, b.position, a.normal, b.normal);
    r.normal = ((s * s) * a.normal + (t * t) * b.normal) + (s * t) * nab;
    return r;
}

// The surface point with barycentric weights (u, v, w) on corners 0, 1, 2: the plane (flat) or the
// patch (pn); attributes interpolate linearly either way.
SR_FN TessVertex tessInnerPoint(TessPatch t, float u, float v, float w, bool pn)
{
    TessVertex r;
    SR_PRECISE vec4 planar = (u * t.v0.position + v * t.v1.position) + w * t.v2.position;
    r.position = planar;
    r.normal = (u * t.v0.normal + v * t.v1.normal) + w * t.v2.normal;
    r.texcoord = (u * t.v0.texcoord + v * t.v1.texcoord) + w * t.v2.texcoord;
    r.color = (u * t.v0.color + v * t.v1.color) + w * t.v2.color;
    if (pn) {
        SR_PRECISE float uu = u * u, vv = v * v, ww = w * w;
        SR_PRECISE vec4 corners =
            ((uu * u) * t.v0.position + (vv * v) * t.v1.position) + (ww * w) * t.v2.position;
        SR_PRECISE vec4 edges01 = (3.0f * uu * v) * t.b210 + (3.0f * u * vv) * t.b120;
        SR_PRECISE vec4 edges12 = (3.0f * vv * w) * t.b021 + (3.0f * v * ww) * t.b012;
        SR_PRECISE vec4 edges20 = (3.0f * ww * u) * t.b102 + (3.0f * w * uu) * t.b201;
        SR_PRECISE vec4 p = ((corners + edges01) + (edges12 + edges20)) + (6.0f * u * v * w) * t.b111;
        r.position = p;
        r.normal = ((uu * t.v0.normal + vv * t.v1.normal) + ww * t.v2.normal) +
                   ((u * v) * t.n110 + (v * w) * t.n011) + (w * u) * t.n101;
    }
    r.position.w = 1.0f;
    r.normal.w = 0.0f;
    return r;
}

SR_FN TessVertex tessCorner(TessPatch t, uint k)
{
    return k == 0u ? t.v0 : (k == 1u ? t.v1 : t.v2);
}

// The mean of three vertices (the centroid baseline's new vertex).
SR_FN TessVertex tessCentroid(TessVertex a, TessVertex b, TessVertex c)
{
    TessVertex r;
    SR_PRECISE vec4 p = ((a.position + b.position) + c.position) * 0.333333343f;
    r.position = p;
    r.position.w = 1.0f;
    r.normal = ((a.normal + b.normal) + c.normal) * 0.333333343f;
    r.texcoord = ((a.texcoord + b.texcoord) + c.texcoord) * 0.333333343f;
    r.color = ((a.color + b.color) + c.color) * 0.333333343f;
    return r;
}

SR_NAMESPACE_END

#endif  // RASTER_SHARED_TESSELLATE_H
