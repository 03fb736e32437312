// shade.cuh - stage `shade`: per output pixel, resolve the visibility keys of its samples (the ssaa x
// ssaa raster pixels it covers, sampleCount samples each) to their triangles; shade each distinct
// triangle of a raster pixel once, at the raster pixel's centre (as hardware MSAA runs a fragment
// shader once per pixel and primitive), interpolating its vertex attributes perspective-correctly and
// applying its material (base colour factor, texture with analytic derivatives); average the samples'
// colours, clamped to the displayable range, in linear space (a box filter) and store RGBA8 (sRGB).
// One thread per output pixel; blocks = ceil(outputPixels / GROUP_SIZE).
namespace sr {

// Colour of primitive `id` at the centre of raster pixel (x, y): a triangle's shaded surface, or a line
// segment's or point's unlit base colour.
__device__ inline vec3 shadePrimitive(const RasterParams& params, const Buffers& b, uint id, int x, int y)
{
    if (id >= params.triangleCount) {
        uint k = id - params.triangleCount;
        if (k >= params.lineCount) return shadeUnlit(params, id, pointBaseColor(params, b, id));
        float u =
            lineParameter(params, x, y, b.positions[b.lines[2u * k]], b.positions[b.lines[2u * k + 1u]]);
        return shadeUnlit(params, id, lineBaseColor(params, b, id, u));
    }
    uint i0 = b.indices[3u * id];
    uint i1 = b.indices[3u * id + 1u];
    uint i2 = b.indices[3u * id + 2u];
    SurfacePoint s = surfaceAt(params, x, y, b.positions[i0], b.positions[i1], b.positions[i2], b.normals[i0],
                               b.normals[i1], b.normals[i2]);
    if (params.aoMode != AO_OFF)
        s.ao = aoShaded(b.ao[params.aoPlane * params.samplePlane + uint(y) * params.width + uint(x)]);
    vec2 uv;
    float lambda;
    vec4 base = materialBaseColor(params, b, id, i0, i1, i2, s, uv, lambda);
    return shadeSurface(params, id, s, base, materialEmissive(params, b, id, i0, i1, i2, s), uv, lambda);
}

// One build per sample count (RasterParams.sampleCount), so that a raster pixel's ids sit in registers
// while its distinct triangles are found; kResolve (SPEC_RESOLVE): whether output pixels have several
// samples (MSAA or SSAA); the build without holds only the one-sample path.
template <uint kSamples, bool kResolve>
__device__ inline void shadeStage(const RasterParams& params, const Buffers& b)
{
    uint i = globalThreadId();
    vec3 background = vec3(params.background.x, params.background.y, params.background.z);
    uint n = params.ssaa;
    if (!kResolve) {  // one sample per pixel
        if (i >= params.width * params.height) return;
        uint id = visibilityId(b.visibility[i]);
        vec3 color = background;
        if (params.shadingMode == SHADING_HIT_COUNT)
            color = hitCountColor(b.hitCount[i], color);
        else if (id != EMPTY_ID)
            color = shadePrimitive(params, b, id, int(i % params.width), int(i / params.width));
        b.framebuffer[i] = packRgba8(color);
        return;
    }
    uint outWidth = params.width / n;
    if (i >= outWidth * (params.height / n)) return;
    vec3 sum = vec3(0.0f);
    for (uint sy = 0u; sy < n; ++sy) {
        for (uint sx = 0u; sx < n; ++sx) {
            int x = int((i % outWidth) * n + sx);
            int y = int((i / outWidth) * n + sy);
            uint pixel = uint(y) * params.width + uint(x);
            if (params.shadingMode == SHADING_HIT_COUNT) {
                for (uint s = 0u; s < kSamples; ++s)
                    sum = sum + hitCountColor(b.hitCount[s * params.samplePlane + pixel], background);
                continue;
            }
            uint id[kSamples];
            for (uint s = 0u; s < kSamples; ++s)
                id[s] = visibilityId(b.visibility[s * params.samplePlane + pixel]);
            for (uint s = 0u; s < kSamples; ++s) {
                // Shade each triangle of the pixel once, at its first sample, weighted by its samples.
                uint owned = 0u;
                bool first = true;
                for (uint o = 0u; o < kSamples; ++o) {
                    if (id[o] != id[s]) continue;
                    first = first && o >= s;
                    ++owned;
                }
                if (!first) continue;
                vec3 color = id[s] == EMPTY_ID ? background : shadePrimitive(params, b, id[s], x, y);
                // Each sample's colour as the image shows it (clamped to [0, 1], packRgba8's range) before
                // the mean: a highlight far above 1 must not bleed over the pixel's other samples.
                sum = sum + clamp(color, vec3(0.0f), vec3(1.0f)) * float(owned);
            }
        }
    }
    b.framebuffer[i] = packRgba8(sum * sampleWeight(n * n * kSamples));
}

}  // namespace sr
