// shared/methods.h - the raster methods `raster study` compares with fixed8 (--raster-method, issue 12):
// fixed4, float and scanline. Each replaces fixed8's setup (snapping and the TriSetup record), its
// coverage test and its tile test; bins, tiles, the visibility key and shading stay the same, so the
// methods differ in their rule only and run the same binned pipeline on every backend.
//
//   fixed4    vertices snapped to 1/16 pixel (cudaraster and older hardware); then exactly fixed8's
//             integer edge functions and top-left rule. Watertight like fixed8; vertices move by up to
//             1/32 pixel, so it differs from a conformant rasterizer along edges.
//   float     the course projects' bounding box + barycentric test, done carefully: unrounded float
//             window positions, edge functions in float relative to an edge's first vertex (so that
//             their error follows the triangle's size, not its distance from the origin), a sample
//             inside the vertices' bbox counted when every barycentric coordinate is >= -FLOAT_EPSILON.
//             No tie rule: a sample on a shared edge is counted by both triangles (a double hit), and
//             where the edge function's rounding error, about 2^-23 |edge| L (L the distance from the
//             edge's first vertex), exceeds FLOAT_EPSILON x the doubled area |edge| h, both triangles
//             can miss a sample (a crack): triangles with L / h > 2^-16 x 2^23 = 128 (slivers).
//   scanline  the course projects' scanline walk: the triangle split at its middle vertex into a
//             flat-bottom and a flat-top half; on each sample row the span between the long edge and
//             the half's short edge, each edge's x evaluated from its upper vertex in float (x_top +
//             (y - y_top) * dx / dy); rows half-open [y_top, y_bottom), spans half-open [x_left,
//             x_right). Two triangles evaluate a shared edge with the same operands, so the edge itself
//             never cracks; failures come where rounding puts two edges of different upper vertices in
//             the wrong order on a row (slivers, and the neighbourhood of vertices). It is written per
//             sample (the span of the sample's row) so that it runs in the binned pipeline; a sequential
//             walk covers the same samples.
// float and scanline test no tile or pixel rectangle against the edges (triangleTouchesTile): the bbox
// is their whole conservative test, and a tile of the bbox the triangle misses costs one empty walk.
// float and scanline keep float window positions in the TriSetup record: its integer slots hold the
// float bits, in subpixels (x 256, exact), and depthPlane.w is 1 / area of the float triangle. Their
// depth is the plane through the vertex depths at the float barycentrics, clamped to the vertices' depth
// range (as the early depth bound of raster_tiles assumes). Lines and points keep fixed8 snapping under
// every method (setupLine); a line's rectangle is then tested by the method's rule.
//
// Part of raster_shared.h (included from there, not on its own); same three-language rules.
#ifndef RASTER_SHARED_METHODS_H
#define RASTER_SHARED_METHODS_H

SR_NAMESPACE_BEGIN

// The viewport transform of snapVertex without its rounding: window position in subpixels (float) and
// window depth; false where snapVertex fails. snapVertex repeats these lines rather than calling this:
// fixed8's setup stays the code it was measured as (setupSnappedTriangle explains why).
SR_FN bool windowSubpixels(vec4 c, uint width, uint height, SR_OUT(vec2) s, SR_OUT(float) z)
{
    s = vec2(0.0f, 0.0f);
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
    s = vec2(sx, sy);
    z = clamp(wz, 0.0f, 1.0f);
    return true;
}

// ---------------------------------------------------------------------------------------------- fixed4

// Snaps to 1/16 pixel (rounded half-to-even there), in fixed8's subpixel units (multiples of 16).
SR_FN bool snapVertexFixed4(vec4 c, uint width, uint height, SR_OUT(ivec2) xy, SR_OUT(float) z)
{
    vec2 s;
    xy = ivec2(0, 0);
    if (!windowSubpixels(c, width, height, s, z)) return false;
    SR_PRECISE float qx = s.x * 0.0625f;
    SR_PRECISE float qy = s.y * 0.0625f;
    xy = ivec2(int(roundEven(qx)) * 16, int(roundEven(qy)) * 16);
    return true;
}

