// shared/interpolate.h - nvdiffrast's interpolate at one pixel, evaluated alike on the host
// (raster::interpolate) and on a CUDA device (cuda/interpolate.cu): the attributes of the pixel's
// triangle weighted by rasterize's perspective-correct (u, v) and 1 - u - v. Included after
// raster_shared.h (lang.h's macros); C++ and CUDA alone (it takes pointers): Vulkan devices interpolate
// on the host.
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

// What interpolatePixel found wrong with a pixel: its fourth channel is no triangle's id + 1 (nor 0), or
// it names `triangle`, which has a vertex index beyond the attributes' rows.
struct InterpolateFault {
    bool badSlot;
    bool badTriangle;
    uint triangle;
};

// One pixel of rasterize's output, `rast` (its four floats), over its view's attributes `attr`
// (vertices x channels) and `triangles` (triangleCount x 3 indices): the `channels` interpolated values
// written to `out`, zeros where the pixel is empty or at fault.
SR_FN InterpolateFault interpolatePixel(const float* rast, const float* attr, const uint* triangles,
                                        uint triangleCount, size_t vertices, size_t channels, float* out)
{
    InterpolateFault fault = {false, false, 0u};
    const uint slot = interpolateSlot(rast[3], triangleCount);
    fault.badSlot = slot == INTERPOLATE_BAD_SLOT;
    bool drawn = slot != 0u && !fault.badSlot;
    const uint* corner = drawn ? triangles + 3 * size_t(slot - 1u) : nullptr;
    if (drawn && (corner[0] >= vertices || corner[1] >= vertices || corner[2] >= vertices)) {
        fault.badTriangle = true;
        fault.triangle = slot - 1u;
        drawn = false;
    }
    for (size_t c = 0; c < channels; ++c)
        out[c] = drawn ? interpolateValue(rast[0], rast[1], attr[corner[0] * channels + c],
                                          attr[corner[1] * channels + c], attr[corner[2] * channels + c])
                       : 0.0f;
    return fault;
}

SR_NAMESPACE_END

#endif  // RASTER_SHARED_INTERPOLATE_H
