// raster_tiles.comp - stage `raster_tiles`: the groups walk the active screen tiles (TILE_SIZE x
// TILE_SIZE pixels with big triangles in their bin, listed by scan_blocks). For each tile the group
// walks the bin in batches of LANES refs: each invocation sets one triangle up into shared memory, then
// every invocation tests its pixels against the whole batch, keeping the smallest visibility key of each
// in a register. The tile's pixels belong to this group alone, so nothing is resolved with atomics: each
// key starts from what setup's small triangles left in the visibility buffer and is stored once at the
// end. A triangle whose depth bound lies behind a pixel's key is skipped there without a coverage test
// (early depth; off while counting hits, which must see every triangle).
// LANES is specialization constant 0: TILE_SIZE^2 on a GPU (one pixel per invocation, as the CUDA
// twin), the SIMD width on a CPU device, where every invocation of a group that synchronizes becomes a
// coroutine and fewer, longer invocations cost far less.
// groups = RasterParams.rasterGroups: on a GPU one per tile active in the previous frame; on a CPU
// device a few per thread (each group that synchronizes costs it about a microsecond). Group g takes
// the active tiles g, g + rasterGroups, ...
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

layout(local_size_x_id = 0) in;
// Whether the alpha test of MASK materials is built in (SPEC_MATERIALS).
layout(constant_id = SPEC_MATERIALS) const bool MATERIALS = true;
#define LANES gl_WorkGroupSize.x
#define PIXELS_PER_LANE (TILE_SIZE * TILE_SIZE / LANES)  // 1 on a GPU, at most MAX_PIXELS_PER_LANE

shared TriSetup tris[TILE_SIZE * TILE_SIZE];
shared uint minDepth[TILE_SIZE * TILE_SIZE];
shared uint masked[TILE_SIZE * TILE_SIZE];  // TRI_FLAG_ALPHA_MASK of each: coverage needs the alpha test

// Resolves the bin entries [begin, end) of one screen tile into its pixels. Uniform across the group.
void rasterTile(uint tile, uint lane, uint begin, uint end)
{
    bool countHits = (params.debugFlags & DEBUG_COUNT_HITS) != 0u;
    int px[MAX_PIXELS_PER_LANE], py[MAX_PIXELS_PER_LANE];
    uint64_t key[MAX_PIXELS_PER_LANE];
    uint hits[MAX_PIXELS_PER_LANE];
    for (uint j = 0u; j < PIXELS_PER_LANE; ++j) {
        uint p = lane + j * LANES;  // this invocation's j-th pixel of the tile
        px[j] = int(tile % params.tilesX) * TILE_SIZE + int(p % uint(TILE_SIZE));
        py[j] = int(tile / params.tilesX) * TILE_SIZE + int(p / uint(TILE_SIZE));
        bool mine =
            p < uint(TILE_SIZE * TILE_SIZE) && uint(px[j]) < params.width && uint(py[j]) < params.height;
        key[j] = mine ? visibility[uint(py[j]) * params.width + uint(px[j])] : ~uint64_t(0);
        if (!mine) px[j] = -1;
        hits[j] = 0u;
    }
    for (uint base = begin; base < end; base += LANES) {
        uint count = min(end - base, LANES);
        if (lane < count) {
            TriSetup t;
            bool ok = loadBinTriangle(binEntries[base + lane], t);
            tris[lane] = t;
            minDepth[lane] = ok ? triangleMinDepthBits(t) : 0xFFFFFFFFu;
            if (MATERIALS) {
                bool maskable = ok && params.materialCount != 0u;
                masked[lane] = maskable ? (triFlags[setupTriId(t)] & TRI_FLAG_ALPHA_MASK) : 0u;
            }
        }
        barrier();
        for (uint j = 0u; j < PIXELS_PER_LANE; ++j) {
            if (px[j] < 0) continue;
            for (uint k = 0u; k < count; ++k) {
                if (!countHits && uint(key[j] >> 32) < minDepth[k]) continue;
                float depth;
                if (minDepth[k] != 0xFFFFFFFFu && rasterPixel(tris[k], px[j], py[j], depth) &&
                    (!MATERIALS || masked[k] == 0u ||
                     alphaMaskCovers(setupTriId(tris[k]), px[j], py[j]))) {
                    key[j] = min(key[j], packVisibility(depth, setupTriId(tris[k])));
                    ++hits[j];
                }
            }
        }
        barrier();
    }
    for (uint j = 0u; j < PIXELS_PER_LANE; ++j) {
        if (px[j] < 0) continue;
        uint pixel = uint(py[j]) * params.width + uint(px[j]);
        visibility[pixel] = key[j];
        if (countHits) hitCount[pixel] += hits[j];
    }
}

void main()
{
    uint lane = gl_LocalInvocationID.x;
    uint activeCount = counters[COUNTER_ACTIVE_TILES];
    for (uint index = gl_WorkGroupID.x; index < activeCount; index += params.rasterGroups) {
        uint tile = activeTiles[index];
        uint begin = tile == 0u ? 0u : min(binEnd(tile - 1u), params.binCapacity);
        uint end = min(binEnd(tile), params.binCapacity);
        if (begin < end) rasterTile(tile, lane, begin, end);
    }
}