SR_FN bool setupTriangleFixed4(vec4 c0, vec4 c1, vec4 c2, uint triId, bool doubleSided, uint cullMode,
                               uint width, uint height, uint bounds, SR_OUT(TriSetup) t)
{
    ivec2 v0, v1, v2;
    float z0, z1, z2;
    if (!snapVertexFixed4(c0, width, height, v0, z0)) return false;
    if (!snapVertexFixed4(c1, width, height, v1, z1)) return false;
    if (!snapVertexFixed4(c2, width, height, v2, z2)) return false;
    return setupSnappedTriangle(v0, v1, v2, z0, z1, z2, triId, doubleSided, cullMode, width, height, bounds,
                                t);
}

// ------------------------------------------------------------------------------- float and scanline

SR_FN vec2 floatV0(TriSetup t)
{
    return vec2(uintBitsToFloat(uint(t.xy01.x)), uintBitsToFloat(uint(t.xy01.y)));
}
SR_FN vec2 floatV1(TriSetup t)
{
    return vec2(uintBitsToFloat(uint(t.xy01.z)), uintBitsToFloat(uint(t.xy01.w)));
}
SR_FN vec2 floatV2(TriSetup t)
{
    return vec2(uintBitsToFloat(uint(t.xy2Id.x)), uintBitsToFloat(uint(t.xy2Id.y)));
}

// Edge function of the directed edge a->b at p in float, relative to a (floatV*'s subpixel units).
SR_FN float floatEdge(vec2 a, vec2 b, vec2 p)
{
    SR_PRECISE float dx = b.x - a.x;
    SR_PRECISE float dy = b.y - a.y;
    SR_PRECISE float px = p.x - a.x;
    SR_PRECISE float py = p.y - a.y;
    SR_PRECISE float l = dx * py;
    SR_PRECISE float r = dy * px;
    SR_PRECISE float e = l - r;
    return e;
}

// The float triangle with window positions s0..s2 (subpixels): as setupSnappedTriangle, with the bbox
// rounded outwards to whole subpixels.
SR_FN bool setupFloatTriangle(vec2 s0, vec2 s1, vec2 s2, float z0, float z1, float z2, uint triId,
                              bool doubleSided, uint cullMode, uint width, uint height, uint bounds,
                              SR_OUT(TriSetup) t)
{
    float area = floatEdge(s0, s1, s2);
    if (!(area != 0.0f) || !isFinite(area)) return false;
    bool frontFacing = area < 0.0f;  // counter-clockwise on screen, glTF's front face
    if (!doubleSided && ((cullMode == CULL_BACK && !frontFacing) || (cullMode == CULL_FRONT && frontFacing)))
        return false;
    if (area < 0.0f) {  // make the edge functions positive inside
        vec2 ts = s1;
        s1 = s2;
        s2 = ts;
        float tz = z1;
        z1 = z2;
        z2 = tz;
        area = -area;
    }
    int loX = int(floor(min(s0.x, min(s1.x, s2.x))));
    int hiX = int(ceil(max(s0.x, max(s1.x, s2.x))));
    int loY = int(floor(min(s0.y, min(s1.y, s2.y))));
    int hiY = int(ceil(max(s0.y, max(s1.y, s2.y))));
    ivec2 spanX = sampleSpan(loX, hiX, width, boundsX(bounds));
    ivec2 spanY = sampleSpan(loY, hiY, height, boundsY(bounds));
    if (spanX.x > spanX.y || spanY.x > spanY.y) return false;
    t.xy01 = ivec4(int(floatBitsToUint(s0.x)), int(floatBitsToUint(s0.y)), int(floatBitsToUint(s1.x)),
                   int(floatBitsToUint(s1.y)));
    t.xy2Id =
        ivec4(int(floatBitsToUint(s2.x)), int(floatBitsToUint(s2.y)), int(triId), spanX.x | (spanY.x << 16));
    SR_PRECISE float dz10 = z1 - z0;
    SR_PRECISE float dz20 = z2 - z0;
    t.depthPlane = vec4(z0, dz10, dz20, recipDet(area));
    return true;
}

