// front_ends_test.cpp - one frame, every front end (issue 45): `raster render`, a `raster batch`
// manifest and the C++ API (and, in python/tests/test_front_ends.py, the Python module) write the same
// PNG, the same EXR (every sample's id and depth included) and the same statistics, byte for byte, for
// the cases of tests/front_ends/every_setting.jsonl, which between them set every setting of the schema
// away from its default.
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "raster/raster.h"

#include "cli/commands.h"
#include "settings/schema.h"
#include "test_util.h"

namespace sr {
namespace {

using json = nlohmann::json;

// A case: the scene and every setting (manifest keys), over a small exact base.
struct Case {
    std::string scene = "builtin";
    json settings;
};

std::vector<Case> loadCases()
{
    std::ifstream file(test::sourceDir() + "/tests/front_ends/every_setting.jsonl");
    std::vector<Case> cases;
    for (std::string line; std::getline(file, line);) {
        if (line.empty()) continue;
        json given = json::parse(line);
        Case c;
        c.settings = {{"width", 48}, {"height", 32}, {"msaa", 1}, {"warmup", 0}, {"repeat", 1}};
        for (auto& [key, value] : given.items()) {
            if (key == "scene")
                c.scene = value.get<std::string>();
            else
                c.settings[key] = value;
        }
        cases.push_back(c);
    }
    return cases;
}

// A setting's value as the command line and Settings::set(name, text) write it.
std::string settingText(const json& value)
{
    if (value.is_string()) return value.get<std::string>();
    if (value.is_array()) {
        std::string text;
        for (const json& v : value) text += (text.empty() ? "" : ",") + settingText(v);
        return text;
    }
    return value.dump();
}

const Setting& byKey(const std::string& key)
{
    for (const Setting& s : settingsSchema())
        if (s.key() == key) return s;
    ADD_FAILURE() << "no setting " << key;
    return settingsSchema().front();
}

// The statistics as compared: everything but the times, which no two runs share, and what a device's
// history sets (its peak memory and the capacities of buffers that earlier frames grew): a process that
// drew other frames first reports more of both for the same frame.
json comparableStats(const std::string& path)
{
    std::ifstream file(path);
    std::stringstream text;
    text << file.rdbuf();
    json stats = json::parse(text.str(), nullptr, false);
    if (stats.is_discarded()) return json("unreadable " + path);
    for (const char* key : {"stages_ms", "gpu_total_ms", "peak_device_bytes", "capacities"}) stats.erase(key);
    if (stats.contains("lod")) stats["lod"].erase("build_ms");
    return stats;
}

}  // namespace

// Between them the cases set every setting of the schema, each away from its default: a setting added to
// the schema fails here until a case draws with it.
TEST(FrontEnds, TheCasesSetEverySettingAwayFromItsDefault)
{
    const std::vector<Case> cases = loadCases();
    ASSERT_FALSE(cases.empty());
    const RenderOptions defaults = imageRenderOptions();
    for (const Setting& s : settingsSchema()) {
        bool set = false;
        for (const Case& c : cases) {
            if (!c.settings.contains(s.key())) continue;
            RenderOptions o = defaults;
            Status stored = setSetting(o, s, c.settings[s.key()], s.key());
            ASSERT_TRUE(stored.ok()) << stored.error().message;
            set = set || settingValue(o, s) != settingValue(defaults, s);
        }
        EXPECT_TRUE(set) << "no case sets " << s.key() << " away from its default";
    }
}

TEST(FrontEnds, EverySettingDrawsTheSameFilesThroughEveryFrontEnd)
{
    const std::vector<Case> cases = loadCases();
    test::ScratchDir dir("front-ends");
    // The manifest: one job per case.
    std::string manifest;
    for (size_t k = 0; k < cases.size(); ++k) {
        json job = cases[k].settings;
        job["scene"] = cases[k].scene;
        job["output"] = fmt::format("batch{}.png", k);
        job["aov"] = fmt::format("batch{}.exr", k);
        job["stats"] = fmt::format("batch{}.json", k);
        manifest += job.dump() + "\n";
    }
    std::ofstream(dir.file("m.jsonl")) << manifest;
    test::ToolRun batch = test::runTool("batch m.jsonl -q", dir.file(""));
    ASSERT_EQ(batch.exitCode, 0) << batch.stderrText;

    auto device = raster::Device::open(raster::Backend::Auto);
    ASSERT_TRUE(device.ok()) << device.error().message;
    for (size_t k = 0; k < cases.size(); ++k) {
        const Case& c = cases[k];
        SCOPED_TRACE(c.scene + " " + c.settings.dump());
        // The command line.
        std::string args =
            fmt::format("render {} -q -o cli{}.png --aov cli{}.exr --stats cli{}.json", c.scene, k, k, k);
        for (auto& [key, value] : c.settings.items())
            args += value.is_boolean() ? (value.get<bool>() ? " --" + byKey(key).name : "")
                                       : " --" + byKey(key).name + " " + settingText(value);
        test::ToolRun cli = test::runTool(args, dir.file(""));
        ASSERT_EQ(cli.exitCode, 0) << args << ": " << cli.stderrText;

        // The C++ API, as an application writes the same three files.
        auto scene = raster::Scene::load(c.scene);
        ASSERT_TRUE(scene.ok()) << scene.error().message;
        raster::Settings settings;
        for (auto& [key, value] : c.settings.items()) {
            raster::Status set = value.is_boolean() ? settings.set(key, value.get<bool>())
                                                    : settings.set(key, settingText(value));
            ASSERT_TRUE(set.ok()) << set.error().message;
        }
        auto session = raster::Session::create(*device, *scene);
        ASSERT_TRUE(session.ok()) << session.error().message;
        raster::RenderRequest request;
        request.surfaceAovs = true;
        auto frame = session->render(raster::Camera::fromSpec("auto"), settings, request);
        ASSERT_TRUE(frame.ok()) << frame.error().message;
        raster::Status png = raster::writePng(*frame, dir.file(fmt::format("api{}.png", k)));
        ASSERT_TRUE(png.ok()) << png.error().message;
        raster::Status exr = raster::writeExr(*frame, dir.file(fmt::format("api{}.exr", k)));
        ASSERT_TRUE(exr.ok()) << exr.error().message;
        std::ofstream(dir.file(fmt::format("api{}.json", k))) << frame->statsJson << "\n";

        for (const char* front : {"batch", "api"}) {
            SCOPED_TRACE(front);
            const std::string cliPng = dir.file(fmt::format("cli{}.png", k));
            const std::string cliExr = dir.file(fmt::format("cli{}.exr", k));
            const std::string cliJson = dir.file(fmt::format("cli{}.json", k));
            EXPECT_FALSE(test::fileBytes(cliPng).empty());
            EXPECT_TRUE(test::fileBytes(cliPng) ==
                        test::fileBytes(dir.file(fmt::format("{}{}.png", front, k))));
            EXPECT_TRUE(test::fileBytes(cliExr) ==
                        test::fileBytes(dir.file(fmt::format("{}{}.exr", front, k))));
            EXPECT_EQ(comparableStats(cliJson),
                      comparableStats(dir.file(fmt::format("{}{}.json", front, k))));
        }
    }
}

// The README's command overview is the table the command line's help is made from (cli/commands.h): a
// subcommand added, renamed or re-described there without `raster commands` pasted into the README
// fails here.
TEST(FrontDoor, ReadmeCommandOverviewIsTheTable)
{
    std::ifstream file(test::sourceDir() + "/README.md");
    ASSERT_TRUE(file.good());
    std::stringstream text;
    text << file.rdbuf();
    const std::string readme = text.str();
    const std::string begin = "<!-- command overview: generated by `raster commands`; begin -->\n";
    const std::string end = "<!-- command overview: end -->";
    const size_t a = readme.find(begin), b = readme.find(end);
    ASSERT_NE(a, std::string::npos) << "README lacks the overview's start marker";
    ASSERT_NE(b, std::string::npos) << "README lacks the overview's end marker";
    EXPECT_EQ(readme.substr(a + begin.size(), b - a - begin.size()), commandsMarkdown())
        << "README's command overview differs from the table: paste `build/raster commands` between the "
           "markers";
    // And `raster commands` prints it.
    test::ToolRun run = test::runTool("commands");
    EXPECT_EQ(run.exitCode, 0);
    EXPECT_EQ(run.stdoutText, commandsMarkdown());
}

}  // namespace sr
