// shared/tess_emit.h - stage tess_emit: one scene triangle's generated vertices and triangles, in the
// pattern of shared/tessellate.h, written through two hooks so that CUDA, GLSL and the host's oracle
// (host/render/tessellate.cpp) run this one loop:
//   TESS_WRITE_VERTEX(k, v)                 generated vertex k (TessVertex v), i.e. vertex
//                                           tessSourceVertices + k of the frame
//   TESS_WRITE_TRIANGLE(k, a, b, c, src)    generated triangle k: vertices a, b, c, scene triangle src
// and TESS_WRITER_PARAM / TESS_WRITER_ARG, the extra parameter that carries the buffers (empty in GLSL,
// whose buffers are globals). C++ and CUDA get TessWriter below; a GLSL stage defines the four macros
// before including this file. Not part of raster_shared.h: included after it by the emitting stages.
#ifndef RASTER_SHARED_TESS_EMIT_H
#define RASTER_SHARED_TESS_EMIT_H

SR_NAMESPACE_BEGIN

#if defined(__cplusplus)
// Where C++ and CUDA write the generated geometry: the per-vertex and per-triangle buffers of the frame.
struct TessWriter {
    vec4* positions;            // BUF_POSITIONS (the scene's vertices first)
    vec4* normals;              // BUF_NORMALS
    vec4* texcoords;            // BUF_TEXCOORDS, when hasTexcoords
    vec4* colors;               // BUF_COLORS, when hasColors
    uint* indices;              // BUF_INDICES
    uint* triFlags;             // BUF_TRI_FLAGS
    uint* triMaterials;         // BUF_TRI_MATERIALS, when materials is not null
    uint* ids;                  // BUF_TESS_IDS
    const uint* materials;      // BUF_TESS_MATERIALS (the scene primitives' materials) or null
    const TessSource* sources;  // BUF_TESS_SOURCE
    uint sourceVertices;        // RasterParams.tessSourceVertices
    bool hasTexcoords;
    bool hasColors;

    SR_FN void vertex(uint k, TessVertex v) const
    {
        uint i = sourceVertices + k;
        positions[i] = v.position;
        normals[i] = v.normal;
        if (hasTexcoords) texcoords[i] = v.texcoord;
        if (hasColors) colors[i] = v.color;
    }
    SR_FN void triangle(uint k, uint a, uint b, uint c, uint src) const
    {
        indices[3u * k] = a;
        indices[3u * k + 1u] = b;
        indices[3u * k + 2u] = c;
        triFlags[k] = (sources[src].flags >> TESS_TRI_FLAGS_SHIFT) & 255u;
        if (materials) triMaterials[k] = materials[src];
        ids[k] = src;
    }
};
#define TESS_WRITER_PARAM , TessWriter writer
#define TESS_WRITER_ARG , writer
#define TESS_WRITE_VERTEX(k, v) writer.vertex(k, v)
#define TESS_WRITE_TRIANGLE(k, a, b, c, src) writer.triangle(k, a, b, c, src)
#endif

// Frame vertex index of point k (0 and f: the corners) of edge e, f = its factor, in the triangle's own
// direction (corner e to corner e + 1). `forward`: that direction is the canonical one, so its points
// were numbered from corner e; `edgeBase`: the edge's first point among the triangle's new vertices.
SR_FN uint tessOuterRef(uvec4 corners, uint e, uint k, uint f, bool forward, uint vertexBase, uint edgeBase)
{
    if (k == 0u) return corners[e];
    if (k == f) return corners[(e + 1u) % 3u];
    uint j = forward ? k : f - k;
    return vertexBase + edgeBase + j - 1u;
}

// Frame vertex index of inner lattice point (b, c) (a = m - b - c weighs corner 0, b corner 1, c corner 2).
SR_FN uint tessInnerRef(uint m, uint b, uint c, uint vertexBase, uint innerBase)
{
    return vertexBase + innerBase + c * (m + 1u) - (c * (c - 1u)) / 2u + b;
}

