// cli_test.cpp - the `raster` command line's usage errors: a misspelt command or option names the
// nearest valid one, and a scene path that is not a scene file says what it is. Each is one line on
// stderr, "raster: error: ...", with exit code 2.
#include <sys/stat.h>

#include <algorithm>
#include <string>

#include <gtest/gtest.h>

#include "cli/usage_errors.h"
#include "test_util.h"

namespace sr::test {
namespace {

// The one error line of a run that must fail as a usage error, without its "raster: error: " prefix.
std::string usageError(const std::string& args)
{
    ToolRun run = runTool(args);
    EXPECT_EQ(run.exitCode, 2) << args << ": " << run.stderrText;
    EXPECT_EQ(std::count(run.stderrText.begin(), run.stderrText.end(), '\n'), 1) << args << run.stderrText;
    EXPECT_EQ(run.stdoutText, "") << args;
    const std::string prefix = "raster: error: ";
    EXPECT_EQ(run.stderrText.rfind(prefix, 0), 0u) << run.stderrText;
    std::string line = run.stderrText.substr(std::min(prefix.size(), run.stderrText.size()));
    if (!line.empty() && line.back() == '\n') line.pop_back();
    return line;
}

TEST(CliSuggest, EditDistanceCountsSwapsAsOneEdit)
{
    EXPECT_EQ(editDistance("render", "render"), 0u);
    EXPECT_EQ(editDistance("rendr", "render"), 1u);
    EXPECT_EQ(editDistance("mssa", "msaa"), 1u);
    EXPECT_EQ(editDistance("comapre", "compare"), 1u);
    EXPECT_EQ(editDistance("", "bench"), 5u);
    EXPECT_EQ(editDistance("kitten", "sitting"), 3u);
}

TEST(CliSuggest, NearestNameWithinAThirdOfTheWordOrTheOnlyPrefix)
{
    const std::vector<std::string> commands = {"render", "compare", "bench",   "view",
                                               "study",  "batch",   "settings"};
    EXPECT_EQ(nearestName("rendr", commands), "render");
    EXPECT_EQ(nearestName("comapre", commands), "compare");
    EXPECT_EQ(nearestName("setings", commands), "settings");
    EXPECT_EQ(nearestName("sett", commands), "settings");  // the only name it starts
    EXPECT_EQ(nearestName("xyzzy", commands), "");
    EXPECT_EQ(nearestName("b", commands), "");  // starts two names: no guess
    EXPECT_EQ(nearestName("mssa", {"msaa", "ssaa", "width"}), "msaa");
}

TEST(CliErrors, UnknownCommandNamesTheNearest)
{
    EXPECT_EQ(usageError("rendr"), "unknown command 'rendr'; did you mean 'render'?");
    EXPECT_EQ(usageError("comapre a.png b.png"), "unknown command 'comapre'; did you mean 'compare'?");
    std::string far = usageError("frobnicate");
    EXPECT_EQ(far.rfind("unknown command 'frobnicate' (commands: render, compare,", 0), 0u) << far;
    std::string none = usageError("");
    EXPECT_EQ(none.rfind("a command is required: render, compare,", 0), 0u) << none;
}

TEST(CliErrors, UnknownOptionNamesTheNearest)
{
    EXPECT_EQ(usageError("render --mssa 4 -o /nonexistent/x.png"),
              "unknown option '--mssa' for 'raster render'; did you mean '--msaa'?");
    EXPECT_EQ(usageError("render --widht=64"),
              "unknown option '--widht' for 'raster render'; did you mean '--width'?");
    EXPECT_EQ(usageError("compare a.png b.png --tolerence 3"),
              "unknown option '--tolerence' for 'raster compare'; did you mean '--tolerance'?");
    EXPECT_EQ(usageError("render --frobnicate"),
              "unknown option '--frobnicate' for 'raster render' (raster render --help lists them)");
    // A negative number is a value, not an option: --orbit's azimuths still parse.
    ScratchDir dir("cli-negative");
    ToolRun run = runTool("render --backend vulkan --width 8 --height 8 -q --frames 2 --orbit -45:45 -o " +
                          dir.file("f%d.png"));
    EXPECT_EQ(run.stderrText.find("unknown option"), std::string::npos) << run.stderrText;
}

TEST(CliErrors, SceneThatIsNotAFileSaysWhatItIs)
{
    ScratchDir dir("cli-scene");
    ASSERT_EQ(::mkdir(dir.file("models").c_str(), 0755), 0);
    EXPECT_EQ(usageError("render " + dir.file("models")),
              "cannot load '" + dir.file("models") +
                  "': it is a directory, not a scene file (.gltf, .glb, .obj, .ply or .stl)");
    EXPECT_EQ(usageError("render " + dir.file("missing")),
              "cannot load '" + dir.file("missing") + "': No such file or directory");
}

}  // namespace
}  // namespace sr::test
