// shared/ao.h - stages ao_gbuffer, ao and ao_denoise: ambient occlusion by GTAO (Jimenez et al. 2016,
// "Practical Realtime Strategies for Accurate Indirect Occlusion") over the visibility buffer.
//
// Ambient occlusion at a surface point p with unit normal n is the cosine-weighted visibility of its
// hemisphere within a radius R,
//   AO(p) = 1/pi * integral over directions w of V(p, w) max(n . w, 0) dw,
// V = 0 where something lies along w within R. GTAO writes a direction as w = cos(t) v + sin(t) d(phi)
// (v the unit vector to the eye, d(phi) the unit vector of screen direction phi orthogonal to v), so
// dw = |sin t| dt dphi over t in (-pi, pi], phi in [0, pi): a slice per phi, the half-plane through the
// eye, p and the screen line through p's pixel. In a slice the normal projects to a vector of length L
// at angle gamma from v, so n . w = L cos(t - gamma), and where the depth buffer's horizon angles h0 <= 0
// <= h1 bound what is visible,
//   AO = 1/pi * integral over phi of L * integral from h0 to h1 of cos(t - gamma) |sin t| dt,
// whose inner integral has the closed form (aoSliceVisibility)
//   1/4 (-cos(2 h1 - gamma) + cos(gamma) + 2 h1 sin(gamma)) + 1/4 (-cos(2 h0 - gamma) + cos(gamma) + 2 h0
//   sin(gamma)).
// An unoccluded point (h = gamma -+ pi/2) gets exactly 1 for every normal. The phi integral is a mean
// over aoSlices slices; each side of a slice finds its horizon from aoSteps depth samples.
//
// Determinism: the slices and samples of a pixel follow a fixed 4 x 4 pattern (aoPattern), no random
// numbers, so a frame is the same every time. Every float operation whose bits matter is a correctly
// rounded +, -, * (precise, never contracted), and the square root, reciprocal, cosine and arc cosine are
// built from those here (sqrtDet, cosDet, acosDet), so CUDA, Vulkan on any device and the host compute
// the same bits.
//
// Part of raster_shared.h (included from there, not on its own); same three-language rules. The buffer
// loads are the stages' (cuda/ao*.cuh, compute_glsl/ao*.comp); these functions are the maths between.
#ifndef RASTER_SHARED_AO_H
#define RASTER_SHARED_AO_H

SR_NAMESPACE_BEGIN

#define AO_PI 3.14159265358979f
#define AO_HALF_PI 1.57079632679490f
#define AO_TWO_PI 6.28318530717959f
#define AO_INV_TWO_PI 0.159154943091895f

// sqrt(x) for x >= 0 from rsqrtDet (setup.h); 0 for x <= 0 or not finite.
SR_FN float sqrtDet(float x)
{
    if (!(x > 0.0f) || !isFinite(x)) return 0.0f;
    SR_PRECISE float r = x * rsqrtDet(x);
    return r;
}

// a . b summed in a fixed order (GLSL's dot may fuse its products).
SR_FN float dotDet(vec3 a, vec3 b)
{
    SR_PRECISE float d = a.x * b.x + a.y * b.y + a.z * b.z;
    return d;
}

SR_FN vec3 crossDet(vec3 a, vec3 b)
{
    SR_PRECISE float x = a.y * b.z - a.z * b.y;
    SR_PRECISE float y = a.z * b.x - a.x * b.z;
    SR_PRECISE float z = a.x * b.y - a.y * b.x;
    return vec3(x, y, z);
}

// a * s per component, and a - b * s (each product rounded, then the difference).
SR_FN vec3 scaleDet(vec3 a, float s)
{
    SR_PRECISE float x = a.x * s;
    SR_PRECISE float y = a.y * s;
    SR_PRECISE float z = a.z * s;
    return vec3(x, y, z);
}

SR_FN vec3 subScaledDet(vec3 a, vec3 b, float s)
{
    SR_PRECISE float x = a.x - b.x * s;
    SR_PRECISE float y = a.y - b.y * s;
    SR_PRECISE float z = a.z - b.z * s;
    return vec3(x, y, z);
}

