// raster_shared.h - the one header family shared by host C++, CUDA and GLSL; this is its umbrella.
//
// Holds everything both ports must agree on bit for bit. This file has the buffer bindings, counters,
// constants and the parameter and record structs; the maths of each stage is in common/shared/:
//   lang.h         type names, built-ins and macros that make one file valid in three languages
//   fixed_point.h  deterministic reciprocals (no float division whose bits matter)
//   vertex.h       stage vertex: clip and view positions with a fixed summation order
//   clip.h         stage setup, first half: outcodes, frustum cull, near/far/guard-band clipping
//   setup.h        stage setup, second half: snapping to n.8 fixed point, edge functions, top-left rule
//   raster.h       raster stages: sample patterns, sample coverage and depth, points, the visibility key
//   texture.h      textures: level of detail, level and texel selection, wrap modes, filters
//   shade.h        stage shade: perspective-correct barycentrics and derivatives, lighting, sRGB
//   cluster.h      stage clusters: whole clusters culled only where setup would cull every triangle
//   ao.h           stages ao_gbuffer, ao, ao_denoise: ground-truth-checked GTAO ambient occlusion
//   stages.h       the stage table: every stage's id, name, group size and launch (C++ and CUDA only)
// The CUDA kernels and the GLSL compute shaders include only this file; they are thin shells that index
// threads, load buffers, call these functions and do the atomics.
//
// Rules that keep every file of the family valid in three languages (their reasons in
// docs/shared-header.md): include guards (glslang has no '#pragma once'), GLSL type names, no swizzles,
// no constructors or aggregate initialisers for structs, arrays passed through SR_ARRAY_INOUT, and every
// float expression whose bits matter across backends stored in a `precise` variable (GLSL NoContraction;
// CUDA is built with --fmad=false and the host with -ffp-contract=off, so no backend fuses a*b+c). Float
// literals carry an 'f' so that C++ and CUDA never widen an expression to double where GLSL stays in
// float. glslang resolves the includes (GL_GOOGLE_include_directive).
#ifndef RASTER_SHARED_H
#define RASTER_SHARED_H

#include "shared/lang.h"

SR_NAMESPACE_BEGIN

// ---------------------------------------------------------------------------------------------------
// Buffer bindings. Vulkan: descriptor binding numbers of set 0. CUDA and host: indices of the device
// buffer table. Same numbers, same names everywhere.
#define BUF_PARAMS 0         // RasterParams (uniform buffer in Vulkan, kernel argument in CUDA)
#define BUF_POSITIONS 1      // vec4 per vertex: world-space position, w = 1
#define BUF_NORMALS 2        // vec4 per vertex: world-space normal, w = 0
#define BUF_COLORS 3         // vec4 per vertex: linear RGBA (only read when RasterParams.hasColors)
#define BUF_INDICES 4        // uint, 3 per triangle, already validated on the host
#define BUF_TRI_FLAGS 5      // uint per triangle: TRI_FLAG_* bits
#define BUF_CLIP_POS 6       // vec4 per vertex: clip-space position (vertex stage output, read by setup)
#define BUF_SETUP_TRIS 7     // TriSetup per clipped big sub-triangle (BIN_REF_RECORD refs)
#define BUF_PIECES 8         // uvec2 per piece of a big triangle: bin ref, first tile index in its tile rect
#define BUF_TILE_BINS 9      // uint per screen tile: bin count -> offset in its scan block -> end (binEnd)
#define BUF_SCAN_SUMS 10     // uint per scan block of tiles: block total, scanned to its base offset
#define BUF_BIN_ENTRIES 11   // uint bin refs, grouped by screen tile (the tile's range is in BUF_TILE_BINS)
#define BUF_ACTIVE_TILES 12  // uint: the screen tiles whose bin is not empty, in no particular order
#define BUF_COUNTERS 13      // uint[COUNTER_WORDS]: list lengths and statistics, and their shards
#define BUF_VISIBILITY \
    14  // uint64 per sample, sample s of pixel p at s * samplePlane + p: depth bits << 32 |
        // primitive id, ~0 = empty
#define BUF_FRAMEBUFFER 15  // uint per output pixel: RGBA8, sRGB-encoded, resolved colour; then stage aovs's
                            // arrays (shared/aovs.h)
#define BUF_HIT_COUNT 16    // uint per sample: covering triangles (written only with DEBUG_COUNT_HITS)
#define BUF_MATERIALS 17    // GpuMaterial per scene material (RasterParams.materialCount of them)
#define BUF_TRI_MATERIALS \
    18                    // uint per primitive id (triangles, lines, points): its material (if materialCount)
#define BUF_TEXCOORDS 19  // vec4 per vertex: (u, v) of TEXCOORD_0, then (u, v) of TEXCOORD_1
#define BUF_TEXTURES 20   // GpuTexture per texture
#define BUF_TEXELS 21     // uint per texel, RGBA8 (R in the low byte): every level of every texture
#define BUF_SRGB_TABLE \
    22  // float[256]: the linear value of each sRGB-encoded byte (decode table); in Vulkan a uniform
        // buffer (vec4[64], std140), which keeps the storage buffers within lavapipe's 32 per stage
