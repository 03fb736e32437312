// buffers.glsl - descriptor set 0 as every stage sees it: the bindings of raster_shared.h (BUF_*),
// mergeFragment (the small-triangle write), and the loads of a triangle that several stages share.
// Each stage includes this after raster_shared.h; unused bindings cost nothing in the shader.
#ifndef RASTER_BUFFERS_GLSL
#define RASTER_BUFFERS_GLSL

#extension GL_EXT_shader_atomic_int64 : require
#if defined(SR_CPU_BUILD)
// The texel views below are images without a sampler (texelFetch takes them directly): a sampled-image
// type of buffer dimension is not valid SPIR-V for Vulkan 1.4's validation.
#extension GL_EXT_samplerless_texture_functions : require
#endif

#include "method.glsl"

#ifndef SHADE_CPU
#define SHADE_CPU 0
#endif
#if SHADE_CPU
// shade's CPU build (compute_glsl/shade.comp): the frame's shading mode and what its scene uses are
// specialization constants, and `params` is the frame's block with them folded in (shade's main sets
// it), so that every test of params.shadingMode, materialCount, hasColors, ... below and in the shared
// headers is decided when the pipeline is built and the code behind a false one is never run.
layout(constant_id = SPEC_SHADE_MODE) const uint SHADE_MODE = SHADING_LAMBERT;
layout(constant_id = SPEC_SHADE_USES) const uint SHADE_USES = SHADE_USES_ALL;
layout(constant_id = SPEC_SHADE_SSAA) const uint SHADE_SSAA = 1u;
layout(std140, set = 0, binding = BUF_PARAMS) uniform ParamsBlock { RasterParams frameParams; };
RasterParams params;
#else
layout(std140, set = 0, binding = BUF_PARAMS) uniform ParamsBlock { RasterParams params; };
#endif
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
layout(std430, set = 0, binding = BUF_MATERIALS) readonly buffer MaterialsBlock { GpuMaterial materials[]; };
layout(std430, set = 0, binding = BUF_TRI_MATERIALS) readonly buffer TriMaterialsBlock {
    uint triMaterials[];
};
layout(std430, set = 0, binding = BUF_TEXCOORDS) readonly buffer TexcoordsBlock { vec4 texcoords[]; };
layout(std430, set = 0, binding = BUF_TEXTURES) readonly buffer TexturesBlock { GpuTexture textures[]; };
layout(std430, set = 0, binding = BUF_TEXELS) readonly buffer TexelsBlock { uint texels[]; };
// A uniform buffer (raster_shared.h): entry i is srgbTable4[i / 4][i % 4].
layout(std140, set = 0, binding = BUF_SRGB_TABLE) uniform SrgbTableBlock { vec4 srgbTable4[64]; };
layout(std430, set = 0, binding = BUF_POINTS) readonly buffer PointsBlock { uint points[]; };
layout(std430, set = 0, binding = BUF_LINES) readonly buffer LinesBlock { uint lines[]; };
layout(std430, set = 0, binding = BUF_CLUSTERS) readonly buffer ClustersBlock { GpuCluster clusters[]; };
layout(std430, set = 0, binding = BUF_CLUSTER_DATA) readonly buffer ClusterDataBlock { uint clusterData[]; };
layout(std430, set = 0, binding = BUF_LOD_CUT) buffer LodCutBlock { uint lodCut[]; };
layout(std430, set = 0, binding = BUF_AO) buffer AoBlock { float ao[]; };

// The CPU builds (SR_CPU_BUILD) read their hot data through the texel views (VIEW_*, raster_shared.h),
// which llvmpipe gathers as vectors, where a storage-buffer load at an index it cannot prove uniform is a
// loop over the SIMD lanes with a branch per lane and component: raster_tiles its records, bin entries and
// keys, shade (through LOAD_*) what it reads by triangle, vertex and texel index.
#if defined(SR_CPU_BUILD)
layout(set = 0, binding = VIEW_SETUP_TRIS) uniform utextureBuffer setupTrisView;
layout(set = 0, binding = VIEW_BIN_ENTRIES) uniform utextureBuffer binEntriesView;
layout(set = 0, binding = VIEW_VISIBILITY) uniform utextureBuffer visibilityView;
layout(set = 0, binding = VIEW_INDICES) uniform utextureBuffer indicesView;
layout(set = 0, binding = VIEW_POSITIONS) uniform utextureBuffer positionsView;
layout(set = 0, binding = VIEW_NORMALS) uniform utextureBuffer normalsView;
layout(set = 0, binding = VIEW_COLORS) uniform utextureBuffer colorsView;
layout(set = 0, binding = VIEW_TEXCOORDS) uniform utextureBuffer texcoordsView;
layout(set = 0, binding = VIEW_TRI_MATERIALS) uniform utextureBuffer triMaterialsView;
layout(set = 0, binding = VIEW_MATERIALS) uniform utextureBuffer materialsView;
layout(set = 0, binding = VIEW_TEXTURES) uniform utextureBuffer texturesView;
layout(set = 0, binding = VIEW_TEXELS) uniform utextureBuffer texelsView;
layout(set = 0, binding = VIEW_SRGB_TABLE) uniform utextureBuffer srgbTableView;
layout(set = 0, binding = VIEW_AO) uniform utextureBuffer aoView;