SR_FN bool setupTriangleFloat(vec4 c0, vec4 c1, vec4 c2, uint triId, bool doubleSided, uint cullMode,
                              uint width, uint height, uint bounds, SR_OUT(TriSetup) t)
{
    vec2 s0, s1, s2;
    float z0, z1, z2;
    if (!windowSubpixels(c0, width, height, s0, z0)) return false;
    if (!windowSubpixels(c1, width, height, s1, z1)) return false;
    if (!windowSubpixels(c2, width, height, s2, z2)) return false;
    return setupFloatTriangle(s0, s1, s2, z0, z1, z2, triId, doubleSided, cullMode, width, height, bounds, t);
}

// A triangle already in fixed point (a line's rectangle) as a float triangle; exact (|v| < 2^24).
SR_FN bool setupSnappedTriangleFloat(ivec2 v0, ivec2 v1, ivec2 v2, float z0, float z1, float z2, uint triId,
                                     bool doubleSided, uint cullMode, uint width, uint height, uint bounds,
                                     SR_OUT(TriSetup) t)
{
    return setupFloatTriangle(vec2(float(v0.x), float(v0.y)), vec2(float(v1.x), float(v1.y)),
                              vec2(float(v2.x), float(v2.y)), z0, z1, z2, triId, doubleSided, cullMode, width,
                              height, bounds, t);
}

// Inclusive pixel bbox as setupPixelBounds, from the float vertices.
SR_FN ivec4 floatPixelBounds(TriSetup t, uint width, uint height, uint bounds)
{
    vec2 v0 = floatV0(t), v1 = floatV1(t), v2 = floatV2(t);
    int hiX = int(ceil(max(v0.x, max(v1.x, v2.x))));
    int hiY = int(ceil(max(v0.y, max(v1.y, v2.y))));
    int maxX = sampleSpan(-SUBPIXEL_SCALE, hiX, width, boundsX(bounds)).y;
    int maxY = sampleSpan(-SUBPIXEL_SCALE, hiY, height, boundsY(bounds)).y;
    return ivec4(t.xy2Id.w & 0xffff, (t.xy2Id.w >> 16) & 0xffff, maxX, maxY);
}

// Depth at barycentrics (1 - b1 - b2, b1, b2), clamped to the vertices' depth range: b may reach
// -FLOAT_EPSILON (or more for scanline's spans) outside the exact triangle.
SR_FN float floatDepth(TriSetup t, float b1, float b2)
{
    float z0 = t.depthPlane.x;
    SR_PRECISE float z1 = z0 + t.depthPlane.y;
    SR_PRECISE float z2 = z0 + t.depthPlane.z;
    SR_PRECISE float z = z0 + b1 * t.depthPlane.y + b2 * t.depthPlane.z;
    z = clamp(z, min(z0, min(z1, z2)), max(z0, max(z1, z2)));
    return z > 0.0f ? min(z, 1.0f) : 0.0f;
}

// Whether p lies in the vertices' bbox rounded outwards to subpixels (the bounding-box loop).
SR_FN bool floatInBox(vec2 v0, vec2 v1, vec2 v2, vec2 p)
{
    return p.x >= floor(min(v0.x, min(v1.x, v2.x))) && p.x <= ceil(max(v0.x, max(v1.x, v2.x))) &&
           p.y >= floor(min(v0.y, min(v1.y, v2.y))) && p.y <= ceil(max(v0.y, max(v1.y, v2.y)));
}

// float: coverage of the sample at subpixel position p and its depth.
SR_FN bool floatSample(TriSetup t, ivec2 p, SR_OUT(float) depth)
{
    depth = 1.0f;
    vec2 v0 = floatV0(t), v1 = floatV1(t), v2 = floatV2(t);
    vec2 q = vec2(float(p.x), float(p.y));
    if (!floatInBox(v0, v1, v2, q)) return false;
    SR_PRECISE float b0 = floatEdge(v1, v2, q) * t.depthPlane.w;
    SR_PRECISE float b1 = floatEdge(v2, v0, q) * t.depthPlane.w;
    SR_PRECISE float b2 = floatEdge(v0, v1, q) * t.depthPlane.w;
    if (b0 < -FLOAT_EPSILON || b1 < -FLOAT_EPSILON || b2 < -FLOAT_EPSILON) return false;
    depth = floatDepth(t, b1, b2);
    return true;
}