#define BUF_POINTS 23      // uint per point: its vertex (point k is primitive triangleCount + lineCount + k)
#define BUF_LINES \
    24  // uint pair per line segment: its two vertices (segment k is primitive triangleCount + k)
// Tessellation (RasterParams.tessMode != TESS_OFF, common/shared/tessellate.h). The scene's vertices
// stay at the head of the per-vertex buffers and the generated ones follow them; the generated triangles
// replace the scene's in BUF_INDICES, BUF_TRI_FLAGS and BUF_TRI_MATERIALS, so every later stage draws
// them unchanged. The scene's triangles live on here:
#define BUF_TESS_SOURCE 25     // TessSource per scene triangle: corners, flags
#define BUF_TESS_COUNTS 26     // uvec4 per scene triangle: vertices, triangles -> local offsets; factors; state
#define BUF_TESS_SUMS 27       // uvec4: [0] the frame's totals; [1 + b] scan block b's totals -> its base
#define BUF_TESS_IDS 28        // uint per generated triangle: its scene triangle (the id AOV maps through it)
#define BUF_TESS_MATERIALS 29  // uint per scene primitive: its material (only when materialCount > 0)
// Clusters (RasterParams.clusterCount > 0, common/shared/cluster.h): the scene's triangles in clusters of
// at most CLUSTER_MAX_VERTICES vertices and CLUSTER_MAX_TRIANGLES triangles, built at load time.
#define BUF_CLUSTERS 30      // GpuCluster per cluster
#define BUF_CLUSTER_DATA 31  // uint: with level of detail first CLUSTER_LOD_WORDS per cluster (cluster.h);
                             // then each cluster's vertex list (scene vertices), then two words per
                             // triangle: its scene triangle id, its local corners (8 bits each)
#define BUF_LOD_CUT 32       // uint: the clusters the level-of-detail cut draws (COUNTER_LOD_CLUSTERS of
                             // them, in no particular order; written by stage lod_cut)
#define BUF_AO 33  // float planes of samplePlane entries (RasterParams.aoMode != AO_OFF, shared/ao.h):
                   // AO_PLANE_RAW, AO_PLANE_DENOISED, AO_PLANE_DISTANCE, AO_PLANE_NORMAL (3 planes)
#define BUF_COUNT 34
// CPU devices (lavapipe) only: read-only views of buffers above as uniform texel buffers, bound after
// them. llvmpipe loads from a storage buffer at an address it cannot prove uniform one lane at a time (a
// loop with a branch per lane and component), but fetches texels of a buffer view with vector gathers;
// the CPU builds of the stages (SR_CPU_BUILD) read their hot data through these.
#define VIEW_SETUP_TRIS 34     // BUF_SETUP_TRIS as RGBA32UI, three texels per TriSetup
#define VIEW_BIN_ENTRIES 35    // BUF_BIN_ENTRIES as R32UI
#define VIEW_VISIBILITY 36     // BUF_VISIBILITY as RG32UI: a key's low word (the id), then its high word
#define VIEW_INDICES 37        // BUF_INDICES as R32UI
#define VIEW_POSITIONS 38      // BUF_POSITIONS as RGBA32UI (float bits: the fetch is exact)
#define VIEW_NORMALS 39        // BUF_NORMALS as RGBA32UI
#define VIEW_COLORS 40         // BUF_COLORS as RGBA32UI
#define VIEW_TEXCOORDS 41      // BUF_TEXCOORDS as RGBA32UI
#define VIEW_TRI_MATERIALS 42  // BUF_TRI_MATERIALS as R32UI
#define VIEW_MATERIALS 43      // BUF_MATERIALS as RGBA32UI, six texels per GpuMaterial
#define VIEW_TEXTURES 44       // BUF_TEXTURES as RGBA32UI, two texels per GpuTexture
#define VIEW_TEXELS 45         // BUF_TEXELS as R32UI
#define VIEW_SRGB_TABLE 46     // BUF_SRGB_TABLE as R32UI (float bits)
#define VIEW_AO 47             // BUF_AO as R32UI (float bits): the AO stages' CPU builds read their planes
#define VIEW_COUNT 14