// setupTris[slot] through its view.
TriSetup fetchSetupRecord(uint slot)
{
    int t = int(3u * slot);
    return TriSetup(ivec4(texelFetch(setupTrisView, t)), ivec4(texelFetch(setupTrisView, t + 1)),
                    uintBitsToFloat(texelFetch(setupTrisView, t + 2)));
}

// visibility[index] through its view.
uint64_t fetchKey(uint index)
{
    uvec2 words = texelFetch(visibilityView, int(index)).xy;
    return (uint64_t(words.y) << 32) | uint64_t(words.x);
}

// materials[k] and textures[k] through their views.
GpuMaterial fetchMaterial(uint k)
{
    int t = int(6u * k);
    uvec4 a = texelFetch(materialsView, t + 4), b = texelFetch(materialsView, t + 5);
    return GpuMaterial(uintBitsToFloat(texelFetch(materialsView, t)),
                       uintBitsToFloat(texelFetch(materialsView, t + 1)),
                       uintBitsToFloat(texelFetch(materialsView, t + 2)),
                       uintBitsToFloat(texelFetch(materialsView, t + 3)), a.x, a.y, a.z, uintBitsToFloat(a.w),
                       b.x, b.y, b.z, b.w);
}

GpuTexture fetchTexture(uint k)
{
    uvec4 a = texelFetch(texturesView, int(2u * k)), b = texelFetch(texturesView, int(2u * k + 1u));
    return GpuTexture(a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w);
}
#endif

// The AO stages' CPU builds (AO_CPU) read the scene, the keys and BUF_AO's planes through the views too,
// and aovs' (AOVS_CPU) the keys.
#if defined(AO_CPU) || defined(AOVS_CPU)
#define LOAD_KEY(i) fetchKey(i)
#define LOAD_AO(i) uintBitsToFloat(texelFetch(aoView, int(i)).x)
#else
#define LOAD_KEY(i) visibility[i]
#define LOAD_AO(i) ao[i]
#endif
#if SHADE_CPU || defined(AO_CPU)
#define LOAD_KEY_ID(i) texelFetch(visibilityView, int(i)).x
#define LOAD_INDEX(i) texelFetch(indicesView, int(i)).x
#define LOAD_POSITION(i) uintBitsToFloat(texelFetch(positionsView, int(i)))
#define LOAD_NORMAL(i) uintBitsToFloat(texelFetch(normalsView, int(i)))
#define LOAD_COLOR(i) uintBitsToFloat(texelFetch(colorsView, int(i)))
#define LOAD_TEXCOORD(i) uintBitsToFloat(texelFetch(texcoordsView, int(i)))
#define LOAD_TRI_MATERIAL(i) texelFetch(triMaterialsView, int(i)).x
#define LOAD_MATERIAL(k) fetchMaterial(k)
#define LOAD_TEXTURE(k) fetchTexture(k)
#define LOAD_TEXEL(i) texelFetch(texelsView, int(i)).x
#define LOAD_SRGB(i) uintBitsToFloat(texelFetch(srgbTableView, int(i)).x)
#else
#define LOAD_KEY_ID(i) visibilityId(visibility[i])
#define LOAD_INDEX(i) indices[i]
#define LOAD_POSITION(i) positions[i]
#define LOAD_NORMAL(i) normals[i]
#define LOAD_COLOR(i) colors[i]
#define LOAD_TEXCOORD(i) texcoords[i]
#define LOAD_TRI_MATERIAL(i) triMaterials[i]
#define LOAD_MATERIAL(k) materials[k]
#define LOAD_TEXTURE(k) textures[k]
#define LOAD_TEXEL(i) texels[i]
#define LOAD_SRGB(i) srgbTable4[(i) >> 2u][(i) & 3u]
#endif

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