// x of the edge from upper vertex a to lower vertex b (a.y < b.y) on row y: the slope form of the
// scanline walk, with the deterministic quotient (fixed_point.h).
SR_FN float scanlineEdgeX(vec2 a, vec2 b, float y)
{
    SR_PRECISE float dy = y - a.y;
    float slope = divDet(b.x - a.x, b.y - a.y);
    SR_PRECISE float x = a.x + dy * slope;
    return x;
}

// scanline: coverage of the sample at subpixel position p (its row y = p.y) and its depth.
SR_FN bool scanlineSample(TriSetup t, ivec2 p, SR_OUT(float) depth)
{
    depth = 1.0f;
    vec2 v0 = floatV0(t), v1 = floatV1(t), v2 = floatV2(t);
    // Sort by y: top (smallest y), middle, bottom.
    vec2 top = v0, mid = v1, bot = v2;
    if (mid.y < top.y) {
        vec2 s = top;
        top = mid;
        mid = s;
    }
    if (bot.y < mid.y) {
        vec2 s = mid;
        mid = bot;
        bot = s;
    }
    if (mid.y < top.y) {
        vec2 s = top;
        top = mid;
        mid = s;
    }
    vec2 q = vec2(float(p.x), float(p.y));
    if (!(q.y >= top.y && q.y < bot.y)) return false;
    float xLong = scanlineEdgeX(top, bot, q.y);
    // The flat-bottom half above the middle vertex, the flat-top half from it down.
    float xShort = q.y < mid.y ? scanlineEdgeX(top, mid, q.y) : scanlineEdgeX(mid, bot, q.y);
    if (!(q.x >= min(xLong, xShort) && q.x < max(xLong, xShort))) return false;
    SR_PRECISE float b1 = floatEdge(v2, v0, q) * t.depthPlane.w;
    SR_PRECISE float b2 = floatEdge(v0, v1, q) * t.depthPlane.w;
    depth = floatDepth(t, b1, b2);
    return true;
}

// The one-sample and sample-mask forms of both, as rasterPixel and pixelCoverage.
SR_FN bool floatPixel(TriSetup t, int px, int py, SR_OUT(float) depth)
{
    return floatSample(t, samplePosition(1u, 0u, px, py), depth);
}
SR_FN bool scanlinePixel(TriSetup t, int px, int py, SR_OUT(float) depth)
{
    return scanlineSample(t, samplePosition(1u, 0u, px, py), depth);
}
SR_FN uint floatCoverage(TriSetup t, uint count, int px, int py)
{
    uint mask = 0u;
    for (uint s = 0u; s < count; ++s) {
        float depth;
        if (floatSample(t, samplePosition(count, s, px, py), depth)) mask |= 1u << s;
    }
    return mask;
}
SR_FN uint scanlineCoverage(TriSetup t, uint count, int px, int py)
{
    uint mask = 0u;
    for (uint s = 0u; s < count; ++s) {
        float depth;
        if (scanlineSample(t, samplePosition(count, s, px, py), depth)) mask |= 1u << s;
    }
    return mask;
}

// ------------------------------------------------------------------------------------ line rectangles

// setupLineTriangle (setup.h) for the float methods: the same fixed-point corners, as a float record. A
// copy of its corner lines rather than a flag on it, so that fixed8's line code stays the code it was
// measured as (the NVIDIA compilers react to such changes; setupSnappedTriangle).
SR_FN bool setupLineTriangleFloat(LineQuad q, uint k, uint id, uint width, uint height, uint bounds,
                                  SR_OUT(TriSetup) t)
{
    ivec2 p0 = ivec2(q.ends.x, q.ends.y);
    ivec2 p1 = ivec2(q.ends.z, q.ends.w);
    ivec2 o = q.offset;
    ivec2 v0 = p0 - o;
    ivec2 v1 = k == 0u ? p1 - o : p1 + o;
    ivec2 v2 = k == 0u ? p1 + o : p0 + o;
    float z2 = k == 0u ? q.depth.y : q.depth.x;
    return setupSnappedTriangleFloat(v0, v1, v2, q.depth.x, q.depth.y, z2, id, true, CULL_NONE, width, height,
                                     bounds, t);
}

SR_NAMESPACE_END

#endif  // RASTER_SHARED_METHODS_H
