// shared/coverage.h - the raster stages: Vulkan's standard sample patterns, sample coverage and depth of a
// TriSetup, points, the early depth bound of raster_tiles, and the 64-bit visibility key whose minimum
// resolves every sample.
//
// Part of raster_shared.h (included from there, not on its own); same three-language rules.
#ifndef RASTER_SHARED_COVERAGE_H
#define RASTER_SHARED_COVERAGE_H

SR_NAMESPACE_BEGIN

// Vulkan's standard sample locations (the spec's "Standard sample locations" table, D3D's patterns),
// sample s of a `count`-sample pixel, in 1/16 pixel from the pixel's top-left corner. Every location is
// a multiple of 1/16 pixel, so on the 1/256 pixel grid of the snapped vertices the edge functions at the
// samples are exact integers and the top-left rule applies per sample exactly as at pixel centres.
// Packed one byte per sample, x | y << 4, four samples per word, sample 0 in the low byte:
//   1x: (8, 8)
//   2x: (12, 12) (4, 4)
//   4x: (6, 2) (14, 6) (2, 10) (10, 14)
//   8x: (9, 5) (7, 11) (13, 9) (5, 3) (3, 13) (1, 7) (11, 15) (15, 1)
//  16x: (9, 9) (7, 5) (5, 10) (12, 7) (3, 6) (10, 13) (13, 11) (11, 3) (6, 14) (8, 1) (4, 2) (2, 12)
//       (0, 8) (15, 4) (14, 15) (1, 0)
SR_FN ivec2 standardSample(uint count, uint s)
{
    uint word = 0x88u;
    if (count == 2u) word = 0x44CCu;
    if (count == 4u) word = 0xEAA26E26u;
    if (count == 8u) word = s < 4u ? 0x359DB759u : 0x1FFB71D3u;
    if (count == 16u) {
        word = s < 4u ? 0x7CA55799u : s < 8u ? 0x3BBDDA63u : s < 12u ? 0xC22418E6u : 0x01FE4F80u;
    }
    uint b = (word >> (8u * (s & 3u))) & 255u;
    return ivec2(int(b & 15u), int(b >> 4));
}

// Position of sample s of pixel (px, py) in subpixels (1/256 pixel).
SR_FN ivec2 samplePosition(uint count, uint s, int px, int py)
{
    ivec2 o = standardSample(count, s);
    return ivec2(px * SUBPIXEL_SCALE + o.x * 16, py * SUBPIXEL_SCALE + o.y * 16);
}

// Extent of a sample pattern within the pixel, in subpixels: minX | minY << 8 | maxX << 16 | maxY << 24
// over its samples (RasterParams.sampleBounds; PIXEL_CENTER_BOUNDS for one sample). Bounds the pixels a
// triangle's samples can fall in (sampleSpan) and the tiles it can touch (triangleTouchesPixels).
SR_FN uint sampleBoundsOf(uint count)
{
    ivec2 lo = ivec2(SUBPIXEL_SCALE, SUBPIXEL_SCALE), hi = ivec2(0, 0);
    for (uint s = 0u; s < count; ++s) {
        ivec2 o = standardSample(count, s);
        lo = min(lo, o * 16);
        hi = max(hi, o * 16);
    }
    return uint(lo.x) | (uint(lo.y) << 8) | (uint(hi.x) << 16) | (uint(hi.y) << 24);
}

// Window depth of a covered sample from its edge values e1 and e2 (the weights of v1 and v2): linear in
// screen space (Vulkan's rule), from the exact edge functions with correctly rounded float steps, so CUDA
// and GLSL produce the same bits. rasterSample takes it from edge values at a sample; raster_tiles' CPU
// build steps the edge values from pixel to pixel by additions (exact: they are integers).
SR_FN float depthFromEdges(TriSetup t, int64_t e1, int64_t e2)
{
    SR_PRECISE float b1 = float(e1) * t.depthPlane.w;
    SR_PRECISE float b2 = float(e2) * t.depthPlane.w;
    SR_PRECISE float z = t.depthPlane.x + b1 * t.depthPlane.y + b2 * t.depthPlane.z;
    // Clamp to the depth range; written so that -0.0 and NaN become +0.0 and keys stay ordered.
    return z > 0.0f ? min(z, 1.0f) : 0.0f;
}