// Clip positions of line segment k's vertices, as setup sees them (setupClipPosition). False when an
// index is out of range.
bool loadClipLine(uint k, out vec4 c0, out vec4 c1)
{
    c0 = c1 = vec4(0.0f);
    uint i0 = lines[2u * k];
    uint i1 = lines[2u * k + 1u];
    if (max(i0, i1) >= params.vertexCount) return false;
    bool stored = params.transformInSetup == 0u;
    c0 = setupClipPosition(params, positions[i0], stored ? clipPos[i0] : vec4(0.0f));
    c1 = setupClipPosition(params, positions[i1], stored ? clipPos[i1] : vec4(0.0f));
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
    return methodSetupTriangle(c0, c1, c2, ref, true, CULL_NONE, params.width, params.height,
                               params.sampleBounds, t);
}

// End of screen tile `tile`'s bin in binEntries, once bin_fill has run (its start is the previous tile's
// end): the tile's offset within its scan block, advanced by every slot bin_fill took, plus the block's
// base from scan_sums.
uint binEnd(uint tile)
{
    return scanSums[tile / uint(SCAN_GROUP_SIZE)] + tileBins[tile];
}

// One texel as linear RGBA: sRGB colour channels through the decode table, the rest as unorm.
vec4 fetchTexel(GpuTexture t, uint index)
{
    uint texel = LOAD_TEXEL(index);
    vec4 c = textureUnorm(texel);
    if (t.srgb != 0u) {
        c.x = LOAD_SRGB(texel & 255u);
        c.y = LOAD_SRGB((texel >> 8) & 255u);
        c.z = LOAD_SRGB((texel >> 16) & 255u);
    }
    return c;
}

// Filter `filterMode` on one level at texture coordinates st (texture.h's rules).
vec4 sampleLevel(GpuTexture t, uint level, uint filterMode, vec2 st)
{
    ivec2 size = textureLevelSize(t, level);
    uint offset = textureLevelOffset(t, level);
    vec2 w;
    ivec2 ij = textureTexelCoords(st, size, filterMode, w);
    if (filterMode == FILTER_NEAREST) return fetchTexel(t, textureTexelIndex(t, offset, size, ij.x, ij.y));
    vec4 t00 = fetchTexel(t, textureTexelIndex(t, offset, size, ij.x, ij.y));
    vec4 t10 = fetchTexel(t, textureTexelIndex(t, offset, size, ij.x + 1, ij.y));
    vec4 t01 = fetchTexel(t, textureTexelIndex(t, offset, size, ij.x, ij.y + 1));
    vec4 t11 = fetchTexel(t, textureTexelIndex(t, offset, size, ij.x + 1, ij.y + 1));
    return textureBilinear(t00, t10, t01, t11, w);
}

// The filtered texture value at st for level of detail lambda (textureLambda).
vec4 sampleTexture(GpuTexture t, vec2 st, float lambda)
{
    TextureLookup look = textureSelect(t, lambda, params.textureFilter);
#if SHADE_CPU
    if ((SHADE_USES & SHADE_USES_NEAREST_FILTER) == 0u) look.filterMode = FILTER_LINEAR;
    if ((SHADE_USES & SHADE_USES_LINEAR_FILTER) == 0u) look.filterMode = FILTER_NEAREST;
    if ((SHADE_USES & SHADE_USES_MIP_BLEND) == 0u) look.blend = 0.0f;
#endif
    vec4 c = sampleLevel(t, look.level0, look.filterMode, st);
    if (look.blend > 0.0f) {
        vec4 c1 = sampleLevel(t, look.level1, look.filterMode, st);
        precise vec4 mixed = c + (c1 - c) * look.blend;
        c = mixed;
    }
    return c;
}