// a / |a|, or `fallback` where |a| is 0 or not finite.
SR_FN vec3 normalizeDet(vec3 a, vec3 fallback)
{
    float lengthSq = dotDet(a, a);
    if (!(lengthSq > 0.0f) || !isFinite(lengthSq)) return fallback;
    return scaleDet(a, rsqrtDet(lengthSq));
}

// cos(x) for |x| < 2^20: x reduced to r in [0, pi] by a multiple of 2 pi and by symmetry, folded to
// [0, pi/2] (cos(pi - r) = -cos(r)), then its Taylor polynomial to r^14, whose remainder there is below
// (pi/2)^16 / 16! = 7e-11, well under a float's rounding.
SR_FN float cosDet(float x)
{
    SR_PRECISE float k = roundEven(x * AO_INV_TWO_PI);
    SR_PRECISE float r = abs(x - k * AO_TWO_PI);
    float sign = 1.0f;
    if (r > AO_HALF_PI) {
        r = AO_PI - r;
        sign = -1.0f;
    }
    SR_PRECISE float r2 = r * r;
    SR_PRECISE float c =
        1.0f +
        r2 * (-0.5f +
              r2 * (4.16666667e-2f +
                    r2 * (-1.38888889e-3f +
                          r2 * (2.48015873e-5f +
                                r2 * (-2.75573192e-7f + r2 * (2.08767570e-9f + r2 * -1.14707456e-11f))))));
    SR_PRECISE float signed_ = sign * c;
    return signed_;
}

// acos(x) for x in [-1, 1] (clamped): Abramowitz and Stegun 4.4.46, acos(a) = sqrt(1 - a) P(a) for
// a = |x| in [0, 1] with a degree-7 polynomial P, at most 2e-8 off; acos(-a) = pi - acos(a).
SR_FN float acosDet(float x)
{
    float a = min(abs(x), 1.0f);
    SR_PRECISE float p =
        1.5707963050f +
        a * (-0.2145988016f +
             a * (0.0889789874f +
                  a * (-0.0501743046f +
                       a * (0.0308918810f +
                            a * (-0.0170881256f + a * (0.0066700901f + a * -0.0012624911f))))));
    SR_PRECISE float r = sqrtDet(1.0f - a) * p;
    SR_PRECISE float result = x < 0.0f ? AO_PI - r : r;
    return result;
}

// The 4 x 4 ordered-dither (Bayer) index of pixel (x, y), 0..15: every 4 x 4 block of pixels holds each
// value once, so ao_denoise's filter, whose weights sum to the same over each residue class mod 4
// (aoDenoiseWeight), averages every pixel's pattern out on a flat surface.
SR_FN uint aoPattern(int x, int y)
{
    uint ux = uint(x) & 3u;
    uint uy = uint(y) & 3u;
    uint d = ux ^ uy;
    return ((d & 1u) << 3) | ((uy & 1u) << 2) | (d & 2u) | ((uy & 2u) >> 1);
}

// The view-space point at NDC `ndc` and view distance `dist` (-z), through the projection's terms in
// RasterParams.aoUnprojectX / Y. Affine in dist along the ray through ndc, for either projection.
SR_FN vec3 aoViewPointNdc(RasterParams params, vec2 ndc, float dist)
{
    SR_PRECISE float z = 0.0f - dist;
    SR_PRECISE float w = params.aoUnprojectX.w * z + params.aoUnprojectY.w;
    SR_PRECISE float x =
        (ndc.x * w - params.aoUnprojectX.y * z - params.aoUnprojectX.z) * params.aoUnprojectX.x;
    SR_PRECISE float y =
        (ndc.y * w - params.aoUnprojectY.y * z - params.aoUnprojectY.z) * params.aoUnprojectY.x;
    return vec3(x, y, z);
}

// The view-space point of the centre of raster pixel (px, py) at view distance `dist`.
SR_FN vec3 aoViewPoint(RasterParams params, int px, int py, float dist)
{
    return aoViewPointNdc(params, pixelCenterNdc(px, py, params.width, params.height), dist);
}