// Counters in BUF_COUNTERS, cleared by the clear stage every frame. The list counters count every
// append, also past the capacity: the host compares them with the capacities, grows and redraws.
#define COUNTER_SETUP 0          // TriSetup records appended (clipped big sub-triangles)
#define COUNTER_SMALL 1          // small (sub-)triangles rasterized by setup itself
#define COUNTER_BIG 2            // big (sub-)triangles binned to screen tiles
#define COUNTER_PIECES 3         // pieces appended to BUF_PIECES
#define COUNTER_BIN_ENTRIES 4    // (big triangle, screen tile) bin entries, written by scan_sums
#define COUNTER_CULLED 5         // input triangles that produced nothing to rasterize
#define COUNTER_CLIPPED 6        // input triangles that went through the polygon clipper
#define COUNTER_INVALID 7        // input triangles dropped for NaN/Inf positions or bad indices
#define COUNTER_WORK_OVERFLOW 8  // non-zero when the pieces or bin entries of one frame pass 2^31
#define COUNTER_ACTIVE_TILES 9   // entries of BUF_ACTIVE_TILES, appended by scan_blocks
#define COUNTER_SPLIT 10         // big triangles of more than one piece (their pieces need bin_count)
#define COUNTER_POINTS 11        // points rasterized (not culled) by setup
#define COUNTER_LINES 12         // line segments set up (not culled, not clipped away) by setup
#define COUNTER_MAX_BIN 13       // the largest bin of a screen tile (written only when rasterChunk != 0)
#define COUNTER_CLUSTERS_CULLED 14  // clusters culled whole by stage clusters (their triangles: COUNTER_CULLED)
#define COUNTER_LOD_TRIANGLES 15    // triangles of the clusters the level-of-detail cut draws (lodScale > 0)
#define COUNTER_LOD_CLUSTERS 16     // entries of BUF_LOD_CUT: the clusters the cut draws
#define COUNTER_COUNT 17
// The statistics that setup and clusters count for nearly every primitive are not added to the words
// above but to COUNTER_SHARDS copies of them, COUNTER_SHARD_STRIDE words (a 128-byte cache line) apart
// after the first line: a warp (subgroup) adds its sums to the copy of its index modulo COUNTER_SHARDS, and
// the host adds the copies to the words above when it reads them back (foldCounters). One word served
// every warp's adds of a frame, one after another in one L2 slice (docs/benchmark.md, "Sixth pass").
// BUF_COUNTERS holds COUNTER_WORDS words; the clear stage zeroes them all.
#define COUNTER_SHARDS 64
#define COUNTER_SHARD_STRIDE 32
#define COUNTER_SHARD_BASE 32
#define COUNTER_WORDS (COUNTER_SHARD_BASE + COUNTER_SHARDS * COUNTER_SHARD_STRIDE)
// Copy `shard` (any uint: taken modulo COUNTER_SHARDS) of statistic `counter`.
#define COUNTER_SHARD_WORD(shard, counter) \
    (COUNTER_SHARD_BASE + ((shard) & (COUNTER_SHARDS - 1)) * COUNTER_SHARD_STRIDE + (counter))

// Stages: their ids (STAGE_*), names, group sizes and launch kinds are the stage table,
// shared/stages.h (C++ and CUDA only, included at the end of this file).

#define GROUP_SIZE 128       // threads per group of the 1D stages
#define SHADE_CPU_PIXELS 4   // output pixels per invocation of shade's CPU build (compute_glsl/shade.comp)
#define CLEAR_SPAN 8         // elements each clear thread resets, GROUP_SIZE apart
#define SCAN_GROUP_SIZE 256  // elements per scan block (one per thread)
#define TILE_SIZE 8          // screen tile edge in pixels; a raster_tiles group has TILE_SIZE^2 threads
#define SMALL_TRI_SPAN 12    // triangles whose pixel bbox is at most this wide and high are small
#define TILES_PER_PIECE 16   // bbox tiles one bin_count / bin_fill thread walks for a big triangle...
#define MAX_PIECES 1024      // ...unless that would make more pieces than this; then pieces grow
#define CLUSTER_MAX_VERTICES 64    // vertices per cluster: a warp transforms them in two rounds
#define CLUSTER_MAX_TRIANGLES 124  // triangles per cluster (as hardware mesh shaders)
#define CLUSTER_LANES 32           // invocations per cluster in stage clusters (a warp on NVIDIA)
// The vertices each of a cluster's CLUSTER_LANES invocations takes (lane, lane + CLUSTER_LANES, ...).
#define CLUSTER_VERTEX_ROUNDS ((CLUSTER_MAX_VERTICES + CLUSTER_LANES - 1) / CLUSTER_LANES)
#define CLUSTERS_PER_GROUP 4       // clusters per clusters group: CLUSTER_LANES x this invocations
#define LOD_CLUSTER_GROUPS 2048    // clusters groups with level of detail on a GPU (they loop over the cut)
#define CLUSTER_PLANE_COUNT 10     // RasterParams.clusterPlanes the culling tests (shared/cluster.h)
#define CLUSTER_PLANE_W 10         // RasterParams.clusterPlanes[10]: clip w as a plane (not normalised)
// Ambient occlusion (shared/ao.h).
#define AO_OFF 0u        // no ambient occlusion
#define AO_GTAO 1u       // GTAO over the visibility buffer (stages ao_gbuffer, ao, ao_denoise)
#define AO_REFERENCE 2u  // ray-cast ground truth from the host (host/ao/ao_reference.h), shaded by shade
// BUF_AO's planes, the ones shade reads first, so that the host transfers only the head of the buffer
// (the plane it reads back, the plane --ao reference uploads).
#define AO_PLANE_RAW 0u       // BUF_AO: GTAO's visibility (stage ao; --ao reference: from the host)
#define AO_PLANE_DENOISED 1u  // BUF_AO: the same after stage ao_denoise
#define AO_PLANE_DISTANCE 2u  // BUF_AO: view distance (-z) of the pixel's surface, 0 where it has none
#define AO_PLANE_NORMAL 3u    // BUF_AO: its unit view-space normal, x, y, z in planes 3, 4, 5 (ao_gbuffer)
#define AO_PLANES 6u
#define AO_MAX_SLICES 16u
#define AO_MAX_STEPS 32u
#define AO_MAX_RADIUS_PX 512.0f  // the screen radius GTAO searches is clamped to this many raster pixels
#define AO_FALLOFF 0.2f          // a sample's weight falls from 1 to 0 over the outer fifth of the radius
#define AO_DENOISE_PLANE 0.02f   // ao_denoise averages neighbours within this x distance of the pixel's plane
#define MIN_RASTER_LANES 8   // raster_tiles invocations per group on a CPU (TILE_SIZE^2 on a GPU)
// Bin entries per raster_tiles work item on a CPU device at one sample per pixel. llvmpipe 22.3 ends
// every loop of a shader invocation after 65,535 turns in all (its loop limiter, docs/benchmark.md
// "Loops on a CPU device"), and one entry costs an invocation about 26 turns at 1x (the alpha test's
// texture lookups hold no loop in the CPU build), so a group resolves at most this many entries of a
// tile (RASTER_CPU_CHUNK / msaa with more samples); the rest of the tile's bin goes to further groups,
// merged with 64-bit atomicMin.
#define RASTER_CPU_CHUNK 1024
#define MAX_PIXELS_PER_LANE \
    (TILE_SIZE * TILE_SIZE / MIN_RASTER_LANES)  // pixels a raster_tiles invocation owns
