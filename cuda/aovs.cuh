// aovs.cuh - stage `aovs`: per output pixel, the id and depth of the sample it reports (aovSampleOf) into
// BUF_FRAMEBUFFER after the colour, and with AOV_OUT_SURFACE or AOV_OUT_RAST the surface of its triangle
// there: barycentrics, texture coordinates of the base colour texture and the shading normal, or rasterize's
// (u, v, z/w, id + 1) (layout: shared/aovs.h). The host then copies out only the arrays it was asked for,
// already unpacked, instead of every sample's 64-bit key. Lines and points get their id and depth, and zero
// surfaces. One thread per output pixel; blocks = ceil(outputPixels / GROUP_SIZE).
namespace sr {

__device__ inline void aovsStage(const RasterParams& params, const Buffers& b)
{
    RasterParams pixelParams = outputParams(params);
    uint n = pixelParams.width * pixelParams.height;
    uint i = globalThreadId();
    if (i >= n) return;
    uint x = i % pixelParams.width;
    uint y = i / pixelParams.width;
    unsigned long long key = b.visibility[aovSampleOf(params, x, y)];
    uint id = visibilityId(key);
    float depth = visibilityDepth(key);
    AovsLayout l = aovsLayout(n, params.aovOutputs);
    b.framebuffer[l.ids + i] = id;
    b.framebuffer[l.depths + i] = floatBitsToUint(depth);
    if ((params.aovOutputs & (AOV_OUT_SURFACE | AOV_OUT_RAST)) == 0u) return;

    vec2 bary = vec2(0.0f);
    vec2 uv = vec2(0.0f);
    vec3 normal = vec3(0.0f);
    if (id < params.triangleCount) {
        uint i0 = b.indices[3u * id];
        uint i1 = b.indices[3u * id + 1u];
        uint i2 = b.indices[3u * id + 2u];
        SurfacePoint s =
            surfaceAtNdc(pixelParams, aovSampleNdc(params, x, y), false, b.positions[i0], b.positions[i1],
                         b.positions[i2], b.normals[i0], b.normals[i1], b.normals[i2]);
        bary = vec2(s.bary.y, s.bary.z);
        if (params.materialCount > 0u) {
            // The base colour texture's coordinates, looked up as materialBaseColor does.
            GpuMaterial m = b.materials[min(b.triMaterials[id], params.materialCount - 1u)];
            if (m.baseColorTexture < params.textureCount) {
                vec2 dx, dy;
                uv = surfaceUvOfSet(s, b.texcoords[i0], b.texcoords[i1], b.texcoords[i2], m.texCoord, dx, dy);
                uv = materialTransformUv(m, uv);
            }
        }
        normal = aovNormal(params, s.bary, b.positions[i0], b.positions[i1], b.positions[i2], b.normals[i0],
                           b.normals[i1], b.normals[i2]);
    }
    if ((params.aovOutputs & AOV_OUT_SURFACE) != 0u) {
        b.framebuffer[l.surface + i] = floatBitsToUint(bary.x);
        b.framebuffer[l.surface + n + i] = floatBitsToUint(bary.y);
        b.framebuffer[l.surface + 2u * n + i] = floatBitsToUint(uv.x);
        b.framebuffer[l.surface + 3u * n + i] = floatBitsToUint(uv.y);
        b.framebuffer[l.surface + 4u * n + i] = floatBitsToUint(normal.x);
        b.framebuffer[l.surface + 5u * n + i] = floatBitsToUint(normal.y);
        b.framebuffer[l.surface + 6u * n + i] = floatBitsToUint(normal.z);
    }
    if ((params.aovOutputs & AOV_OUT_RAST) != 0u) {
        vec4 r = rastOutput(id, depth, bary.x, bary.y);
        b.framebuffer[l.rast + 4u * i] = floatBitsToUint(r.x);
        b.framebuffer[l.rast + 4u * i + 1u] = floatBitsToUint(r.y);
        b.framebuffer[l.rast + 4u * i + 2u] = floatBitsToUint(r.z);
        b.framebuffer[l.rast + 4u * i + 3u] = floatBitsToUint(r.w);
    }
}

}  // namespace sr
