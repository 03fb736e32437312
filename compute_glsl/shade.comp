// shade.comp - stage `shade`: per output pixel, resolve the visibility keys of its samples (the ssaa x
// ssaa raster pixels it covers, sampleCount samples each) to their triangles; shade each distinct
// triangle of a raster pixel once, at the raster pixel's centre (as hardware MSAA runs a fragment
// shader once per pixel and primitive), interpolating its vertex attributes perspective-correctly and
// applying its material (base colour factor, texture with analytic derivatives); average the samples'
// colours, clamped to the displayable range, in linear space (a box filter) and store RGBA8 (sRGB).
// One invocation per output pixel, groups = ceil(outputPixels / GROUP_SIZE); the CPU build (below) takes
// SHADE_CPU_PIXELS output pixels per invocation, groups = ceil(outputPixels / (GROUP_SIZE *
// SHADE_CPU_PIXELS)).
// SHADE_CPU (a preprocessor definition, 0 or 1): the build for CPU devices (CMakeLists.txt compiles this
// shader twice). A CPU device runs every invocation as a SIMD lane, both sides of each branch, so this
// build takes the frame's shading mode and scene features as specialization constants (buffers.glsl)
// and encodes sRGB without pow (srgbEncode8); the GPU build is unchanged by it.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(local_size_x = GROUP_SIZE) in;
// Samples per pixel (SPEC_SAMPLES, RasterParams.sampleCount): one build per count, so that a raster
// pixel's ids sit in registers while its distinct triangles are found.
layout(constant_id = SPEC_SAMPLES) const uint SAMPLES = 1u;
// Whether output pixels have several samples, MSAA or SSAA (SPEC_RESOLVE).
layout(constant_id = SPEC_RESOLVE) const bool RESOLVE = false;