// b0 x0 + b1 x1 + b2 x2 per component, each product rounded, summed in that order.
SR_FN vec3 interpolateDet(vec3 b, vec3 x0, vec3 x1, vec3 x2)
{
    SR_PRECISE float x = x0.x * b.x + x1.x * b.y + x2.x * b.z;
    SR_PRECISE float y = x0.y * b.x + x1.y * b.y + x2.y * b.z;
    SR_PRECISE float z = x0.z * b.x + x1.z * b.y + x2.z * b.z;
    return vec3(x, y, z);
}

// Stage ao_gbuffer: what AO knows of the surface of a raster pixel, at the barycentrics `bary` of the
// surface shade lights there (surfaceAt's, themselves computed bit for bit alike everywhere) of the
// triangle with world-space corners pos* and normals nrm*: x the view distance -z (at least 1e-30, so
// that 0 means no surface), yzw the unit normal shadePixel lights with (the interpolated vertex normal,
// or the face normal where that is zero, turned to the viewer's side of the face). Everything is
// recomputed here with deterministic operations, not taken from SurfacePoint, whose interpolations GLSL
// may fuse and whose vertex normals come from GLSL's sqrt and division (a few ulp apart between
// devices): the G-buffer, and with it the AO, has the same bits on every backend.
SR_FN vec4 aoGbufferOf(RasterParams params, vec3 bary, vec4 pos0, vec4 pos1, vec4 pos2, vec4 nrm0, vec4 nrm1,
                       vec4 nrm2)
{
    vec4 p0 = mulPoint(params.viewFromWorld, pos0);
    vec4 p1 = mulPoint(params.viewFromWorld, pos1);
    vec4 p2 = mulPoint(params.viewFromWorld, pos2);
    vec4 m0 = mulPoint(params.normalFromWorld, vec4(nrm0.x, nrm0.y, nrm0.z, 0.0f));
    vec4 m1 = mulPoint(params.normalFromWorld, vec4(nrm1.x, nrm1.y, nrm1.z, 0.0f));
    vec4 m2 = mulPoint(params.normalFromWorld, vec4(nrm2.x, nrm2.y, nrm2.z, 0.0f));
    vec3 zero = vec3(0.0f);
    vec3 viewPos =
        interpolateDet(bary, vec3(p0.x, p0.y, p0.z), vec3(p1.x, p1.y, p1.z), vec3(p2.x, p2.y, p2.z));
    vec3 viewNormal = interpolateDet(bary, normalizeDet(vec3(m0.x, m0.y, m0.z), zero),
                                     normalizeDet(vec3(m1.x, m1.y, m1.z), zero),
                                     normalizeDet(vec3(m2.x, m2.y, m2.z), zero));
    vec3 e1 = vec3(p1.x - p0.x, p1.y - p0.y, p1.z - p0.z);
    vec3 e2 = vec3(p2.x - p0.x, p2.y - p0.y, p2.z - p0.z);
    vec3 toEye = vec3(0.0f - viewPos.x, 0.0f - viewPos.y, 0.0f - viewPos.z);
    vec3 fn = normalizeDet(crossDet(e1, e2), vec3(0.0f, 0.0f, 1.0f));
    if (dotDet(fn, toEye) < 0.0f) fn = vec3(0.0f - fn.x, 0.0f - fn.y, 0.0f - fn.z);
    vec3 n = normalizeDet(viewNormal, fn);
    if (dotDet(n, fn) < 0.0f) n = vec3(0.0f - n.x, 0.0f - n.y, 0.0f - n.z);
    return vec4(max(0.0f - viewPos.z, 1e-30f), n.x, n.y, n.z);
}

// What GTAO knows of its pixel.
struct AoPixel {
    vec3 p;             // view-space point
    vec3 n;             // unit normal, facing the viewer
    vec3 v;             // unit vector to the eye (+z for an orthographic camera)
    float radiusPx;     // the occlusion radius projected at p, in raster pixels (at most AO_MAX_RADIUS_PX)
    float sliceJitter;  // the pattern's rotation of the slice directions, in slices
    float stepJitter;   // and its shift of the samples along a slice, in steps
};

