// buffers.cuh - the device buffer table as the CUDA stages see it: the BUF_* bindings of
// raster_shared.h with the same names as compute_glsl/buffers.glsl, mergeFragment (the small-triangle
// write), and the loads of a triangle that several stages share.
#ifndef RASTER_CUDA_BUFFERS_CUH
#define RASTER_CUDA_BUFFERS_CUH

#include "raster_shared.h"
#include "shared/tess_emit.h"
#include "method.cuh"

namespace sr {

struct Buffers {
    const vec4* positions;           // BUF_POSITIONS
    const vec4* normals;             // BUF_NORMALS
    const vec4* colors;              // BUF_COLORS
    const uint* indices;             // BUF_INDICES
    const uint* triFlags;            // BUF_TRI_FLAGS
    vec4* clipPos;                   // BUF_CLIP_POS
    TriSetup* setupTris;             // BUF_SETUP_TRIS
    uvec2* pieces;                   // BUF_PIECES
    uint* tileBins;                  // BUF_TILE_BINS
    uint* scanSums;                  // BUF_SCAN_SUMS
    uint* binEntries;                // BUF_BIN_ENTRIES
    uint* activeTiles;               // BUF_ACTIVE_TILES
    uint* counters;                  // BUF_COUNTERS
    unsigned long long* visibility;  // BUF_VISIBILITY (CUDA's 64-bit atomics take unsigned long long)
    uint* framebuffer;               // BUF_FRAMEBUFFER
    uint* hitCount;                  // BUF_HIT_COUNT
    const GpuMaterial* materials;    // BUF_MATERIALS
    const uint* triMaterials;        // BUF_TRI_MATERIALS
    const vec4* texcoords;           // BUF_TEXCOORDS
    const GpuTexture* textures;      // BUF_TEXTURES
    const uint* texels;              // BUF_TEXELS
    const float* srgbTable;          // BUF_SRGB_TABLE
    const uint* points;              // BUF_POINTS
    const uint* lines;               // BUF_LINES
    const TessSource* tessSource;    // BUF_TESS_SOURCE
    uvec4* tessCounts;               // BUF_TESS_COUNTS
    uvec4* tessSums;                 // BUF_TESS_SUMS
    const GpuCluster* clusters;      // BUF_CLUSTERS
    const uint* clusterData;         // BUF_CLUSTER_DATA
    uint* lodCut;                    // BUF_LOD_CUT
    float* ao;                       // BUF_AO
    // tess_emit's writable view of the per-vertex and per-triangle buffers, BUF_TESS_IDS and
    // BUF_TESS_MATERIALS (the stages above read the same memory through the const pointers).
    TessWriter tess;
};

// The depth test and id write of one covered pixel in a single 64-bit atomicMin (see packVisibility),
// plus the debug hit count. Used by setup for small triangles; raster_tiles owns its pixels and writes
// them plainly.
__device__ inline void mergeFragment(const RasterParams& params, const Buffers& b, uint pixel, float depth,
                                     uint id)
{
    atomicMin(&b.visibility[pixel], packVisibility(depth, id));
    if ((params.debugFlags & DEBUG_COUNT_HITS) != 0u) atomicAdd(&b.hitCount[pixel], 1u);
}

// Element i of a vec4 buffer in one 16-byte load. GLM's vec4 is 4-byte aligned, so `p[i]` compiles to
// four 32-bit loads, which ptxas spread among the previous corner's arithmetic (setup issued 28 load
// instructions a triangle, 12 of them the stored-clip path's, predicated off). One load a corner: setup
// 1-3% faster on the H200's small sweeps, sweep-128px 3.7% (docs/benchmark.md, issue 46's third pass).
// Every BUF_* buffer is a cudaMalloc of its own, 256-byte aligned, so the float4 view is aligned.
__device__ inline vec4 loadVec4(const vec4* p, uint i)
{
    float4 v = reinterpret_cast<const float4*>(p)[i];
    return vec4(v.x, v.y, v.z, v.w);
}

// Element i of a 16-byte aligned ivec4 array (stage clusters' shared vertices) in one 16-byte load.
__device__ inline ivec4 loadIvec4(const ivec4* p, uint i)
{
    int4 v = reinterpret_cast<const int4*>(p)[i];
    return ivec4(v.x, v.y, v.z, v.w);
}

// Stores of the same, one 16-byte access each.
__device__ inline void storeVec4(vec4* p, uint i, vec4 v)
{
    reinterpret_cast<float4*>(p)[i] = make_float4(v.x, v.y, v.z, v.w);
}
__device__ inline void storeIvec4(ivec4* p, uint i, ivec4 v)
{
    reinterpret_cast<int4*>(p)[i] = make_int4(v.x, v.y, v.z, v.w);
}

// The buffer setup reads a vertex from: world positions it transforms itself, or the clip positions stage
// vertex stored. setupClipPosition(params, p, p) then transforms p or returns it.
__device__ inline const vec4* clipSource(const RasterParams& params, const Buffers& b)
{
    return params.transformInSetup != 0u ? b.positions : b.clipPos;
}

// The clip position of vertex v as setup sees it, read with one 16-byte load.
__device__ inline vec4 loadClipPosition(const RasterParams& params, const Buffers& b, uint v)
{
    vec4 p = loadVec4(clipSource(params, b), v);
    return setupClipPosition(params, p, p);
}

// Clip positions of input triangle `tri`'s vertices, as setup sees them (setupClipPosition). False when
// an index is out of range. The three corners are loaded before any is used.
__device__ inline bool loadClipTriangle(const RasterParams& params, const Buffers& b, uint tri, vec4& c0,
                                        vec4& c1, vec4& c2)
{
    uint i0 = b.indices[3u * tri];
    uint i1 = b.indices[3u * tri + 1u];
    uint i2 = b.indices[3u * tri + 2u];
    if (max(i0, max(i1, i2)) >= params.vertexCount) return false;
    const vec4* from = clipSource(params, b);
    vec4 p0 = loadVec4(from, i0), p1 = loadVec4(from, i1), p2 = loadVec4(from, i2);
    c0 = setupClipPosition(params, p0, p0);
    c1 = setupClipPosition(params, p1, p1);
    c2 = setupClipPosition(params, p2, p2);
    return true;
}

// Clip positions of line segment k's vertices, as setup sees them (setupClipPosition). False when an
// index is out of range.
__device__ inline bool loadClipLine(const RasterParams& params, const Buffers& b, uint k, vec4& c0, vec4& c1)
{
    uint i0 = b.lines[2u * k];
    uint i1 = b.lines[2u * k + 1u];
    if (max(i0, i1) >= params.vertexCount) return false;
    const vec4* from = clipSource(params, b);
    vec4 p0 = loadVec4(from, i0), p1 = loadVec4(from, i1);
    c0 = setupClipPosition(params, p0, p0);
    c1 = setupClipPosition(params, p1, p1);
    return true;
}

// The big triangle a bin ref names: a stored record, or an unclipped input triangle set up again from
// the scene exactly as setup did (same function, same bits; setup already culled it, so facing needs
// no second look). False for a ref setup would never have written (a slot of an overflowed frame).
template <uint kMethod>
__device__ inline bool loadBinTriangle(const RasterParams& params, const Buffers& b, uint ref, TriSetup& t)
{
    if ((ref & BIN_REF_RECORD) != 0u) {
        if ((ref & ~BIN_REF_RECORD) >= params.setupCapacity) return false;
        t = b.setupTris[ref & ~BIN_REF_RECORD];
        return true;
    }
    if (ref >= params.triangleCount) return false;
    vec4 c0, c1, c2;
    if (!loadClipTriangle(params, b, ref, c0, c1, c2)) return false;
    return methodSetupTriangle<kMethod>(c0, c1, c2, ref, true, CULL_NONE, params.width, params.height,
                                        params.sampleBounds, t);
}

// End of screen tile `tile`'s bin in binEntries, once bin_fill has run (its start is the previous tile's
// end): the tile's offset within its scan block, advanced by every slot bin_fill took, plus the block's
// base from scan_sums.
__device__ inline uint binEnd(const Buffers& b, uint tile)
{
    return b.scanSums[tile / uint(SCAN_GROUP_SIZE)] + b.tileBins[tile];
}

// One texel as linear RGBA: sRGB colour channels through the decode table, the rest as unorm.
__device__ inline vec4 fetchTexel(const Buffers& b, const GpuTexture& t, uint index)
{
    uint texel = b.texels[index];
    vec4 c = textureUnorm(texel);
    if (t.srgb != 0u) {
        c.x = b.srgbTable[texel & 255u];
        c.y = b.srgbTable[(texel >> 8) & 255u];
        c.z = b.srgbTable[(texel >> 16) & 255u];
    }
    return c;
}

// Filter `filterMode` on one level at texture coordinates st (texture.h's rules).
__device__ inline vec4 sampleLevel(const Buffers& b, const GpuTexture& t, uint level, uint filterMode,
                                   vec2 st)
{
    ivec2 size = textureLevelSize(t, level);
    uint offset = textureLevelOffset(t, level);
    vec2 w;
    ivec2 ij = textureTexelCoords(st, size, filterMode, w);
    if (filterMode == FILTER_NEAREST) return fetchTexel(b, t, textureTexelIndex(t, offset, size, ij.x, ij.y));
    vec4 t00 = fetchTexel(b, t, textureTexelIndex(t, offset, size, ij.x, ij.y));
    vec4 t10 = fetchTexel(b, t, textureTexelIndex(t, offset, size, ij.x + 1, ij.y));
    vec4 t01 = fetchTexel(b, t, textureTexelIndex(t, offset, size, ij.x, ij.y + 1));
    vec4 t11 = fetchTexel(b, t, textureTexelIndex(t, offset, size, ij.x + 1, ij.y + 1));
    return textureBilinear(t00, t10, t01, t11, w);
}

// The filtered texture value at st for level of detail lambda (textureLambda).
__device__ inline vec4 sampleTexture(const RasterParams& params, const Buffers& b, const GpuTexture& t,
                                     vec2 st, float lambda)
{
    TextureLookup look = textureSelect(t, lambda, params.textureFilter);
    vec4 c = sampleLevel(b, t, look.level0, look.filterMode, st);
    if (look.blend > 0.0f) {
        vec4 c1 = sampleLevel(b, t, look.level1, look.filterMode, st);
        c = c + (c1 - c) * look.blend;
    }
    return c;
}

// Base colour (linear RGBA: vertex colour x material factor x texture) of triangle `id` at the surface
// point s, with the texture coordinates and level of detail used (for the debug views; lambda -128
// without a texture).
__device__ inline vec4 materialBaseColor(const RasterParams& params, const Buffers& b, uint id, uint i0,
                                         uint i1, uint i2, const SurfacePoint& s, vec2& uv, float& lambda)
{
    vec4 white = vec4(1.0f);
    bool hasColors = params.hasColors != 0u;
    vec4 base = surfaceColor(s, hasColors ? b.colors[i0] : white, hasColors ? b.colors[i1] : white,
                             hasColors ? b.colors[i2] : white);
    uv = vec2(0.0f);
    lambda = -128.0f;
    if (params.materialCount == 0u) return base;
    GpuMaterial m = b.materials[min(b.triMaterials[id], params.materialCount - 1u)];
    base = base * m.baseColorFactor;
    if (m.baseColorTexture >= params.textureCount) return base;
    vec2 dx, dy;
    uv = surfaceUvOfSet(s, b.texcoords[i0], b.texcoords[i1], b.texcoords[i2], m.texCoord, dx, dy);
    uv = materialTransformUv(m, uv);
    GpuTexture t = b.textures[m.baseColorTexture];
    lambda = textureLambda(materialTransformDerivative(m, dx), materialTransformDerivative(m, dy), t.width,
                           t.height);
    return base * sampleTexture(params, b, t, uv, lambda);
}

// Emitted colour (linear: emissive factor x emissive texture) of triangle `id` at the surface point s;
// zero without materials or with a zero factor (the texture is then not read).
__device__ inline vec3 materialEmissive(const RasterParams& params, const Buffers& b, uint id, uint i0,
                                        uint i1, uint i2, const SurfacePoint& s)
{
    if (params.materialCount == 0u) return vec3(0.0f);
    GpuMaterial m = b.materials[min(b.triMaterials[id], params.materialCount - 1u)];
    vec3 e = vec3(m.emissive.x, m.emissive.y, m.emissive.z);
    if (m.emissiveTexture >= params.textureCount || (e.x == 0.0f && e.y == 0.0f && e.z == 0.0f)) return e;
    vec2 dx, dy;
    vec2 uv =
        surfaceUvOfSet(s, b.texcoords[i0], b.texcoords[i1], b.texcoords[i2], m.emissiveTexCoord, dx, dy);
    GpuTexture t = b.textures[m.emissiveTexture];
    vec4 texel = sampleTexture(params, b, t, uv, textureLambda(dx, dy, t.width, t.height));
    return e * vec3(texel.x, texel.y, texel.z);
}

// Base colour (linear RGBA: vertex colour x material factor; points take no texture) of point primitive
// `id`.
__device__ inline vec4 pointBaseColor(const RasterParams& params, const Buffers& b, uint id)
{
    uint v = b.points[id - params.triangleCount - params.lineCount];
    vec4 base = params.hasColors != 0u ? b.colors[v] : vec4(1.0f);
    if (params.materialCount == 0u) return base;
    return base * b.materials[min(b.triMaterials[id], params.materialCount - 1u)].baseColorFactor;
}

// Base colour of line segment primitive `id` at parameter t along it (0 at its first vertex, 1 at its
// second; perspective-correct, lineParameter): the vertex colours mixed, times the material factor.
__device__ inline vec4 lineBaseColor(const RasterParams& params, const Buffers& b, uint id, float t)
{
    uint k = id - params.triangleCount;
    vec4 base = vec4(1.0f);
    if (params.hasColors != 0u) base = mix(b.colors[b.lines[2u * k]], b.colors[b.lines[2u * k + 1u]], t);
    if (params.materialCount == 0u) return base;
    return base * b.materials[min(b.triMaterials[id], params.materialCount - 1u)].baseColorFactor;
}

// The alpha test of an alphaMode MASK triangle at pixel (px, py), for the visibility stages: a pixel
// whose base colour alpha is below the cutoff is not covered (so cut-outs show in ids and depth too).
__device__ inline bool alphaMaskCovers(const RasterParams& params, const Buffers& b, uint id, int px, int py)
{
    uint i0 = b.indices[3u * id];
    uint i1 = b.indices[3u * id + 1u];
    uint i2 = b.indices[3u * id + 2u];
    SurfacePoint s = surfaceAt(params, px, py, b.positions[i0], b.positions[i1], b.positions[i2],
                               b.normals[i0], b.normals[i1], b.normals[i2]);
    vec2 uv;
    float lambda;
    vec4 base = materialBaseColor(params, b, id, i0, i1, i2, s, uv, lambda);
    return base.w >= b.materials[min(b.triMaterials[id], params.materialCount - 1u)].alphaCutoff;
}

// Thread index in a 1D grid, as gl_GlobalInvocationID.x.
__device__ inline uint globalThreadId()
{
    return blockIdx.x * blockDim.x + threadIdx.x;
}

}  // namespace sr

#endif  // RASTER_CUDA_BUFFERS_CUH
