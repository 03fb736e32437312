// buffers.glsl - descriptor set 0 as every stage sees it: the bindings of raster_shared.h (BUF_*), and
// mergeFragment, the one place a covered pixel is written. Each stage includes this after
// raster_shared.h; unused bindings cost nothing in the shader.
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
layout(std430, set = 0, binding = BUF_BIG_TRIS) buffer BigTrisBlock { uint bigTris[]; };
layout(std430, set = 0, binding = BUF_BIG_OFFSETS) buffer BigOffsetsBlock { uint bigOffsets[]; };
layout(std430, set = 0, binding = BUF_SCAN_SUMS) buffer ScanSumsBlock { uint scanSums[]; };
layout(std430, set = 0, binding = BUF_COUNTERS) buffer CountersBlock { uint counters[]; };
layout(std430, set = 0, binding = BUF_VISIBILITY) buffer VisibilityBlock { uint64_t visibility[]; };
layout(std430, set = 0, binding = BUF_FRAMEBUFFER) buffer FramebufferBlock { uint framebuffer[]; };
layout(std430, set = 0, binding = BUF_HIT_COUNT) buffer HitCountBlock { uint hitCount[]; };

// The depth test and id write of one covered pixel in a single 64-bit atomicMin (see packVisibility),
// plus the debug hit count. Used by setup (small triangles) and raster_tiles.
void mergeFragment(uint pixel, float depth, uint id)
{
    atomicMin(visibility[pixel], packVisibility(depth, id));
    if ((params.debugFlags & DEBUG_COUNT_HITS) != 0u) atomicAdd(hitCount[pixel], 1u);
}

#endif  // RASTER_BUFFERS_GLSL
