// vertex.cuh - stage `vertex`: world-space vertex position to clip space, for setup.
// One thread per vertex; blocks = ceil(vertexCount / GROUP_SIZE).
namespace sr {

__device__ inline void vertexStage(const RasterParams& params, const Buffers& b)
{
    uint v = globalThreadId();
    if (v < params.vertexCount) b.clipPos[v] = mulPoint(params.clipFromWorld, b.positions[v]);
}

}  // namespace sr
