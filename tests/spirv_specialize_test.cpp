// spirv_specialize_test.cpp - the modules a CPU device gets specialized to their constants
// (host/vulkan/spirv_specialize.h): the code a constant turns off is gone and the code it leaves on is
// kept, every specialized module of every CPU build is valid SPIR-V for Vulkan 1.2, the cache keys tell
// modules and values apart, and the raster tool draws the same bytes with and without specializing.
#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <spirv-tools/libspirv.hpp>

#include "raster_shared.h"
#include "test_util.h"
#include "vulkan/spirv_specialize.h"

#include "ao_cpu.spv.h"
#include "aovs_cpu.spv.h"
#include "clusters_cpu.spv.h"
#include "raster_tiles_chunked.spv.h"
#include "setup_cpu.spv.h"
#include "setup_lines_points_cpu.spv.h"
#include "shade_cpu.spv.h"
#include "stage_spirv.h"

namespace sr {
namespace {

struct Module {
    const char* name;
    const uint32_t* code;
    size_t bytes;
};
#define SR_MODULE(array)            \
    Module                          \
    {                               \
#array, array, sizeof array \
    }

// The names of the functions a module defines, read from its OpName and OpFunction instructions.
std::set<std::string> functionNames(const std::vector<uint32_t>& words)
{
    constexpr uint32_t kOpName = 5, kOpFunction = 54;
    std::map<uint32_t, std::string> names;
    std::set<uint32_t> functions;
    for (size_t at = 5; at < words.size();) {  // after the 5-word header
        const uint32_t count = words[at] >> 16, op = words[at] & 0xffffu;
        if (count == 0 || at + count > words.size()) break;
        if (op == kOpName && count > 2)
            names[words[at + 1]] = reinterpret_cast<const char*>(&words[at + 2]);  // nul-terminated
        if (op == kOpFunction) functions.insert(words[at + 2]);
        at += count;
    }
    std::set<std::string> out;
    for (uint32_t f : functions)
        if (names.count(f)) out.insert(names[f].substr(0, names[f].find('(')));
    return out;
}

std::vector<uint32_t> wordsOf(const Module& m)
{
    return std::vector<uint32_t>(m.code, m.code + m.bytes / sizeof(uint32_t));
}

std::vector<uint32_t> specialized(const Module& m, const std::vector<SpecValue>& values)
{
    Result<std::vector<uint32_t>> out = specializeModule(m.code, m.bytes, values);
    EXPECT_TRUE(out.ok()) << m.name << ": " << (out.ok() ? "" : out.error().message);
    return out.ok() ? *out : std::vector<uint32_t>{};
}

TEST(SpirvSpecialize, CodeAConstantTurnsOffIsGoneAndCodeItLeavesOnStays)
{
    // The alpha test of MASK materials (SPEC_MATERIALS) in the CPU builds that cover pixels.
    for (const Module& m :
         {SR_MODULE(kSpv_clusters_cpu), SR_MODULE(kSpv_setup_cpu), SR_MODULE(kSpv_raster_tiles_chunked)}) {
        SCOPED_TRACE(m.name);
        ASSERT_TRUE(functionNames(wordsOf(m)).count("alphaMaskCovers"));
        std::set<std::string> off = functionNames(specialized(m, {{SPEC_MATERIALS, 0}, {SPEC_SAMPLES, 1}}));
        std::set<std::string> on = functionNames(specialized(m, {{SPEC_MATERIALS, 1}, {SPEC_SAMPLES, 1}}));
        EXPECT_FALSE(off.count("alphaMaskCovers"));
        EXPECT_FALSE(off.count("sampleTexture"));
        EXPECT_TRUE(on.count("alphaMaskCovers"));
        EXPECT_TRUE(on.count("sampleTexture"));
    }
    // shade: textures only where a material has one (SHADE_USES_BASE_TEXTURES), lines and points only
    // where the scene has some, the hit-count colours only in that mode.
    const Module shade = SR_MODULE(kSpv_shade_cpu);
    auto shadeWith = [&](uint32_t mode, uint32_t uses) {
        return functionNames(specialized(shade, {{SPEC_SAMPLES, 1},
                                                 {SPEC_RESOLVE, 0},
                                                 {SPEC_SHADE_MODE, mode},
                                                 {SPEC_SHADE_USES, uses},
                                                 {SPEC_SHADE_SSAA, 1}}));
    };
    std::set<std::string> plain = shadeWith(SHADING_LAMBERT, SHADE_USES_COLORS);
    std::set<std::string> textured = shadeWith(
        SHADING_LAMBERT, SHADE_USES_MATERIALS | SHADE_USES_BASE_TEXTURES | SHADE_USES_LINEAR_FILTER);
    std::set<std::string> lines = shadeWith(SHADING_LAMBERT, SHADE_USES_LINES_POINTS);
    EXPECT_FALSE(plain.count("sampleTexture"));
    EXPECT_TRUE(textured.count("sampleTexture"));
    EXPECT_FALSE(plain.count("lineParameter"));
    EXPECT_TRUE(lines.count("lineParameter"));
    EXPECT_TRUE(plain.count("surfaceAt") && textured.count("surfaceAt"));
    EXPECT_FALSE(plain.count("hitCountColor"));
    EXPECT_TRUE(shadeWith(SHADING_HIT_COUNT, 0).count("hitCountColor"));
}

TEST(SpirvSpecialize, EverySpecializedModuleIsValidSpirv)
{
    spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_2);
    std::string diagnostic;
    tools.SetMessageConsumer(
        [&](spv_message_level_t, const char*, const spv_position_t&, const char* m) { diagnostic = m; });
    struct Case {
        Module module;
        std::vector<std::vector<SpecValue>> values;
    };
    const std::vector<std::vector<SpecValue>> coverage = {
        {{SPEC_MATERIALS, 0}, {SPEC_SAMPLES, 1}, {SPEC_COUNT_HITS, 0}},
        {{SPEC_MATERIALS, 1}, {SPEC_SAMPLES, 4}, {SPEC_COUNT_HITS, 1}},
        {{SPEC_MATERIALS, 0}, {SPEC_SAMPLES, 16}, {SPEC_COUNT_HITS, 0}}};
    std::vector<std::vector<SpecValue>> shading;
    for (uint32_t mode : {SHADING_LAMBERT, SHADING_BLINN_PHONG, SHADING_HIT_COUNT, SHADING_MIP})
        for (uint32_t uses : {0u, uint32_t(SHADE_USES_COLORS), uint32_t(SHADE_USES_ALL)})
            for (uint32_t samples : {1u, 4u})
                shading.push_back({{SPEC_SAMPLES, samples},
                                   {SPEC_RESOLVE, samples > 1 ? 1u : 0u},
                                   {SPEC_SHADE_MODE, mode},
                                   {SPEC_SHADE_USES, uses},
                                   {SPEC_SHADE_SSAA, samples > 1 ? 2u : 1u}});
    const std::vector<Case> cases = {{SR_MODULE(kSpv_clusters_cpu), coverage},
                                     {SR_MODULE(kSpv_setup_cpu), coverage},
                                     {SR_MODULE(kSpv_setup_lines_points_cpu), coverage},
                                     {SR_MODULE(kSpv_raster_tiles_chunked), coverage},
                                     {SR_MODULE(kSpv_shade_cpu), shading},
                                     {SR_MODULE(kSpv_aovs_cpu), {{}}},
                                     {SR_MODULE(kSpv_ao_cpu), {{}}},
                                     {SR_MODULE(kSpv_bin_count), {{}}},
                                     {SR_MODULE(kSpv_bin_fill), {{}}},
                                     {SR_MODULE(kSpv_vertex), {{}}}};
    for (const Case& c : cases) {
        for (const std::vector<SpecValue>& values : c.values) {
            SCOPED_TRACE(specializationKey(c.module.code, c.module.bytes, values) + " of " + c.module.name);
            std::vector<uint32_t> out = specialized(c.module, values);
            ASSERT_FALSE(out.empty());
            diagnostic.clear();
            EXPECT_TRUE(tools.Validate(out)) << diagnostic;
            EXPECT_LE(out.size() * sizeof(uint32_t), c.module.bytes);
        }
    }
}

TEST(SpirvSpecialize, KeysTellModulesAndValuesApart)
{
    const Module a = SR_MODULE(kSpv_setup_cpu), b = SR_MODULE(kSpv_clusters_cpu);
    const std::vector<SpecValue> v1 = {{SPEC_MATERIALS, 0}, {SPEC_SAMPLES, 1}};
    const std::vector<SpecValue> v4 = {{SPEC_MATERIALS, 0}, {SPEC_SAMPLES, 4}};
    EXPECT_EQ(specializationKey(a.code, a.bytes, v1), specializationKey(a.code, a.bytes, v1));
    EXPECT_NE(specializationKey(a.code, a.bytes, v1), specializationKey(a.code, a.bytes, v4));
    EXPECT_NE(specializationKey(a.code, a.bytes, v1), specializationKey(b.code, b.bytes, v1));
    EXPECT_NE(specializationKey(a.code, a.bytes, v1), specializationKey(a.code, a.bytes, {}));
    // One word of the module changed: another key.
    std::vector<uint32_t> changed = wordsOf(a);
    changed[changed.size() / 2] ^= 1u;
    EXPECT_NE(specializationKey(a.code, a.bytes, v1), specializationKey(changed.data(), a.bytes, v1));
}

// The frames whose pipelines take every specialization constant through its values, drawn by the raster
// tool with the modules specialized and as built: the same bytes, colour and AOVs (ids, depth, surface).
TEST(SpirvSpecialize, TheToolDrawsTheSameBytesWithAndWithoutSpecializing)
{
    bool skip = false;
    if (!test::openBackend("vulkan", skip)) {
        if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
        FAIL() << "no Vulkan device";
    }
    test::ScratchDir dir("sr_specialize");
    const std::vector<std::string> frames = {
        "builtin",  // MSAA 4 and the clusters of the built-in scene
        "builtin:checker --msaa 1 --texture-filter trilinear --shading phong",
        "builtin:checker --msaa 2 --ssaa 2 --texture-filter nearest --uv-interpolation affine",
        "builtin:cutout --msaa 1 --shading lambert",  // MASK materials: the alpha test
        "builtin:cutout --msaa 4 --shading hits",
        "builtin:lowpoly --msaa 1 --tessellate pn --wireframe",  // lines over the triangles
        "builtin:dense --msaa 1 --primitive-mode points --point-size 3",
        "builtin:ao --msaa 1 --ao gtao --shading ao",
        "builtin:checker --msaa 1 --raster-method float --shading mip",
    };
    for (size_t f = 0; f < frames.size(); ++f) {
        SCOPED_TRACE(frames[f]);
        std::vector<unsigned char> images[2], aovs[2];
        for (int off = 0; off < 2; ++off) {
            const std::string stem = dir.file(std::to_string(f) + (off ? "-off" : "-on"));
            test::ToolRun run = test::runTool(
                "render " + frames[f] + " -q --backend vulkan --width 48 --height 40 -o " + stem +
                    ".png --aov " + stem + ".exr",
                "", std::string("env RASTER_PIPELINE_CACHE=off RASTER_SPECIALIZE=") + (off ? "off" : "on"));
            ASSERT_EQ(run.exitCode, 0) << run.stderrText;
            EXPECT_EQ(run.stderrText, "");
            images[off] = test::fileBytes(stem + ".png");
            aovs[off] = test::fileBytes(stem + ".exr");
            ASSERT_FALSE(images[off].empty());
            ASSERT_FALSE(aovs[off].empty());
        }
        EXPECT_TRUE(images[0] == images[1]);
        EXPECT_TRUE(aovs[0] == aovs[1]);
    }
    // Any other value is refused, in one line.
    test::ToolRun bad =
        test::runTool("render builtin -q --backend vulkan --width 8 --height 8 -o " + dir.file("bad.png"), "",
                      "env RASTER_SPECIALIZE=maybe");
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_EQ(bad.stderrText, "raster: error: RASTER_SPECIALIZE is 'maybe'; it takes on or off\n");
}

}  // namespace
}  // namespace sr
