// shared/cluster.h - stage `clusters`: whole clusters culled before any per-triangle work, only where
// every triangle of the cluster would have been culled by setup itself.
//
// A cluster (GpuCluster) is up to CLUSTER_MAX_VERTICES vertices and CLUSTER_MAX_TRIANGLES triangles of
// one mesh, built at load time (host/scene/clusters.cpp). The stage transforms a cluster's vertices once
// and sets up its triangles from them with setup's own functions, so a drawn cluster gives the same bits
// as setup; the tests here only decide when a cluster need not be drawn at all, and they must never be
// wrong: culling a cluster may only skip triangles that setup would have dropped, and count them the same
// way (COUNTER_CULLED). Two tests, both conservative by explicit error bounds:
//
// Frustum. setup culls a triangle whose three clip positions lie outside one viewport plane (x > w, x < -w,
// y > w, y < -w, z < 0, z > w; frustumOutcode). A cluster whose bounding sphere lies outside such a plane
// by more than the float error of the clip positions (RasterParams.clusterCone.w per unit of the
// vertices' magnitude) has every vertex outside it as setup computes it.
//
// Facing. setup culls by the sign of the snapped window-space area. In exact arithmetic that sign is
// sign(det L) * sign(n . (p - e)) for a triangle with unit normal n (by its winding) through p, seen from
// the camera centre e, where L is the linear part of clip x, y and w (their determinant is the volume
// the camera's rays span): the window area is det L * 2 area * n . (p - e) * width * height / 4 / (w0 w1 w2).
// Snapping moves each corner by up to half a subpixel per axis and float rounding of the clip positions by
// a little more; the sign survives when the exactly projected triangle's inradius exceeds twice that
// displacement (the area changes by at most displacement x perimeter plus a square term, and area =
// inradius x perimeter / 2). So a cluster is culled when, for every triangle, sign * n . (p - e) has a
// positive lower bound s and the projected inradius has a lower bound above the threshold:
//   s >= h + sign * a . (c - e) - beta |c - e|        (GpuCluster: h per sign, axis a, spread beta)
//   inradius_px >= rho * K * s / (|c - e| + r)^2      (rho: smallest inradius; K: RasterParams.clusterCone.x)
// The second line is the smallest singular value of the projection from the triangle's plane to the
// window (area scale over the largest stretch) with |x|, |y| <= 2w, which the cluster must satisfy (it
// also keeps every triangle clear of the clipper: no clipped sub-triangle, whose slivers could flip).
// Part of raster_shared.h (included from there, not on its own); same three-language rules.
#ifndef RASTER_SHARED_CLUSTER_H
#define RASTER_SHARED_CLUSTER_H

SR_NAMESPACE_BEGIN

#define CLUSTER_DRAWN 0u
#define CLUSTER_FRUSTUM_CULLED 1u  // outside a viewport plane: every triangle is PREPARE_CULLED
#define CLUSTER_FACING_CULLED 2u   // every triangle faces the culled way, by the bounds above
// The safety factor on the facing test's inradius threshold, for the float evaluation of the bound.
#define CLUSTER_FACING_SAFETY 1.25f

// Signed distance (world units) of the cluster's centre from plane k of RasterParams.clusterPlanes.
SR_FN float clusterPlaneDistance(RasterParams params, uint k, vec3 centre)
{
    vec4 plane = params.clusterPlanes[k];
    return dot(vec3(plane.x, plane.y, plane.z), centre) + plane.w;
}

