// raster_tiles.comp - stage `raster_tiles`: the groups walk the active screen tiles (TILE_SIZE x
// TILE_SIZE pixels with big triangles in their bin, listed by scan_blocks). For each tile the group
// walks the bin in batches of LANES refs: each invocation sets one triangle up into shared memory, then
// every invocation tests its pixels against the whole batch, keeping the smallest visibility key of each
// of their samples in a register (one build per sample count, SPEC_SAMPLES, so the keys stay registers).
// The tile's pixels belong to this group alone, so nothing is resolved with atomics: each key starts
// from what setup's small triangles left in the visibility buffer and is stored once at the end. A
// triangle whose depth bound lies behind every sample's key of a pixel is skipped there without a
// coverage test (early depth; off while counting hits, which must see every triangle).
// LANES is specialization constant 0: TILE_SIZE^2 on a GPU (one pixel per invocation, as the CUDA
// twin), the SIMD width on a CPU device, where one group is one SIMD bundle of invocations, each owning
// TILE_SIZE^2 / LANES pixels of the tile.
// groups = RasterParams.rasterGroups: one per work item of the previous frame. On a GPU a work item is an
// active tile. On a CPU device (RASTER_TILES_CHUNKED, a second module, RasterParams.rasterChunk) it is
// a chunk of at most rasterChunk entries of an active tile's bin, so that no invocation runs into
// llvmpipe's loop limiter (65,535 loop iterations per invocation, after which every loop silently
// ends); the chunks of one tile merge their keys with 64-bit atomicMin, and the host draws a frame
// again if it had more work items than groups. Group g takes the items g, g + rasterGroups, ...
// The CPU build shares nothing between its invocations: every invocation walks the whole chunk, entry
// by entry, fetching each triangle's record (setup's CPU build stores every big triangle) and the tile's
// keys through texel views (VIEW_*), which llvmpipe gathers as vectors, where a storage-buffer or
// shared-memory load at an index it cannot prove uniform is a loop over the SIMD lanes. So it needs no
// shared memory and no barrier (a barrier makes every invocation a coroutine there), and it steps the
// exact edge functions from pixel to pixel by additions.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "raster_shared.h"
#include "buffers.glsl"

#ifndef RASTER_TILES_CHUNKED
#define RASTER_TILES_CHUNKED 0
#endif

layout(local_size_x_id = 0) in;
// Whether the alpha test of MASK materials is built in (SPEC_MATERIALS).
layout(constant_id = SPEC_MATERIALS) const bool MATERIALS = true;
// Samples per pixel (SPEC_SAMPLES, RasterParams.sampleCount): sizes each invocation's array of keys.
layout(constant_id = SPEC_SAMPLES) const uint SAMPLES = 1u;
#if RASTER_TILES_CHUNKED
// Whether the frame counts hits (SPEC_COUNT_HITS: DEBUG_COUNT_HITS of RasterParams.debugFlags).
layout(constant_id = SPEC_COUNT_HITS) const bool COUNT_HITS = false;
#endif
#define LANES gl_WorkGroupSize.x
#define PIXELS_PER_LANE (TILE_SIZE * TILE_SIZE / LANES)  // 1 on a GPU, at most MAX_PIXELS_PER_LANE

#if !RASTER_TILES_CHUNKED
shared TriSetup tris[TILE_SIZE * TILE_SIZE];
shared uint minDepth[TILE_SIZE * TILE_SIZE];
shared uint masked[TILE_SIZE * TILE_SIZE];  // TRI_FLAG_ALPHA_MASK of each: coverage needs the alpha test
#endif