// Colour of primitive `id` at the centre of raster pixel (x, y): a triangle's shaded surface, or a line
// segment's or point's unlit base colour.
vec3 shadePrimitive(uint id, int x, int y)
{
#if SHADE_CPU
    if ((SHADE_USES & SHADE_USES_LINES_POINTS) != 0u && id >= params.triangleCount) {
#else
    if (id >= params.triangleCount) {
#endif
        uint k = id - params.triangleCount;
        if (k >= params.lineCount) return shadeUnlit(params, id, pointBaseColor(id));
        float u = lineParameter(params, x, y, positions[lines[2u * k]], positions[lines[2u * k + 1u]]);
        return shadeUnlit(params, id, lineBaseColor(id, u));
    }
    uint i0 = LOAD_INDEX(3u * id);
    uint i1 = LOAD_INDEX(3u * id + 1u);
    uint i2 = LOAD_INDEX(3u * id + 2u);
    SurfacePoint s = surfaceAt(params, x, y, LOAD_POSITION(i0), LOAD_POSITION(i1), LOAD_POSITION(i2),
                               LOAD_NORMAL(i0), LOAD_NORMAL(i1), LOAD_NORMAL(i2));
    if (params.aoMode != AO_OFF)
        s.ao = aoShaded(ao[params.aoPlane * params.samplePlane + uint(y) * params.width + uint(x)]);
    vec2 uv;
    float lambda;
    vec4 base = materialBaseColor(id, i0, i1, i2, s, uv, lambda);
    return shadeSurface(params, id, s, base, materialEmissive(id, i0, i1, i2, s), uv, lambda);
}

// A pixel's stored colour, RGBA8 sRGB-encoded: packRgba8, or on a CPU device the same code without pow.
// The frame's shading mode: on a CPU device the constant itself, so that a module specialized to it
// holds no other mode's resolve (host/vulkan/spirv_specialize.h).
#if SHADE_CPU
#define encodeColor packRgba8NoPow
#define FRAME_SHADING_MODE SHADE_MODE
#else
#define encodeColor packRgba8
#define FRAME_SHADING_MODE params.shadingMode
#endif

// Output pixel i. The GPU build is main itself, one invocation per pixel; the CPU build's main calls it
// for SHADE_CPU_PIXELS pixels per invocation.
#if SHADE_CPU
void shadeOutputPixel(uint i)
{
#else
void main()
{
    uint i = gl_GlobalInvocationID.x;
#endif
    vec3 background = vec3(params.background.x, params.background.y, params.background.z);
    uint n = params.ssaa;
    if (!RESOLVE) {  // one sample per pixel
        if (i >= params.width * params.height) return;
        uint id = LOAD_KEY_ID(i);
        vec3 color = background;
        if (FRAME_SHADING_MODE == SHADING_HIT_COUNT)
            color = hitCountColor(hitCount[i], color);
        else if (id != EMPTY_ID)
            color = shadePrimitive(id, int(i % params.width), int(i / params.width));
        framebuffer[i] = encodeColor(color);
        return;
    }
    uint outWidth = params.width / n;
    if (i >= outWidth * (params.height / n)) return;
    precise vec3 sum = vec3(0.0f);
    for (uint sy = 0u; sy < n; ++sy) {
        for (uint sx = 0u; sx < n; ++sx) {
            int x = int((i % outWidth) * n + sx);
            int y = int((i / outWidth) * n + sy);
            uint pixel = uint(y) * params.width + uint(x);
            if (FRAME_SHADING_MODE == SHADING_HIT_COUNT) {
                for (uint s = 0u; s < SAMPLES; ++s)
                    sum = sum + hitCountColor(hitCount[s * params.samplePlane + pixel], background);
                continue;
            }
            uint id[SAMPLES];
            for (uint s = 0u; s < SAMPLES; ++s)
                id[s] = LOAD_KEY_ID(s * params.samplePlane + pixel);
#if SHADE_CPU
            // A CPU device would run the loop below's shading once per sample, each turn masked to the
            // pixels whose sample is a first. Here each turn shades the lowest sample not yet shaded,
            // weighted by all its samples, so a SIMD bundle of pixels takes as many turns as its pixel with
            // the most distinct triangles (one inside a triangle); the same colours summed in the same order.
            // A do-while: llvmpipe tests for live lanes at the end of a loop's body, so a test at the top
            // would cost one more turn, with every lane masked off.
            uint pending = (1u << SAMPLES) - 1u;
            do {
                // The lowest pending sample's id, picked with constant indices: indexing id[] by a varying
                // index here gave wrong colours at 5% of the pixels on llvmpipe 22.3 (Mesa 22.3.6).
                uint first = EMPTY_ID;
                for (uint o = SAMPLES; o > 0u; --o)
                    if ((pending & (1u << (o - 1u))) != 0u) first = id[o - 1u];
                uint owned = 0u;
                for (uint o = 0u; o < SAMPLES; ++o) {
                    if ((pending & (1u << o)) == 0u || id[o] != first) continue;
                    pending &= ~(1u << o);
                    ++owned;
                }
                vec3 color = first == EMPTY_ID ? background : shadePrimitive(first, x, y);
                sum = sum + clamp(color, vec3(0.0f), vec3(1.0f)) * float(owned);
            } while (pending != 0u);
#else
            for (uint s = 0u; s < SAMPLES; ++s) {
                // Shade each triangle of the pixel once, at its first sample, weighted by its samples.
                uint owned = 0u;
                bool first = true;
                for (uint o = 0u; o < SAMPLES; ++o) {
                    if (id[o] != id[s]) continue;
                    first = first && o >= s;
                    ++owned;
                }
                if (!first) continue;
                vec3 color = id[s] == EMPTY_ID ? background : shadePrimitive(id[s], x, y);
                // Each sample's colour as the image shows it (clamped to [0, 1], packRgba8's range) before
                // the mean: a highlight far above 1 must not bleed over the pixel's other samples.
                sum = sum + clamp(color, vec3(0.0f), vec3(1.0f)) * float(owned);
            }
#endif
        }
    }
    framebuffer[i] = encodeColor(sum * sampleWeight(n * n * SAMPLES));
}

#if SHADE_CPU
// A CPU device runs a group's invocations as SIMD bundles, and each bundle of a dispatch costs as much
// as a 4-byte store per lane before it does anything (an empty pass over 1920x1080 takes 11 ms on
// llvmpipe 25.0, docs/benchmark.md). So each invocation takes SHADE_CPU_PIXELS output pixels, GROUP_SIZE
// apart, and a bundle's lanes stay on neighbouring pixels in every turn (GroupCounts::shadePixels).
void main()
{
    params = frameParams;
    params.shadingMode = SHADE_MODE;
    params.sampleCount = SAMPLES;
    // A loop whose trip count is only known at run time costs a CPU device one more turn, all lanes
    // masked off, to find that every lane has left it; constant counts unroll.
    params.ssaa = SHADE_SSAA;
    if ((SHADE_USES & SHADE_USES_MATERIALS) == 0u) params.materialCount = 0u;
    if ((SHADE_USES & SHADE_USES_COLORS) == 0u) params.hasColors = 0u;
    params.uvInterpolation = (SHADE_USES & SHADE_USES_AFFINE_UV) != 0u ? UV_AFFINE : UV_PERSPECTIVE;
    const uint first = gl_WorkGroupID.x * uint(GROUP_SIZE * SHADE_CPU_PIXELS) + gl_LocalInvocationID.x;
    uint k = 0u;
    do {  // tested at the end: llvmpipe checks for live lanes there (see the resolve loop above)
        shadeOutputPixel(first + k * uint(GROUP_SIZE));
        ++k;
    } while (k < uint(SHADE_CPU_PIXELS));
}
#endif