// The pixel (px, py) at view distance `dist` with unit view-space normal n.
SR_FN AoPixel aoPixelAt(RasterParams params, int px, int py, float dist, vec3 n)
{
    AoPixel a;
    a.p = aoViewPoint(params, px, py, dist);
    a.n = n;
    // A perspective camera's eye is the origin; an orthographic one looks along -z everywhere.
    bool orthographic = params.aoUnprojectX.w == 0.0f;
    a.v = orthographic ? vec3(0.0f, 0.0f, 1.0f) : normalizeDet(scaleDet(a.p, -1.0f), vec3(0.0f, 0.0f, 1.0f));
    SR_PRECISE float w = params.aoUnprojectX.w * a.p.z + params.aoUnprojectY.w;
    SR_PRECISE float r = params.aoRadius * params.aoPixelScale * recipDet(w);
    a.radiusPx = w > 0.0f ? min(r, AO_MAX_RADIUS_PX) : 0.0f;
    uint pattern = aoPattern(px, py);
    a.sliceJitter = (float(pattern) + 0.5f) * (1.0f / 16.0f);
    a.stepJitter = (float((pattern * 7u + 5u) & 15u) + 0.5f) * (1.0f / 16.0f);
    return a;
}

// One slice of a pixel, its horizons as far as the samples so far have raised them.
struct AoSlice {
    vec2 dir;     // the slice's screen direction, raster pixels (x right, y down)
    float gamma;  // the angle of the projected normal from v, positive towards +dir
    float cosGamma;
    float sinGamma;
    float projLength;   // the length of the normal projected onto the slice's plane
    float horizonCos0;  // cos of the highest horizon towards -dir (starts at the tangent plane)
    float horizonCos1;  // towards +dir
    float lowCos0;      // the tangent plane's horizon cosines, where a sample of no weight leaves them
    float lowCos1;
};

// Slice k of the pixel: direction phi = (k + sliceJitter) pi / aoSlices.
SR_FN AoSlice aoSliceBegin(RasterParams params, AoPixel a, uint k)
{
    AoSlice s;
    SR_PRECISE float phi = (float(k) + a.sliceJitter) * AO_PI * params.aoInvSlices;
    SR_PRECISE float cy = cosDet(phi - AO_HALF_PI);  // sin(phi)
    s.dir = vec2(cosDet(phi), cy);
    // The screen direction in view space (screen y runs down, view y up), made orthogonal to v.
    vec3 d = vec3(s.dir.x, 0.0f - s.dir.y, 0.0f);
    vec3 ortho = normalizeDet(subScaledDet(d, a.v, dotDet(d, a.v)), d);
    vec3 axis = normalizeDet(crossDet(ortho, a.v), vec3(0.0f, 0.0f, 1.0f));
    vec3 projected = subScaledDet(a.n, axis, dotDet(a.n, axis));
    float lengthSq = dotDet(projected, projected);
    s.projLength = sqrtDet(lengthSq);
    SR_PRECISE float cosG = clamp(dotDet(projected, a.v) * rsqrtDet(max(lengthSq, 1e-30f)), -1.0f, 1.0f);
    float sign = dotDet(projected, ortho) < 0.0f ? -1.0f : 1.0f;
    SR_PRECISE float gamma = sign * acosDet(cosG);
    SR_PRECISE float sinG = sign * sqrtDet(1.0f - cosG * cosG);
    s.gamma = gamma;
    s.cosGamma = cosG;
    s.sinGamma = sinG;
    // The tangent plane: t = gamma + pi/2 towards +dir (cos = -sin(gamma)), gamma - pi/2 towards -dir.
    s.lowCos1 = 0.0f - sinG;
    s.lowCos0 = sinG;
    s.horizonCos0 = s.lowCos0;
    s.horizonCos1 = s.lowCos1;
    return s;
}

