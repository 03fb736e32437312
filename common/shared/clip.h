// shared/clip.h - the clipping half of stage `setup`: outcodes, frustum culling and the polygon clipper.
//
// Near and far are clipped exactly (no vertex with w <= 0 reaches the divide); x and y only at the
// guard band, which keeps snapped coordinates in range. The clipper interpolates each cut edge from its
// nearer endpoint, whichever way the edge runs, so shared edges stay watertight. Part of
// raster_shared.h (included from there, not on its own); same three-language rules.
#ifndef RASTER_SHARED_CLIP_H
#define RASTER_SHARED_CLIP_H

SR_NAMESPACE_BEGIN

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

// Classifies the triangle without touching a polygon: PREPARE_DIRECT triangles (nearly all of them)
// are set up straight from c0, c1, c2, so the polygon array, which dynamic indexing puts in local
// memory, is only written for the few that need the clipper. `planes` names the planes to clip against.
SR_FN uint classifyTriangle(vec4 c0, vec4 c1, vec4 c2, vec4 guardBand, SR_OUT(uint) planes)
{
    planes = 0u;
    bool finite = true;
    for (int k = 0; k < 4; ++k) finite = finite && isFinite(c0[k]) && isFinite(c1[k]) && isFinite(c2[k]);
    if (!finite) return PREPARE_INVALID;
    if ((frustumOutcode(c0) & frustumOutcode(c1) & frustumOutcode(c2)) != 0u) return PREPARE_CULLED;
    planes = clipOutcode(c0, guardBand) | clipOutcode(c1, guardBand) | clipOutcode(c2, guardBand);
    return planes == 0u ? PREPARE_DIRECT : PREPARE_CLIPPED;
}

// Classifies the triangle and fills `poly`/`count` with the convex polygon to set up as a fan
// (poly[0], poly[k], poly[k + 1]).
SR_FN uint prepareTriangle(vec4 c0, vec4 c1, vec4 c2, vec4 guardBand,
                           SR_ARRAY_INOUT(vec4, poly, MAX_CLIP_VERTS), SR_OUT(uint) count)
{
    uint planes;
    uint kind = classifyTriangle(c0, c1, c2, guardBand, planes);
    count = 0u;
    if (kind == PREPARE_DIRECT) {
        poly[0] = c0;
        poly[1] = c1;
        poly[2] = c2;
        count = 3u;
    } else if (kind == PREPARE_CLIPPED) {
        count = clipTriangle(c0, c1, c2, planes, guardBand, poly);
    }
    return kind;
}

// What setup does with one input line segment before snapping: the same PREPARE_* classes as a
// triangle. The segment c0 -> c1 is cut to the part inside near, far and the guard band (Liang-Barsky:
// one parameter interval, narrowed plane by plane); a and b are its clip-space ends, u.x and u.y their
// parameters along c0 -> c1 (for shading: the vertex attributes interpolate in u). An end moved by a
// plane is put exactly on it, as the polygon clipper does. Culled also when the segment lies outside
// one viewport plane: Vulkan clips lines against the view volume, so a wide line whose centre line is
// off screen draws nothing.
SR_FN uint prepareLine(vec4 c0, vec4 c1, vec4 guardBand, SR_OUT(vec4) a, SR_OUT(vec4) b, SR_OUT(vec2) u)
{
    a = c0;
    b = c1;
    u = vec2(0.0f, 1.0f);
    bool finite = true;
    for (int k = 0; k < 4; ++k) finite = finite && isFinite(c0[k]) && isFinite(c1[k]);
    if (!finite) return PREPARE_INVALID;
    if ((frustumOutcode(c0) & frustumOutcode(c1)) != 0u) return PREPARE_CULLED;
    uint planes = clipOutcode(c0, guardBand) | clipOutcode(c1, guardBand);
    if (planes == 0u) return PREPARE_DIRECT;
    float u0 = 0.0f, u1 = 1.0f;
    uint plane0 = uint(CLIP_PLANE_COUNT);  // the plane that moved each end, if any
    uint plane1 = uint(CLIP_PLANE_COUNT);
    for (uint p = 0u; p < uint(CLIP_PLANE_COUNT); ++p) {
        if ((planes & (1u << p)) == 0u) continue;
        float d0 = planeDistance(c0, p, guardBand);
        float d1 = planeDistance(c1, p, guardBand);
        if (d0 < 0.0f && d1 < 0.0f) return PREPARE_CULLED;
        SR_PRECISE float denom = d0 - d1;
        float cut = divDet(d0, denom);  // where the distance, linear in the parameter, is zero
        if (d0 < 0.0f && cut > u0) {
            u0 = cut;
            plane0 = p;
        } else if (d1 < 0.0f && cut < u1) {
            u1 = cut;
            plane1 = p;
        }
    }
    if (!(u0 < u1)) return PREPARE_CULLED;
    if (plane0 != uint(CLIP_PLANE_COUNT)) a = projectOntoPlane(lerpClip(c0, c1, u0), plane0, guardBand);
    if (plane1 != uint(CLIP_PLANE_COUNT)) b = projectOntoPlane(lerpClip(c0, c1, u1), plane1, guardBand);
    u = vec2(u0, u1);
    return PREPARE_CLIPPED;
}

SR_NAMESPACE_END

#endif  // RASTER_SHARED_CLIP_H
