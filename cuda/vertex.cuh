// vertex.cuh - stage `vertex`: world-space vertex to clip position, view position and view normal.
// One thread per vertex; blocks = ceil(vertexCount / GROUP_SIZE).
namespace sr {

__device__ inline void vertexStage(const RasterParams& params, const Buffers& b)
{
    uint v = globalThreadId();
    if (v >= params.vertexCount) return;
    vec4 clip, eyePos, eyeNormal;
    transformVertex(params, b.positions[v], b.normals[v], clip, eyePos, eyeNormal);
    b.clipPos[v] = clip;
    b.viewPos[v] = eyePos;
    b.viewNormal[v] = eyeNormal;
}

}  // namespace sr
