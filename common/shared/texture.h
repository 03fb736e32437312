// shared/texture.h - texture sampling maths of stage `shade` (and of the alpha test of the visibility
// stages): Vulkan's level-of-detail and level selection, texel selection with wrap modes, and the
// filters, on textures held in storage buffers (GpuTexture + BUF_TEXELS) rather than hardware samplers,
// so that every backend computes the same bits.
//
// The rules are Vulkan's ("Texel Filtering" and "LOD Operation" of the spec): u = s * width, texel
// centres at integer + 0.5, lambda = log2(rho_max), magnification when lambda <= 0, nearest level
// d = ceil(lambda + 0.5) - 1, linear levels floor(lambda) and the next with weight fract(lambda). Two
// deliberate choices, both within the spec's allowances: rho is the exact length of the derivative
// vector (the spec also allows max(|du|, |dv|)), and lambda is rounded to 1/256 of a level so that a
// last-bit difference of the log cannot pick another level on one backend.
//
// Texel fetches need the buffers, which only the backends see: each backend has a short
// sampleTexture (compute_glsl/buffers.glsl, cuda/buffers.cuh) that calls the functions here in the
// same order. Part of raster_shared.h (included from there, not on its own); same three-language rules.
#ifndef RASTER_SHARED_TEXTURE_H
#define RASTER_SHARED_TEXTURE_H

SR_NAMESPACE_BEGIN

// i - floor(i / period) period for |i| <= 2^22 + 1 and period >= 1, without an integer division: float(i)
// is exact, so a float quotient even 2.5 ulp off is within 1.25 of the real one and its floor within 2
// of the right one, which two corrections by the remainder's range take out.
SR_FN int floorModNoDivide(int i, int period)
{
    int q = int(floor(float(i) / float(period)));
    int m = i - q * period;
    for (int step = 0; step < 2; ++step) {
        if (m < 0) m = m + period;
        if (m >= period) m = m - period;
    }
    return m;
}

// Texel index i wrapped into [0, size) by `mode` (WRAP_*). REPEAT and MIRRORED_REPEAT take floored
// remainders, so u < 0 repeats the way it does for u > 1. GLSL leaves % of a negative operand
// undefined (NVIDIA and C++ disagree), so i is first moved up by a multiple of the period: i stays
// within +-(2^22 + 1) (textureTexelCoords), hence i + k * period is positive and below 2^31.
//
// A CPU device runs a vector of integer divisions as one scalar division per lane, so the CPU builds
// (SR_CPU_BUILD) take the floored remainder from floorModNoDivide instead, the same value.
SR_FN int wrapTexel(int i, int size, uint mode)
{
    if (mode == WRAP_CLAMP_TO_EDGE) return clamp(i, 0, size - 1);
    int period = mode == WRAP_MIRRORED_REPEAT ? 2 * size : size;
#if defined(SR_CPU_BUILD)
    int m = floorModNoDivide(i, period);
#else
    int shifted = i + (4194306 / period + 1) * period;
    int m = shifted % period;
#endif
    if (mode == WRAP_MIRRORED_REPEAT) return m < size ? m : period - 1 - m;
    return m;
}

// Size of level `level` (max(1, size >> level) on each axis).
SR_FN ivec2 textureLevelSize(GpuTexture t, uint level)
{
    return ivec2(max(int(t.width >> level), 1), max(int(t.height >> level), 1));
}

// Index in BUF_TEXELS of the first texel of level `level`: the levels are stored one after another.
SR_FN uint textureLevelOffset(GpuTexture t, uint level)
{
    uint offset = t.texelOffset;
#if defined(SR_CPU_BUILD)
    // On a CPU device every turn of a loop whose trip count is only known at run time counts towards
    // llvmpipe's limit of 65,535 per invocation (docs/benchmark.md "Loops on a CPU device"), and
    // raster_tiles' alpha test looks levels up for every pixel of every bin entry: a constant trip count
    // unrolls, with no turn to count.
    for (uint k = 0u; k < MAX_TEXTURE_LEVELS - 1u; ++k) {
        ivec2 s = textureLevelSize(t, k);
        if (k < level) offset += uint(s.x) * uint(s.y);
    }
#else
    for (uint k = 0u; k < level; ++k) {
        ivec2 s = textureLevelSize(t, k);
        offset += uint(s.x) * uint(s.y);
    }
#endif
    return offset;
}

// Index in BUF_TEXELS of texel (i, j) of a level, after wrapping; `levelOffset` from textureLevelOffset.
SR_FN uint textureTexelIndex(GpuTexture t, uint levelOffset, ivec2 size, int i, int j)
{
    int x = wrapTexel(i, size.x, t.wrapS);
    int y = wrapTexel(j, size.y, t.wrapT);
    return levelOffset + uint(y) * uint(size.x) + uint(x);
}