// CLUSTER_DRAWN, CLUSTER_FRUSTUM_CULLED or CLUSTER_FACING_CULLED. A cluster with a vertex that is not
// finite has an infinite radius: every comparison below fails and it is drawn (its triangles are counted
// invalid by setup's functions, as without clusters).
SR_FN uint clusterCull(RasterParams params, GpuCluster c)
{
    vec3 centre = vec3(c.sphere.x, c.sphere.y, c.sphere.z);
    float radius = c.sphere.w;
    // The largest vertex coordinate magnitude (plus one, for the translation column) the float error of
    // a clip position scales with.
    float extent = max(abs(centre.x), max(abs(centre.y), abs(centre.z))) + radius + 1.0f;
    float slack = radius + params.clusterCone.w * extent;
    // Planes 0-5 are the viewport's (x >= -w, x <= w, y >= -w, y <= w, z >= 0, z <= w); the cluster is
    // eligible for the facing test only inside near, far and the sides at twice the viewport (4-9).
    bool eligible = true;
    for (uint k = 0u; k < CLUSTER_PLANE_COUNT; ++k) {
        float d = clusterPlaneDistance(params, k, centre);
        if (k < 6u && d < -slack) return CLUSTER_FRUSTUM_CULLED;
        if (k >= 4u && !(d > slack)) eligible = false;
    }
    float sign = params.clusterEye.w;
    float rho = c.coneBounds.z;
    if (!eligible || sign == 0.0f || !(rho > 0.0f)) return CLUSTER_DRAWN;

    vec3 eye = vec3(params.clusterEye.x, params.clusterEye.y, params.clusterEye.z);
    vec3 toCentre = centre - eye;
    float dist = sqrt(dot(toCentre, toCentre));
    vec3 axis = vec3(c.cone.x, c.cone.y, c.cone.z);
    // Lower bound of sign * n . (p - e) over the cluster's triangles, less the float error of this sum.
    float s = (sign > 0.0f ? c.coneBounds.x : c.coneBounds.y) + sign * dot(axis, toCentre) - c.cone.w * dist;
    s -= 1.0e-5f * (dist + radius + abs(c.coneBounds.x) + abs(c.coneBounds.y));
    if (!(s > 0.0f)) return CLUSTER_DRAWN;
    // Clip w over the sphere (plane CLUSTER_PLANE_W is clip w itself, not normalised): the float error
    // of the projected corners grows as extent / w.
    vec4 wRow = params.clusterPlanes[CLUSTER_PLANE_W];
    float wMin = clusterPlaneDistance(params, CLUSTER_PLANE_W, centre) -
                 radius * sqrt(wRow.x * wRow.x + wRow.y * wRow.y + wRow.z * wRow.z);
    if (!(wMin > 0.0f)) return CLUSTER_DRAWN;
    float reach = dist + radius;
    float inradiusPx = rho * params.clusterCone.x * s / (reach * reach);
    float needPx = params.clusterCone.z + params.clusterCone.y * extent / wMin;
    return inradiusPx > CLUSTER_FACING_SAFETY * needPx ? CLUSTER_FACING_CULLED : CLUSTER_DRAWN;
}