#define BIN_REF_RECORD 0x80000000u  // bin ref bit: the rest indexes BUF_SETUP_TRIS, else an input triangle
#define PIECE_COUNTED 0x80000000u   // piece first-tile bit: setup already counted the piece's tiles
#define SUBPIXEL_BITS 8             // vertices snap to 1/256 pixel, as Vulkan on NVIDIA, lavapipe and D3D
#define SUBPIXEL_SCALE 256
#define MAX_CLIP_VERTS 9    // a triangle clipped by the 6 planes below has at most 3 + 6 vertices
#define CLIP_PLANE_COUNT 6  // near, far, and the four guard-band planes
// Window coordinates are clipped to +-GUARD_BAND_PX around the viewport centre, so |window x| stays
// below 8192 + 16384 < 2^15 pixels. There a float still resolves half a subpixel (a wider guard band
// lets float rounding of clipped vertices move edges by more than the 1/256 snap), snapped coordinates
// stay below 2^23 subpixels and edge-function products below 2^48, comfortably inside int64.
#define GUARD_BAND_PX 16384.0f
#define MAX_FRAMEBUFFER_DIM 16384  // largest raster grid side (output resolution x ssaa)
#define MAX_SAMPLES 16             // largest sampleCount
#define MAX_POINT_SIZE 64.0f       // largest point size in pixels: a point is rasterized by one thread
#define MAX_LINE_WIDTH 64.0f       // largest line width in pixels
#define MAX_SSAA 8                 // largest ssaa factor
// The 1x sample pattern's sampleBounds: the pixel centre, 128 subpixels from the pixel's corner.
#define PIXEL_CENTER_BOUNDS 0x80808080u
// The most groups one dispatch may have: invocation indices are 32-bit and the largest group has
// SCAN_GROUP_SIZE = 256 invocations. The largest the pipeline asks for is setup's for 2^31 / 3
// triangles, 5.6M groups.
#define MAX_DISPATCH_GROUPS 16777216u
#define EMPTY_ID 0xFFFFFFFFu

// RasterParams.aovOutputs: what stage aovs writes to BUF_FRAMEBUFFER after the colour (shared/aovs.h)
// besides each output pixel's id and depth.
#define AOV_OUT_IDS_DEPTH 1u  // the ids and depths alone
#define AOV_OUT_SURFACE 2u    // and the surface AOVs: barycentrics, texture coordinates, shading normal
#define AOV_OUT_RAST 4u       // and rasterize's (u, v, z/w, id + 1), from the barycentrics
#define AOV_SURFACE_PLANES 7  // the surface AOVs' planes: bary u, v; texture u, v; normal x, y, z

#define TRI_FLAG_DOUBLE_SIDED 1u  // never culled by facing (glTF doubleSided materials)
#define TRI_FLAG_ALPHA_MASK 2u    // material is alphaMode MASK: the visibility stages test its alpha

