// raster_tiles.cuh - stage `raster_tiles`: the blocks walk the active screen tiles (TILE_SIZE x
// TILE_SIZE pixels with big triangles in their bin, listed by scan_blocks). For each tile the block
// walks the bin in batches of kLanes refs: each thread sets one triangle up into shared memory, then
// every thread tests its pixels against the whole batch, keeping the smallest visibility key of each of
// their samples in a register (one build per sample count, so the keys stay registers). The tile's
// pixels belong to this block alone, so nothing is resolved with atomics: each key starts from what
// setup's small triangles left in the visibility buffer and is stored once at the end. A triangle whose
// depth bound lies behind every sample's key of a pixel is skipped there without a coverage test (early
// depth; off while counting hits, which must see every triangle). CUDA runs TILE_SIZE^2 threads, one
// pixel each; the GLSL twin takes its lane count from a specialization constant so that a CPU device
// runs fewer, longer invocations.
// blocks = RasterParams.rasterGroups: one per tile active in the previous frame; block g takes the
// active tiles g, g + rasterGroups, ...
namespace sr {

constexpr uint kLanes = TILE_SIZE * TILE_SIZE;
constexpr uint kPixelsPerLane = TILE_SIZE * TILE_SIZE / kLanes;  // 1: the GLSL twin's loops run once here

// Resolves the bin entries [begin, end) of one screen tile into its pixels' kSamples samples each
// (RasterParams.sampleCount). Uniform across the block.
template <bool kMaterials, uint kSamples, uint kMethod>
__device__ inline void rasterTile(const RasterParams& params, const Buffers& b, uint tile, uint lane,
                                  uint begin, uint end)
{
    __shared__ TriSetup tris[kLanes];
    __shared__ uint minDepth[kLanes];
    __shared__ uint masked[kMaterials ? kLanes : 1];  // TRI_FLAG_ALPHA_MASK of each: needs the alpha test
    bool countHits = (params.debugFlags & DEBUG_COUNT_HITS) != 0u;
    int px[kPixelsPerLane], py[kPixelsPerLane];
    uint64_t key[kPixelsPerLane][kSamples];
    uint hits[kPixelsPerLane][kSamples];
    uint farthest[kPixelsPerLane];  // the largest depth bits among the pixel's keys
    for (uint j = 0u; j < kPixelsPerLane; ++j) {
        uint p = lane + j * kLanes;  // this thread's j-th pixel of the tile
        px[j] = int(tile % params.tilesX) * TILE_SIZE + int(p % uint(TILE_SIZE));
        py[j] = int(tile / params.tilesX) * TILE_SIZE + int(p / uint(TILE_SIZE));
        bool mine =
            p < uint(TILE_SIZE * TILE_SIZE) && uint(px[j]) < params.width && uint(py[j]) < params.height;
        uint pixel = mine ? uint(py[j]) * params.width + uint(px[j]) : 0u;
        farthest[j] = 0u;
        for (uint s = 0u; s < kSamples; ++s) {
            key[j][s] = mine ? uint64_t(b.visibility[s * params.samplePlane + pixel]) : ~uint64_t(0);
            farthest[j] = max(farthest[j], uint(key[j][s] >> 32));
            hits[j][s] = 0u;
        }
        if (!mine) px[j] = -1;
    }
    for (uint base = begin; base < end; base += kLanes) {
        uint count = min(end - base, kLanes);
        if (lane < count) {
            TriSetup t;
            bool ok = loadBinTriangle<kMethod>(params, b, b.binEntries[base + lane], t);
            tris[lane] = t;
            minDepth[lane] = ok ? triangleMinDepthBits(t) : 0xFFFFFFFFu;
            if (kMaterials)
                // Lines have no alpha test (and no triangle flags).
                masked[lane] = ok && params.materialCount != 0u && setupTriId(t) < params.triangleCount
                                   ? (b.triFlags[setupTriId(t)] & TRI_FLAG_ALPHA_MASK)
                                   : 0u;
        }
        __syncthreads();
        for (uint j = 0u; j < kPixelsPerLane; ++j) {
            if (px[j] < 0) continue;
            for (uint k = 0u; k < count; ++k) {
                // Early depth: every sample of the pixel already holds something nearer.
                if (minDepth[k] == 0xFFFFFFFFu || (!countHits && farthest[j] < minDepth[k])) continue;
                uint id = setupTriId(tris[k]);
                if (kSamples == 1u) {
                    float depth;
                    if (methodPixel<kMethod>(tris[k], px[j], py[j], depth) &&
                        (!kMaterials || masked[k] == 0u || alphaMaskCovers(params, b, id, px[j], py[j]))) {
                        key[j][0] = min(key[j][0], packVisibility(depth, id));
                        farthest[j] = uint(key[j][0] >> 32);
                        ++hits[j][0];
                    }
                    continue;
                }
                // One test of the pixel's sample rectangle rejects most uncovered pixels at the cost of
                // one sample's edge functions.
                if (!methodTouchesPixels<kMethod>(tris[k], px[j], py[j], px[j], py[j], params.sampleBounds))
                    continue;
                float depth[kSamples];
                uint mask = 0u;
                for (uint s = 0u; s < kSamples; ++s)
                    if (methodSample<kMethod>(tris[k], samplePosition(kSamples, s, px[j], py[j]), depth[s]))
                        mask |= 1u << s;
                // The alpha test runs once per pixel, at its centre, as hardware shades a pixel.
                if (mask == 0u ||
                    (kMaterials && masked[k] != 0u && !alphaMaskCovers(params, b, id, px[j], py[j])))
                    continue;
                farthest[j] = 0u;
                for (uint s = 0u; s < kSamples; ++s) {
                    if ((mask & (1u << s)) != 0u) {
                        key[j][s] = min(key[j][s], packVisibility(depth[s], id));
                        ++hits[j][s];
                    }
                    farthest[j] = max(farthest[j], uint(key[j][s] >> 32));
                }
            }
        }
        __syncthreads();
    }
    for (uint j = 0u; j < kPixelsPerLane; ++j) {
        if (px[j] < 0) continue;
        uint pixel = uint(py[j]) * params.width + uint(px[j]);
        for (uint s = 0u; s < kSamples; ++s) {
            b.visibility[s * params.samplePlane + pixel] = key[j][s];
            if (countHits) b.hitCount[s * params.samplePlane + pixel] += hits[j][s];
        }
    }
}

template <bool kMaterials, uint kSamples, uint kMethod>
__device__ inline void rasterTilesStage(const RasterParams& params, const Buffers& b)
{
    uint lane = threadIdx.x;
    uint activeCount = b.counters[COUNTER_ACTIVE_TILES];
    for (uint index = blockIdx.x; index < activeCount; index += params.rasterGroups) {
        uint tile = b.activeTiles[index];
        uint begin = tile == 0u ? 0u : min(binEnd(b, tile - 1u), params.binCapacity);
        uint end = min(binEnd(b, tile), params.binCapacity);
        if (begin < end) rasterTile<kMaterials, kSamples, kMethod>(params, b, tile, lane, begin, end);
    }
}
}  // namespace sr