// Base colour (linear RGBA: vertex colour x material factor x texture) of triangle `id` at the surface
// point s, with the texture coordinates and level of detail used (for the debug views; lambda -128
// without a texture).
vec4 materialBaseColor(uint id, uint i0, uint i1, uint i2, SurfacePoint s, out vec2 uv, out float lambda)
{
    vec4 white = vec4(1.0f);
    bool hasColors = params.hasColors != 0u;
    vec4 base = surfaceColor(s, hasColors ? LOAD_COLOR(i0) : white, hasColors ? LOAD_COLOR(i1) : white,
                             hasColors ? LOAD_COLOR(i2) : white);
    uv = vec2(0.0f);
    lambda = -128.0f;
    if (params.materialCount == 0u) return base;
    GpuMaterial m = LOAD_MATERIAL(min(LOAD_TRI_MATERIAL(id), params.materialCount - 1u));
    base = base * m.baseColorFactor;
#if SHADE_CPU
    if ((SHADE_USES & SHADE_USES_BASE_TEXTURES) == 0u) return base;
#endif
    if (m.baseColorTexture >= params.textureCount) return base;
    vec2 dx, dy;
    uv = surfaceUvOfSet(s, LOAD_TEXCOORD(i0), LOAD_TEXCOORD(i1), LOAD_TEXCOORD(i2), m.texCoord, dx, dy);
    uv = materialTransformUv(m, uv);
    GpuTexture t = LOAD_TEXTURE(m.baseColorTexture);
    lambda = textureLambda(materialTransformDerivative(m, dx), materialTransformDerivative(m, dy), t.width,
                           t.height);
    return base * sampleTexture(t, uv, lambda);
}

// Emitted colour (linear: emissive factor x emissive texture) of triangle `id` at the surface point s;
// zero without materials or with a zero factor (the texture is then not read).
vec3 materialEmissive(uint id, uint i0, uint i1, uint i2, SurfacePoint s)
{
    if (params.materialCount == 0u) return vec3(0.0f);
    GpuMaterial m = LOAD_MATERIAL(min(LOAD_TRI_MATERIAL(id), params.materialCount - 1u));
    vec3 e = vec3(m.emissive.x, m.emissive.y, m.emissive.z);
#if SHADE_CPU
    if ((SHADE_USES & SHADE_USES_EMISSIVE_TEXTURES) == 0u) return e;
#endif
    if (m.emissiveTexture >= params.textureCount || e == vec3(0.0f)) return e;
    vec2 dx, dy;
    vec2 uv = surfaceUvOfSet(s, LOAD_TEXCOORD(i0), LOAD_TEXCOORD(i1), LOAD_TEXCOORD(i2), m.emissiveTexCoord,
                             dx, dy);
    GpuTexture t = LOAD_TEXTURE(m.emissiveTexture);
    vec4 texel = sampleTexture(t, uv, textureLambda(dx, dy, t.width, t.height));
    return e * vec3(texel.x, texel.y, texel.z);
}

// Base colour (linear RGBA: vertex colour x material factor; points take no texture) of point primitive
// `id`.
vec4 pointBaseColor(uint id)
{
    uint v = points[id - params.triangleCount - params.lineCount];
    vec4 base = params.hasColors != 0u ? colors[v] : vec4(1.0f);
    if (params.materialCount == 0u) return base;
    return base * materials[min(triMaterials[id], params.materialCount - 1u)].baseColorFactor;
}

// Base colour of line segment primitive `id` at parameter t along it (0 at its first vertex, 1 at its
// second; perspective-correct, lineParameter): the vertex colours mixed, times the material factor.
vec4 lineBaseColor(uint id, float t)
{
    uint k = id - params.triangleCount;
    vec4 base = vec4(1.0f);
    if (params.hasColors != 0u) base = mix(colors[lines[2u * k]], colors[lines[2u * k + 1u]], t);
    if (params.materialCount == 0u) return base;
    return base * materials[min(triMaterials[id], params.materialCount - 1u)].baseColorFactor;
}

// The alpha test of an alphaMode MASK triangle at pixel (px, py), for the visibility stages: a pixel
// whose base colour alpha is below the cutoff is not covered (so cut-outs show in ids and depth too).
bool alphaMaskCovers(uint id, int px, int py)
{
    uint i0 = indices[3u * id];
    uint i1 = indices[3u * id + 1u];
    uint i2 = indices[3u * id + 2u];
    SurfacePoint s = surfaceAt(params, px, py, positions[i0], positions[i1], positions[i2], normals[i0],
                               normals[i1], normals[i2]);
    vec2 uv;
    float lambda;
    vec4 base = materialBaseColor(id, i0, i1, i2, s, uv, lambda);
    return base.w >= materials[min(triMaterials[id], params.materialCount - 1u)].alphaCutoff;
}

#endif  // RASTER_BUFFERS_GLSL
