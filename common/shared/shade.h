// shared/shade.h - stage `shade`: perspective-correct barycentrics from clip space, the lighting
// models and debug views, and sRGB encoding.
//
// Shading re-derives each vertex from the scene buffers (see shadeTriangleAt), so it needs no per-vertex
// output of the earlier stages. Part of raster_shared.h (included from there, not on its own); same
// three-language rules.
#ifndef RASTER_SHARED_SHADE_H
#define RASTER_SHARED_SHADE_H

SR_NAMESPACE_BEGIN

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

SR_NAMESPACE_END

#endif  // RASTER_SHARED_SHADE_H
