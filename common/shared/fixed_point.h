// shared/fixed_point.h - deterministic division, the arithmetic every stage builds on.
//
// Vulkan lets OpFDiv be 2.5 ulp off while CUDA divides correctly rounded, so no float quotient whose bits
// matter may use '/': these build reciprocals from integer operations on the float's bits, which every
// backend executes identically. Part of raster_shared.h (included from there, not on its own); same
// three-language rules.
#ifndef RASTER_SHARED_FIXED_POINT_H
#define RASTER_SHARED_FIXED_POINT_H

SR_NAMESPACE_BEGIN

// floor(2^47 / m) for a 24-bit mantissa m (2^23 <= m < 2^24), from an estimate q within 3 of it: the
// exact remainder r = 2^47 - q m (a 32 x 32-bit product, which SIMD units multiply natively) moves q
// down while r < 0 and up while r >= m.
SR_FN uint floorQuotient47(uint m, uint q)
{
    int64_t r = int64_t(uint64_t(1) << 47) - int64_t(uint64_t(q) * uint64_t(m));
    for (int step = 0; step < 3; ++step) {
        if (r < int64_t(0)) {
            q = q - 1u;
            r = r + int64_t(m);
        }
        if (r >= int64_t(m)) {
            q = q + 1u;
            r = r - int64_t(m);
        }
    }
    return q;
}

// floor(2^47 / m) estimated by a float division and made exact by floorQuotient47. The quotient X lies in
// (2^23, 2^24], where floats are integers, so an estimate E at most 2.5 ulp (2.5) off is an integer with
// floor(X) - 2 <= E <= floor(X) + 3.
SR_FN uint quotient47NoDivide(uint m)
{
    return floorQuotient47(m, uint(divideEstimate(140737488355328.0f, float(m))));  // 2^47 / m
}

// Deterministic reciprocal. Vulkan only promises 2.5 ulp for OpFDiv while CUDA divides correctly
// rounded, so a plain '/' would let the backends disagree on snapped vertices and depth. This builds
// 1/b from integer operations on the float's bits, which every backend executes identically:
// b = m * 2^(E-150) with a 24-bit mantissa m, so 1/b = floor(2^47 / m) * 2^(103-E) up to < 1 ulp.
// Returns +-0 for |b| >= 2^126 and +-inf for zero or denormal b.
//
// The quotient comes from quotient47NoDivide, which tests/shared_math_test.cpp checks against the 64-bit
// division for every mantissa. A 64-bit division is a software routine everywhere: about 70
// instructions on NVIDIA GPUs (ncu, sweep-0.5px: setup's three snaps spent a fifth of its instructions
// there) and one scalar division per lane on a CPU device.
SR_FN float recipDet(float b)
{
    uint bits = floatBitsToUint(b);
    uint sign = bits & 0x80000000u;
    uint e = (bits >> 23) & 0xffu;
    if (e == 0u) return uintBitsToFloat(sign | 0x7f800000u);
    if (e >= 253u) return uintBitsToFloat(sign);
    uint q = quotient47NoDivide((bits & 0x7fffffu) | 0x800000u);  // in (2^23, 2^24]
    if (q == (1u << 24)) return uintBitsToFloat(sign | ((254u - e) << 23));
    return uintBitsToFloat(sign | ((253u - e) << 23) | (q & 0x7fffffu));
}

SR_FN float divDet(float a, float b)
{
    SR_PRECISE float r = a * recipDet(b);
    return r;
}

SR_NAMESPACE_END

#endif  // RASTER_SHARED_FIXED_POINT_H
