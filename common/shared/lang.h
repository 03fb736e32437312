// shared/lang.h - what makes one header valid C++, CUDA and GLSL: type names, built-ins and macros.
//
// C++ and CUDA get GLSL's vector and matrix types from GLM and the GLSL built-ins GLM lacks; GLSL gets
// no-op versions of the C++ qualifiers. Every file of the shared family includes this first (through
// raster_shared.h) and wraps its C++ definitions in SR_NAMESPACE_BEGIN / SR_NAMESPACE_END.
//
// SR_FN: a function callable from host and device. SR_OUT / SR_INOUT / SR_ARRAY_INOUT: GLSL parameter
// qualifiers, references in C++. SR_PRECISE: GLSL `precise` (NoContraction) on float expressions whose
// bits matter; C++ and CUDA get the same effect from -ffp-contract=off and --fmad=false.
#ifndef RASTER_SHARED_LANG_H
#define RASTER_SHARED_LANG_H

#if defined(__cplusplus)
#include <cmath>
#include <cstdint>
#include <cstring>

#include <glm/glm.hpp>
#if defined(__CUDACC__)
#define SR_FN __host__ __device__ inline
#else
#define SR_FN inline
#endif
#define SR_OUT(T) T&
#define SR_INOUT(T) T&
#define SR_ARRAY_INOUT(T, name, N) T(&name)[N]
#define SR_PRECISE
namespace sr {
using glm::abs;
using glm::ceil;
using glm::clamp;
using glm::cross;
using glm::dot;
using glm::floor;
using glm::fract;
using glm::ivec2;
using glm::ivec3;
using glm::ivec4;
using glm::mat4;
using glm::max;
using glm::min;
using glm::mix;
using glm::normalize;
using glm::pow;
using glm::sqrt;
using glm::uvec2;
using glm::uvec4;
using glm::vec2;
using glm::vec3;
using glm::vec4;
using uint = std::uint32_t;
using std::int64_t;
using std::uint64_t;

// GLSL built-ins that GLM lacks on the device or spells differently.
SR_FN uint floatBitsToUint(float f)
{
#if defined(__CUDA_ARCH__)
    return __float_as_uint(f);
#else
    uint u;
    std::memcpy(&u, &f, sizeof u);
    return u;
#endif
}
SR_FN float uintBitsToFloat(uint u)
{
#if defined(__CUDA_ARCH__)
    return __uint_as_float(u);
#else
    float f;
    std::memcpy(&f, &u, sizeof f);
    return f;
#endif
}
// Round half to even, the rounding of GLSL roundEven and of the x86 default mode.
SR_FN float roundEven(float x)
{
#if defined(__CUDA_ARCH__)
    return rintf(x);
#else
    return std::nearbyint(x);
#endif
}
SR_FN bool isFinite(float x)
{
    return (floatBitsToUint(x) & 0x7f800000u) != 0x7f800000u;
}
// a / b where only an estimate is needed (the caller makes the result exact): CUDA's fast division (at
// most 2 ulp off, without the correctly rounded division's branch to a slow path), '/' elsewhere (Vulkan
// allows 2.5 ulp).
SR_FN float divideEstimate(float a, float b)
{
#if defined(__CUDA_ARCH__)
    return __fdividef(a, b);
#else
    return a / b;
#endif
}
}  // namespace sr
#else  // GLSL
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#define SR_FN
#define SR_OUT(T) out T
#define SR_INOUT(T) inout T
#define SR_ARRAY_INOUT(T, name, N) inout T name[N]
#define SR_PRECISE precise
bool isFinite(float x)
{
    return (floatBitsToUint(x) & 0x7f800000u) != 0x7f800000u;
}
float divideEstimate(float a, float b)
{
    return a / b;
}
#endif

#if defined(__cplusplus)
#define SR_NAMESPACE_BEGIN namespace sr {
#define SR_NAMESPACE_END }  // namespace sr
#else
#define SR_NAMESPACE_BEGIN
#define SR_NAMESPACE_END
#endif

#endif  // RASTER_SHARED_LANG_H