// Textures: wrap modes and filters (GpuTexture), the --texture-filter override (RasterParams), UV
// interpolation, material alpha modes.
#define WRAP_REPEAT 0u
#define WRAP_CLAMP_TO_EDGE 1u
#define WRAP_MIRRORED_REPEAT 2u
#define FILTER_NEAREST 0u
#define FILTER_LINEAR 1u
#define MIPMAP_NONE 0u               // level 0 only (glTF minFilter NEAREST / LINEAR)
#define MIPMAP_NEAREST 1u            // nearest level (..._MIPMAP_NEAREST)
#define MIPMAP_LINEAR 2u             // blend of the two nearest levels (..._MIPMAP_LINEAR)
#define TEXTURE_FILTER_AUTO 0u       // each texture's own sampler
#define TEXTURE_FILTER_NEAREST 1u    // nearest texel of level 0
#define TEXTURE_FILTER_BILINEAR 2u   // bilinear on level 0
#define TEXTURE_FILTER_TRILINEAR 3u  // bilinear on the two nearest levels, blended
#define UV_PERSPECTIVE 0u            // texture coordinates interpolated perspective-correctly
#define UV_AFFINE 1u  // interpolated linearly in screen space (the classic mistake, for comparison)
#define ALPHA_OPAQUE 0u
#define ALPHA_MASK 1u  // covered only where alpha >= alphaCutoff
#define NO_TEXTURE 0xFFFFFFFFu
// Specialization constant (Vulkan) / template argument (CUDA) of setup and raster_tiles: false builds
// them without the alpha test of MASK materials, the build a scene without MASK triangles runs.
#define SPEC_MATERIALS 1
// Specialization constant (Vulkan) / template argument (CUDA) of raster_tiles and shade: the sample
// count they are built for (RasterParams.sampleCount), which sizes each invocation's array of keys or ids.
// Vulkan's setup takes it too, so that a one-sample build holds only the one-sample loop.
#define SPEC_SAMPLES 2
// Specialization constant of shade (Vulkan): false builds only the one-sample-per-pixel path, the build
// a frame without MSAA and SSAA runs (a CPU device would otherwise run the resolve loops too, masked).
#define SPEC_RESOLVE 3
// Specialization constants of shade's CPU build (compute_glsl/shade.comp, SHADE_CPU): the frame's
// shading mode (SHADING_*) and the SHADE_USES_* bits of what its scene has. A CPU device runs both sides
// of every branch on each SIMD bundle of pixels, so this build compiles out what the frame cannot reach.
#define SPEC_SHADE_MODE 4
#define SPEC_SHADE_USES 5
#define SPEC_SHADE_SSAA 6  // RasterParams.ssaa: the resolve loops get constant trip counts
// Specialization constant of raster_tiles' CPU build (RASTER_TILES_CHUNKED): whether the frame counts
// hits (DEBUG_COUNT_HITS). A CPU device runs each hit-count load, store and atomic as a loop over the
// SIMD lanes even when every lane is masked off, 64 such loops per tile; the build without them is
// 11-25% faster there (docs/benchmark-log.md, "The CPU raster core").
#define SPEC_COUNT_HITS 7
#define SHADE_USES_MATERIALS 1u          // RasterParams.materialCount > 0
#define SHADE_USES_BASE_TEXTURES 2u      // a material has a base colour texture
#define SHADE_USES_EMISSIVE_TEXTURES 4u  // a material has an emissive texture
#define SHADE_USES_COLORS 8u             // RasterParams.hasColors
#define SHADE_USES_LINES_POINTS 16u      // RasterParams.lineCount + pointCount > 0
#define SHADE_USES_AFFINE_UV 32u         // RasterParams.uvInterpolation == UV_AFFINE
#define SHADE_USES_NEAREST_FILTER 64u    // a lookup may filter NEAREST (a sampler's or --texture-filter)
#define SHADE_USES_LINEAR_FILTER 128u    // a lookup may filter LINEAR
#define SHADE_USES_MIP_BLEND 256u        // a lookup may blend two levels (MIPMAP_LINEAR)
#define SHADE_USES_ALL 511u
// Raster methods (--raster-method; a build selector like SPEC_MATERIALS: GLSL preprocessor definition
// RASTER_METHOD of setup, bin_count, bin_fill and raster_tiles, CUDA template argument). Plain integers,
// so that the GLSL preprocessor can compare them. common/shared/methods.h has the three alternatives.
#define RASTER_FIXED8 0    // vertices snapped to 1/256 px, exact int64 edge functions, top-left rule
#define RASTER_FIXED4 1    // the same rule with vertices snapped to 1/16 px (cudaraster, older hardware)
#define RASTER_FLOAT 2     // float window positions, float edge functions, barycentrics >= -FLOAT_EPSILON
#define RASTER_SCANLINE 3  // float window positions, per-row float span ends, half-open rows and spans
#define RASTER_METHOD_COUNT 4
// The float method's tolerance on each barycentric coordinate (edge function / area): a sample counts
// as inside when every coordinate is at least -FLOAT_EPSILON, so that rounding does not open cracks
// between triangles of ordinary shape (methods.h derives where it stops being enough).
#define FLOAT_EPSILON 1.52587890625e-5f  // 2^-16
#define MAX_TEXTURE_DIM 16384  // largest texture edge accepted; a 16384^2 level 0 is 1 GiB of texels
#define MAX_TEXTURE_LEVELS 15u  // levels of a MAX_TEXTURE_DIM texture: 16384 down to 1

#define TESS_OFF 0u       // no tessellation: the tess_* stages do not run
#define TESS_FLAT 1u      // split each triangle to the screen size its edges ask for, in its plane
#define TESS_PN 2u        // the same pattern, new vertices moved onto the Curved PN triangle patch
#define TESS_CENTROID 3u  // the course project's baseline: 1 -> 3 at the centroid, tessMaxLevel times
#define TESS_MAX_LEVEL 64u      // largest edge factor (flat, pn): at most 4,222 triangles per scene triangle
#define TESS_MAX_CENTROID 8u    // largest centroid level: 3^8 = 6,561 triangles per scene triangle
// TessSource.flags bits. Bits 0-2: edge k (corner k -> corner k + 1 mod 3) stays straight under pn (its
// two triangles disagree on the normals at its ends, or it has more than two); TESS_FLAT_PATCH: no pn
// on this triangle (a corner normal is zero or not finite); bits 8-15: the triangle's TRI_FLAG_* bits.
#define TESS_STRAIGHT_EDGES 7u
#define TESS_FLAT_PATCH 8u
#define TESS_TRI_FLAGS_SHIFT 8u
// BUF_TESS_COUNTS .w bits.
#define TESS_STATE_CULLED 1u  // outside the view volume or facing the culled way: generates nothing
#define TESS_STATE_PASS 2u    // drawn as it is (factors all 1, non-finite corners, level 0)