// Point l (0..m, from the end near corner e) of the inner lattice side parallel to edge e.
SR_FN uint tessInnerSideRef(uint m, uint e, uint l, uint vertexBase, uint innerBase)
{
    if (e == 0u) return tessInnerRef(m, l, 0u, vertexBase, innerBase);     // (m - l, l, 0)
    if (e == 1u) return tessInnerRef(m, m - l, l, vertexBase, innerBase);  // (0, m - l, l)
    return tessInnerRef(m, 0u, m - l, vertexBase, innerBase);              // (l, 0, m - l)
}

// The corners of triangle q of centroid round `level` (3^level of them; round 0 is the scene triangle),
// with their frame vertex indices, by walking q's base-3 digits from the scene triangle down: child d of
// (A, B, C) with centroid G is (A, B, G), (B, C, G) or (C, A, G). Every centroid on the way is recomputed
// from the same corners in the same order, so it has the bits tess_emit wrote for it.
SR_FN void tessCentroidWalk(TessPatch t, uvec4 corners, uint vertexBase, uint level, uint q,
                            SR_OUT(TessVertex) A, SR_OUT(TessVertex) B, SR_OUT(TessVertex) C,
                            SR_OUT(uvec4) refs)
{
    A = t.v0;
    B = t.v1;
    C = t.v2;
    refs = corners;
    for (uint i = 0u; i < level; ++i) {
        uint parent = q / tessPow3(level - i);  // the path's triangle of round i
        uint d = (q / tessPow3(level - 1u - i)) % 3u;
        TessVertex G = tessCentroid(A, B, C);
        uint g = vertexBase + (tessPow3(i) - 1u) / 2u + parent;
        if (d == 0u) {
            C = G;
            refs.z = g;
        } else if (d == 1u) {
            A = B;
            B = C;
            C = G;
            refs.x = refs.y;
            refs.y = refs.z;
            refs.z = g;
        } else {
            B = A;
            A = C;
            C = G;
            refs.y = refs.x;
            refs.x = refs.z;
            refs.z = g;
        }
    }
}