// Coverage of the sample at subpixel position p and, when covered, its window depth (depthFromEdges).
SR_FN bool rasterSample(TriSetup t, ivec2 p, SR_OUT(float) depth)
{
    depth = 1.0f;
    ivec2 v0 = setupV0(t), v1 = setupV1(t), v2 = setupV2(t);
    int64_t e0 = edgeFunction(v1, v2, p);  // weight of v0
    int64_t e1 = edgeFunction(v2, v0, p);  // weight of v1
    int64_t e2 = edgeFunction(v0, v1, p);  // weight of v2
    if (e0 - edgeBias(v1, v2) < int64_t(0)) return false;
    if (e1 - edgeBias(v2, v0) < int64_t(0)) return false;
    if (e2 - edgeBias(v0, v1) < int64_t(0)) return false;
    depth = depthFromEdges(t, e1, e2);
    return true;
}

// The samples of pixel (px, py) the triangle covers, as a bit mask (bit s: sample s of the `count`-
// sample pattern); the same edge tests as rasterSample, without the depth.
SR_FN uint pixelCoverage(TriSetup t, uint count, int px, int py)
{
    ivec2 v0 = setupV0(t), v1 = setupV1(t), v2 = setupV2(t);
    int64_t bias0 = edgeBias(v1, v2), bias1 = edgeBias(v2, v0), bias2 = edgeBias(v0, v1);
    uint mask = 0u;
    for (uint s = 0u; s < count; ++s) {
        ivec2 p = samplePosition(count, s, px, py);
        if (edgeFunction(v1, v2, p) - bias0 >= int64_t(0) && edgeFunction(v2, v0, p) - bias1 >= int64_t(0) &&
            edgeFunction(v0, v1, p) - bias2 >= int64_t(0))
            mask |= 1u << s;
    }
    return mask;
}

// Coverage and depth at the centre of pixel (px, py): the one-sample pattern.
SR_FN bool rasterPixel(TriSetup t, int px, int py, SR_OUT(float) depth)
{
    return rasterSample(t, samplePosition(1u, 0u, px, py), depth);
}

// A small triangle's three edge functions at pixel centres in 32-bit integers, stepped from pixel to
// pixel by additions: setup's one-thread loop over a small triangle's pixels (one sample per pixel, fixed-
// point methods) tests them instead of rasterPixel's three 64-bit products per edge. Exact where the
// triangle's bbox is at most SMALL_EDGE_EXTENT subpixels (64 pixels) wide and high (smallEdgesFit): the
// loop visits pixel centres inside that bbox, or one pixel past it, each within 2^14 + 256 subpixels of
// every corner, so |edgeFunction| < 2 * 2^14 * (2^14 + 256) < 2^30 and the int32 values are the int64
// ones. A small triangle reaching far outside the viewport does not fit and takes rasterPixel.
#define SMALL_EDGE_EXTENT 16384
struct SmallEdges {
    ivec3 start;  // edgeFunction of edges v1v2, v2v0, v0v1 (the weights of v0, v1, v2) at the first pixel
    ivec3 stepX;  // their change one pixel to the right
    ivec3 stepY;  // their change one pixel down
    ivec3 bias;   // the fill rule's edgeBias: a pixel centre is covered where every value >= its bias
};

SR_FN bool smallEdgesFit(TriSetup t)
{
    ivec2 v0 = setupV0(t), v1 = setupV1(t), v2 = setupV2(t);
    return max(v0.x, max(v1.x, v2.x)) - min(v0.x, min(v1.x, v2.x)) <= SMALL_EDGE_EXTENT &&
           max(v0.y, max(v1.y, v2.y)) - min(v0.y, min(v1.y, v2.y)) <= SMALL_EDGE_EXTENT;
}

// The edge functions at the centre of pixel (px, py) and their per-pixel steps (edgeStepX, edgeStepY
// times SUBPIXEL_SCALE).
SR_FN SmallEdges smallEdges(TriSetup t, int px, int py)
{
    ivec2 v0 = setupV0(t), v1 = setupV1(t), v2 = setupV2(t);
    ivec2 p = samplePosition(1u, 0u, px, py);
    SmallEdges s;
    s.start = ivec3((v2.x - v1.x) * (p.y - v1.y) - (v2.y - v1.y) * (p.x - v1.x),
                    (v0.x - v2.x) * (p.y - v2.y) - (v0.y - v2.y) * (p.x - v2.x),
                    (v1.x - v0.x) * (p.y - v0.y) - (v1.y - v0.y) * (p.x - v0.x));
    s.stepX = ivec3(v1.y - v2.y, v2.y - v0.y, v0.y - v1.y) * SUBPIXEL_SCALE;
    s.stepY = ivec3(v2.x - v1.x, v0.x - v2.x, v1.x - v0.x) * SUBPIXEL_SCALE;
    s.bias = ivec3(int(edgeBias(v1, v2)), int(edgeBias(v2, v0)), int(edgeBias(v0, v1)));
    return s;
}