#define CULL_NONE 0u
#define CULL_BACK 1u
#define CULL_FRONT 2u

#define SHADING_LAMBERT 0u
#define SHADING_PHONG 1u
#define SHADING_BLINN_PHONG 2u
#define SHADING_FLAT 3u
#define SHADING_NORMALS 4u
#define SHADING_DEPTH 5u
#define SHADING_PRIMITIVE_ID 6u
#define SHADING_HIT_COUNT 7u  // debug: how many triangles covered each pixel (needs DEBUG_COUNT_HITS)
#define SHADING_TEXCOORD 8u   // debug: the material's texture coordinates as red and green (fract)
#define SHADING_MIP 9u        // debug: the texture LOD (lambda) of the base colour as a colour ramp
#define SHADING_AO 10u        // the ambient occlusion alone (white where unoccluded; needs an --ao mode)

// RasterParams.debugFlags bits.
#define DEBUG_COUNT_HITS 1u  // raster stages also count every covered pixel in BUF_HIT_COUNT

// Per-frame constants. std140 in Vulkan: mat4/vec4 first, then 4-byte scalars, 16-byte total multiple.
struct RasterParams {
    mat4 clipFromWorld;     // world -> clip; Vulkan conventions: depth 0..1, NDC y = -1 is the top row
    mat4 viewFromWorld;     // world -> view space (camera at the origin looking down -z)
    mat4 normalFromWorld;   // inverse transpose of viewFromWorld; only its 3x3 part is used
    vec4 lightDirView;      // xyz: unit vector towards the light, view space
    vec4 lightColor;        // rgb: directional light colour; a: ambient intensity
    vec4 background;        // rgb: linear background colour
    vec4 shadeExtra;        // x: specular exponent; y, z: view distances mapped to white/black in depth
                            // view; w: specular strength (the highlight's peak as a fraction of the light)
    vec4 guardBand;         // x, y: guard-band half-extent in NDC units (|x| <= x * w); zw unused
    // Stage clusters (shared/cluster.h). clusterEye: xyz the camera centre in world space (where clip x,
    // y and w vanish); w the facing test's sign: +1 culls clusters that face away from it by their
    // triangles' winding, -1 those that face it, 0 none (no culling, an orthographic camera, a float
    // raster method). clusterCone: x the inradius scale K (pixels per world unit of inradius x facing
    // distance / distance^2), y the float error of projected corners in pixels per unit of vertex
    // magnitude / w, z the displacement threshold in pixels (snapping and the window transform's
    // rounding), w the plane slack per unit of vertex magnitude. clusterPlanes: world-space planes with
    // unit normals, inside >= 0: 0-3 the viewport sides (x >= -w, x <= w, y >= -w, y <= w), 4 near
    // (z >= 0), 5 far (z <= w), 6-9 the sides at twice the viewport; 10 clip w itself.
    vec4 clusterEye;
    vec4 clusterCone;
    vec4 clusterPlanes[CLUSTER_PLANE_COUNT + 1];
    // Ambient occlusion (shared/ao.h's aoViewPoint): the projection's terms that give a pixel's view-space
    // point from its depth z, x = (ndc.x w - P20 z - P30) / P00 and y likewise, w = P23 z + P33 (P is
    // clipFromView, GLM's [column][row]). aoUnprojectX: 1 / P00, P20, P30, P23; aoUnprojectY: 1 / P11,
    // P21, P31, P33.
    vec4 aoUnprojectX;
    vec4 aoUnprojectY;
    uint width;             // framebuffer width in pixels, 1..MAX_FRAMEBUFFER_DIM
    uint height;            // framebuffer height in pixels
    uint vertexCount;       // entries in the per-vertex buffers
    uint triangleCount;     // entries in BUF_TRI_FLAGS; BUF_INDICES has 3x as many
    uint cullMode;          // CULL_*
    uint shadingMode;       // SHADING_*
    uint hasColors;         // 1 when BUF_COLORS holds vertexCount colours, else colours are white
    uint setupCapacity;     // capacity of BUF_SETUP_TRIS
    uint pieceCapacity;     // capacity of BUF_PIECES
    uint binCapacity;       // capacity of BUF_BIN_ENTRIES
    uint tilesX;            // screen tiles per row: ceil(width / TILE_SIZE)
    uint tilesY;            // screen tile rows: ceil(height / TILE_SIZE)
    uint rasterGroups;      // groups raster_tiles runs; group g takes work items g, g + rasterGroups, ...
    uint debugFlags;        // DEBUG_* bits
    uint transformInSetup;  // 1: no vertex is shared, setup transforms positions itself (no vertex stage)
    uint binGroups;         // groups bin_count and bin_fill run; thread i takes pieces i, i + binGroups *
                            // GROUP_SIZE, ...
    uint materialCount;     // entries in BUF_MATERIALS; 0: every triangle is white, untextured, opaque
    uint textureFilter;     // TEXTURE_FILTER_*: AUTO follows each texture's sampler
    uint uvInterpolation;   // UV_PERSPECTIVE or UV_AFFINE
    uint textureCount;      // entries in BUF_TEXTURES
    uint sampleCount;       // coverage samples per pixel (MSAA): 1, 2, 4, 8 or 16, at standardSample()
    uint sampleBounds;      // sampleBoundsOf(sampleCount): the pattern's extent within a pixel
    uint ssaa;              // SSAA factor N: width x height is the raster grid, N times the output's per side
    uint samplePlane;       // width * height: the stride of BUF_VISIBILITY's sample planes
    uint pointCount;      // entries in BUF_POINTS; setup runs triangleCount + lineCount + pointCount threads
    float pointSize;      // point side in pixels, 1..MAX_POINT_SIZE
    uint lineCount;       // segments in BUF_LINES (primitive ids triangleCount .. + lineCount - 1)
    float lineWidth;      // line width in pixels, 1..MAX_LINE_WIDTH, a multiple of 1/8
    float lineDepthBias;  // b: a line's window depth z is drawn as z - b (1 - z) (0 unless --wireframe)
    uint rasterChunk;     // raster_tiles work item: 0 = a tile's whole bin (GPUs); else at most this many
                          // bin entries (CPU devices, RASTER_CPU_CHUNK / sampleCount)
    uint tessMode;             // TESS_*; TESS_OFF: the tess_* stages do not run
    uint tessMaxLevel;         // flat, pn: largest edge factor (1..TESS_MAX_LEVEL); centroid: 1 -> 3 splits
    float tessEdgePx;          // flat, pn: target projected edge length in output pixels
    uint tessSourceTriangles;  // scene triangles (BUF_TESS_SOURCE entries)
    uint tessSourceVertices;   // scene vertices: generated vertex k is vertex tessSourceVertices + k
    uint tessBlocks;           // scan blocks of scene triangles: ceil(tessSourceTriangles / SCAN_GROUP_SIZE)
    uint clusterCount;         // entries in BUF_CLUSTERS; 0: the triangles are set up by stage setup
    uint setupFirstPrimitive;  // setup's invocation i takes primitive setupFirstPrimitive + i (with
                               // clusters, triangleCount: setup sets up the lines and points alone)
    // Level of detail (shared/cluster.h's clusterLodDrawn; RenderSettings::lod): lodScale = pixels per
    // world unit at clip w = 1 (the window's larger half extent times its row's scale) over the error
    // asked for (--lod-error-px), 0 with level of detail off; lodWLength = |linear part of clip w's row|,
    // how fast clip w changes per world unit (0 for an orthographic camera).
    float lodScale;
    float lodWLength;
    // Ambient occlusion (shared/ao.h; RenderSettings::ao). aoMode AO_OFF: no AO stage runs and shade reads
    // no BUF_AO; AO_GTAO: stages ao_gbuffer, ao (and ao_denoise) fill it; AO_REFERENCE: the host fills
    // AO_PLANE_RAW.
    uint aoMode;
    uint aoPlane;        // the plane of BUF_AO shade reads: AO_PLANE_DENOISED after ao_denoise, else AO_PLANE_RAW
    uint aoSlices;       // GTAO's slice directions per pixel, 1..AO_MAX_SLICES
    uint aoSteps;        // its depth samples per side of a slice, 1..AO_MAX_STEPS
    float aoRadius;      // the occlusion radius in view-space units (> 0 with AO on)
    float aoPixelScale;  // raster pixels per view-space unit at clip w = 1 (aoRadius projects to
                         // aoRadius aoPixelScale / w pixels)
    // Reciprocals the AO stages need per pixel or sample, made once on the host with recipDet (the same
    // bits a stage would compute): 1 / aoSlices, 1 / aoSteps, 1 / (AO_FALLOFF aoRadius), 1 / width,
    // 1 / height.
    float aoInvSlices;
    float aoInvSteps;
    float aoInvFalloff;
    float aoInvWidth;
    float aoInvHeight;
    uint aovOutputs;  // AOV_OUT_* bits: what stage aovs writes after the colour (0: the stage does not run)
};

