// buffers.glsl - descriptor set 0 as every stage sees it: the bindings of raster_shared.h (BUF_*),
// mergeFragment (the small-triangle write), and the loads of a triangle that several stages share.
// Each stage includes this after raster_shared.h; unused bindings cost nothing in the shader.
#ifndef RASTER_BUFFERS_GLSL
#define RASTER_BUFFERS_GLSL

#extension GL_EXT_shader_atomic_int64 : require

layout(std140, set = 0, binding = BUF_PARAMS) uniform ParamsBlock { RasterParams params; };
layout(std430, set = 0, binding = BUF_POSITIONS) readonly buffer PositionsBlock { vec4 positions[]; };
layout(std430, set = 0, binding = BUF_NORMALS) readonly buffer NormalsBlock { vec4 normals[]; };
layout(std430, set = 0, binding = BUF_COLORS) readonly buffer ColorsBlock { vec4 colors[]; };
layout(std430, set = 0, binding = BUF_INDICES) readonly buffer IndicesBlock { uint indices[]; };
layout(std430, set = 0, binding = BUF_TRI_FLAGS) readonly buffer TriFlagsBlock { uint triFlags[]; };
layout(std430, set = 0, binding = BUF_CLIP_POS) buffer ClipPosBlock { vec4 clipPos[]; };
layout(std430, set = 0, binding = BUF_SETUP_TRIS) buffer SetupTrisBlock { TriSetup setupTris[]; };
layout(std430, set = 0, binding = BUF_PIECES) buffer PiecesBlock { uvec2 pieces[]; };
layout(std430, set = 0, binding = BUF_TILE_BINS) buffer TileBinsBlock { uint tileBins[]; };
layout(std430, set = 0, binding = BUF_SCAN_SUMS) buffer ScanSumsBlock { uint scanSums[]; };
layout(std430, set = 0, binding = BUF_BIN_ENTRIES) buffer BinEntriesBlock { uint binEntries[]; };
layout(std430, set = 0, binding = BUF_ACTIVE_TILES) buffer ActiveTilesBlock { uint activeTiles[]; };
layout(std430, set = 0, binding = BUF_COUNTERS) buffer CountersBlock { uint counters[]; };
layout(std430, set = 0, binding = BUF_VISIBILITY) buffer VisibilityBlock { uint64_t visibility[]; };
layout(std430, set = 0, binding = BUF_FRAMEBUFFER) buffer FramebufferBlock { uint framebuffer[]; };
layout(std430, set = 0, binding = BUF_HIT_COUNT) buffer HitCountBlock { uint hitCount[]; };

// The depth test and id write of one covered pixel in a single 64-bit atomicMin (see packVisibility),
// plus the debug hit count. Used by setup for small triangles; raster_tiles owns its pixels and writes
// them plainly.
void mergeFragment(uint pixel, float depth, uint id)
{
    atomicMin(visibility[pixel], packVisibility(depth, id));
    if ((params.debugFlags & DEBUG_COUNT_HITS) != 0u) atomicAdd(hitCount[pixel], 1u);
}

// Clip positions of input triangle `tri`'s vertices, as setup sees them (setupClipPosition). False when
// an index is out of range.
bool loadClipTriangle(uint tri, out vec4 c0, out vec4 c1, out vec4 c2)
{
    c0 = c1 = c2 = vec4(0.0f);
    uint i0 = indices[3u * tri];
    uint i1 = indices[3u * tri + 1u];
    uint i2 = indices[3u * tri + 2u];
    if (max(i0, max(i1, i2)) >= params.vertexCount) return false;
    bool stored = params.transformInSetup == 0u;
    c0 = setupClipPosition(params, positions[i0], stored ? clipPos[i0] : vec4(0.0f));
    c1 = setupClipPosition(params, positions[i1], stored ? clipPos[i1] : vec4(0.0f));
    c2 = setupClipPosition(params, positions[i2], stored ? clipPos[i2] : vec4(0.0f));
    return true;
}

// The big triangle a bin ref names: a stored record, or an unclipped input triangle set up again from
// the scene exactly as setup did (same function, same bits; setup already culled it, so facing needs
// no second look). False for a ref setup would never have written (a slot of an overflowed frame).
bool loadBinTriangle(uint ref, out TriSetup t)
{
    if ((ref & BIN_REF_RECORD) != 0u) {
        t = setupTris[min(ref & ~BIN_REF_RECORD, params.setupCapacity - 1u)];
        return (ref & ~BIN_REF_RECORD) < params.setupCapacity;
    }
    if (ref >= params.triangleCount) {
        t = setupTris[0];
        return false;
    }
    vec4 c0, c1, c2;
    if (!loadClipTriangle(ref, c0, c1, c2)) {
        t = setupTris[0];
        return false;
    }
    return setupTriangle(c0, c1, c2, ref, true, CULL_NONE, params.width, params.height, t);
}

// End of screen tile `tile`'s bin in binEntries, once bin_fill has run (its start is the previous tile's
// end): the tile's offset within its scan block, advanced by every slot bin_fill took, plus the block's
// base from scan_sums.
uint binEnd(uint tile)
{
    return scanSums[tile / uint(SCAN_GROUP_SIZE)] + tileBins[tile];
}

#endif  // RASTER_BUFFERS_GLSL
