// tess_emit.cuh - stage `tess_emit`: per scene triangle, its generated vertices and triangles at the
// offsets the scans gave it (shared/tess_emit.h, through Buffers::tess); the threads past the triangles
// copy the materials of the scene's line segments and points behind the generated triangles (primitive
// ids shift with them). One thread per scene primitive; blocks = ceil((tessSourceTriangles + lineCount +
// pointCount) / GROUP_SIZE).
namespace sr {

__device__ inline void tessEmitStage(const RasterParams& params, const Buffers& b)
{
    uint id = globalThreadId();
    uint sources = params.tessSourceTriangles;
    if (id >= sources) {
        uint k = id - sources;
        if (params.materialCount > 0u && k < params.lineCount + params.pointCount)
            b.tess.triMaterials[params.triangleCount + k] = b.tess.materials[id];
        return;
    }
    TessSource s = b.tessSource[id];
    uvec4 entry = b.tessCounts[id];
    uvec4 base = b.tessSums[1u + id / uint(SCAN_GROUP_SIZE)];
    tessEmitTriangle(params, s, loadTessPatch(params, b, s), id, entry,
                     params.tessSourceVertices + base.x + entry.x, base.y + entry.y, b.tess);
}

}  // namespace sr
