// shared/raster.h - the raster stages: pixel coverage and depth of a TriSetup, the early depth bound of
// raster_tiles, and the 64-bit visibility key whose minimum resolves every pixel.
//
// Part of raster_shared.h (included from there, not on its own); same three-language rules.
#ifndef RASTER_SHARED_RASTER_H
#define RASTER_SHARED_RASTER_H

SR_NAMESPACE_BEGIN

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

// A lower bound, as float bits, on the depth rasterPixel returns at any pixel the triangle covers, for
// the per-pixel early depth test in raster_tiles: a pixel whose key already holds a smaller depth cannot
// be won by this triangle, whatever its id. At a covered pixel centre the barycentrics e_i / area are
// exact and non-negative, so the exact interpolated depth is a convex combination of the vertex depths.
// rasterPixel's float steps differ from it by relative errors of about 2^-22 (float(e), the truncated
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

#endif  // RASTER_SHARED_RASTER_H