// Stage tess_emit for scene triangle `tri`: its BUF_TESS_COUNTS entry `entry` (factors, state), its
// first new vertex (vertexBase, a frame vertex index) and first generated triangle (triBase).
SR_FN void tessEmitTriangle(RasterParams params, TessSource src, TessPatch t, uint tri, uvec4 entry,
                            uint vertexBase, uint triBase TESS_WRITER_PARAM)
{
    uvec4 corners = uvec4(src.i0, src.i1, src.i2, 0u);
    if ((entry.w & TESS_STATE_CULLED) != 0u) return;
    if ((entry.w & TESS_STATE_PASS) != 0u) {
        TESS_WRITE_TRIANGLE(triBase, src.i0, src.i1, src.i2, tri);
        return;
    }
    uint firstVertex = vertexBase - params.tessSourceVertices;  // TESS_WRITE_VERTEX counts from 0
    if (params.tessMode == TESS_CENTROID) {
        uint level = params.tessMaxLevel;
        TessVertex A, B, C;
        uvec4 refs;
        for (uint split = 0u; split < level; ++split) {
            uint triangles = tessPow3(split);
            for (uint q = 0u; q < triangles; ++q) {
                tessCentroidWalk(t, corners, vertexBase, split, q, A, B, C, refs);
                TESS_WRITE_VERTEX(firstVertex + (triangles - 1u) / 2u + q, tessCentroid(A, B, C));
            }
        }
        uint parents = tessPow3(level - 1u);
        for (uint q = 0u; q < parents; ++q) {
            tessCentroidWalk(t, corners, vertexBase, level - 1u, q, A, B, C, refs);
            uint g = vertexBase + (parents - 1u) / 2u + q;
            TESS_WRITE_TRIANGLE(triBase + 3u * q, refs.x, refs.y, g, tri);
            TESS_WRITE_TRIANGLE(triBase + 3u * q + 1u, refs.y, refs.z, g, tri);
            TESS_WRITE_TRIANGLE(triBase + 3u * q + 2u, refs.z, refs.x, g, tri);
        }
        return;
    }

    bool pn = tessUsesPn(params.tessMode, src.flags);
    uint f[3];
    f[0] = tessFactor(entry.z, 0u);
    f[1] = tessFactor(entry.z, 1u);
    f[2] = tessFactor(entry.z, 2u);
    uint m = tessInnerLevel(max(f[0], max(f[1], f[2])));
    bool forward[3];
    uint edgeBase[3];
    uint next = 0u;
    // The edges' points, each from the canonical end (tessPrecedes), so that the neighbour across the
    // edge writes the same bits.
    for (uint e = 0u; e < 3u; ++e) {
        TessVertex a = tessCorner(t, e);
        TessVertex b = tessCorner(t, (e + 1u) % 3u);
        forward[e] = tessPrecedes(a.position, b.position);
        edgeBase[e] = next;
        bool curved = pn && ((src.flags >> e) & 1u) == 0u;
        for (uint j = 1u; j < f[e]; ++j)
            TESS_WRITE_VERTEX(firstVertex + next + j - 1u, forward[e] ? tessEdgePoint(a, b, j, f[e], curved)
                                                                      : tessEdgePoint(b, a, j, f[e], curved));
        next += f[e] - 1u;
    }
    // The inner lattice, (a + 1, b + 1, c + 1) / (m + 3).
    uint innerBase = next;
    float denominator = float(m + 3u);
    for (uint c = 0u; c <= m; ++c) {
        for (uint b = 0u; b + c <= m; ++b) {
            uint a = m - b - c;
            TessVertex v =
                tessInnerPoint(t, divDet(float(a + 1u), denominator), divDet(float(b + 1u), denominator),
                               divDet(float(c + 1u), denominator), pn);
            TESS_WRITE_VERTEX(firstVertex + innerBase + c * (m + 1u) - (c * (c - 1u)) / 2u + b, v);
        }
    }
    // Its triangles, rows of `c`: upright (b, c), (b + 1, c), (b, c + 1) and between them inverted
    // (b + 1, c), (b + 1, c + 1), (b, c + 1), both wound like the scene triangle.
    uint k = triBase;
    for (uint c = 0u; c < m; ++c) {
        for (uint b = 0u; b + c < m; ++b) {
            TESS_WRITE_TRIANGLE(k, tessInnerRef(m, b, c, vertexBase, innerBase),
                                tessInnerRef(m, b + 1u, c, vertexBase, innerBase),
                                tessInnerRef(m, b, c + 1u, vertexBase, innerBase), tri);
            ++k;
            if (b + c + 1u < m) {
                TESS_WRITE_TRIANGLE(k, tessInnerRef(m, b + 1u, c, vertexBase, innerBase),
                                    tessInnerRef(m, b + 1u, c + 1u, vertexBase, innerBase),
                                    tessInnerRef(m, b, c + 1u, vertexBase, innerBase), tri);
                ++k;
            }
        }
    }
    // The strips. Outer point i of f sits at i / f along the edge, inner point l of m + 1 at
    // (l + 1) / (m + 2); walk both rows in that order (outer first on ties), one triangle per step.
    for (uint e = 0u; e < 3u; ++e) {
        uint F = f[e];
        uint i = 0u, l = 0u;
        while (i < F || l < m) {
            uint o0 = tessOuterRef(corners, e, i, F, forward[e], vertexBase, edgeBase[e]);
            uint in0 = tessInnerSideRef(m, e, l, vertexBase, innerBase);
            if (l == m || (i < F && (i + 1u) * (m + 2u) <= (l + 2u) * F)) {
                uint o1 = tessOuterRef(corners, e, i + 1u, F, forward[e], vertexBase, edgeBase[e]);
                TESS_WRITE_TRIANGLE(k, o0, o1, in0, tri);
                ++i;
            } else {
                TESS_WRITE_TRIANGLE(k, o0, tessInnerSideRef(m, e, l + 1u, vertexBase, innerBase), in0, tri);
                ++l;
            }
            ++k;
        }
    }
}

SR_NAMESPACE_END

#endif  // RASTER_SHARED_TESS_EMIT_H