// The distance in raster pixels of sample j (of aoSteps) from the pixel along a slice: quadratic in
// (j + stepJitter) / aoSteps, so that samples crowd where near occluders matter most, and at least one
// pixel more per step, so that no sample reads the pixel itself.
SR_FN float aoStepOffset(RasterParams params, AoPixel a, uint j)
{
    SR_PRECISE float t = (float(j) + a.stepJitter) * params.aoInvSteps;
    SR_PRECISE float offset = t * t * a.radiusPx;
    return max(offset, float(j) + 1.0f);
}

// The screen position, in raster pixels, of the sample `offset` pixels from the centre of pixel (px, py)
// along `dir`, towards -dir when `negative`; the sample reads the pixel it falls in (floor).
SR_FN vec2 aoSamplePosition(int px, int py, vec2 dir, float offset, bool negative)
{
    SR_PRECISE float o = negative ? 0.0f - offset : offset;
    SR_PRECISE float sx = float(px) + 0.5f + dir.x * o;
    SR_PRECISE float sy = float(py) + 0.5f + dir.y * o;
    return vec2(sx, sy);
}

// The surface point a sample at screen position `position` (raster pixels) sees: where the view ray
// through that exact position meets the tangent plane of the pixel it falls in (its centre's point at
// view distance `dist`, unit normal qn), and that centre's point itself where the ray runs within a few
// degrees of the plane or meets it more than a quarter of the distance away. A pixel's centre is up to
// 0.7 pixels off the slice's line, and on a surface seen at a grazing angle that is enough to lift an
// open plane's horizon above its own tangent (an open floor came out 0.93 at 75 degrees); on the
// tangent plane the sample stays on the slice, where a plane occludes nothing.
SR_FN vec3 aoSurfaceAt(RasterParams params, vec2 position, int qx, int qy, float dist, vec3 qn)
{
    vec3 centre = aoViewPoint(params, qx, qy, dist);
    SR_PRECISE float nx = position.x * 2.0f * params.aoInvWidth - 1.0f;
    SR_PRECISE float ny = position.y * 2.0f * params.aoInvHeight - 1.0f;
    vec3 r0 = aoViewPointNdc(params, vec2(nx, ny), 0.0f);
    vec3 r1 = aoViewPointNdc(params, vec2(nx, ny), 1.0f);
    vec3 dir = vec3(r1.x - r0.x, r1.y - r0.y, r1.z - r0.z);
    float facing = dotDet(dir, qn);
    SR_PRECISE float limit = 0.05f * sqrtDet(dotDet(dir, dir));  // about 3 degrees
    if (!(abs(facing) > limit)) return centre;
    vec3 toCentre = vec3(centre.x - r0.x, centre.y - r0.y, centre.z - r0.z);
    SR_PRECISE float d = dotDet(toCentre, qn) * recipDet(facing);
    SR_PRECISE float moved = abs(d - dist);
    if (!(moved <= 0.25f * dist)) return centre;
    SR_PRECISE float x = r0.x + dir.x * d;
    SR_PRECISE float y = r0.y + dir.y * d;
    SR_PRECISE float z = r0.z + dir.z * d;
    return vec3(x, y, z);
}

// Raises the slice's horizon on one side with the surface point q a sample sees (aoSurfaceAt): the
// cosine of the angle between v and the direction to it, weighted down to the tangent plane's over the
// outer AO_FALLOFF of the radius (nothing beyond it occludes).
SR_FN void aoSample(RasterParams params, AoPixel a, SR_INOUT(AoSlice) s, vec3 q, bool negative)
{
    vec3 delta = vec3(q.x - a.p.x, q.y - a.p.y, q.z - a.p.z);
    float lengthSq = dotDet(delta, delta);
    if (!(lengthSq > 0.0f)) return;
    float len = sqrtDet(lengthSq);
    SR_PRECISE float c = dotDet(delta, a.v) * rsqrtDet(lengthSq);
    SR_PRECISE float weight = clamp((params.aoRadius - len) * params.aoInvFalloff, 0.0f, 1.0f);
    float low = negative ? s.lowCos0 : s.lowCos1;
    SR_PRECISE float h = low + (c - low) * weight;
    if (negative)
        s.horizonCos0 = max(s.horizonCos0, h);
    else
        s.horizonCos1 = max(s.horizonCos1, h);
}