// A glTF metallic-roughness material as far as the pipeline uses it: base colour, alpha and emission.
// 96 bytes.
struct GpuMaterial {
    vec4 baseColorFactor;   // linear RGBA, multiplies the texture and the vertex colour
    vec4 uvTransformU;      // u' = x u + y v + z (KHR_texture_transform; identity when absent), w unused
    vec4 uvTransformV;      // v' = x u + y v + z
    vec4 emissive;          // rgb: linear emitted colour (emissiveFactor x emissive strength), w unused
    uint baseColorTexture;  // index into BUF_TEXTURES, NO_TEXTURE when none
    uint texCoord;          // 0: TEXCOORD_0, 1: TEXCOORD_1 (BUF_TEXCOORDS .xy or .zw)
    uint alphaMode;         // ALPHA_OPAQUE or ALPHA_MASK (BLEND is drawn as OPAQUE)
    float alphaCutoff;      // MASK: covered where alpha >= alphaCutoff
    uint emissiveTexture;   // index into BUF_TEXTURES (multiplies `emissive`), NO_TEXTURE when none
    uint emissiveTexCoord;  // its coordinate set, as texCoord (no texture transform)
    uint pad0;
    uint pad1;
};

// One texture: its levels in BUF_TEXELS and its sampler. Level k is max(1, width >> k) x
// max(1, height >> k) texels, row-major, top row first (glTF's v = 0), levels one after another from
// texelOffset. 32 bytes.
struct GpuTexture {
    uint texelOffset;  // first texel of level 0 in BUF_TEXELS
    uint width;        // level 0 size, 1..MAX_TEXTURE_DIM
    uint height;
    uint levels;   // 1 + floor(log2(max(width, height))): the full chain down to 1x1
    uint wrapS;    // WRAP_* along u
    uint wrapT;    // WRAP_* along v
    uint filters;  // magFilter | minFilter << 8 | mipmapMode << 16 (FILTER_*, MIPMAP_*)
    uint srgb;     // 1: texels are sRGB-encoded and decoded through BUF_SRGB_TABLE before filtering
};

