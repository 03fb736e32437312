// shared/setup.h - the snapping half of stage `setup`: viewport transform, snapping to n.8 fixed point,
// exact int64 edge functions with the top-left rule, and the TriSetup record with its pixel bounds.
//
// Everything after snapping is integer arithmetic or correctly rounded float steps from exact integers,
// which is what makes coverage bit-identical across backends. Part of raster_shared.h (included from
// there, not on its own); same three-language rules.
#ifndef RASTER_SHARED_SETUP_H
#define RASTER_SHARED_SETUP_H

SR_NAMESPACE_BEGIN

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

// How edgeFunction(a, b, p) changes when p moves one subpixel right (X) or down (Y): it is linear in p,
// so a walk over sample positions can step it by additions, exactly.
SR_FN int64_t edgeStepX(ivec2 a, ivec2 b)
{
    return int64_t(a.y - b.y);
}
SR_FN int64_t edgeStepY(ivec2 a, ivec2 b)
{
    return int64_t(b.x - a.x);
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

// First and last pixel index that has a sample of the pattern with extent `bounds` (sampleBoundsOf;
// PIXEL_CENTER_BOUNDS for the pixel centres, 256 i + 128 subpixels) in [lo, hi] along one axis, clamped
// to [0, size - 1]: a sample of pixel i lies at 256 i + o with o between the pattern's smallest and
// largest offset on that axis (`offsets`: smallest in the low byte, largest in the next). Empty when
// first > last. Arithmetic shift is floor division for negative values.
SR_FN ivec2 sampleSpan(int lo, int hi, uint size, uint offsets)
{
    int oLo = int(offsets & 255u);
    int oHi = int((offsets >> 8) & 255u);
    int first = (lo - oHi + SUBPIXEL_SCALE - 1) >> SUBPIXEL_BITS;
    int last = (hi - oLo) >> SUBPIXEL_BITS;
    return ivec2(max(first, 0), min(last, int(size) - 1));
}

// The x and y halves of a sampleBounds word (minX | minY << 8 | maxX << 16 | maxY << 24) in the form
// sampleSpan takes.
SR_FN uint boundsX(uint bounds)
{
    return (bounds & 255u) | (((bounds >> 16) & 255u) << 8);
}
SR_FN uint boundsY(uint bounds)
{
    return ((bounds >> 8) & 255u) | (((bounds >> 24) & 255u) << 8);
}

// Pixel centres only: the one-sample span.
SR_FN ivec2 pixelSpan(int lo, int hi, uint size)
{
    return sampleSpan(lo, hi, size, 128u | (128u << 8));
}

// Deterministic 1 / area for a positive int64 area: the float nearest to floor(2^47 / d), times
// 2^-(47 + shift), where d = area >> shift < 2^24 keeps the area's top 24 bits. Identical on every
// backend, and without a 64-bit division (a 70-instruction routine on GPUs, once per drawn triangle):
// write d = m 2^-j with 2^23 <= m < 2^24 (j > 0 only for areas below 2^23). Then
// floor(2^47 / d) = Q 2^j + t with Q = floor(2^47 / m) (quotient47NoDivide, in (2^23, 2^24]),
// r = 2^47 - Q m and t = floor(2^j r / m) < 2^j. Floats near Q 2^j are 2^j apart, so the nearest one
// is Q 2^j when t < 2^(j-1) (2r < m), (Q + 1) 2^j when t > 2^(j-1) (2^(j-1) (2r - m) >= m), and the
// even one of the two at the tie. tests/shared_math_test.cpp checks every d against the division.
SR_FN float recipArea(int64_t area)
{
    uint64_t a = uint64_t(area);
    int shift = 0;
    while ((a >> shift) >= (uint64_t(1) << 24)) ++shift;  // a >> shift < 2^24
    uint d = uint(a >> shift);
    int j = 150 - int(floatBitsToUint(float(d)) >> 23);  // 23 - floor(log2 d): d < 2^24 converts exactly
    uint m = d << uint(j);
    uint q = quotient47NoDivide(m);
    if (j > 0) {
        int64_t r = int64_t(uint64_t(1) << 47) - int64_t(uint64_t(q) * uint64_t(m));
        int64_t u = int64_t(2) * r - int64_t(m);  // >= 0: t >= 2^(j-1)
        if (u >= int64_t(0) && ((u << (j - 1)) >= int64_t(m) || (q & 1u) != 0u)) q = q + 1u;
    }
    SR_PRECISE float r = float(q) * uintBitsToFloat(uint(127 + j - 47 - shift) << 23);
    return r;
}

// Everything raster needs from one (sub-)triangle. Returns false (and leaves `t` undefined) when the
// snapped triangle has zero area, faces the culled way, or its bbox holds no sample of the viewport
// (samples of the pattern with extent `bounds`, RasterParams.sampleBounds). The sample span is tested
// first: every test returns false alike, so the order changes no result, and a triangle whose bbox
// holds no sample (most of a dense mesh's, at hundredths of a pixel each) leaves before any 64-bit work.
// setupSnappedTriangle does the part after snapping, for triangles whose corners are already in fixed
// point (a line's rectangle). setupTriangle repeats its body instead of calling it: on the H100,
// NVIDIA's Vulkan compiler ran the triangle path of `setup` twice as slow through the extra call with
// its output record (sweep-2px setup 0.100 -> 0.200 ms), CUDA not at all.
SR_FN bool setupSnappedTriangle(ivec2 v0, ivec2 v1, ivec2 v2, float z0, float z1, float z2, uint triId,
                                bool doubleSided, uint cullMode, uint width, uint height, uint bounds,
                                SR_OUT(TriSetup) t)
{
    ivec2 spanX = sampleSpan(min(v0.x, min(v1.x, v2.x)), max(v0.x, max(v1.x, v2.x)), width, boundsX(bounds));
    ivec2 spanY = sampleSpan(min(v0.y, min(v1.y, v2.y)), max(v0.y, max(v1.y, v2.y)), height, boundsY(bounds));
    if (spanX.x > spanX.y || spanY.x > spanY.y) return false;
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
    t.xy01 = ivec4(v0.x, v0.y, v1.x, v1.y);
    t.xy2Id = ivec4(v2.x, v2.y, int(triId), spanX.x | (spanY.x << 16));
    SR_PRECISE float dz10 = z1 - z0;
    SR_PRECISE float dz20 = z2 - z0;
    t.depthPlane = vec4(z0, dz10, dz20, recipArea(area));
    return true;
}

SR_FN bool setupTriangle(vec4 c0, vec4 c1, vec4 c2, uint triId, bool doubleSided, uint cullMode, uint width,
                         uint height, uint bounds, SR_OUT(TriSetup) t)
{
    ivec2 v0, v1, v2;
    float z0, z1, z2;
    if (!snapVertex(c0, width, height, v0, z0)) return false;
    if (!snapVertex(c1, width, height, v1, z1)) return false;
    if (!snapVertex(c2, width, height, v2, z2)) return false;
    ivec2 spanX = sampleSpan(min(v0.x, min(v1.x, v2.x)), max(v0.x, max(v1.x, v2.x)), width, boundsX(bounds));
    ivec2 spanY = sampleSpan(min(v0.y, min(v1.y, v2.y)), max(v0.y, max(v1.y, v2.y)), height, boundsY(bounds));
    if (spanX.x > spanX.y || spanY.x > spanY.y) return false;
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
    t.xy01 = ivec4(v0.x, v0.y, v1.x, v1.y);
    t.xy2Id = ivec4(v2.x, v2.y, int(triId), spanX.x | (spanY.x << 16));
    SR_PRECISE float dz10 = z1 - z0;
    SR_PRECISE float dz20 = z2 - z0;
    t.depthPlane = vec4(z0, dz10, dz20, recipArea(area));
    return true;
}

// Deterministic 1 / sqrt(x) for x > 0: the classic bit-level first guess refined by three Newton steps
// y' = y (3/2 - x y^2 / 2) in correctly rounded float multiplies and subtractions, so every backend
// computes the same bits (GLSL's inversesqrt and sqrt carry a few ulp of implementation freedom). The
// result is within a few ulp of the true value.
SR_FN float rsqrtDet(float x)
{
    float halfX = 0.5f * x;
    float y = uintBitsToFloat(0x5f3759dfu - (floatBitsToUint(x) >> 1));
    for (int k = 0; k < 3; ++k) {
        SR_PRECISE float yy = y * y;
        SR_PRECISE float hyy = halfX * yy;
        SR_PRECISE float f = 1.5f - hyy;
        SR_PRECISE float next = y * f;
        y = next;
    }
    return y;
}

// A line segment as Vulkan's rectangular lines draw it: the rectangle of the line width centred on the
// snapped segment p0 -> p1, its ends cut square at the endpoints. `offset` is half the width along the
// segment's left normal, in subpixels, rounded once (as lavapipe rounds it), so the corners are
// p0 - offset, p1 - offset, p1 + offset, p0 + offset and the rectangle is symmetric about the segment.
// depth holds the (biased) window depths at p0 and p1, which the rectangle's two triangles interpolate:
// every corner carries its endpoint's depth, so depth varies along the segment only.
struct LineQuad {
    ivec4 ends;    // p0.x, p0.y, p1.x, p1.y (subpixels)
    ivec2 offset;  // half the width, perpendicular to the segment (subpixels)
    vec2 depth;    // window depth at p0, at p1
};

// Snaps the clipped segment a -> b (clip space) and builds its rectangle for width `lineWidth` pixels.
// depthBias b draws depth z as z - b (1 - z): an affine map of window depth, so it stays linear across
// the rectangle; for a perspective camera 1 - z is about near / distance, so the bias brings a line
// closer by the fraction b of its distance whatever the scene's scale (--wireframe). False when an end
// leaves the guard band or the snapped segment has zero length (nothing drawn, as lavapipe).
SR_FN bool setupLine(vec4 a, vec4 b, float lineWidth, float depthBias, uint width, uint height,
                     SR_OUT(LineQuad) q)
{
    ivec2 p0, p1;
    float z0, z1;
    q.ends = ivec4(0, 0, 0, 0);
    q.offset = ivec2(0, 0);
    q.depth = vec2(0.0f, 0.0f);
    if (!snapVertex(a, width, height, p0, z0) || !snapVertex(b, width, height, p1, z1)) return false;
    if (p0.x == p1.x && p0.y == p1.y) return false;
    // The segment's direction in float from exact integers (below 2^24 per axis inside the guard band).
    float dx = float(p1.x - p0.x);
    float dy = float(p1.y - p0.y);
    SR_PRECISE float lengthSq = dx * dx + dy * dy;
    SR_PRECISE float halfWidth = lineWidth * float(SUBPIXEL_SCALE / 2);
    SR_PRECISE float scale = halfWidth * rsqrtDet(lengthSq);
    SR_PRECISE float ox = -dy * scale;
    SR_PRECISE float oy = dx * scale;
    q.ends = ivec4(p0.x, p0.y, p1.x, p1.y);
    q.offset = ivec2(int(roundEven(ox)), int(roundEven(oy)));
    SR_PRECISE float b0 = z0 - depthBias * (1.0f - z0);
    SR_PRECISE float b1 = z1 - depthBias * (1.0f - z1);
    q.depth = vec2(max(b0, 0.0f), max(b1, 0.0f));
    return true;
}

// Triangle k (0 or 1) of the line's rectangle: (p0 - o, p1 - o, p1 + o) and (p0 - o, p1 + o, p0 + o).
// They share the diagonal, so the top-left rule gives each sample of the rectangle to exactly one.
SR_FN bool setupLineTriangle(LineQuad q, uint k, uint id, uint width, uint height, uint bounds,
                             SR_OUT(TriSetup) t)
{
    ivec2 p0 = ivec2(q.ends.x, q.ends.y);
    ivec2 p1 = ivec2(q.ends.z, q.ends.w);
    ivec2 o = q.offset;
    ivec2 v0 = p0 - o;
    ivec2 v1 = k == 0u ? p1 - o : p1 + o;
    ivec2 v2 = k == 0u ? p1 + o : p0 + o;
    float z2 = k == 0u ? q.depth.y : q.depth.x;
    return setupSnappedTriangle(v0, v1, v2, q.depth.x, q.depth.y, z2, id, true, CULL_NONE, width, height,
                                bounds, t);
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

// Inclusive pixel bbox (minX, minY, maxX, maxY) of the pixels with a sample of the pattern with extent
// `bounds` inside the triangle's bbox, already clamped to the viewport.
SR_FN ivec4 setupPixelBounds(TriSetup t, uint width, uint height, uint bounds)
{
    ivec2 v0 = setupV0(t), v1 = setupV1(t), v2 = setupV2(t);
    int maxX = sampleSpan(-SUBPIXEL_SCALE, max(v0.x, max(v1.x, v2.x)), width, boundsX(bounds)).y;
    int maxY = sampleSpan(-SUBPIXEL_SCALE, max(v0.y, max(v1.y, v2.y)), height, boundsY(bounds)).y;
    return ivec4(t.xy2Id.w & 0xffff, (t.xy2Id.w >> 16) & 0xffff, maxX, maxY);
}

SR_FN bool isSmallTriangle(ivec4 bounds)
{
    return bounds.z - bounds.x < SMALL_TRI_SPAN && bounds.w - bounds.y < SMALL_TRI_SPAN;
}

// The screen tiles (TILE_SIZE x TILE_SIZE pixels) the bbox touches, inclusive: (x0, y0, x1, y1).
SR_FN ivec4 tileRect(ivec4 bounds)
{
    return ivec4(bounds.x / TILE_SIZE, bounds.y / TILE_SIZE, bounds.z / TILE_SIZE, bounds.w / TILE_SIZE);
}

// Number of screen tiles the bbox touches.
SR_FN uint tileCount(ivec4 bounds)
{
    ivec4 r = tileRect(bounds);
    return uint(r.z - r.x + 1) * uint(r.w - r.y + 1);
}

// Pieces a big triangle is cut into: bin_count and bin_fill give each piece one thread, which walks
// pieceTiles consecutive tiles of the bbox (row-major). TILES_PER_PIECE tiles each, so a screen-filling
// triangle spreads over many threads, but at most MAX_PIECES pieces, so the setup thread that writes
// them stays short; a larger triangle gets larger pieces.
SR_FN uint pieceTiles(uint tiles)
{
    return max(uint(TILES_PER_PIECE), (tiles + uint(MAX_PIECES) - 1u) / uint(MAX_PIECES));
}
SR_FN uint pieceCount(uint tiles)
{
    uint length = pieceTiles(tiles);
    return (tiles + length - 1u) / length;
}

// raster_tiles work items per active tile: one (rasterChunk 0, GPUs), or as many chunks of rasterChunk
// bin entries as the largest bin (maxBin, COUNTER_MAX_BIN) needs.
SR_FN uint rasterChunksPerTile(uint rasterChunk, uint maxBin)
{
    return rasterChunk == 0u ? 1u : max(1u, (maxBin + rasterChunk - 1u) / rasterChunk);
}

// Largest value of edge function a->b (as edgeFunction) over the rectangle of subpixel positions
// [lo, hi]: the function is linear, so its maximum sits at the corner it grows towards.
SR_FN int64_t edgeMaxOverRect(ivec2 a, ivec2 b, ivec2 lo, ivec2 hi)
{
    int dx = b.x - a.x;
    int dy = b.y - a.y;
    ivec2 p = ivec2(dy > 0 ? lo.x : hi.x, dx > 0 ? hi.y : lo.y);
    return edgeFunction(a, b, p);
}

// Whether the triangle may cover a sample of the pixels x0..x1, y0..y1 (inclusive), for a pattern with
// extent `sampleBounds`. Exact for the rectangle spanned by those samples: false only when one edge
// function, with its fill-rule bias, is negative at every point of it, so no sample that rasterSample
// would cover is ever dropped.
SR_FN bool triangleTouchesPixels(TriSetup t, int x0, int y0, int x1, int y1, uint sampleBounds)
{
    ivec2 lo = ivec2(x0 * SUBPIXEL_SCALE + int(sampleBounds & 255u),
                     y0 * SUBPIXEL_SCALE + int((sampleBounds >> 8) & 255u));
    ivec2 hi = ivec2(x1 * SUBPIXEL_SCALE + int((sampleBounds >> 16) & 255u),
                     y1 * SUBPIXEL_SCALE + int((sampleBounds >> 24) & 255u));
    ivec2 v0 = setupV0(t), v1 = setupV1(t), v2 = setupV2(t);
    if (edgeMaxOverRect(v1, v2, lo, hi) - edgeBias(v1, v2) < int64_t(0)) return false;
    if (edgeMaxOverRect(v2, v0, lo, hi) - edgeBias(v2, v0) < int64_t(0)) return false;
    if (edgeMaxOverRect(v0, v1, lo, hi) - edgeBias(v0, v1) < int64_t(0)) return false;
    return true;
}

// Whether the triangle may cover a sample of screen tile (tx, ty) inside its bbox (triangleTouchesPixels
// over the tile's part of the bbox); a tile that only the rectangle's corner region reaches costs one
// empty walk in raster_tiles.
SR_FN bool triangleTouchesTile(TriSetup t, ivec4 bounds, int tx, int ty, uint sampleBounds)
{
    return triangleTouchesPixels(t, max(tx * TILE_SIZE, bounds.x), max(ty * TILE_SIZE, bounds.y),
                                 min(tx * TILE_SIZE + TILE_SIZE - 1, bounds.z),
                                 min(ty * TILE_SIZE + TILE_SIZE - 1, bounds.w), sampleBounds);
}

SR_NAMESPACE_END

#endif  // RASTER_SHARED_SETUP_H
