// shared/aovs.h - the AOVs of an output pixel as stage `aovs` writes them to BUF_FRAMEBUFFER after the
// colour (the frame's outputs in one buffer: a Vulkan device may bind no more storage buffers), and as the host
// computed them before (render/aov.cpp keeps that form as the tests' oracle): the id and depth of the
// sample the pixel reports, and the surface there (barycentrics, texture coordinates, shading normal),
// or the four floats nvdiffrast's rasterize returns per pixel.
//
// BUF_FRAMEBUFFER holds, for n = output pixels (aovsLayout), in 32-bit words: the colours (n, shade's), the
// ids (n), the depths (n, float bits); with AOV_OUT_SURFACE the barycentrics of vertices 1 and 2, the texture coordinates and the unit
// view-space shading normal as seven planes of n; with AOV_OUT_RAST (u, v, z/w, id + 1) per pixel (4n).
// Every array starts where the one before ends, so each is one transfer to the host.
#ifndef RASTER_SHARED_AOVS_H
#define RASTER_SHARED_AOVS_H

SR_NAMESPACE_BEGIN

// The raster sample whose id and depth output pixel (x, y) reports: sample 0 (Vulkan's first standard
// location) of the raster pixel nearest the output pixel's centre, (ssaa / 2, ssaa / 2) within its
// ssaa x ssaa block; its index in BUF_VISIBILITY's first plane.
SR_FN uint aovSampleOf(RasterParams params, uint x, uint y)
{
    uint mid = params.ssaa / 2u;
    return (y * params.ssaa + mid) * params.width + x * params.ssaa + mid;
}

// `params` for evaluating surfaces at output pixels (the surface AOVs): width and height divided by the
// SSAA factor, ssaa 1, and sampleCount the output pixel's samples (msaa x ssaa^2), so that a surface whose
// triangle covers only some of them extrapolates to the centre. Not for rasterizing.
SR_FN RasterParams outputParams(RasterParams params)
{
    RasterParams p = params;
    p.width = params.width / params.ssaa;
    p.height = params.height / params.ssaa;
    p.ssaa = 1u;
    p.samplePlane = p.width * p.height;
    p.sampleCount = params.sampleCount * params.ssaa * params.ssaa;
    p.sampleBounds = 0u;
    return p;
}

// NDC of the sample output pixel (x, y) reports (aovSampleOf), where its surface is evaluated: not the
// output pixel's centre, which under MSAA or SSAA need not lie on the triangle at all.
SR_FN vec2 aovSampleNdc(RasterParams params, uint x, uint y)
{
    int mid = int(params.ssaa / 2u);
    ivec2 at = samplePosition(params.sampleCount, 0u, int(x) * int(params.ssaa) + mid,
                                  int(y) * int(params.ssaa) + mid);
    return subpixelNdc(at, params.width, params.height);
}

// The surface AOVs' normal: the one shadePixel lights with (the interpolated vertex normal, or the face
// normal where that is zero, turned to the viewer's side of the face), at barycentrics `bary`, as ambient
// occlusion's G-buffer computes it (aoGbufferOf, shared/ao.h): in correctly rounded operations alone, so
// that every backend and the host give it the same bits (GLSL's normalize, sqrt and division are not,
// and a GPU's compiler may fuse SurfacePoint's interpolations).
SR_FN vec3 aovNormal(RasterParams params, vec3 bary, vec4 pos0, vec4 pos1, vec4 pos2, vec4 nrm0, vec4 nrm1,
                     vec4 nrm2)
{
    vec4 g = aoGbufferOf(params, bary, pos0, pos1, pos2, nrm0, nrm1, nrm2);
    return vec3(g.y, g.z, g.w);
}

// Where each array of BUF_FRAMEBUFFER starts (in 32-bit words) for n output pixels and the outputs asked
// (AOV_OUT_* bits), and the words in all (n, the colours alone, without stage aovs). The surface is AOV_SURFACE_PLANES planes of n (barycentric
// weights of vertices 1 and 2, texture coordinates u and v, normal x, y and z), as the EXR's channels.
struct AovsLayout {
    uint ids;
    uint depths;
    uint surface;  // plane k at surface + k n
    uint rast;     // 4 floats per pixel
    uint words;
};

SR_FN AovsLayout aovsLayout(uint n, uint outputs)
{
    AovsLayout l;
    l.ids = n;
    l.depths = 2u * n;
    l.surface = 3u * n;
    l.rast = l.surface;
    if ((outputs & AOV_OUT_SURFACE) != 0u) l.rast = l.surface + uint(AOV_SURFACE_PLANES) * n;
    l.words = outputs == 0u ? n : l.rast;
    if ((outputs & AOV_OUT_RAST) != 0u) l.words = l.rast + 4u * n;
    return l;
}

// nvdiffrast's rasterize output of a pixel showing `id` at window depth `depth` with barycentrics
// (b1, b2) of vertices 1 and 2: (u, v, z/w, id + 1) with u, v the weights of vertices 0 and 1 and z/w in
// OpenGL's -1..1 (window depth 0..1 is (z/w + 1) / 2 under rasterize's depth mapping); 0 where empty.
SR_FN vec4 rastOutput(uint id, float depth, float b1, float b2)
{
    if (id == EMPTY_ID) return vec4(0.0f);
    SR_PRECISE float u = 1.0f - b1 - b2;
    SR_PRECISE float z = 2.0f * depth - 1.0f;
    SR_PRECISE float slot = float(id) + 1.0f;
    return vec4(u, b1, z, slot);
}

SR_NAMESPACE_END

#endif  // RASTER_SHARED_AOVS_H
