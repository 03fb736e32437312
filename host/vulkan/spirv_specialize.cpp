// spirv_specialize.cpp - see spirv_specialize.h.
#include "vulkan/spirv_specialize.h"

#include <spirv-tools/optimizer.hpp>

#include <string>
#include <unordered_map>

#include "vulkan/pipeline_cache.h"

namespace sr {

// Changes with the passes below, so that a cache never hands out a module specialized differently.
constexpr uint32_t kPassesVersion = 1;

std::string specializationKey(const uint32_t* code, size_t bytes, const std::vector<SpecValue>& values)
{
    std::string key = fmt::format("v{} {} {:016x}", kPassesVersion, bytes, fnv1a(code, bytes));
    for (const SpecValue& v : values) key += fmt::format(" {}={}", v.id, v.bits);
    return key;
}

Result<std::vector<uint32_t>> specializeModule(const uint32_t* code, size_t bytes,
                                               const std::vector<SpecValue>& values)
{
    std::unordered_map<uint32_t, std::vector<uint32_t>> defaults;
    for (const SpecValue& v : values) defaults[v.id] = {v.bits};
    spvtools::Optimizer optimizer(SPV_ENV_VULKAN_1_2);
    std::string diagnostic;
    optimizer.SetMessageConsumer(
        [&](spv_message_level_t level, const char*, const spv_position_t&, const char* message) {
            if (level <= SPV_MSG_ERROR && diagnostic.empty()) diagnostic = message;
        });
    // The constants become ordinary constants, and so do the expressions of them (glslang writes
    // `(SHADE_USES & SHADE_USES_MATERIALS) == 0u` as a specialization-constant operation); a function
    // variable stored once (a `bool masked = ...`) becomes its value, so that constant propagation reaches
    // the branches it guards; then what no longer runs goes: dead branches, dead instructions, functions no
    // longer called.
    optimizer.RegisterPass(spvtools::CreateSetSpecConstantDefaultValuePass(defaults))
        .RegisterPass(spvtools::CreateFreezeSpecConstantValuePass())
        .RegisterPass(spvtools::CreateFoldSpecConstantOpAndCompositePass())
        .RegisterPass(spvtools::CreateLocalSingleBlockLoadStoreElimPass())
        .RegisterPass(spvtools::CreateLocalSingleStoreElimPass())
        .RegisterPass(spvtools::CreateCCPPass())
        .RegisterPass(spvtools::CreateDeadBranchElimPass())
        .RegisterPass(spvtools::CreateAggressiveDCEPass())
        .RegisterPass(spvtools::CreateEliminateDeadFunctionsPass());
    // The modules are ours, validated when they were built (CMakeLists.txt) and by the tests; validating
    // again would cost more than the passes.
    spvtools::OptimizerOptions options;
    options.set_run_validator(false);
    std::vector<uint32_t> out;
    if (!optimizer.Run(code, bytes / sizeof(uint32_t), &out, options))
        return makeError(ExitCode::Runtime, "specializing a compute module for the CPU device failed: {}",
                         diagnostic.empty() ? "no diagnostic" : diagnostic);
    return out;
}

}  // namespace sr