// rasterPixel from the edge values e at a pixel centre: coverage, and the depth when covered.
SR_FN bool smallEdgesPixel(TriSetup t, SmallEdges s, ivec3 e, SR_OUT(float) depth)
{
    depth = 1.0f;
    if (e.x < s.bias.x || e.y < s.bias.y || e.z < s.bias.z) return false;
    depth = depthFromEdges(t, int64_t(e.y), int64_t(e.z));
    return true;
}

// A point (Vulkan "Basic Point Rasterization"): the square of side pointSize centred on the snapped
// vertex covers the samples inside it; a sample on its left or top side is inside and one on its
// right or bottom side is not, the top-left rule of a square drawn as two triangles. Its depth is the
// vertex's. A point whose vertex lies outside the view volume is discarded whole, however far its
// square would reach into the viewport (pointClippingBehavior ALL_CLIP_PLANES).
struct PointSetup {
    ivec4 square;  // minX, minY, maxX, maxY in subpixels: covered where min <= p < max per axis
    float depth;
};

// Whether a point at clip position c is kept: its vertex inside the view volume.
SR_FN bool pointInViewVolume(vec4 c)
{
    return c.w > 0.0f && abs(c.x) <= c.w && abs(c.y) <= c.w && c.z >= 0.0f && c.z <= c.w;
}

// Sets up the point at clip position c; false when it is culled.
SR_FN bool setupPoint(vec4 c, float pointSize, uint width, uint height, SR_OUT(PointSetup) pt)
{
    pt.square = ivec4(0, 0, 0, 0);
    pt.depth = 1.0f;
    if (!pointInViewVolume(c)) return false;
    ivec2 xy;
    float z;
    if (!snapVertex(c, width, height, xy, z)) return false;
    // Half the side in subpixels; sizes are multiples of 1/128 pixel (the CLI checks), so this is exact.
    int halfSide = int(pointSize * float(SUBPIXEL_SCALE / 2));
    pt.square = ivec4(xy.x - halfSide, xy.y - halfSide, xy.x + halfSide, xy.y + halfSide);
    pt.depth = z;
    return true;
}

SR_FN bool pointCoversSample(PointSetup pt, ivec2 p)
{
    return p.x >= pt.square.x && p.x < pt.square.z && p.y >= pt.square.y && p.y < pt.square.w;
}

// Inclusive pixel bbox of the point's samples (pattern extent `bounds`), clamped to the viewport;
// empty when x > z or y > w.
SR_FN ivec4 pointPixelBounds(PointSetup pt, uint width, uint height, uint bounds)
{
    ivec2 x = sampleSpan(pt.square.x, pt.square.z - 1, width, boundsX(bounds));
    ivec2 y = sampleSpan(pt.square.y, pt.square.w - 1, height, boundsY(bounds));
    return ivec4(x.x, y.x, x.y, y.y);
}

// A lower bound, as float bits, on the depth rasterSample returns at any sample the triangle covers,
// for the early depth test in raster_tiles: a sample whose key already holds a smaller depth cannot be
// won by this triangle, whatever its id. At a covered sample the barycentrics e_i / area are exact and
// non-negative, so the exact interpolated depth is a convex combination of the vertex depths.
// rasterSample's float steps differ from it by relative errors of about 2^-22 (float(e), the truncated
// 1 / area, the products) on terms whose magnitudes sum to at most 1, plus a few roundings of 2^-24:
// under 2^-20 in all, a quarter of the margin of 2^-18 taken here.
SR_FN uint triangleMinDepthBits(TriSetup t)
{
    float z0 = t.depthPlane.x;
    SR_PRECISE float z1 = z0 + t.depthPlane.y;
    SR_PRECISE float z2 = z0 + t.depthPlane.z;
    SR_PRECISE float zmin = min(z0, min(z1, z2)) - 3.814697265625e-6f;  // 2^-18
    return zmin > 0.0f ? floatBitsToUint(zmin) : 0u;
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

SR_NAMESPACE_END

#endif  // RASTER_SHARED_COVERAGE_H
