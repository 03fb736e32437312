// tess_count.cuh - stage `tess_count`: per scene triangle, cull it or choose its edge factors, and count
// the vertices and triangles it will generate (shared/tessellate.h, tessCountTriangle).
// One thread per scene triangle; blocks = ceil(tessSourceTriangles / GROUP_SIZE).
namespace sr {

// Scene vertex i as tessellation reads it (white where the scene has no colours, zero texture
// coordinates where it has no textures).
__device__ inline TessVertex loadTessVertex(const RasterParams& params, const Buffers& b, uint i)
{
    TessVertex v;
    v.position = b.positions[i];
    v.normal = b.normals[i];
    v.texcoord = params.textureCount > 0u ? b.texcoords[i] : vec4(0.0f);
    v.color = params.hasColors != 0u ? b.colors[i] : vec4(1.0f);
    return v;
}

__device__ inline TessPatch loadTessPatch(const RasterParams& params, const Buffers& b, const TessSource& s)
{
    return tessMakePatch(params.tessMode, loadTessVertex(params, b, s.i0), loadTessVertex(params, b, s.i1),
                         loadTessVertex(params, b, s.i2), s.flags);
}

__device__ inline void tessCountStage(const RasterParams& params, const Buffers& b)
{
    uint tri = globalThreadId();
    if (tri >= params.tessSourceTriangles) return;
    b.tessCounts[tri] = tessCountTriangle(params, loadTessPatch(params, b, b.tessSource[tri]));
}

}  // namespace sr
