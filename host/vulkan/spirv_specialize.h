// spirv_specialize.h - a compute module specialized before a CPU device translates it.
//
// Lavapipe turns a pipeline's SPIR-V into NIR, inlines every call and optimizes the result before it
// consults its shader cache, on every run (docs/benchmark.md, "Start-up"). It sets the specialization
// constants during that translation but removes the code they disable only after inlining, so a module
// whose alpha test, MSAA or shading branches are off still inlines all of them: the clusters module
// grew from 9,000 to 64,000 instructions there, and took 0.57 s of a 1 s start-up.
//
// specializeModule does that part first, on the SPIR-V, with SPIRV-Tools' optimizer: the constants'
// values are frozen into the module, loads and stores of function variables that are assigned once
// are forwarded, constants are propagated, and the branches, instructions and functions they leave
// unreachable are removed. Nothing else is transformed (no inlining, no arithmetic rewritten beyond
// folding operations on constants, which SPIR-V defines exactly), so the module computes what the
// original did with those constants.
#ifndef RASTER_SPIRV_SPECIALIZE_H
#define RASTER_SPIRV_SPECIALIZE_H

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "base/result.h"

namespace sr {

// One specialization constant: its SpecId and the 32 bits of its value (a bool is 0 or 1).
struct SpecValue {
    uint32_t id;
    uint32_t bits;
};

// The module `code` (`bytes` long) with `values` frozen in and the code they leave unreachable removed.
// Constants the module does not declare are ignored; those it declares and `values` does not name keep
// their defaults. An error means the optimizer refused the module.
Result<std::vector<uint32_t>> specializeModule(const uint32_t* code, size_t bytes,
                                               const std::vector<SpecValue>& values);

// The key under which the pipeline cache keeps the module `specializeModule(code, bytes, values)` makes:
// the version of the passes, the module's length and FNV-1a hash, and the values.
std::string specializationKey(const uint32_t* code, size_t bytes, const std::vector<SpecValue>& values);

}  // namespace sr

#endif  // RASTER_SPIRV_SPECIALIZE_H
