// stage_table_test.cpp - the stage table (common/shared/stages.h) against what it stands for: every
// stage's files exist in the checkout, its shader's group size is the table's, the names are unique,
// the ids run 0..STAGE_COUNT-1 in table order, and the lines CMake reads off the file (SR_STAGES) are
// the stages C++ sees.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "raster_shared.h"
#include "render/compute_device.h"
#include "test_util.h"

namespace sr {
namespace {

using test::sourceDir;

std::string readFile(const std::string& path)
{
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

// One row of the table as the preprocessor expands it, with its arguments as written.
struct Row {
    uint32_t id;
    std::string idName, name, kind;
};

std::vector<Row> expandedRows()
{
    std::vector<Row> rows;
#define SR_TEST_ROW(ID, name, function, threads, kind) rows.push_back({STAGE_##ID, #ID, #name, #kind});
    SR_STAGE_TABLE(SR_TEST_ROW)
#undef SR_TEST_ROW
    return rows;
}

// The rows as CMake reads them: the lines that start with `X(`, with the same regular expression.
std::vector<Row> textRows()
{
    std::vector<Row> rows;
    std::istringstream lines(readFile(sourceDir() + "/common/shared/stages.h"));
    const std::regex stageLine(R"(^ *X\()");
    const std::regex row(R"(^ *X\( *([A-Z0-9_]+) *, *([a-z0-9_]+) *,.*, *(PLAIN|METHOD|SHADE) *\))");
    std::smatch m;
    for (std::string line; std::getline(lines, line);) {
        if (!std::regex_search(line, stageLine)) continue;
        if (std::regex_search(line, m, row))
            rows.push_back({uint32_t(rows.size()), m[1], m[2], m[3]});
        else
            ADD_FAILURE() << "CMake cannot read: " << line;
    }
    return rows;
}

// The value of a local_size_x expression: a product of numbers and the group-size constants of
// raster_shared.h (0 and a failure for anything else).
uint32_t evaluateSize(const std::string& expression)
{
    const std::map<std::string, uint32_t> constants = {{"GROUP_SIZE", GROUP_SIZE},
                                                       {"SCAN_GROUP_SIZE", SCAN_GROUP_SIZE},
                                                       {"TILE_SIZE", TILE_SIZE},
                                                       {"CLUSTER_LANES", CLUSTER_LANES},
                                                       {"CLUSTERS_PER_GROUP", CLUSTERS_PER_GROUP}};
    uint32_t value = 1;
    std::istringstream factors(expression);
    for (std::string factor; std::getline(factors, factor, '*');) {
        factor = std::regex_replace(factor, std::regex(R"(^\s+|\s+$)"), "");
        if (!factor.empty() && factor.find_first_not_of("0123456789") == std::string::npos) {
            value *= uint32_t(std::stoul(factor));
        } else if (constants.count(factor)) {
            value *= constants.at(factor);
        } else {
            ADD_FAILURE() << "unknown factor '" << factor << "' in local_size_x = " << expression;
            return 0;
        }
    }
    return value;
}

// Invocations per group of compute_glsl/<name>.comp on a GPU, from its `layout(local_size_x...) in;`.
uint32_t shaderGroupSize(const std::string& name)
{
    const std::string text = readFile(sourceDir() + "/compute_glsl/" + name + ".comp");
    std::smatch m;
    if (!std::regex_search(text, m,
                           std::regex(R"(layout\s*\(\s*local_size_x(_id)?\s*=\s*([^,)]+?)\s*[,)])"))) {
        ADD_FAILURE() << name << ".comp declares no local_size_x";
        return 0;
    }
    if (m[1].matched) {
        // A group size from a specialization constant: constant 0, the lanes of a raster_tiles group,
        // which the Vulkan device sets to TILE_SIZE^2 on a GPU, one per tile pixel as the CUDA block
        // (host/vulkan/vulkan_device.cpp; fewer, longer lanes on a CPU device).
        EXPECT_EQ(m[2].str(), "0") << name;
        return TILE_SIZE * TILE_SIZE;
    }
    return evaluateSize(m[2]);
}

TEST(StageTable, EveryStageHasItsCudaAndGlslFiles)
{
    for (uint32_t stage = 0; stage < STAGE_COUNT; ++stage) {
        const std::string name = stageName(stage);
        EXPECT_TRUE(std::filesystem::is_regular_file(sourceDir() + "/cuda/" + name + ".cuh")) << name;
        EXPECT_TRUE(std::filesystem::is_regular_file(sourceDir() + "/compute_glsl/" + name + ".comp"))
            << name;
    }
}

TEST(StageTable, NamesAreUniqueAndUnknownPastTheEnd)
{
    std::set<std::string> names;
    for (uint32_t stage = 0; stage < STAGE_COUNT; ++stage) names.insert(stageName(stage));
    EXPECT_EQ(names.size(), size_t(STAGE_COUNT));
    EXPECT_STREQ(stageName(STAGE_COUNT), "unknown");
    EXPECT_STREQ(stageName(UINT32_MAX), "unknown");
}

TEST(StageTable, IdsAreTheRowsInOrder)
{
    const std::vector<Row> rows = expandedRows();
    ASSERT_EQ(rows.size(), size_t(STAGE_COUNT));
    for (uint32_t i = 0; i < rows.size(); ++i) {
        EXPECT_EQ(rows[i].id, i) << rows[i].idName;
        EXPECT_EQ(rows[i].name, stageName(i));
    }
}

TEST(StageTable, CMakeReadsTheSameStages)
{
    const std::vector<Row> expanded = expandedRows();
    const std::vector<Row> text = textRows();
    ASSERT_EQ(text.size(), expanded.size());
    for (size_t i = 0; i < text.size(); ++i) {
        EXPECT_EQ(text[i].idName, expanded[i].idName) << i;
        EXPECT_EQ(text[i].name, expanded[i].name) << i;
        EXPECT_EQ(text[i].kind, expanded[i].kind) << i;
    }
}

TEST(StageTable, GroupSizesAreTheShadersLocalSize)
{
    for (uint32_t stage = 0; stage < STAGE_COUNT; ++stage) {
        EXPECT_EQ(stageGroupSize(stage), shaderGroupSize(stageName(stage))) << stageName(stage);
        EXPECT_GT(stageGroupSize(stage), 0u) << stageName(stage);
    }
    EXPECT_EQ(stageGroupSize(STAGE_COUNT), 0u);
}

TEST(StageTable, MethodStagesAreTheOnesEachRasterMethodRebuilds)
{
    // CMake compiles these once more per raster method, VulkanDevice picks their module by
    // Dispatch::rasterMethod and CUDA launches them through launchMethodStage.
    std::vector<std::string> method;
    for (uint32_t stage = 0; stage < STAGE_COUNT; ++stage)
        if (methodStage(stage)) method.push_back(stageName(stage));
    EXPECT_EQ(method,
              (std::vector<std::string>{"clusters", "setup", "bin_count", "bin_fill", "raster_tiles"}));
    EXPECT_FALSE(methodStage(STAGE_COUNT));
}

}  // namespace
}  // namespace sr