// The slice's visible fraction: the closed form above, with the horizons no lower than the tangent
// plane (h in [gamma - pi/2, gamma + pi/2]), weighted by the projected normal's length.
SR_FN float aoSliceVisibility(AoSlice s)
{
    SR_PRECISE float h0 = 0.0f - acosDet(s.horizonCos0);
    SR_PRECISE float h1 = acosDet(s.horizonCos1);
    h0 = s.gamma + max(h0 - s.gamma, 0.0f - AO_HALF_PI);
    h1 = s.gamma + min(h1 - s.gamma, AO_HALF_PI);
    SR_PRECISE float arc0 = s.cosGamma + 2.0f * h0 * s.sinGamma - cosDet(2.0f * h0 - s.gamma);
    SR_PRECISE float arc1 = s.cosGamma + 2.0f * h1 * s.sinGamma - cosDet(2.0f * h1 - s.gamma);
    SR_PRECISE float visibility = s.projLength * (arc0 + arc1) * 0.25f;
    return visibility;
}

// The pixel's ambient occlusion from the sum of its slices' visibilities: their mean, not clamped to 1.
// A slice's unoccluded value is L (cos(gamma) + gamma sin(gamma)), which is 1 only on average over the
// slice directions (from cos(a) to about 1.4 for a normal a = 60 degrees from v), so clamping a pixel's
// few slices would bias ao_denoise's mean of 16 rotations low (a tilted open floor came out 0.92); the
// value shade and the AOV read is clamped to [0, 1] (aoShaded).
SR_FN float aoResolve(RasterParams params, float sum)
{
    SR_PRECISE float mean = sum * params.aoInvSlices;
    return max(mean, 0.0f);
}

// The AO shade applies, from the value BUF_AO holds.
SR_FN float aoShaded(float stored)
{
    return clamp(stored, 0.0f, 1.0f);
}

// Stage ao_denoise: the weight of neighbour (dx, dy) in -2..2 of pixel a at view point q. A separable
// tent (1, 2, 2, 2, 1) per axis, whose weights sum to 2 over each residue class mod 4, so that it takes
// each of aoPattern's 16 rotations equally on a flat surface; 0 for a neighbour farther from the pixel's
// tangent plane than AO_DENOISE_PLANE of its view distance (another surface: the filter keeps edges).
SR_FN float aoDenoiseWeight(AoPixel a, float dist, vec3 q, int dx, int dy)
{
    vec3 delta = vec3(q.x - a.p.x, q.y - a.p.y, q.z - a.p.z);
    SR_PRECISE float limit = AO_DENOISE_PLANE * dist;
    if (abs(dotDet(delta, a.n)) > limit) return 0.0f;
    float wx = dx == -2 || dx == 2 ? 1.0f : 2.0f;
    float wy = dy == -2 || dy == 2 ? 1.0f : 2.0f;
    return wx * wy;
}

// The coordinate ao_denoise reads for neighbour coordinate q (x + dx or y + dy, |d| <= 2) on an axis of
// `size` pixels: outside the image, the pixel 4 further in, which has the same rotation of the pattern
// (aoPattern), so the filter still weighs every rotation alike at the border (cut off there, an open
// floor's border pixels came out 10% dark with one slice); -1 where that too is outside (an image
// narrower than 5 pixels).
SR_FN int aoDenoiseNeighbour(int q, uint size)
{
    int n = int(size);
    int r = q < 0 ? q + 4 : (q >= n ? q - 4 : q);
    return r >= 0 && r < n ? r : -1;
}

// The denoised value from the weighted sum and the weights' total (at least the pixel's own 4).
SR_FN float aoDenoiseResolve(float sum, float weights)
{
    SR_PRECISE float mean = sum * recipDet(weights);
    return clamp(mean, 0.0f, 1.0f);
}

SR_NAMESPACE_END

#endif  // RASTER_SHARED_AO_H
