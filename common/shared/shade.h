// shared/shade.h - stage `shade`: barycentrics and their screen derivatives from clip space, the
// surface at a pixel, the lighting models and debug views, and sRGB encoding.
//
// Shading re-derives each vertex from the scene buffers (see surfaceAt), so it needs no per-vertex
// output of the earlier stages. Part of raster_shared.h (included from there, not on its own); same
// three-language rules.
#ifndef RASTER_SHARED_SHADE_H
#define RASTER_SHARED_SHADE_H

SR_NAMESPACE_BEGIN

// Barycentrics at an NDC point with their derivatives, straight from clip space (no division per
// vertex). With p_i = xy_i - ndc * w_i the sub-areas a_i = cross(p_j, p_k) are proportional to the
// perspective-correct barycentrics (the surface point is the combination of the p_i that gives 0), and
// they are affine in ndc: their XY terms cancel, so da_i / dndc is a constant. Screen-space (affine)
// barycentrics are a_i w_i normalised the same way. `weights` (1, 1, 1) gives the perspective-correct
// set, (w0, w1, w2) the affine one; derivatives are per NDC unit. Works for vertices with w <= 0
// because the covered point itself always has w > 0. A point inside the triangle gets barycentrics
// clamped to [0, 1] against rounding at grazing angles; with `extrapolate` (an MSAA pixel whose centre
// may lie outside the triangle, shaded there as hardware does without centroid interpolation) they
// are the plane's values, negative outside.
SR_FN vec3 clipBarycentrics(vec4 c0, vec4 c1, vec4 c2, vec2 ndc, vec3 weights, bool extrapolate,
                            SR_OUT(vec3) dX, SR_OUT(vec3) dY)
{
    // Every step is `precise` and the one division goes through recipDet, so that the texture
    // coordinates and their derivatives, and with them the texel and level a lookup picks, have the
    // same bits on every backend (Vulkan may contract a * b + c and divide 2.5 ulp off).
    SR_PRECISE vec2 p0 = vec2(c0.x - ndc.x * c0.w, c0.y - ndc.y * c0.w);
    SR_PRECISE vec2 p1 = vec2(c1.x - ndc.x * c1.w, c1.y - ndc.y * c1.w);
    SR_PRECISE vec2 p2 = vec2(c2.x - ndc.x * c2.w, c2.y - ndc.y * c2.w);
    SR_PRECISE vec3 a =
        vec3(p1.x * p2.y - p1.y * p2.x, p2.x * p0.y - p2.y * p0.x, p0.x * p1.y - p0.y * p1.x) * weights;
    // d(cross(p_j, p_k)) / dX = w_k y_j - w_j y_k and / dY = w_j x_k - w_k x_j, with p for x, y.
    SR_PRECISE vec3 ax =
        vec3(c2.w * p1.y - c1.w * p2.y, c0.w * p2.y - c2.w * p0.y, c1.w * p0.y - c0.w * p1.y) * weights;
    SR_PRECISE vec3 ay =
        vec3(c1.w * p2.x - c2.w * p1.x, c2.w * p0.x - c0.w * p2.x, c0.w * p1.x - c1.w * p0.x) * weights;
    SR_PRECISE float sum = a.x + a.y + a.z;
    dX = vec3(0.0f);
    dY = vec3(0.0f);
    float inv = recipDet(sum);
    if (!isFinite(sum) || !isFinite(inv) || inv == 0.0f) return vec3(1.0f / 3.0f, 1.0f / 3.0f, 1.0f / 3.0f);
    SR_PRECISE float sx = ax.x + ax.y + ax.z;
    SR_PRECISE float sy = ay.x + ay.y + ay.z;
    SR_PRECISE vec3 b = a * inv;
    // Quotient rule: d(a_i / S) = (da_i - b_i dS) / S.
    SR_PRECISE vec3 bx = (ax - b * sx) * inv;
    SR_PRECISE vec3 by = (ay - b * sy) * inv;
    dX = bx;
    dY = by;
    return extrapolate ? b : clamp(b, vec3(0.0f), vec3(1.0f));
}

