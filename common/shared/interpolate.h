// shared/interpolate.h - nvdiffrast's interpolate at one pixel, evaluated alike on the host and on a
// CUDA device (cuda/interpolate.cu): the attributes of the pixel's triangle weighted by rasterize's
// perspective-correct (u, v) and 1 - u - v. Included after raster_shared.h (lang.h's macros); a GLSL
// port is not needed (Vulkan devices interpolate on the host).
#ifndef RASTER_SHARED_INTERPOLATE_H
#define RASTER_SHARED_INTERPOLATE_H

SR_NAMESPACE_BEGIN

// interpolateSlot's answer for a fourth channel that is no triangle's id + 1 and not 0.
#define INTERPOLATE_BAD_SLOT 0xFFFFFFFFu

// The triangle named by rasterize's fourth channel `slot` (id + 1, 0 where empty) among `triangles`:
// slot itself as a whole number, or INTERPOLATE_BAD_SLOT where it is not a whole number in 0..triangles
// (NaN included).
SR_FN uint interpolateSlot(float slot, uint triangles)
{
    if (!(slot >= 0.0f && slot <= float(triangles))) return INTERPOLATE_BAD_SLOT;
    uint whole = uint(slot);
    return float(whole) == slot ? whole : INTERPOLATE_BAD_SLOT;
}

// u a0 + v a1 + (1 - u - v) a2, left to right, every product and sum rounded on its own (no backend fuses
// them: CUDA is built with --fmad=false, the host with -ffp-contract=off), so the host's and the
// device's values are the same bits.
SR_FN float interpolateValue(float u, float v, float a0, float a1, float a2)
{
    SR_PRECISE float w = 1.0f - u - v;
    SR_PRECISE float value = u * a0 + v * a1 + w * a2;
    return value;
}

SR_NAMESPACE_END

#endif  // RASTER_SHARED_INTERPOLATE_H
