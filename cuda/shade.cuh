// shade.cuh - stage `shade`: per pixel, resolve the visibility key to its triangle, interpolate that
// triangle's vertex attributes perspective-correctly at the pixel centre, apply its material (base
// colour factor, texture with analytic derivatives), shade, and store RGBA8 (sRGB).
// One thread per pixel; blocks = ceil(width * height / GROUP_SIZE).
namespace sr {

__device__ inline void shadeStage(const RasterParams& params, const Buffers& b)
{
    uint i = globalThreadId();
    if (i >= params.width * params.height) return;
    uint id = visibilityId(b.visibility[i]);
    vec3 color = vec3(params.background.x, params.background.y, params.background.z);
    if (params.shadingMode == SHADING_HIT_COUNT) {
        color = hitCountColor(b.hitCount[i], color);
    } else if (id != EMPTY_ID) {
        uint i0 = b.indices[3u * id];
        uint i1 = b.indices[3u * id + 1u];
        uint i2 = b.indices[3u * id + 2u];
        SurfacePoint s =
            surfaceAt(params, int(i % params.width), int(i / params.width), b.positions[i0], b.positions[i1],
                      b.positions[i2], b.normals[i0], b.normals[i1], b.normals[i2]);
        vec2 uv;
        float lambda;
        vec4 base = materialBaseColor(params, b, id, i0, i1, i2, s, uv, lambda);
        color = shadeSurface(params, id, s, base, uv, lambda);
    }
    b.framebuffer[i] = packRgba8(color);
}

}  // namespace sr