SR_FN vec3 perspectiveBarycentrics(vec4 c0, vec4 c1, vec4 c2, vec2 ndc)
{
    vec3 dX, dY;
    return clipBarycentrics(c0, c1, c2, ndc, vec3(1.0f), false, dX, dY);
}

// NDC of the centre of pixel (px, py).
SR_FN vec2 pixelCenterNdc(int px, int py, uint width, uint height)
{
    SR_PRECISE float x = (float(px) + 0.5f) * 2.0f * recipDet(float(width)) - 1.0f;
    SR_PRECISE float y = (float(py) + 0.5f) * 2.0f * recipDet(float(height)) - 1.0f;
    return vec2(x, y);
}

// NDC of subpixel position p (1/256 pixel, as samplePosition gives) of a width x height raster. For a
// pixel centre, p = 256 px + 128, it has the bits of pixelCenterNdc: p / 256 is exact in float.
SR_FN vec2 subpixelNdc(ivec2 p, uint width, uint height)
{
    SR_PRECISE float x = float(p.x) * (1.0f / float(SUBPIXEL_SCALE)) * 2.0f * recipDet(float(width)) - 1.0f;
    SR_PRECISE float y = float(p.y) * (1.0f / float(SUBPIXEL_SCALE)) * 2.0f * recipDet(float(height)) - 1.0f;
    return vec2(x, y);
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

// linearToSrgb(c) * 255 rounded, as packRgba8 stores it, without pow: for the CPU build of shade, where
// pow is a long polynomial on every lane. y = c^(1/2.4) is the root of y^12 = c^5; the start, three
// square roots weighted by a relative least-squares fit over the curve's pow part [0.0031308, 1], is
// within 0.4% of it, and two Newton steps y += (c^5 / y^11 - y) / 12 bring that to float precision
// (quadratic convergence: 4e-3 -> 9e-5 -> 1e-7). The code then differs from a correctly rounded pow only
// where 255 sRGB(c) + 0.5 lies within a few 1e-5 of an integer, where single-precision pow on two devices
// disagrees as well: by at most 1 level (tests/shared_math_test.cpp measures it in double precision).
SR_FN uint srgbEncode8(float c)
{
    c = clamp(c, 0.0f, 1.0f);
    float s1 = sqrt(c);
    float s2 = sqrt(s1);
    float s3 = sqrt(s2);
    float y = 0.65072639f * s1 + 0.47230837f * s2 - 0.11925504f * s3;
    float c2 = c * c;
    float c5 = c2 * c2 * c;
    for (int step = 0; step < 2; ++step) {
        float y2 = y * y;
        float y4 = y2 * y2;
        float y11 = y4 * y4 * y2 * y;
        y = y + (c5 / y11 - y) * (1.0f / 12.0f);
    }
    float srgb = c <= 0.0031308f ? 12.92f * c : 1.055f * y - 0.055f;
    return uint(srgb * 255.0f + 0.5f);
}

// packRgba8 through srgbEncode8.
SR_FN uint packRgba8NoPow(vec3 linearRgb)
{
    return srgbEncode8(linearRgb.x) | (srgbEncode8(linearRgb.y) << 8) | (srgbEncode8(linearRgb.z) << 16) |
           (255u << 24);
}

// 1 / count, the weight of one of `count` samples in a pixel's mean: exact for a power of two (built
// from the exponent bits, no division), else the deterministic reciprocal.
SR_FN float sampleWeight(uint count)
{
    if ((count & (count - 1u)) != 0u) return recipDet(float(count));
    uint log2Count = 0u;
    while ((1u << log2Count) < count) ++log2Count;
    return uintBitsToFloat((127u - log2Count) << 23);
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
// n: unit normal facing the viewer; v: unit vector towards the eye; l: unit vector towards the light;
// lightColor: rgb the light, a the ambient intensity. The colour is
//   albedo (ambient + max(n.l, 0) light) + specStrength light lobe,
// the lobe pow(r.v, specPower) (Phong) or pow(n.h, specPower) (Blinn-Phong), at most 1. A white surface
// (albedo 1) therefore peaks at ambient + light (1 + specStrength): the default lighting
// (render_settings.h) keeps that at 1, the display's white, so a lit surface never clips.
SR_FN vec3 shadeLight(uint mode, vec3 albedo, vec3 n, vec3 v, vec3 l, vec4 lightColor, float specPower,
                      float specStrength)
{
    vec3 light = vec3(lightColor.x, lightColor.y, lightColor.z);
    float ndotl = max(dot(n, l), 0.0f);
    vec3 color = albedo * (lightColor.w + ndotl * light);
    if (ndotl > 0.0f && mode == SHADING_PHONG) {
        vec3 r = 2.0f * dot(n, l) * n - l;
        color += light * pow(max(dot(r, v), 0.0f), specPower) * specStrength;
    } else if (ndotl > 0.0f && mode == SHADING_BLINN_PHONG) {
        vec3 h = normalize(l + v);
        color += light * pow(max(dot(n, h), 0.0f), specPower) * specStrength;
    }
    return color;
}

// Full shading of one covered pixel from its interpolated attributes.
// viewPos/viewNormal/color: perspective-correct interpolations; faceNormal: geometric normal of the
// triangle in view space (unnormalised); albedo: linear base colour; occlusion: the ambient occlusion at the
// pixel (shared/ao.h; 1 without), which scales the ambient term of every lit mode.
SR_FN vec3 shadePixel(RasterParams params, uint triId, vec3 viewPos, vec3 viewNormal, vec3 faceNormal,
                      vec3 albedo, float occlusion)
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
    if (mode == SHADING_AO) return vec3(occlusion);
    vec3 l = vec3(params.lightDirView.x, params.lightDirView.y, params.lightDirView.z);
    vec4 light =
        vec4(params.lightColor.x, params.lightColor.y, params.lightColor.z, params.lightColor.w * occlusion);
    if (mode == SHADING_FLAT) return shadeLight(SHADING_LAMBERT, albedo, fn, v, l, light, 1.0f, 0.0f);
    return shadeLight(mode, albedo, n, v, l, light, params.shadeExtra.x, params.shadeExtra.w);
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

// What the shade stage knows of the surface at one pixel centre, interpolated from the triangle's
// three vertices.
struct SurfacePoint {
    vec3 bary;        // perspective-correct barycentrics
    vec3 uvBary;      // the barycentrics texture coordinates use (perspective-correct, or affine)
    vec3 uvBaryDx;    // their derivatives per pixel along x
    vec3 uvBaryDy;    // and along y (down)
    vec3 viewPos;     // view-space position
    vec3 viewNormal;  // interpolated view-space vertex normal (not normalised)
    vec3 faceNormal;  // geometric normal of the triangle in view space (not normalised)
    float ao;         // ambient occlusion at the pixel (shared/ao.h): 1 until the shade stage reads it
};

// The surface of triangle (pos*, nrm*) at NDC point `ndc`, from its world-space vertex positions and
// normals. Shading re-derives each vertex's clip position, view position and view normal with
// transformVertex instead of reading them from per-vertex buffers: three small matrix products per pixel
// cost less than storing and re-reading 48 bytes per vertex, and the clip positions come out
// bit-identical to the vertex stage's, so the barycentrics match the rasterized triangle exactly.
// `extrapolate`: the point need not be covered by the triangle (clipBarycentrics). The texture
// coordinate derivatives are per pixel of a params.width x params.height grid.
SR_FN SurfacePoint surfaceAtNdc(RasterParams params, vec2 ndc, bool extrapolate, vec4 pos0, vec4 pos1,
                                vec4 pos2, vec4 nrm0, vec4 nrm1, vec4 nrm2)
{
    vec4 c0, c1, c2, p0, p1, p2, n0, n1, n2;
    transformVertex(params, pos0, nrm0, c0, p0, n0);
    transformVertex(params, pos1, nrm1, c1, p1, n1);
    transformVertex(params, pos2, nrm2, c2, p2, n2);
    SurfacePoint s;
    vec3 dX, dY;
    s.bary = clipBarycentrics(c0, c1, c2, ndc, vec3(1.0f), extrapolate, dX, dY);
    if (params.uvInterpolation == UV_AFFINE)
        s.uvBary = clipBarycentrics(c0, c1, c2, ndc, vec3(c0.w, c1.w, c2.w), extrapolate, dX, dY);
    else
        s.uvBary = s.bary;
    // One pixel is 2 / width NDC units along x and 2 / height along y.
    SR_PRECISE vec3 pdx = dX * (2.0f * recipDet(float(params.width)));
    SR_PRECISE vec3 pdy = dY * (2.0f * recipDet(float(params.height)));
    s.uvBaryDx = pdx;
    s.uvBaryDy = pdy;
    s.viewPos = interpolate3(s.bary, p0, p1, p2);
    s.viewNormal = interpolate3(s.bary, n0, n1, n2);
    vec3 e1 = vec3(p1.x - p0.x, p1.y - p0.y, p1.z - p0.z);
    vec3 e2 = vec3(p2.x - p0.x, p2.y - p0.y, p2.z - p0.z);
    s.faceNormal = cross(e1, e2);
    s.ao = 1.0f;
    return s;
}

// The surface the shade stage lights: at the centre of pixel (px, py). With one sample the centre is
// covered; with several it may be any of the samples, and the triangle's plane is extrapolated there
// as hardware does without centroid interpolation.
SR_FN SurfacePoint surfaceAt(RasterParams params, int px, int py, vec4 pos0, vec4 pos1, vec4 pos2, vec4 nrm0,
                             vec4 nrm1, vec4 nrm2)
{
    return surfaceAtNdc(params, pixelCenterNdc(px, py, params.width, params.height), params.sampleCount > 1u,
                        pos0, pos1, pos2, nrm0, nrm1, nrm2);
}

// Texture coordinates of one set (tc*: the set's (u, v) at the three vertices) at the surface point,
// with their derivatives per pixel.
SR_FN vec2 surfaceUv(SurfacePoint s, vec2 tc0, vec2 tc1, vec2 tc2, SR_OUT(vec2) dUvDx, SR_OUT(vec2) dUvDy)
{
    SR_PRECISE vec2 dx = tc0 * s.uvBaryDx.x + tc1 * s.uvBaryDx.y + tc2 * s.uvBaryDx.z;
    SR_PRECISE vec2 dy = tc0 * s.uvBaryDy.x + tc1 * s.uvBaryDy.y + tc2 * s.uvBaryDy.z;
    SR_PRECISE vec2 uv = tc0 * s.uvBary.x + tc1 * s.uvBary.y + tc2 * s.uvBary.z;
    dUvDx = dx;
    dUvDy = dy;
    return uv;
}

// Coordinate set `set` (0 or 1) of a vertex's packed texture coordinates t, as the scene's texcoords
// buffer stores them: set 0 in (x, y), set 1 in (z, w).
SR_FN vec2 texcoordSet(vec4 t, uint set)
{
    return set != 0u ? vec2(t.z, t.w) : vec2(t.x, t.y);
}

// surfaceUv of coordinate set `set`, from the three vertices' packed texture coordinates.
SR_FN vec2 surfaceUvOfSet(SurfacePoint s, vec4 t0, vec4 t1, vec4 t2, uint set, SR_OUT(vec2) dUvDx,
                          SR_OUT(vec2) dUvDy)
{
    return surfaceUv(s, texcoordSet(t0, set), texcoordSet(t1, set), texcoordSet(t2, set), dUvDx, dUvDy);
}

// Interpolated vertex colour (linear RGBA) at the surface point.
SR_FN vec4 surfaceColor(SurfacePoint s, vec4 col0, vec4 col1, vec4 col2)
{
    vec3 rgb = interpolate3(s.bary, col0, col1, col2);
    float a = col0.w * s.bary.x + col1.w * s.bary.y + col2.w * s.bary.z;
    return vec4(rgb.x, rgb.y, rgb.z, a);
}

// Colour of the surface point with base colour `baseColor` (linear: material factor x texture x vertex
// colour) and emitted colour `emissive` (linear: emissive factor x emissive texture), which the lit
// modes add to the reflected light, as glTF's emission is added to the BRDF's. `uv` and `lambda` feed
// the SHADING_TEXCOORD and SHADING_MIP debug views; the other debug views show no emission.
SR_FN vec3 shadeSurface(RasterParams params, uint triId, SurfacePoint s, vec4 baseColor, vec3 emissive,
                        vec2 uv, float lambda)
{
    uint mode = params.shadingMode;
    if (mode == SHADING_TEXCOORD) return vec3(fract(uv.x), fract(uv.y), 0.0f);
    if (mode == SHADING_MIP) return mipColor(lambda);
    vec3 color = shadePixel(params, triId, s.viewPos, s.viewNormal, s.faceNormal,
                            vec3(baseColor.x, baseColor.y, baseColor.z), s.ao);
    bool lit = mode == SHADING_LAMBERT || mode == SHADING_PHONG || mode == SHADING_BLINN_PHONG ||
               mode == SHADING_FLAT;
    return lit ? color + emissive : color;
}

// Parameter u (0 at the first vertex, 1 at the second) along the line segment with world-space ends
// pos0 -> pos1 of the point the centre of raster pixel (px, py) shades: Vulkan's rule for lines, the
// point of the drawn (clipped) segment nearest to the centre in screen space, its screen fraction s made
// perspective-correct (s / w1) / ((1 - s) / w0 + s / w1) within the clipped part and mapped back to the
// whole segment's parameter, in which clip space, and so every vertex attribute, is linear.
SR_FN float lineParameter(RasterParams params, int px, int py, vec4 pos0, vec4 pos1)
{
    vec4 a, b;
    vec2 u;
    uint kind = prepareLine(mulPoint(params.clipFromWorld, pos0), mulPoint(params.clipFromWorld, pos1),
                            params.guardBand, a, b, u);
    if (kind == PREPARE_INVALID || kind == PREPARE_CULLED || !(a.w > 0.0f) || !(b.w > 0.0f)) return 0.0f;
    vec2 ndc = pixelCenterNdc(px, py, params.width, params.height);
    vec2 pa = vec2(a.x / a.w, a.y / a.w);
    vec2 d = vec2(b.x / b.w, b.y / b.w) - pa;
    // Aspect: NDC units differ per axis, so measure in pixels.
    vec2 scale = vec2(float(params.width), float(params.height));
    vec2 dPx = d * scale;
    vec2 qPx = (ndc - pa) * scale;
    float lengthSq = dot(dPx, dPx);
    float s = lengthSq > 0.0f ? clamp(dot(qPx, dPx) / lengthSq, 0.0f, 1.0f) : 0.0f;
    float t = (s / b.w) / ((1.0f - s) / a.w + s / b.w);
    return u.x + t * (u.y - u.x);
}

// Colour of a line segment or point, primitive `id`, with base colour `baseColor` (vertex colour x
// material factor): they are drawn unlit (they have no surface to light), in every shading mode but the
// id view.
SR_FN vec3 shadeUnlit(RasterParams params, uint id, vec4 baseColor)
{
    if (params.shadingMode == SHADING_PRIMITIVE_ID) return idColor(id);
    return vec3(baseColor.x, baseColor.y, baseColor.z);
}

SR_NAMESPACE_END

#endif  // RASTER_SHARED_SHADE_H