// Level of detail (RasterParams.lodScale > 0; host/scene/lod.cpp builds the hierarchy). Every level of a
// mesh's simplification hierarchy is in the clusters: the mesh's own clusters and the clusters of each
// simplified group of clusters, as in Nanite. A cluster carries two LOD bounds, each a sphere and an error
// in world units: its own (the group it was simplified from; error 0 for the mesh's own clusters) and its
// parent's (the group it is simplified in, infinite where it is a root). Every cluster of a group carries
// that group's bounds bit for bit, and a group's bounds contain those of its members (sphere inside
// sphere, error at least theirs). A bound is too coarse where its error, projected at the sphere's
// nearest clip w, exceeds the error asked for:
//   error x K / w_min > E   with w_min = w(centre) - radius x |d w / d p|, K the pixels per world unit at
//                           w = 1,
// written without a division as w_min < error x lodScale (lodScale = K / E). A cluster is drawn where its
// own bound is fine enough and its parent's is not. The decision is per cluster, in any order, and the
// cut is consistent: a group's members are drawn exactly where the group's bound is too coarse, the
// clusters simplified from it exactly where it is not (the same test on the same bits), so each part of
// the surface is drawn at one level, and the groups' locked borders make the levels meet without cracks.
// The containment makes w_min of a parent no larger than of its members, so the choice is monotonic (a
// member too coarse has a parent too coarse); the host widens parent spheres by a relative 2^-10 to keep
// that through the float rounding of w(centre).
// Blocks of CLUSTER_LOD_BLOCK consecutive clusters (a lod_cut group) carry bounds of their clusters' bounds,
// so that a group can skip its clusters without reading them: a sphere holding every parent sphere with
// the largest parent error, and a sphere holding every own sphere with the smallest own error. No cluster
// of the block is in the cut where no parent bound is too coarse (the block's parent sphere is no nearer
// than any of them and its error no smaller) or where every own bound is (the farthest clip w of the
// block's own sphere is at least every own sphere's nearest, and its error no larger). Both tests are made
// with a slack for the float rounding of the clip w of either sphere, so that a skipped block holds no
// cluster that clusterLodDrawn would draw. A block with a bound that is not finite is never skipped.
#define CLUSTER_LOD_BLOCK GROUP_SIZE
SR_FN bool lodBlockSkipped(RasterParams params, vec4 parentSphere, float parentMaxError, vec4 ownSphere,
                           float ownMinError)
{
    vec4 wRow = params.clusterPlanes[CLUSTER_PLANE_W];
    // Every parent fine enough: the block's nearest clip w, less the slack, still at or past the largest
    // error's threshold.
    SR_PRECISE float pCentre =
        ((wRow.x * parentSphere.x + wRow.y * parentSphere.y) + wRow.z * parentSphere.z) + wRow.w;
    SR_PRECISE float pReach = parentSphere.w * params.lodWLength;
    SR_PRECISE float pSlack =
        2.0e-6f *
        (((abs(wRow.x * parentSphere.x) + abs(wRow.y * parentSphere.y)) + abs(wRow.z * parentSphere.z)) +
         abs(wRow.w) + pReach);
    SR_PRECISE float pNearest = (pCentre - pReach) - pSlack;
    SR_PRECISE float pAllowed = parentMaxError * params.lodScale;
    if (pNearest >= pAllowed) return true;
    // Every own bound too coarse: the block's farthest clip w, plus the slack, short of the smallest
    // error's threshold (an own error of 0, the scene's clusters, is never too coarse).
    if (!(ownMinError > 0.0f)) return false;
    SR_PRECISE float oCentre =
        ((wRow.x * ownSphere.x + wRow.y * ownSphere.y) + wRow.z * ownSphere.z) + wRow.w;
    SR_PRECISE float oReach = ownSphere.w * params.lodWLength;
    SR_PRECISE float oSlack =
        2.0e-6f * (((abs(wRow.x * ownSphere.x) + abs(wRow.y * ownSphere.y)) + abs(wRow.z * ownSphere.z)) +
                   abs(wRow.w) + oReach);
    SR_PRECISE float oFarthest = (oCentre + oReach) + oSlack;
    SR_PRECISE float oAllowed = ownMinError * params.lodScale;
    return oFarthest < oAllowed;
}

// Cluster k's words at the head of BUF_CLUSTER_DATA, from k * CLUSTER_LOD_WORDS (float bits unless said):
// own sphere xyz r, own error, parent sphere xyz r, parent error, its triangle count (uint), one unused.
// After them (from clusterCount * CLUSTER_LOD_WORDS) block b's CLUSTER_LOD_WORDS: parent sphere xyz r,
// largest parent error, own sphere xyz r, smallest own error, 1 where the block is never skipped (uint),
// one unused.
// Stage lod_cut (cuda/lod_cut.cuh, compute_glsl/lod_cut.comp) takes the cut with a thread per cluster and
// lists the clusters drawn for stage clusters.
#define CLUSTER_LOD_WORDS 12u

// Whether the LOD bound (sphere, error) is too coarse for this frame; an error of 0 (the mesh itself)
// never is, an infinite one (no parent) always is.
SR_FN bool lodTooCoarse(RasterParams params, vec4 sphere, float error)
{
    if (!(error > 0.0f)) return false;
    vec4 wRow = params.clusterPlanes[CLUSTER_PLANE_W];
    SR_PRECISE float wCentre = ((wRow.x * sphere.x + wRow.y * sphere.y) + wRow.z * sphere.z) + wRow.w;
    SR_PRECISE float wNearest = wCentre - sphere.w * params.lodWLength;
    SR_PRECISE float allowed = error * params.lodScale;
    return !(wNearest >= allowed);  // a sphere that is not finite is too coarse: its parents are drawn
}

// Whether the level-of-detail cut draws a cluster with these bounds (see above).
SR_FN bool clusterLodDrawn(RasterParams params, vec4 ownSphere, float ownError, vec4 parentSphere,
                           float parentError)
{
    return !lodTooCoarse(params, ownSphere, ownError) && lodTooCoarse(params, parentSphere, parentError);
}