// Resolves the bin entries [begin, end) of one screen tile into its pixels' SAMPLES samples each.
// Uniform across the group. Sample s of the invocation's j-th pixel has its key at j * SAMPLES + s.
#if RASTER_TILES_CHUNKED
// `merge`: other groups resolve other chunks of the tile's bin, so the keys merge with atomicMin.
void rasterTile(uint tile, uint lane, uint begin, uint end, bool merge)
#else
void rasterTile(uint tile, uint lane, uint begin, uint end)
#endif
{
#if RASTER_TILES_CHUNKED
    bool countHits = COUNT_HITS;
#else
    bool countHits = (params.debugFlags & DEBUG_COUNT_HITS) != 0u;
#endif
    int px[MAX_PIXELS_PER_LANE], py[MAX_PIXELS_PER_LANE];
    uint64_t key[MAX_PIXELS_PER_LANE * SAMPLES];
    uint hits[MAX_PIXELS_PER_LANE * SAMPLES];
    uint farthest[MAX_PIXELS_PER_LANE];  // the largest depth bits among the pixel's keys
    float depth[SAMPLES];
    for (uint j = 0u; j < PIXELS_PER_LANE; ++j) {
        uint p = lane + j * LANES;  // this invocation's j-th pixel of the tile
        px[j] = int(tile % params.tilesX) * TILE_SIZE + int(p % uint(TILE_SIZE));
        py[j] = int(tile / params.tilesX) * TILE_SIZE + int(p / uint(TILE_SIZE));
        bool mine =
            p < uint(TILE_SIZE * TILE_SIZE) && uint(px[j]) < params.width && uint(py[j]) < params.height;
        uint pixel = mine ? uint(py[j]) * params.width + uint(px[j]) : 0u;
        farthest[j] = 0u;
        for (uint s = 0u; s < SAMPLES; ++s) {
#if RASTER_TILES_CHUNKED
            key[j * SAMPLES + s] = mine ? fetchKey(s * params.samplePlane + pixel) : ~uint64_t(0);
#else
            key[j * SAMPLES + s] = mine ? visibility[s * params.samplePlane + pixel] : ~uint64_t(0);
#endif
            farthest[j] = max(farthest[j], uint(key[j * SAMPLES + s] >> 32));
            hits[j * SAMPLES + s] = 0u;
        }
        if (!mine) px[j] = -1;
    }
#if RASTER_TILES_CHUNKED
    // A CPU device: entry by entry, every invocation the same triangle. Loops test at the end there:
    // llvmpipe checks for live lanes at the end of a loop's body, so a test at the top costs one more
    // turn of the whole body with every lane masked off. The caller passes begin < end.
    uint entry = begin;
    do {
        uint ref = texelFetch(binEntriesView, int(entry)).x;
        ++entry;
        uint slot = ref & ~BIN_REF_RECORD;
        bool ok = (ref & BIN_REF_RECORD) != 0u && slot < params.setupCapacity;
        TriSetup tri = fetchSetupRecord(min(slot, params.setupCapacity - 1u));
        uint triMinDepth = ok ? triangleMinDepthBits(tri) : 0xFFFFFFFFu;
        uint id = setupTriId(tri);
        // Lines have no alpha test (and no triangle flags).
        bool triMasked = MATERIALS && ok && params.materialCount != 0u && id < params.triangleCount &&
                         (triFlags[id] & TRI_FLAG_ALPHA_MASK) != 0u;
        if (triMinDepth == 0xFFFFFFFFu) continue;
#if RASTER_METHOD == RASTER_FIXED8 || RASTER_METHOD == RASTER_FIXED4
        if (SAMPLES == 1u) {
            // The exact edge functions (rasterSample's) stepped from pixel to pixel by additions
            // (edgeStepX, edgeStepY): the invocation's pixels lie in rows of TILE_SIZE / LANES, LANES
            // apart (pixel j is p = lane + j LANES of the tile; LANES divides TILE_SIZE on a CPU device).
            ivec2 v0 = setupV0(tri), v1 = setupV1(tri), v2 = setupV2(tri);
            int64_t bias0 = edgeBias(v1, v2), bias1 = edgeBias(v2, v0), bias2 = edgeBias(v0, v1);
            ivec2 first = samplePosition(1u, 0u, int(tile % params.tilesX) * TILE_SIZE + int(lane),
                                         int(tile / params.tilesX) * TILE_SIZE);
            int64_t row0 = edgeFunction(v1, v2, first), row1 = edgeFunction(v2, v0, first);
            int64_t row2 = edgeFunction(v0, v1, first);
            // Next pixel of the row: LANES pixels right; next row: one pixel down.
            int64_t columnStep = int64_t(SUBPIXEL_SCALE) * int64_t(LANES), rowStep = int64_t(SUBPIXEL_SCALE);
            int64_t dx0 = edgeStepX(v1, v2) * columnStep, dx1 = edgeStepX(v2, v0) * columnStep;
            int64_t dx2 = edgeStepX(v0, v1) * columnStep;
            int64_t dy0 = edgeStepY(v1, v2) * rowStep, dy1 = edgeStepY(v2, v0) * rowStep;
            int64_t dy2 = edgeStepY(v0, v1) * rowStep;
            for (uint row = 0u; row < uint(TILE_SIZE); ++row) {
                int64_t e0 = row0, e1 = row1, e2 = row2;
                for (uint c = 0u; c < uint(TILE_SIZE) / LANES; ++c) {
                    uint j = row * (uint(TILE_SIZE) / LANES) + c;
                    if (px[j] >= 0 && (countHits || farthest[j] >= triMinDepth) && e0 >= bias0 &&
                        e1 >= bias1 && e2 >= bias2 && (!triMasked || alphaMaskCovers(id, px[j], py[j]))) {
                        key[j] = min(key[j], packVisibility(depthFromEdges(tri, e1, e2), id));
                        farthest[j] = uint(key[j] >> 32);
                        ++hits[j];
                    }
                    e0 += dx0;
                    e1 += dx1;
                    e2 += dx2;
                }
                row0 += dy0;
                row1 += dy1;
                row2 += dy2;
            }
            continue;
        }
#endif
        for (uint j = 0u; j < PIXELS_PER_LANE; ++j) {
            if (px[j] < 0 || (!countHits && farthest[j] < triMinDepth)) continue;
            if (SAMPLES == 1u) {
                if (methodPixel(tri, px[j], py[j], depth[0]) &&
                    (!triMasked || alphaMaskCovers(id, px[j], py[j]))) {
                    key[j * SAMPLES] = min(key[j * SAMPLES], packVisibility(depth[0], id));
                    farthest[j] = uint(key[j * SAMPLES] >> 32);
                    ++hits[j * SAMPLES];
                }
                continue;
            }
            if (!methodTouchesPixels(tri, px[j], py[j], px[j], py[j], params.sampleBounds)) continue;
            uint mask = 0u;
            for (uint s = 0u; s < SAMPLES; ++s)
                if (methodSample(tri, samplePosition(SAMPLES, s, px[j], py[j]), depth[s]))
                    mask |= 1u << s;
            if (mask == 0u || (triMasked && !alphaMaskCovers(id, px[j], py[j]))) continue;
            farthest[j] = 0u;
            for (uint s = 0u; s < SAMPLES; ++s) {
                if ((mask & (1u << s)) != 0u) {
                    key[j * SAMPLES + s] = min(key[j * SAMPLES + s], packVisibility(depth[s], id));
                    ++hits[j * SAMPLES + s];
                }
                farthest[j] = max(farthest[j], uint(key[j * SAMPLES + s] >> 32));
            }
        }
    } while (entry < end);
#else
    for (uint base = begin; base < end; base += LANES) {
        uint count = min(end - base, LANES);
        if (lane < count) {
            TriSetup t;
            bool ok = loadBinTriangle(binEntries[base + lane], t);
            tris[lane] = t;
            minDepth[lane] = ok ? triangleMinDepthBits(t) : 0xFFFFFFFFu;
            if (MATERIALS) {
                // Lines have no alpha test (and no triangle flags).
                bool maskable = ok && params.materialCount != 0u && setupTriId(t) < params.triangleCount;
                masked[lane] = maskable ? (triFlags[setupTriId(t)] & TRI_FLAG_ALPHA_MASK) : 0u;
            }
        }
        barrier();
        for (uint j = 0u; j < PIXELS_PER_LANE; ++j) {
            if (px[j] < 0) continue;
            for (uint k = 0u; k < count; ++k) {
                // Early depth: every sample of the pixel already holds something nearer.
                if (minDepth[k] == 0xFFFFFFFFu || (!countHits && farthest[j] < minDepth[k])) continue;
                uint id = setupTriId(tris[k]);
                if (SAMPLES == 1u) {
                    if (methodPixel(tris[k], px[j], py[j], depth[0]) &&
                        (!MATERIALS || masked[k] == 0u || alphaMaskCovers(id, px[j], py[j]))) {
                        key[j * SAMPLES] = min(key[j * SAMPLES], packVisibility(depth[0], id));
                        farthest[j] = uint(key[j * SAMPLES] >> 32);
                        ++hits[j * SAMPLES];
                    }
                    continue;
                }
                // One test of the pixel's sample rectangle rejects most uncovered pixels at the cost of
                // one sample's edge functions.
                if (!methodTouchesPixels(tris[k], px[j], py[j], px[j], py[j], params.sampleBounds))
                    continue;
                uint mask = 0u;
                for (uint s = 0u; s < SAMPLES; ++s)
                    if (methodSample(tris[k], samplePosition(SAMPLES, s, px[j], py[j]), depth[s]))
                        mask |= 1u << s;
                // The alpha test runs once per pixel, at its centre, as hardware shades a pixel.
                if (mask == 0u || (MATERIALS && masked[k] != 0u && !alphaMaskCovers(id, px[j], py[j])))
                    continue;
                farthest[j] = 0u;
                for (uint s = 0u; s < SAMPLES; ++s) {
                    if ((mask & (1u << s)) != 0u) {
                        key[j * SAMPLES + s] = min(key[j * SAMPLES + s], packVisibility(depth[s], id));
                        ++hits[j * SAMPLES + s];
                    }
                    farthest[j] = max(farthest[j], uint(key[j * SAMPLES + s] >> 32));
                }
            }
        }
        barrier();
    }
#endif
    for (uint j = 0u; j < PIXELS_PER_LANE; ++j) {
        if (px[j] < 0) continue;
        uint pixel = uint(py[j]) * params.width + uint(px[j]);
        for (uint s = 0u; s < SAMPLES; ++s) {
#if RASTER_TILES_CHUNKED
            if (merge) {
                atomicMin(visibility[s * params.samplePlane + pixel], key[j * SAMPLES + s]);
                if (countHits) atomicAdd(hitCount[s * params.samplePlane + pixel], hits[j * SAMPLES + s]);
                continue;
            }
#endif
            visibility[s * params.samplePlane + pixel] = key[j * SAMPLES + s];
            if (countHits) hitCount[s * params.samplePlane + pixel] += hits[j * SAMPLES + s];
        }
    }
}