// log2 of a positive, finite float from its exponent and the series
// log2(m) = 2 / ln 2 * (r + r^3 / 3 + r^5 / 5 + ...), r = (m - 1) / (m + 1), with m in [sqrt(1/2), sqrt(2)),
// so |r| < 0.172 and seven terms leave an error below 1e-9: the same few correctly rounded operations
// on every backend (the division through recipDet), where the built-in log2 differs in its last bits
// between CUDA and GLSL drivers.
SR_FN float log2Deterministic(float x)
{
    uint bits = floatBitsToUint(x);
    int e = int((bits >> 23) & 255u) - 127;
    float m = uintBitsToFloat((bits & 0x007FFFFFu) | 0x3F800000u);  // [1, 2)
    if (m > 1.41421356f) {
        m = m * 0.5f;
        e = e + 1;
    }
    SR_PRECISE float r = (m - 1.0f) * recipDet(m + 1.0f);
    SR_PRECISE float r2 = r * r;
    SR_PRECISE float s = 1.0f / 13.0f;
    s = s * r2 + 1.0f / 11.0f;
    s = s * r2 + 1.0f / 9.0f;
    s = s * r2 + 1.0f / 7.0f;
    s = s * r2 + 1.0f / 5.0f;
    s = s * r2 + 1.0f / 3.0f;
    s = s * r2 + 1.0f;
    SR_PRECISE float l = float(e) + 2.8853900817779268f * r * s;  // 2 / ln 2
    return l;
}

// Level of detail from the screen-space derivatives of (s, t) (per pixel) and the level-0 size:
// lambda = log2(rho_max) = log2(rho_max^2) / 2, rounded to 1/256. Returns -128 (magnification) for
// zero or non-finite derivatives, +128 beyond any level for infinite ones.
SR_FN float textureLambda(vec2 dSTdx, vec2 dSTdy, uint width, uint height)
{
    SR_PRECISE float ux = dSTdx.x * float(width);
    SR_PRECISE float vx = dSTdx.y * float(height);
    SR_PRECISE float uy = dSTdy.x * float(width);
    SR_PRECISE float vy = dSTdy.y * float(height);
    SR_PRECISE float rx = ux * ux + vx * vx;
    SR_PRECISE float ry = uy * uy + vy * vy;
    float rho2 = max(rx, ry);
    if (!(rho2 > 0.0f)) return -128.0f;
    if (!isFinite(rho2)) return 128.0f;
    SR_PRECISE float lambda = 0.5f * log2Deterministic(rho2);
    return clamp(floor(lambda * 256.0f + 0.5f) * (1.0f / 256.0f), -128.0f, 128.0f);
}

// What one lookup reads: a filter (FILTER_*) applied on level0 and, when blend > 0, on level1, mixed
// with weight blend.
struct TextureLookup {
    uint filterMode;
    uint level0;
    uint level1;
    float blend;
};

// Vulkan's filter and level selection for `lambda`, or the --texture-filter override
// (TEXTURE_FILTER_*). The sampler's min filter applies when lambda > 0, its mag filter otherwise.
SR_FN TextureLookup textureSelect(GpuTexture t, float lambda, uint filterOverride)
{
    uint magFilter = t.filters & 255u;
    uint minFilter = (t.filters >> 8) & 255u;
    uint mipmapMode = (t.filters >> 16) & 255u;
    if (filterOverride == TEXTURE_FILTER_NEAREST) {
        magFilter = FILTER_NEAREST;
        minFilter = FILTER_NEAREST;
        mipmapMode = MIPMAP_NONE;
    } else if (filterOverride == TEXTURE_FILTER_BILINEAR) {
        magFilter = FILTER_LINEAR;
        minFilter = FILTER_LINEAR;
        mipmapMode = MIPMAP_NONE;
    } else if (filterOverride == TEXTURE_FILTER_TRILINEAR) {
        magFilter = FILTER_LINEAR;
        minFilter = FILTER_LINEAR;
        mipmapMode = MIPMAP_LINEAR;
    }
    TextureLookup look;
    look.filterMode = lambda > 0.0f ? minFilter : magFilter;
    look.level0 = 0u;
    look.level1 = 0u;
    look.blend = 0.0f;
    if (lambda <= 0.0f || mipmapMode == MIPMAP_NONE) return look;
    float q = float(t.levels - 1u);
    float d = min(lambda, q);
    if (mipmapMode == MIPMAP_NEAREST) {
        look.level0 = uint(max(ceil(d + 0.5f) - 1.0f, 0.0f));
        look.level1 = look.level0;
        return look;
    }
    float lo = floor(d);
    look.level0 = uint(lo);
    look.level1 = min(look.level0 + 1u, t.levels - 1u);
    look.blend = d - lo;
    return look;
}