// Corner k (0-2) of a cluster triangle's packed corners (BUF_CLUSTER_DATA's second word: three local
// vertex indices of 8 bits, then CLUSTER_TRI_DOUBLE_SIDED).
SR_FN uint clusterCorner(uint packed, uint k)
{
    return (packed >> (8u * k)) & 255u;
}
#define CLUSTER_TRI_DOUBLE_SIDED 0x1000000u  // the triangle's TRI_FLAG_DOUBLE_SIDED, beside its corners

// The per-vertex half of setup, done once per cluster vertex instead of once per corner (fixed8): the
// clip position's finiteness, its outcodes and its snapped window position. Flags: frustumOutcode in bits
// 0-5, clipOutcode in bits 8-13, and:
#define CLUSTER_VERTEX_FINITE 0x10000u   // every clip coordinate is finite
#define CLUSTER_VERTEX_SNAPPED 0x20000u  // snapVertex succeeded (xy, z hold its result)
SR_FN uint clusterVertex(vec4 c, vec4 guardBand, uint width, uint height, SR_OUT(ivec2) xy, SR_OUT(float) z)
{
    bool finite = isFinite(c.x) && isFinite(c.y) && isFinite(c.z) && isFinite(c.w);
    uint flags = 0u;
    if (finite) flags = CLUSTER_VERTEX_FINITE | frustumOutcode(c) | (clipOutcode(c, guardBand) << 8u);
    if (snapVertex(c, width, height, xy, z)) flags |= CLUSTER_VERTEX_SNAPPED;
    return flags;
}

// The first part of what setup decides for a triangle from its corners' clusterVertex results, in
// prepareTriangle's and setupTriangle's order, from the corners' flags and snapped x, y alone:
// PREPARE_INVALID (a coordinate is not finite), PREPARE_CULLED (outside one viewport plane, not snapped, or
// no sample inside its bounding box), PREPARE_CLIPPED (it needs the clipper), or PREPARE_DIRECT where the
// rest of setupSnappedTriangle (area, facing) decides. On a dense mesh most triangles end here: of the
// triangles in the drawn clusters of the 10.2M-triangle sphere at 1920x1080, one in eight has a sample in
// its box.
SR_FN uint clusterTriangleKind(uint f0, uint f1, uint f2, ivec2 v0, ivec2 v1, ivec2 v2, uint width,
                               uint height, uint bounds)
{
    uint all = f0 & f1 & f2;
    if ((all & CLUSTER_VERTEX_FINITE) == 0u) return PREPARE_INVALID;
    if ((all & 63u) != 0u) return PREPARE_CULLED;
    if ((((f0 | f1 | f2) >> 8u) & 63u) != 0u) return PREPARE_CLIPPED;
    if ((all & CLUSTER_VERTEX_SNAPPED) == 0u) return PREPARE_CULLED;
    ivec2 spanX = sampleSpan(min(v0.x, min(v1.x, v2.x)), max(v0.x, max(v1.x, v2.x)), width, boundsX(bounds));
    ivec2 spanY = sampleSpan(min(v0.y, min(v1.y, v2.y)), max(v0.y, max(v1.y, v2.y)), height, boundsY(bounds));
    if (spanX.x > spanX.y || spanY.x > spanY.y) return PREPARE_CULLED;
    return PREPARE_DIRECT;
}

// What setup decides for a triangle from its corners' clusterVertex results: clusterTriangleKind's verdict,
// and where that is PREPARE_DIRECT the rest of setupSnappedTriangle, PREPARE_DIRECT with `t` set up, bit
// for bit setupTriangle's (the same snapped corners through the same steps), or PREPARE_CULLED (zero area,
// the culled facing).
SR_FN uint clusterSetupTriangle(uint f0, uint f1, uint f2, ivec2 v0, ivec2 v1, ivec2 v2, float z0, float z1,
                                float z2, uint triId, bool doubleSided, uint cullMode, uint width,
                                uint height, uint bounds, SR_OUT(TriSetup) t)
{
    uint kind = clusterTriangleKind(f0, f1, f2, v0, v1, v2, width, height, bounds);
    if (kind != PREPARE_DIRECT) return kind;
    return setupSnappedTriangle(v0, v1, v2, z0, z1, z2, triId, doubleSided, cullMode, width, height, bounds,
                                t)
               ? PREPARE_DIRECT
               : PREPARE_CULLED;
}

SR_NAMESPACE_END

#endif  // RASTER_SHARED_CLUSTER_H
