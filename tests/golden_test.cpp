// golden_test.cpp - the Vulkan compute backend against the CUDA goldens in tests/golden/.
//
// Each scene of tests/golden/scenes.txt is rendered by the `raster` tool with --backend vulkan (lavapipe
// in CI) and compared with the PNG and EXR that CUDA produced on a GPU (ci/gpu-check --goldens).
// Criteria (docs/building-and-testing.md, "Goldens"): coverage and triangle ids identical, depth
// bit-identical, colour within 1/255 per channel. A golden whose provenance does not say it came from CUDA
// fails.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/compare.h"
#include "io/image_io.h"
#include "test_util.h"

namespace sr::test {
namespace {

struct GoldenScene {
    std::string name;
    std::string args;
};

// gtest prints a parameter through this instead of dumping its bytes.
void PrintTo(const GoldenScene& scene, std::ostream* os)
{
    *os << scene.name;
}

// A scene's arguments with @assimp (manifest shorthand for Debian's assimp-testmodels folder, which
// SR_ASSIMP_MODELS overrides) expanded.
std::string expandAssimp(std::string args)
{
    const char* env = std::getenv("SR_ASSIMP_MODELS");
    const std::string root = env ? env : "/usr/share/assimp/models";
    for (size_t at = args.find("@assimp"); at != std::string::npos;
         at = args.find("@assimp", at + root.size()))
        args.replace(at, 7, root);
    return args;
}

std::vector<GoldenScene> loadManifest()
{
    std::vector<GoldenScene> scenes;
    std::ifstream in(sourceDir() + "/tests/golden/scenes.txt");
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream words(line);
        GoldenScene scene;
        words >> scene.name;
        std::getline(words >> std::ws, scene.args);
        scenes.push_back(scene);
    }
    return scenes;
}

class GoldenTest : public ::testing::TestWithParam<GoldenScene> {};

TEST_P(GoldenTest, VulkanComputeMatchesCudaGolden)
{
    const GoldenScene& scene = GetParam();
    std::string golden = sourceDir() + "/tests/golden/" + scene.name;

    std::ifstream provenanceFile(golden + ".json");
    ASSERT_TRUE(provenanceFile) << "missing " << golden << ".json: regenerate with ci/gpu-check --goldens";
    nlohmann::json provenance = nlohmann::json::parse(provenanceFile);
    ASSERT_EQ(provenance.value("backend", ""), "cuda") << golden << ".json: a golden must come from CUDA";
    ASSERT_EQ(provenance.value("args", ""), scene.args) << golden << ".json was made for other arguments";

    std::string out = ::testing::TempDir() + "golden_" + scene.name;
    // The tool runs from the source tree so that asset paths in the manifest resolve.
    ToolRun run = runTool("render " + expandAssimp(scene.args) + " --backend vulkan -q -o " + out +
                              ".png --aov " + out + ".exr",
                          sourceDir());
    ASSERT_EQ(run.exitCode, 0) << run.stderrText;

    CompareTolerance exact;
    auto aov = compareFiles(golden + ".exr", out + ".exr", exact);
    ASSERT_TRUE(aov.ok()) << aov.error().message;
    EXPECT_EQ(aov->coverageMismatches, 0u) << scene.name;
    EXPECT_EQ(aov->idMismatches, 0u) << scene.name;
    EXPECT_EQ(aov->maxDepthDiff, 0.0) << scene.name << " at " << aov->maxX << "," << aov->maxY;

    // Ambient occlusion (an --ao scene): the AO channel CUDA wrote and lavapipe's within 1/255.
    auto goldenAov = readAovExr(golden + ".exr");
    auto ownAov = readAovExr(out + ".exr");
    ASSERT_TRUE(goldenAov.ok() && ownAov.ok());
    ASSERT_EQ(goldenAov->hasAo(), ownAov->hasAo()) << scene.name;
    ASSERT_EQ(goldenAov->ao.size(), ownAov->ao.size()) << scene.name;
    double aoDiff = 0.0;
    for (size_t i = 0; i < ownAov->ao.size(); ++i)
        aoDiff = std::max(aoDiff, std::abs(double(goldenAov->ao[i]) - ownAov->ao[i]));
    EXPECT_LE(aoDiff, 1.0 / 255.0) << scene.name;

    CompareTolerance colour;
    colour.colorLsb = 1;
    auto png = compareFiles(golden + ".png", out + ".png", colour);
    ASSERT_TRUE(png.ok()) << png.error().message;
    EXPECT_LE(png->maxError, 1) << scene.name << " at " << png->maxX << "," << png->maxY;
}

INSTANTIATE_TEST_SUITE_P(Goldens, GoldenTest, ::testing::ValuesIn(loadManifest()), [](const auto& info) {
    std::string name = info.param.name;
    for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return name;
});

TEST(Goldens, ManifestIsComplete)
{
    // Catches an unreadable manifest, which would otherwise instantiate no golden test at all.
    EXPECT_GE(loadManifest().size(), 15u);
}

}  // namespace
}  // namespace sr::test