// Texel coordinates of a lookup at (s, t) on a level of `size`: for FILTER_NEAREST the texel in .xy
// (floor(u), floor(v)); for FILTER_LINEAR the lower-left texel of the 2x2 footprint in .xy
// (floor(u - 0.5), floor(v - 0.5)). `weights` gets the linear filter's fractions (u - 0.5 - i0, ...).
// Coordinates are clamped to +-2^22 texels first, where float still resolves the fraction and int
// cannot overflow; texture coordinates that large are noise for any filter.
SR_FN ivec2 textureTexelCoords(vec2 st, ivec2 size, uint filterMode, SR_OUT(vec2) weights)
{
    SR_PRECISE float u = clamp(st.x * float(size.x), -4194304.0f, 4194304.0f);
    SR_PRECISE float v = clamp(st.y * float(size.y), -4194304.0f, 4194304.0f);
    if (filterMode == FILTER_NEAREST) {
        weights = vec2(0.0f, 0.0f);
        return ivec2(int(floor(u)), int(floor(v)));
    }
    SR_PRECISE float uc = u - 0.5f;
    SR_PRECISE float vc = v - 0.5f;
    float fu = floor(uc);
    float fv = floor(vc);
    SR_PRECISE float au = uc - fu;
    SR_PRECISE float av = vc - fv;
    weights = vec2(au, av);
    return ivec2(int(fu), int(fv));
}

// The four texels of a linear footprint, (i0, j0), (i0 + 1, j0), (i0, j0 + 1), (i0 + 1, j0 + 1), mixed
// with the fractions: first along u, then along v (the order fixes the bits).
SR_FN vec4 textureBilinear(vec4 t00, vec4 t10, vec4 t01, vec4 t11, vec2 weights)
{
    SR_PRECISE vec4 top = t00 + (t10 - t00) * weights.x;
    SR_PRECISE vec4 bottom = t01 + (t11 - t01) * weights.x;
    SR_PRECISE vec4 result = top + (bottom - top) * weights.y;
    return result;
}

// One RGBA8 texel as linear floats: sRGB colour channels through the decode table entries the backend
// looked up (rgbLinear), alpha and non-sRGB channels as byte / 255.
SR_FN vec4 textureUnorm(uint texel)
{
    SR_PRECISE vec4 c = vec4(float(texel & 255u), float((texel >> 8) & 255u), float((texel >> 16) & 255u),
                             float(texel >> 24)) *
                        (1.0f / 255.0f);
    return c;
}

// Texture coordinates (s, t) after a material's KHR_texture_transform (two rows of the affine map).
SR_FN vec2 materialTransformUv(GpuMaterial m, vec2 uv)
{
    SR_PRECISE float s = m.uvTransformU.x * uv.x + m.uvTransformU.y * uv.y + m.uvTransformU.z;
    SR_PRECISE float t = m.uvTransformV.x * uv.x + m.uvTransformV.y * uv.y + m.uvTransformV.z;
    return vec2(s, t);
}

// The transform's linear part applied to a derivative of (u, v).
SR_FN vec2 materialTransformDerivative(GpuMaterial m, vec2 d)
{
    SR_PRECISE float s = m.uvTransformU.x * d.x + m.uvTransformU.y * d.y;
    SR_PRECISE float t = m.uvTransformV.x * d.x + m.uvTransformV.y * d.y;
    return vec2(s, t);
}

// Colour ramp of the SHADING_MIP debug view: level 0 and magnification blue, then cyan, green, yellow,
// red at levels 1, 2, 3, 4 and beyond.
SR_FN vec3 mipColor(float lambda)
{
    float l = clamp(lambda, 0.0f, 4.0f);
    vec3 c0 = vec3(0.0f, 0.0f, 1.0f), c1 = vec3(0.0f, 1.0f, 1.0f), c2 = vec3(0.0f, 1.0f, 0.0f);
    vec3 c3 = vec3(1.0f, 1.0f, 0.0f), c4 = vec3(1.0f, 0.0f, 0.0f);
    if (l < 1.0f) return mix(c0, c1, l);
    if (l < 2.0f) return mix(c1, c2, l - 1.0f);
    if (l < 3.0f) return mix(c2, c3, l - 2.0f);
    return mix(c3, c4, l - 3.0f);
}

SR_NAMESPACE_END

#endif  // RASTER_SHARED_TEXTURE_H
