// raster_small.cuh - stage `raster_small`: one thread per small triangle tests every pixel centre of
// its bbox (at most SMALL_TRI_SPAN^2) and merges covered pixels with mergeFragment.
// Grid-stride loop over the small list; blocks = RasterParams.rasterGroups.
namespace sr {

__device__ inline void rasterSmallStage(const RasterParams& params, const Buffers& b)
{
    uint count = b.counters[COUNTER_SMALL];
    uint stride = gridDim.x * uint(GROUP_SIZE);
    for (uint i = globalThreadId(); i < count; i += stride) {
        TriSetup t = b.setupTris[b.smallTris[i]];
        ivec4 bounds = setupPixelBounds(t, params.width, params.height);
        uint id = setupTriId(t);
        for (int y = bounds.y; y <= bounds.w; ++y) {
            for (int x = bounds.x; x <= bounds.z; ++x) {
                float depth;
                if (rasterPixel(t, x, y, depth))
                    mergeFragment(params, b, uint(y) * params.width + uint(x), depth, id);
            }
        }
    }
}

}  // namespace sr
