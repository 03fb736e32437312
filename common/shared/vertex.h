// shared/vertex.h - stage `vertex`: world space to clip space (and view space for shading).
//
// Matrix products with a fixed summation order and no contraction, so the clip positions - and with
// them the snapped vertices - are the same bits on the host, in CUDA and in GLSL. Part of
// raster_shared.h (included from there, not on its own); same three-language rules.
#ifndef RASTER_SHARED_VERTEX_H
#define RASTER_SHARED_VERTEX_H

SR_NAMESPACE_BEGIN

// m * v with a fixed summation order and no contraction. GLSL's built-in matrix product leaves the
// order to the driver, which would let clip positions (and so snapped vertices) differ by an ulp.
SR_FN vec4 mulPoint(mat4 m, vec4 v)
{
    SR_PRECISE vec4 r = ((m[0] * v.x + m[1] * v.y) + m[2] * v.z) + m[3] * v.w;
    return r;
}

// World-space vertex to clip position, view position and unit view-space normal.
SR_FN void transformVertex(RasterParams params, vec4 position, vec4 normal, SR_OUT(vec4) clip,
                           SR_OUT(vec4) viewPos, SR_OUT(vec4) viewNormal)
{
    clip = mulPoint(params.clipFromWorld, position);
    viewPos = mulPoint(params.viewFromWorld, position);
    vec4 n = mulPoint(params.normalFromWorld, vec4(normal.x, normal.y, normal.z, 0.0f));
    vec3 n3 = vec3(n.x, n.y, n.z);
    float len2 = dot(n3, n3);
    n3 = len2 > 0.0f ? n3 / sqrt(len2) : n3;
    viewNormal = vec4(n3.x, n3.y, n3.z, 0.0f);
}

SR_NAMESPACE_END

#endif  // RASTER_SHARED_VERTEX_H