// One rasterizable triangle after clipping and snapping, positively oriented (edge functions are
// positive inside). 48 bytes. Stored only for clipped big sub-triangles; every other big triangle is set
// up again from the scene wherever it is needed, which gives the same bits and costs no memory.
struct TriSetup {
    ivec4 xy01;       // x0, y0, x1, y1: snapped window coordinates in 1/256 pixel
    ivec4 xy2Id;      // x2, y2, triangle id (uint bits), pixel bbox packed as minX | minY << 16
    vec4 depthPlane;  // z0, z1 - z0, z2 - z0 (window depth at the snapped vertices), 1 / area
};

// One cluster of the scene's triangles (BUF_CLUSTERS; host/scene/clusters.cpp builds it, shared/cluster.h
// culls it). 64 bytes.
struct GpuCluster {
    vec4 sphere;      // xyz centre, w radius: every vertex inside (world); an infinite radius never culls
    vec4 cone;        // xyz axis a (unit), w spread beta >= |n - a| for the unit normal n of every triangle
    vec4 coneBounds;  // x: h <= n . (p - c) of every triangle (p a corner, c the centre); y: -H, H >= every
                      // n . (p - c); z: rho <= every triangle's inradius (0: never culled by facing)
    uint vertexOffset;    // its vertex list in BUF_CLUSTER_DATA: scene vertices, vertexCount words
    uint triangleOffset;  // its triangles in BUF_CLUSTER_DATA: two words each (scene id, corners)
    uint vertexCount;     // 1..CLUSTER_MAX_VERTICES
    uint triangleCount;   // 1..CLUSTER_MAX_TRIANGLES
};

// A scene triangle as tessellation reads it. 16 bytes.
struct TessSource {
    uint i0;     // corner vertices (validated on the host)
    uint i1;
    uint i2;
    uint flags;  // TESS_STRAIGHT_EDGES bits, TESS_FLAT_PATCH, TRI_FLAG_* << TESS_TRI_FLAGS_SHIFT
};

#if defined(__cplusplus)
static_assert(sizeof(TessSource) == 16, "TessSource must match std430");
static_assert(sizeof(RasterParams) == 3 * 64 + (9 + CLUSTER_PLANE_COUNT + 1) * 16 + 52 * 4,
              "RasterParams must match std140");
static_assert(sizeof(GpuCluster) == 64, "GpuCluster must match std430");
static_assert(sizeof(GpuMaterial) == 96, "GpuMaterial must match std430");
static_assert(sizeof(GpuTexture) == 32, "GpuTexture must match std430");
static_assert(sizeof(TriSetup) == 48, "TriSetup must match std430");
static_assert(COUNTER_COUNT <= COUNTER_SHARD_BASE && COUNTER_COUNT <= COUNTER_SHARD_STRIDE &&
                  (COUNTER_SHARDS & (COUNTER_SHARDS - 1)) == 0,
              "each shard of the counters fits its stride, their number a power of two");

// The counters as the host reads them: BUF_COUNTERS' first COUNTER_COUNT words (`words`, COUNTER_WORDS
// of them) with every shard's copy added, into `counters` (COUNTER_COUNT).
inline void foldCounters(const uint* words, uint* counters)
{
    for (uint c = 0u; c < uint(COUNTER_COUNT); ++c) {
        uint sum = words[c];
        for (uint s = 0u; s < uint(COUNTER_SHARDS); ++s) sum += words[COUNTER_SHARD_WORD(s, c)];
        counters[c] = sum;
    }
}
#endif

SR_NAMESPACE_END

// The stages' maths, in dependency order.
#include "shared/fixed_point.h"
#include "shared/vertex.h"
#include "shared/clip.h"
#include "shared/setup.h"
#include "shared/coverage.h"
#include "shared/methods.h"
#include "shared/texture.h"
#include "shared/shade.h"
#include "shared/tessellate.h"
#include "shared/cluster.h"
#include "shared/ao.h"
#include "shared/aovs.h"

#if defined(__cplusplus)
#include "shared/stages.h"
#endif

#endif  // RASTER_SHARED_H