void main()
{
    uint lane = gl_LocalInvocationID.x;
    uint activeCount = counters[COUNTER_ACTIVE_TILES];
#if RASTER_TILES_CHUNKED
    uint chunks = rasterChunksPerTile(params.rasterChunk, counters[COUNTER_MAX_BIN]);
    uint items = activeCount * chunks;
    uint item = gl_WorkGroupID.x;
    if (item < items) do {  // tested at the end, as rasterTile's loops
        uint tile = activeTiles[item / chunks];
        uint begin = tile == 0u ? 0u : min(binEnd(tile - 1u), params.binCapacity);
        uint end = min(binEnd(tile), params.binCapacity);
        begin = min(end, begin + (item % chunks) * params.rasterChunk);
        end = min(end, begin + params.rasterChunk);
        if (begin < end) rasterTile(tile, lane, begin, end, chunks > 1u);
        item += params.rasterGroups;
    } while (item < items);
#else
    for (uint index = gl_WorkGroupID.x; index < activeCount; index += params.rasterGroups) {
        uint tile = activeTiles[index];
        uint begin = tile == 0u ? 0u : min(binEnd(tile - 1u), params.binCapacity);
        uint end = min(binEnd(tile), params.binCapacity);
        if (begin < end) rasterTile(tile, lane, begin, end);
    }
#endif
}
