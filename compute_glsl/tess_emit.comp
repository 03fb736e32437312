// tess_emit.comp - stage `tess_emit`: per scene triangle, its generated vertices and triangles at the
// offsets the scans gave it (shared/tess_emit.h); the threads past the triangles copy the materials of
// the scene's line segments and points behind the generated triangles (primitive ids shift with them).
// One thread per scene primitive; groups = ceil((tessSourceTriangles + lineCount + pointCount) / GROUP_SIZE).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "tess_buffers.glsl"

layout(local_size_x = GROUP_SIZE) in;

void tessWriteVertex(uint k, TessVertex v)
{
    uint i = params.tessSourceVertices + k;
    positions[i] = v.position;
    normals[i] = v.normal;
    if (params.textureCount > 0u) texcoords[i] = v.texcoord;
    if (params.hasColors != 0u) colors[i] = v.color;
}

void tessWriteTriangle(uint k, uint a, uint b, uint c, uint src)
{
    indices[3u * k] = a;
    indices[3u * k + 1u] = b;
    indices[3u * k + 2u] = c;
    triFlags[k] = (tessSource[src].flags >> TESS_TRI_FLAGS_SHIFT) & 255u;
    if (params.materialCount > 0u) triMaterials[k] = tessMaterials[src];
    tessIds[k] = src;
}

#define TESS_WRITER_PARAM
#define TESS_WRITER_ARG
#define TESS_WRITE_VERTEX(k, v) tessWriteVertex(k, v)
#define TESS_WRITE_TRIANGLE(k, a, b, c, src) tessWriteTriangle(k, a, b, c, src)
#include "shared/tess_emit.h"

void main()
{
    uint id = gl_GlobalInvocationID.x;
    uint sources = params.tessSourceTriangles;
    if (id >= sources) {
        uint k = id - sources;
        if (params.materialCount > 0u && k < params.lineCount + params.pointCount)
            triMaterials[params.triangleCount + k] = tessMaterials[id];
        return;
    }
    TessSource s = tessSource[id];
    uvec4 entry = tessCounts[id];
    uvec4 base = tessSums[1u + id / uint(SCAN_GROUP_SIZE)];
    tessEmitTriangle(params, s, loadTessPatch(s), id, entry, params.tessSourceVertices + base.x + entry.x,
                     base.y + entry.y);
}
