// tess_buffers.glsl - descriptor set 0 as the tess_* stages see it: the scene triangles they read
// (BUF_TESS_SOURCE and the scene's vertices at the head of the per-vertex buffers) and the generated
// vertices and triangles they write into the buffers every later stage draws from (buffers.glsl has
// those read-only, so the tess stages declare the set themselves). cuda/tess_buffers.cuh is the twin.
#ifndef RASTER_TESS_BUFFERS_GLSL
#define RASTER_TESS_BUFFERS_GLSL

layout(std140, set = 0, binding = BUF_PARAMS) uniform ParamsBlock { RasterParams params; };
layout(std430, set = 0, binding = BUF_POSITIONS) buffer PositionsBlock { vec4 positions[]; };
layout(std430, set = 0, binding = BUF_NORMALS) buffer NormalsBlock { vec4 normals[]; };
layout(std430, set = 0, binding = BUF_COLORS) buffer ColorsBlock { vec4 colors[]; };
layout(std430, set = 0, binding = BUF_TEXCOORDS) buffer TexcoordsBlock { vec4 texcoords[]; };
layout(std430, set = 0, binding = BUF_INDICES) writeonly buffer IndicesBlock { uint indices[]; };
layout(std430, set = 0, binding = BUF_TRI_FLAGS) writeonly buffer TriFlagsBlock { uint triFlags[]; };
layout(std430, set = 0, binding = BUF_TRI_MATERIALS) writeonly buffer TriMaterialsBlock { uint triMaterials[]; };
layout(std430, set = 0, binding = BUF_TESS_SOURCE) readonly buffer TessSourceBlock { TessSource tessSource[]; };
layout(std430, set = 0, binding = BUF_TESS_COUNTS) buffer TessCountsBlock { uvec4 tessCounts[]; };
layout(std430, set = 0, binding = BUF_TESS_SUMS) buffer TessSumsBlock { uvec4 tessSums[]; };
layout(std430, set = 0, binding = BUF_TESS_IDS) writeonly buffer TessIdsBlock { uint tessIds[]; };
layout(std430, set = 0, binding = BUF_TESS_MATERIALS) readonly buffer TessMaterialsBlock { uint tessMaterials[]; };

// Scene vertex i as tessellation reads it (white where the scene has no colours, zero texture
// coordinates where it has no textures).
TessVertex loadTessVertex(uint i)
{
    TessVertex v;
    v.position = positions[i];
    v.normal = normals[i];
    v.texcoord = params.textureCount > 0u ? texcoords[i] : vec4(0.0f);
    v.color = params.hasColors != 0u ? colors[i] : vec4(1.0f);
    return v;
}

TessPatch loadTessPatch(TessSource s)
{
    return tessMakePatch(params.tessMode, loadTessVertex(s.i0), loadTessVertex(s.i1), loadTessVertex(s.i2), s.flags);
}

#endif  // RASTER_TESS_BUFFERS_GLSL
