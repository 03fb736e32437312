// batch_test.cpp - `raster batch`: shard and device choice, manifest parsing and its one-line errors,
// turntable expansion, every output equal to a direct `raster render` of the same job, resume (done
// jobs skipped, changed ones rendered again), failing jobs reported without stopping the batch, and a
// batch killed mid-way leaving no final file a rerun would trust.
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "batch/manifest.h"
#include "batch/outputs.h"
#include "batch/shard.h"
#include "batch/batch_runner.h"
#include "io/image_io.h"
#include "settings/schema.h"
#include "test_util.h"

namespace sr::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// ---- shards and devices -----------------------------------------------------------------------

TEST(BatchShard, ShardSpecs)
{
    auto s = parseShardSpec("2/5");
    ASSERT_TRUE(s.ok());
    EXPECT_EQ(s->index, 2u);
    EXPECT_EQ(s->count, 5u);
    EXPECT_EQ(s->source, "--shard");
    for (const char* bad :
         {"3/2", "2/2", "a/b", "1/0", "-1/2", "1/2/3", "", "/2", "1/", " 1/2", "1/2 ", "1"}) {
        auto r = parseShardSpec(bad);
        ASSERT_FALSE(r.ok()) << bad;
        EXPECT_EQ(r.error().code, ExitCode::Usage);
        EXPECT_TRUE(isOneLine(r.error().message));
        EXPECT_EQ(r.error().message.rfind(fmt::format("invalid --shard '{}'", bad), 0), 0u)
            << r.error().message;
    }
}

TEST(BatchShard, SlurmArrays)
{
    using Env = std::map<std::string, std::string>;
    auto none = shardFromEnvironment(Env{});
    ASSERT_TRUE(none.ok());
    EXPECT_EQ(none->count, 1u);
    EXPECT_EQ(none->source, "none");
    // --array=0-3: id and count.
    auto a = shardFromEnvironment(Env{{"SLURM_ARRAY_TASK_ID", "2"}, {"SLURM_ARRAY_TASK_COUNT", "4"}});
    ASSERT_TRUE(a.ok()) << a.error().message;
    EXPECT_EQ(a->index, 2u);
    EXPECT_EQ(a->count, 4u);
    EXPECT_EQ(a->source, "slurm");
    // --array=5-8: numbered from the minimum.
    auto b = shardFromEnvironment(Env{{"SLURM_ARRAY_TASK_ID", "7"},
                                      {"SLURM_ARRAY_TASK_MIN", "5"},
                                      {"SLURM_ARRAY_TASK_MAX", "8"},
                                      {"SLURM_ARRAY_TASK_COUNT", "4"}});
    ASSERT_TRUE(b.ok()) << b.error().message;
    EXPECT_EQ(b->index, 2u);
    EXPECT_EQ(b->count, 4u);
    // --array=0-8:2 (ids 0, 2, 4, 6, 8).
    auto c = shardFromEnvironment(Env{{"SLURM_ARRAY_TASK_ID", "6"},
                                      {"SLURM_ARRAY_TASK_MIN", "0"},
                                      {"SLURM_ARRAY_TASK_MAX", "8"},
                                      {"SLURM_ARRAY_TASK_STEP", "2"},
                                      {"SLURM_ARRAY_TASK_COUNT", "5"}});
    ASSERT_TRUE(c.ok()) << c.error().message;
    EXPECT_EQ(c->index, 3u);
    EXPECT_EQ(c->count, 5u);
    // --array=1,4,9 has no regular numbering; a task id alone says nothing about the count.
    for (const Env& bad : {Env{{"SLURM_ARRAY_TASK_ID", "4"},
                               {"SLURM_ARRAY_TASK_MIN", "1"},
                               {"SLURM_ARRAY_TASK_MAX", "9"},
                               {"SLURM_ARRAY_TASK_COUNT", "3"}},
                           Env{{"SLURM_ARRAY_TASK_ID", "3"}},
                           Env{{"SLURM_ARRAY_TASK_ID", "4"}, {"SLURM_ARRAY_TASK_COUNT", "4"}},
                           Env{{"SLURM_ARRAY_TASK_ID", "x"}, {"SLURM_ARRAY_TASK_COUNT", "4"}}}) {
        auto r = shardFromEnvironment(bad);
        ASSERT_FALSE(r.ok()) << json(bad).dump();
        EXPECT_EQ(r.error().code, ExitCode::Usage);
        EXPECT_TRUE(isOneLine(r.error().message));
    }
    // --shard wins over the environment.
    auto d = chooseShard("1/3", Env{{"SLURM_ARRAY_TASK_ID", "0"}, {"SLURM_ARRAY_TASK_COUNT", "2"}});
    ASSERT_TRUE(d.ok());
    EXPECT_EQ(d->index, 1u);
    EXPECT_EQ(d->count, 3u);
}

TEST(BatchShard, ShardsCoverEveryJobOnce)
{
    for (uint32_t n = 1; n <= 7; ++n)
        for (size_t job = 0; job < 50; ++job) {
            int owners = 0;
            for (uint32_t i = 0; i < n; ++i) owners += inShard(Shard{i, n, "--shard"}, job);
            EXPECT_EQ(owners, 1) << job << " of " << n;
        }
}

TEST(BatchShard, DeviceLists)
{
    auto all = parseDeviceList("all");
    ASSERT_TRUE(all.ok());
    EXPECT_TRUE(all->all);
    auto two = parseDeviceList("0,3");
    ASSERT_TRUE(two.ok());
    EXPECT_EQ(two->indices, (std::vector<int>{0, 3}));
    for (const char* bad : {"", "x", "0,", ",1", "1,1", "-1", "0;1", "al"}) {
        auto r = parseDeviceList(bad);
        ASSERT_FALSE(r.ok()) << bad;
        EXPECT_TRUE(isOneLine(r.error().message));
        EXPECT_EQ(r.error().message.rfind(fmt::format("invalid --devices '{}'", bad), 0), 0u);
    }
}

// ---- manifests --------------------------------------------------------------------------------

TEST(BatchManifest, DefaultsMergeUnderJobsAndPathsJoinTheManifestFolder)
{
    const std::string text =
        "{\"defaults\": {\"width\": 100, \"shading\": \"lambert\"}}\n"
        "\n"
        "{\"scene\": \"a.obj\", \"output\": \"out/a.png\", \"exr\": \"out/a.exr\"}\r\n"
        "{\"scene\": \"builtin\", \"width\": 30, \"height\": 20, \"png\": \"/abs/b.png\", \"msaa\": 4, "
        "\"id\": \"b\"}\n";
    auto m = parseManifest(text, "m.jsonl", "dir", json{{"width", 8}, {"height", 9}, {"ssaa", 2}});
    ASSERT_TRUE(m.ok()) << m.error().message;
    ASSERT_EQ(m->jobs.size(), 2u);
    const ManifestJob& a = m->jobs[0];
    EXPECT_EQ(a.line, 3);
    EXPECT_EQ(a.scene, "dir/a.obj");
    EXPECT_EQ(a.output, "dir/out/a.png");
    EXPECT_EQ(a.aov, "dir/out/a.exr");
    EXPECT_EQ(a.options.settings.width, 100u);  // the header over the command line
    EXPECT_EQ(a.options.settings.height, 9u);   // the command line where nothing else says
    EXPECT_EQ(a.options.settings.ssaa, 2u);
    EXPECT_EQ(a.options.settings.shadingMode, uint32_t(SHADING_LAMBERT));
    EXPECT_EQ(a.id, "out/a.png");
    EXPECT_EQ(a.canonical["output"], "out/a.png");  // as written
    EXPECT_EQ(a.canonical["aov"], "out/a.exr");
    const ManifestJob& b = m->jobs[1];
    EXPECT_EQ(b.scene, "builtin");  // a name, not a path
    EXPECT_EQ(b.output, "/abs/b.png");
    EXPECT_EQ(b.options.settings.width, 30u);  // the job over the header
    EXPECT_EQ(b.options.settings.msaa, 4u);
    EXPECT_EQ(b.id, "b");
    EXPECT_EQ(b.options.camera, "auto");
    // Defaults spelled out or left implicit give the same canonical settings.
    auto explicitDefaults = parseManifest(
        "{\"scene\": \"builtin\", \"output\": \"x.png\", \"shading\": \"blinn-phong\", \"cull\": \"back\"}",
        "m", "", json::object());
    auto implicitDefaults =
        parseManifest("{\"scene\": \"builtin\", \"output\": \"x.png\"}", "m", "", json::object());
    ASSERT_TRUE(explicitDefaults.ok() && implicitDefaults.ok());
    EXPECT_EQ(explicitDefaults->jobs[0].canonical, implicitDefaults->jobs[0].canonical);
}

TEST(BatchManifest, ErrorsNameTheLine)
{
    const std::string good = "{\"scene\": \"builtin\", \"output\": \"a.png\"}\n";
    struct Case {
        std::string text, message;
    };
    for (const Case& c : std::vector<Case>{
             {good + good + "{\"scene\": \"builtin\", \"output\": \"b.png\",}\n",
              "m.jsonl:3: malformed JSON: "},
             {good + "{\"scene\": \"builtin\", \"output\": \"b.png\", \"widht\": 3}\n",
              "m.jsonl:2: unknown key 'widht'"},
             {"{\"scene\": \"builtin\", \"output\": \"b.png\", \"width\": -3}\n",
              "m.jsonl:1: width must be a non-negative integer, not -3"},
             {"{\"scene\": \"builtin\", \"output\": \"b.png\", \"width\": 0}\n",
              "m.jsonl:1: width 0 is outside 1..16384"},
             {"{\"scene\": \"builtin\", \"output\": \"b.png\", \"shading\": \"toon\"}\n",
              "m.jsonl:1: invalid shading 'toon'"},
             {"{\"scene\": \"builtin\", \"output\": \"b.png\", \"msaa\": 3}\n",
              "m.jsonl:1: msaa 3 is not one of 1, 2, 4, 8, 16"},
             {"{\"scene\": \"builtin\", \"output\": \"b.png\", \"camera\": \"orbit:1\"}\n", "m.jsonl:1: "},
             {"{\"scene\": \"builtin\", \"output\": \"b.png\", \"light_dir\": [1, 2]}\n",
              "m.jsonl:1: light_dir must be an array of three numbers"},
             {"{\"output\": \"b.png\"}\n", "m.jsonl:1: no 'scene'"},
             {"{\"scene\": \"builtin\"}\n", "m.jsonl:1: no 'output'"},
             {"{\"scene\": \"builtin\", \"output\": \"b.png\", \"png\": \"c.png\"}\n",
              "m.jsonl:1: 'output' and 'png'"},
             {good + "{\"defaults\": {\"width\": 3}}\n",
              "m.jsonl:2: the defaults line must be the first line"},
             {"{\"defaults\": {\"output\": \"x.png\"}}\n" + good, "m.jsonl:1: 'output' belongs to one job"},
             {"{\"scene\": \"builtin\", \"output\": \"b.png\", \"aov_samples\": true}\n",
              "m.jsonl:1: aov_samples needs an 'aov' file"},
             {"{\"scene\": \"builtin\", \"output\": \"b.png\", \"aov\": \"b.exr\", \"aov_samples\": true, "
              "\"msaa\": 16, \"ssaa\": 4}\n",
              "m.jsonl:1: aov_samples writes at most 64 samples per pixel, not 256"},
             {"{\"defaults\": {\"aov_samples\": true}}\n" + good,
              "m.jsonl:2: aov_samples needs an 'aov' file"},
             {"[1, 2]\n", "m.jsonl:1: expected a JSON object"},
             {"\n\n", "m.jsonl: no jobs"},
             // Numbers past a double's range (the parser throws out_of_range, not parse_error).
             {"{\"scene\": \"builtin\", \"output\": \"b.png\", \"width\": 1e400}\n",
              "m.jsonl:1: 'width' is a number outside the range of a double"},
             {good + "{\"scene\": \"builtin\", \"output\": \"b.png\", \"width\": -1e400}\n",
              "m.jsonl:2: 'width' is a number outside the range of a double"},
             {"{\"scene\": \"builtin\", \"output\": \"b.png\", \"ambient\": 1e400}\n",
              "m.jsonl:1: 'ambient' is a number outside the range of a double"},
             {"{\"scene\": \"builtin\", \"output\": \"b.png\", \"light_dir\": [1, 1e999, 0]}\n",
              "m.jsonl:1: 'light_dir'[1] is a number outside the range of a double"},
             {"{\"defaults\": {\"width\": 1e400}}\n" + good,
              "m.jsonl:1: 'defaults'.'width' is a number outside the range of a double"},
             {"{\"scene\": \"builtin\", \"output\": \"b.png\", \"width\": " + std::string(10 << 20, '9') +
                  "}\n",
              "m.jsonl:1: 'width' is a number outside the range of a double"}}) {
        auto m = parseManifest(c.text, "m.jsonl", "", json::object());
        ASSERT_FALSE(m.ok()) << c.text;
        EXPECT_EQ(m.error().code, ExitCode::Usage);
        EXPECT_TRUE(isOneLine(m.error().message)) << m.error().message;
        EXPECT_LT(m.error().message.size(), 300u);
        EXPECT_EQ(m.error().message.rfind(c.message, 0), 0u) << clippedText(m.error().message, 300);
    }
    auto cli = parseManifest(good, "m.jsonl", "", json{{"shading", "toon"}});
    ASSERT_FALSE(cli.ok());
    EXPECT_NE(cli.error().message.find("toon"), std::string::npos) << cli.error().message;
}

TEST(BatchManifest, TurntablesExpandIntoFrames)
{
    auto m = parseManifest(
        "{\"scene\": \"builtin\", \"orbit\": \"0:90\", \"frames\": 4, \"output\": \"t_%02d.png\", \"aov\": "
        "\"t_%d.exr\"}\n"
        "{\"scene\": \"builtin\", \"output\": \"single.png\"}\n",
        "m", "100%", json::object());
    ASSERT_TRUE(m.ok()) << m.error().message;
    auto frames = expandJobs(*m);
    ASSERT_TRUE(frames.ok()) << frames.error().message;
    ASSERT_EQ(frames->size(), 5u);
    EXPECT_EQ((*frames)[3].png, "100%/t_03.png");  // a % in the folder is no pattern
    EXPECT_EQ((*frames)[3].aov, "100%/t_3.exr");
    EXPECT_EQ((*frames)[3].azimuthDeg, 90.0f);
    EXPECT_EQ((*frames)[1].azimuthDeg, 30.0f);
    EXPECT_EQ((*frames)[1].settings["frame"], 1);
    EXPECT_EQ((*frames)[4].png, "100%/single.png");
    EXPECT_EQ((*frames)[0].sceneKey, (*frames)[4].sceneKey);

    struct Case {
        std::string text, message;
    };
    for (const Case& c : std::vector<Case>{
             {"{\"scene\": \"builtin\", \"orbit\": \"0:90\", \"output\": \"a.png\"}",
              "m:1: 'orbit' needs 'frames'"},
             {"{\"scene\": \"builtin\", \"frames\": 3, \"output\": \"a_%d.png\"}",
              "m:1: 'frames' needs 'orbit'"},
             {"{\"scene\": \"builtin\", \"orbit\": \"0:90\", \"frames\": 3, \"output\": \"a.png\"}",
              "m:1: invalid output 'a.png'"},
             {"{\"scene\": \"builtin\", \"orbit\": \"0\", \"frames\": 3, \"output\": \"a%d.png\"}",
              "m:1: invalid --orbit"},
             {"{\"scene\": \"builtin\", \"output\": \"a.png\"}\n{\"scene\": \"builtin\", \"output\": "
              "\"a.png\"}",
              "m:2: 'a.png' is also written by line 1"}}) {
        auto parsed = parseManifest(c.text, "m", "", json::object());
        ASSERT_TRUE(parsed.ok()) << parsed.error().message;
        auto expanded = expandJobs(*parsed);
        ASSERT_FALSE(expanded.ok()) << c.text;
        EXPECT_TRUE(isOneLine(expanded.error().message));
        EXPECT_EQ(expanded.error().message.rfind(c.message, 0), 0u) << expanded.error().message;
    }
}

// Every file a batch writes (outputs, statistics, sidecars) against every other and against what it
// reads (the manifest, scene files), by resolved path: through a link to a folder that does not exist
// yet, a job's stats on another job's sidecar or its own, stats on the manifest or on a scene.
TEST(BatchManifest, WrittenFilesCollideWithNoOtherFile)
{
    ScratchDir dir("batch-collide");
    fs::create_symlink("a", dir.file("link2"));  // a/ does not exist yet
    std::ofstream(dir.file("s.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    const std::string job = "{\"scene\": \"builtin\", ";
    struct Case {
        std::string text, message;
    };
    for (const Case& c :
         std::vector<Case>{{job + "\"output\": \"a/b.png\"}\n" + job + "\"output\": \"link2/b.png\"}\n",
                            "m.jsonl:2: 'link2/b.png' is also written by line 1"},
                           {job + "\"output\": \"a.png\", \"stats\": \"b.png.job.json\"}\n" + job +
                                "\"output\": \"b.png\"}\n",
                            "m.jsonl:2: 'b.png.job.json' (the sidecar of 'b.png') is also written by line 1"},
                           {job + "\"output\": \"a.png\", \"stats\": \"a.png.job.json\"}\n",
                            "m.jsonl:1: 'a.png.job.json' (the sidecar of 'a.png') is also written by line 1"},
                           {job + "\"output\": \"a.png\", \"stats\": \"./m.jsonl\"}\n",
                            "m.jsonl:1: './m.jsonl' would overwrite the manifest"},
                           {"{\"scene\": \"s.obj\", \"output\": \"a.png\"}\n" + job +
                                "\"output\": \"b.png\", \"aov\": "
                                "\"c.exr\", \"stats\": \"link2/../s.obj\"}\n",
                            "m.jsonl:2: 'link2/../s.obj' would overwrite the scene of line 1"}}) {
        SCOPED_TRACE(c.text);
        std::ofstream(dir.file("m.jsonl"), std::ios::binary) << c.text;
        auto m = loadManifest(dir.file("m.jsonl"), json::object());
        ASSERT_TRUE(m.ok()) << m.error().message;
        auto frames = expandJobs(*m);
        ASSERT_FALSE(frames.ok());
        std::string message = frames.error().message;  // with the folder left out, as the cases write it
        for (size_t at; (at = message.find(dir.file(""))) != std::string::npos;)
            message.erase(at, dir.file("").size());
        EXPECT_EQ(message, c.message);
    }
    EXPECT_FALSE(fs::exists(dir.file("a")));
    EXPECT_EQ(resolvedPath(dir.file("link2/b.png")), resolvedPath(dir.file("a/b.png")));
    EXPECT_EQ(resolvedPath(dir.file("link2/../s.obj")), resolvedPath(dir.file("s.obj")));
}

TEST(BatchOutputs, SidecarsAndTemporaries)
{
    ScratchDir dir("batch-outputs");
    const std::string png = dir.file("a.png");
    const json settings{{"width", 3}};
    EXPECT_FALSE(jobComplete(sidecarPath(png), sidecarJson(settings, "builtin"), {png}));
    const std::string bytes = "not really a png";
    ASSERT_TRUE(writeFileAtomically(png, bytes.data(), bytes.size()).ok());
    EXPECT_FALSE(fs::exists(temporaryPath(png)));
    const std::string sidecar = sidecarJson(settings, "builtin").dump();
    ASSERT_TRUE(writeFileAtomically(sidecarPath(png), sidecar.data(), sidecar.size()).ok());
    EXPECT_TRUE(jobComplete(sidecarPath(png), sidecarJson(settings, "builtin"), {png}));
    EXPECT_FALSE(jobComplete(sidecarPath(png), sidecarJson(json{{"width", 4}}, "builtin"), {png}));
    EXPECT_FALSE(jobComplete(sidecarPath(png), sidecarJson(settings, "builtin"), {png, dir.file("a.exr")}));
    // A scene file's size and time are part of the record.
    const std::string scene = dir.file("s.obj");
    std::ofstream(scene) << "v 0 0 0\n";
    EXPECT_TRUE(sidecarJson(settings, scene).contains("scene_file"));
    // Leftovers of killed runs go: temporaries of this host whose process has ended (a child that
    // exited; the older NAME.tmp.<pid> form too). The temporaries of a process still running (the test's
    // parent), of another host, of other outputs, and other files stay.
    const pid_t child = fork();
    if (child == 0) _exit(0);
    ASSERT_GT(child, 0);
    ASSERT_EQ(waitpid(child, nullptr, 0), child);
    const std::string own = temporaryPath("a.png");  // a.png.tmp.<host>.<pid>
    const std::string host = own.substr(10, own.rfind('.') - 10);
    const std::string dead = std::to_string(child), live = std::to_string(getppid());
    const std::vector<std::string> gone = {"a.png.tmp." + dead, "a.png.tmp." + host + "." + dead,
                                           "a.png.job.json.tmp." + host + "." + dead};
    const std::vector<std::string> kept = {
        "a.png.tmp." + host + "." + live, "a.png.tmp." + live, "a.png.tmp.otherhost." + dead,
        "b.png.tmp." + host + "." + dead, "a.png.tmp.x",       "a.png.tmpx"};
    for (const std::vector<std::string>* names : {&gone, &kept})
        for (const std::string& name : *names) std::ofstream(dir.file(name)) << "x";
    EXPECT_EQ(removeTemporaries({png, sidecarPath(png)}), gone.size());
    for (const std::string& name : gone) EXPECT_FALSE(fs::exists(dir.file(name))) << name;
    for (const std::string& name : kept) EXPECT_TRUE(fs::exists(dir.file(name))) << name;
    EXPECT_TRUE(fs::exists(png));
}

// ---- the command line -------------------------------------------------------------------------

std::string raster()
{
    const char* exe = std::getenv("SR_RASTER_EXE");
    return exe ? exe : SR_RASTER_EXE;
}

void writeText(const std::string& path, const std::string& text)
{
    std::ofstream(path, std::ios::binary) << text;
}

json summaryOf(const ToolRun& run)
{
    json summary = json::parse(run.stdoutText, nullptr, false);
    EXPECT_FALSE(summary.is_discarded()) << run.stdoutText;
    return summary;
}

// PNGs and, where both paths are given, EXRs identical: colour, ids and depth.
::testing::AssertionResult sameImages(const std::string& pngA, const std::string& pngB,
                                      const std::string& exrA = "", const std::string& exrB = "")
{
    auto a = readPng(pngA), b = readPng(pngB);
    if (!a.ok() || !b.ok()) return ::testing::AssertionFailure() << "unreadable " << pngA << " or " << pngB;
    if (a->width != b->width || a->pixels != b->pixels)
        return ::testing::AssertionFailure() << "colours differ: " << pngA << " vs " << pngB;
    if (exrA.empty()) return ::testing::AssertionSuccess();
    auto ea = readAovExr(exrA), eb = readAovExr(exrB);
    if (!ea.ok() || !eb.ok()) return ::testing::AssertionFailure() << "unreadable " << exrA << " or " << exrB;
    if (std::count_if(ea->id.begin(), ea->id.end(), [](uint32_t id) { return id != EMPTY_ID; }) == 0)
        return ::testing::AssertionFailure() << exrA << " shows nothing";
    if (ea->id != eb->id) return ::testing::AssertionFailure() << "ids differ: " << exrA << " vs " << exrB;
    if (ea->depth != eb->depth) return ::testing::AssertionFailure() << "depths differ: " << exrA;
    return ::testing::AssertionSuccess();
}

class BatchToolTest : public BackendTest {};

// Every output is what `raster render` writes for the same options; a rerun skips every job; a changed
// job (and only it) renders again; shards split the work and each renders only its own.
TEST_P(BatchToolTest, OutputsEqualDirectRendersAndRerunsSkip)
{
    ScratchDir dir("batch");
    const std::string backend = " --backend " + GetParam();
    const std::string jobs =
        "{\"defaults\": {\"width\": 64, \"height\": 48}}\n"
        "{\"scene\": \"builtin\", \"camera\": \"orbit:30,20,9\", \"output\": \"out/a.png\", \"aov\": "
        "\"out/a.exr\", \"stats\": \"out/a.json\"}\n"
        "{\"scene\": \"builtin\", \"msaa\": 4, \"shading\": \"normals\", \"model\": "
        "\"rotate:0,30,0,scale:1.25\", "
        "\"output\": \"out/b.png\", \"aov\": \"out/b.exr\"}\n"
        "{\"scene\": \"builtin\", \"orbit\": \"0:90\", \"frames\": 3, \"camera\": \"orbit:0,20,9\", "
        "\"model\": \"translate:0.25,0,0\", \"output\": "
        "\"out/t_%d.png\", \"aov\": \"out/t_%d.exr\"}\n";
    writeText(dir.file("m.jsonl"), jobs);
    ToolRun run = runTool("batch m.jsonl" + backend, dir.file(""));
    ASSERT_EQ(run.exitCode, 0) << run.stderrText;
    json summary = summaryOf(run);
    EXPECT_EQ(summary["rendered"], 5);
    EXPECT_EQ(summary["jobs"]["skipped"], 0);
    EXPECT_EQ(summary["failed"], 0);
    EXPECT_EQ(summary["scene_loads"]["count"], 1);  // one scene, loaded once
    EXPECT_GT(summary["per_frame_ms"]["gpu"]["mean"].get<double>(), 0.0);
    EXPECT_EQ(summary["devices"][0]["backend"], GetParam());

    const std::string common =
        backend + " --width 64 --height 48 -q -o " + dir.file("r.png") + " --aov " + dir.file("r.exr");
    ToolRun a = runTool("render --camera orbit:30,20,9" + common);
    ASSERT_EQ(a.exitCode, 0) << a.stderrText;
    EXPECT_TRUE(
        sameImages(dir.file("out/a.png"), dir.file("r.png"), dir.file("out/a.exr"), dir.file("r.exr")));
    std::ifstream stats(dir.file("out/a.json"));
    EXPECT_EQ(json::parse(stats)["backend"], GetParam());
    ToolRun b = runTool("render --msaa 4 --shading normals --model rotate:0,30,0,scale:1.25" + common);
    ASSERT_EQ(b.exitCode, 0) << b.stderrText;
    EXPECT_TRUE(
        sameImages(dir.file("out/b.png"), dir.file("r.png"), dir.file("out/b.exr"), dir.file("r.exr")));
    for (int k = 0; k < 3; ++k) {
        ToolRun t =
            runTool(fmt::format("render --camera orbit:{},20,9 --model translate:0.25,0,0", 45 * k) + common);
        ASSERT_EQ(t.exitCode, 0) << t.stderrText;
        EXPECT_TRUE(sameImages(dir.file(fmt::format("out/t_{}.png", k)), dir.file("r.png"),
                               dir.file(fmt::format("out/t_{}.exr", k)), dir.file("r.exr")))
            << "frame " << k;
    }

    ToolRun again = runTool("batch m.jsonl" + backend, dir.file(""));
    ASSERT_EQ(again.exitCode, 0) << again.stderrText;
    EXPECT_EQ(summaryOf(again)["jobs"]["skipped"], 5);
    EXPECT_EQ(summaryOf(again)["rendered"], 0);

    // One job changed: it alone renders again. A missing output makes its job render again too.
    std::string changed = jobs;
    changed.replace(changed.find("\"msaa\": 4"), 9, "\"msaa\": 2");
    writeText(dir.file("m.jsonl"), changed);
    fs::remove(dir.file("out/t_1.exr"));
    ToolRun third = runTool("batch m.jsonl" + backend, dir.file(""));
    ASSERT_EQ(third.exitCode, 0) << third.stderrText;
    EXPECT_EQ(summaryOf(third)["rendered"], 2);
    EXPECT_EQ(summaryOf(third)["jobs"]["skipped"], 3);

    // Shards 0/2 and 1/2 of a fresh folder render disjoint halves, together everything.
    ScratchDir shards("batch-shards");
    writeText(shards.file("m.jsonl"), jobs);
    ToolRun s0 = runTool("batch m.jsonl --shard 0/2" + backend, shards.file(""));
    ToolRun s1 = runTool("batch m.jsonl" + backend, shards.file(""),
                         "env SLURM_ARRAY_TASK_ID=1 SLURM_ARRAY_TASK_COUNT=2");
    ASSERT_EQ(s0.exitCode, 0) << s0.stderrText;
    ASSERT_EQ(s1.exitCode, 0) << s1.stderrText;
    EXPECT_EQ(summaryOf(s0)["rendered"], 3);
    EXPECT_EQ(summaryOf(s1)["rendered"], 2);
    EXPECT_EQ(summaryOf(s1)["shard"]["source"], "slurm");
    EXPECT_TRUE(fs::exists(shards.file("out/t_0.png")) && fs::exists(shards.file("out/t_2.png")) &&
                fs::exists(shards.file("out/a.png")));
    EXPECT_TRUE(sameImages(shards.file("out/t_1.png"), dir.file("out/t_1.png")));
    ToolRun whole = runTool("batch m.jsonl" + backend, shards.file(""));
    EXPECT_EQ(summaryOf(whole)["jobs"]["skipped"], 5);
}

// A job whose scene cannot be loaded fails alone: the others are written, the summary names it with its
// one-line error, the exit code is 1.
TEST_P(BatchToolTest, AFailingJobDoesNotStopTheBatch)
{
    ScratchDir dir("batch-fail");
    writeText(dir.file("m.jsonl"),
              "{\"scene\": \"builtin\", \"width\": 32, \"height\": 32, \"output\": \"a.png\"}\n"
              "{\"scene\": \"missing.obj\", \"output\": \"m.png\"}\n"
              "{\"scene\": \"builtin\", \"width\": 32, \"height\": 32, \"output\": \"c.png\"}\n");
    ToolRun run = runTool("batch m.jsonl --devices 0 --backend " + GetParam(), dir.file(""));
    EXPECT_EQ(run.exitCode, 1) << run.stderrText;
    json summary = summaryOf(run);
    EXPECT_EQ(summary["rendered"], 2);
    EXPECT_EQ(summary["failed"], 1);
    ASSERT_EQ(summary["failures"].size(), 1u);
    EXPECT_EQ(summary["failures"][0]["line"], 2);
    const std::string error = summary["failures"][0]["error"];
    EXPECT_TRUE(isOneLine(error));
    EXPECT_NE(error.find("missing.obj"), std::string::npos) << error;
    EXPECT_TRUE(fs::exists(dir.file("a.png")) && fs::exists(dir.file("c.png")));
    EXPECT_FALSE(fs::exists(dir.file("m.png")));
}

INSTANTIATE_TEST_SUITE_P(Backends, BatchToolTest, ::testing::Values("vulkan", "cuda"),
                         [](const auto& info) { return info.param; });

TEST(BatchTool, BadRequestsAreOneLineUsageErrors)
{
    ScratchDir dir("batch-bad");
    const std::string good =
        "{\"scene\": \"builtin\", \"width\": 16, \"height\": 16, \"output\": \"a.png\"}\n";
    writeText(dir.file("good.jsonl"), good);
    writeText(dir.file("malformed.jsonl"), good + "{\"scene\": \"builtin\",, \"output\": \"b.png\"}\n");
    writeText(dir.file("unknown.jsonl"),
              good + "{\"scene\": \"builtin\", \"output\": \"b.png\", \"size\": 3}\n");
    writeText(dir.file("huge.jsonl"),
              good + "{\"scene\": \"builtin\", \"output\": \"b.png\", \"width\": 1e400}\n");
    struct Case {
        std::string args, message;
    };
    for (const Case& c : std::vector<Case>{
             {"batch missing.jsonl", "cannot read manifest 'missing.jsonl'"},
             {"batch malformed.jsonl", "malformed.jsonl:2: malformed JSON"},
             {"batch unknown.jsonl", "unknown.jsonl:2: unknown key 'size'"},
             {"batch huge.jsonl", "huge.jsonl:2: 'width' is a number outside the range of a double"},
             {"batch good.jsonl --shard 3/2", "invalid --shard '3/2'"},
             {"batch good.jsonl --shard a/b", "invalid --shard 'a/b'"},
             {"batch good.jsonl --devices x", "invalid --devices 'x'"},
             {"batch good.jsonl --devices 0,0", "invalid --devices '0,0'"},
             {"batch good.jsonl --backend vulkan --devices 7", "vulkan: device index 7 out of range"},
             {"batch good.jsonl --shading toon", "invalid --shading 'toon'"}}) {
        ToolRun run = runTool(c.args, dir.file(""));
        EXPECT_EQ(run.exitCode, 2) << c.args << ": " << run.stderrText;
        EXPECT_EQ(std::count(run.stderrText.begin(), run.stderrText.end(), '\n'), 1)
            << c.args << run.stderrText;
        EXPECT_EQ(run.stderrText.rfind("raster: error: " + c.message, 0), 0u)
            << c.args << ": " << run.stderrText;
    }
    EXPECT_FALSE(fs::exists(dir.file("a.png")));
}

// A stats JSON without what depends on timing or on the frames drawn before in the same session (a
// batch worker keeps one session per scene): GPU times, list capacities, redraws, peak memory.
json withoutHistory(json stats)
{
    for (const char* key : {"gpu_total_ms", "stages_ms", "capacities", "redraws", "peak_device_bytes"})
        stats.erase(key);
    if (stats.contains("lod")) stats["lod"].erase("build_ms");
    return stats;
}

std::string fileBytes(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Every setting of the schema, given in a manifest, writes the PNG, EXR and statistics `raster render`
// writes with the same options (the campaign found aov_samples accepted, echoed and ignored: 13 EXR
// channels where render wrote 21). Each key has a value other than its default, in a job with the
// settings that make it show (ao_radius with ao gtao, point_size with points, texture_filter on a
// textured scene, ...); the jobs run in one batch (sharing a worker's sessions), each against a
// `raster render` of its own.
TEST(BatchTool, EveryManifestKeyRendersAsRenderDoes)
{
    bool skip = false;
    if (!openBackend("vulkan", skip)) {
        if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
        return;
    }
    struct Job {
        std::string scene;
        std::vector<std::pair<std::string, std::string>> settings;  // key, command-line text
    };
    const std::vector<Job> jobs = {
        {"builtin",
         {{"width", "20"},
          {"height", "14"},
          {"camera", "orbit:30,20,9"},
          {"model", "rotate:10,20,30"},
          {"clusters", "on"}}},
        {"builtin",
         {{"shading", "phong"},
          {"cull", "none"},
          {"light_dir", "0.2,0.5,0.8"},
          {"light_color", "0.9,0.5,0.3"},
          {"ambient", "0.3"},
          {"specular", "0.6"},
          {"background", "0.3,0.2,0.1"},
          {"repeat", "2"},
          {"warmup", "2"}}},
        {"builtin",
         {{"ao", "gtao"},
          {"ao_radius", "0.5"},
          {"ao_slices", "2"},
          {"ao_steps", "4"},
          {"ao_denoise", "off"}}},
        {"builtin", {{"ao", "reference"}, {"ao_reference_rays", "8"}}},
        {"builtin:checker", {{"texture_filter", "nearest"}, {"uv_interpolation", "affine"}}},
        {"builtin", {{"msaa", "8"}, {"ssaa", "2"}, {"raster_method", "fixed4"}, {"aov_samples", "true"}}},
        {"builtin", {{"primitive_mode", "lines"}, {"line_width", "2"}}},
        {"builtin", {{"primitive_mode", "points"}, {"point_size", "3"}}},
        {"builtin", {{"wireframe", "true"}}},
        {"builtin:lowpoly", {{"tessellate", "pn"}, {"tess_edge_px", "4"}, {"tess_max_level", "4"}}},
        {"builtin:lowpoly", {{"lod", "on"}, {"lod_error_px", "2"}}},
    };
    std::set<std::string> covered;
    ScratchDir dir("batch-keys");
    std::string manifest = "{\"defaults\": {\"width\": 16, \"height\": 12, \"warmup\": 0}}\n";
    for (size_t k = 0; k < jobs.size(); ++k) {
        const std::string name = "j" + std::to_string(k);
        json job{{"scene", jobs[k].scene},
                 {"output", name + ".png"},
                 {"aov", name + ".exr"},
                 {"stats", name + ".json"}};
        for (const auto& [key, text] : jobs[k].settings) {
            const Setting* setting = findSetting(key);
            ASSERT_TRUE(setting) << key;
            auto value = parseSettingText(*setting, text, key);
            ASSERT_TRUE(value.ok()) << value.error().message;
            job[key] = *value;
            covered.insert(key);
        }
        manifest += job.dump() + "\n";
    }
    for (const Setting& setting : settingsSchema())
        EXPECT_TRUE(covered.count(setting.key())) << "no job sets '" << setting.key() << "'";
    writeText(dir.file("m.jsonl"), manifest);
    ToolRun batch = runTool("batch m.jsonl --backend vulkan -q", dir.file(""));
    ASSERT_EQ(batch.exitCode, 0) << batch.stderrText;
    for (size_t k = 0; k < jobs.size(); ++k) {
        const std::string name = "j" + std::to_string(k);
        std::map<std::string, std::string> options = {{"width", "16"}, {"height", "12"}, {"warmup", "0"}};
        for (const auto& [key, text] : jobs[k].settings) options[key] = text;
        std::string args = "render " + jobs[k].scene + " --backend vulkan -q";
        for (const auto& [key, text] : options) {
            const Setting* setting = findSetting(key);
            args += " --" + setting->name + (setting->type == SettingType::Bool ? "" : " " + text);
        }
        SCOPED_TRACE(args);
        ToolRun render =
            runTool(args + " -o r_" + name + ".png --aov r_" + name + ".exr --stats r_" + name + ".json",
                    dir.file(""));
        ASSERT_EQ(render.exitCode, 0) << render.stderrText;
        EXPECT_TRUE(sameImages(dir.file(name + ".png"), dir.file("r_" + name + ".png")));
        EXPECT_TRUE(fileBytes(dir.file(name + ".exr")) == fileBytes(dir.file("r_" + name + ".exr")))
            << "the EXRs differ";
        const json a = json::parse(fileBytes(dir.file(name + ".json")), nullptr, false);
        const json b = json::parse(fileBytes(dir.file("r_" + name + ".json")), nullptr, false);
        ASSERT_FALSE(a.is_discarded() || b.is_discarded());
        EXPECT_TRUE(withoutHistory(a) == withoutHistory(b))
            << json::diff(withoutHistory(a), withoutHistory(b));
    }
    auto samples = readAovExr(dir.file("j5.exr"));
    ASSERT_TRUE(samples.ok()) << samples.error().message;
    EXPECT_EQ(samples->sampleId.size(), 8u * 2u * 2u) << "every sample: msaa 8, ssaa 2";
}

// Input quoted in a message is cut to a readable length: a 10 MB unknown key, shading value, scene path
// or output name made a 10 MB stderr line and a 31 MB summary. Each still names what is wrong.
TEST(BatchTool, MessagesQuoteInputAtAReadableLength)
{
    ScratchDir dir("batch-long");
    const std::string huge(10 << 20, 'x');
    struct Case {
        std::string job, names;
    };
    for (const Case& c : std::vector<Case>{
             {"{\"scene\": \"builtin\", \"output\": \"a.png\", \"" + huge + "\": 1}", "unknown key"},
             {"{\"scene\": \"builtin\", \"output\": \"a.png\", \"shading\": \"" + huge + "\"}",
              "invalid shading"},
             {"{\"scene\": \"" + huge + ".obj\", \"output\": \"a.png\"}", "cannot load"},
             {"{\"scene\": \"builtin\", \"width\": 16, \"height\": 16, \"output\": \"" + huge + ".png\"}",
              "cannot write"}}) {
        SCOPED_TRACE(c.names);
        writeText(dir.file("m.jsonl"), c.job + "\n");
        ToolRun run = runTool("batch m.jsonl --backend vulkan --summary s.json", dir.file(""));
        EXPECT_NE(run.exitCode, 0);
        EXPECT_LT(run.stderrText.size(), 2000u) << run.stderrText.substr(0, 200);
        EXPECT_NE(run.stderrText.find(c.names), std::string::npos) << run.stderrText.substr(0, 200);
        EXPECT_NE(run.stderrText.find("(10485"), std::string::npos) << "the length is said";
        EXPECT_LT(run.stdoutText.size(), 20000u);
        if (fs::exists(dir.file("s.json"))) {
            EXPECT_LT(fs::file_size(dir.file("s.json")), 20000u);
        }
        fs::remove(dir.file("s.json"));
    }
    ToolRun render = runTool("render -q --shading " + std::string(100000, 'y'), dir.file(""));
    EXPECT_EQ(render.exitCode, 2);
    EXPECT_LT(render.stderrText.size(), 2000u);
    ToolRun option = runTool("render -q --" + std::string(100000, 'z') + " 1", dir.file(""));
    EXPECT_EQ(option.exitCode, 2);
    EXPECT_LT(option.stderrText.size(), 2000u);
}

// Whether process `pid` has ended (gone, or a zombie nobody reaped).
bool ended(int pid)
{
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    std::string line;
    if (!std::getline(stat, line)) return true;
    const size_t paren = line.rfind(')');
    return paren != std::string::npos && paren + 2 < line.size() && line[paren + 2] == 'Z';
}

size_t countFiles(const std::string& folder, const std::string& suffix)
{
    size_t n = 0;
    for (const auto& entry : fs::directory_iterator(folder)) {
        const std::string name = entry.path().filename().string();
        n += name.size() >= suffix.size() &&
             name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
    }
    return n;
}

// Two batches of one manifest writing into one folder at once: the second one removes none of the
// first one's temporaries (its writer is alive), and both finish every job (the campaign's second
// batch removed the first one's in-flight files, which then failed "cannot rename").
TEST(BatchTool, ConcurrentBatchesKeepEachOthersTemporaries)
{
    bool skip = false;
    if (!openBackend("vulkan", skip)) {
        if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
        return;
    }
    ScratchDir dir("batch-two");
    constexpr int kFrames = 6;
    writeText(dir.file("m.jsonl"),
              fmt::format("{{\"scene\": \"builtin\", \"orbit\": \"0:300\", \"frames\": {}, "
                          "\"width\": 32, \"height\": 32, \"output\": \"f/t_%02d.png\"}}\n",
                          kFrames));
    // The first batch pauses between staging each frame's files and renaming them.
    const std::string command = fmt::format(
        "cd '{}' && exec '{}' batch m.jsonl --backend vulkan --io-threads 1 --queue 1 --io-delay-ms 400 "
        "--summary first.json -q >first.log 2>&1 & echo $! > '{}'",
        dir.file(""), raster(), dir.file("pid"));
    ASSERT_EQ(std::system(command.c_str()), 0);
    int pid = 0;
    std::ifstream(dir.file("pid")) >> pid;
    ASSERT_GT(pid, 0);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    auto staged = [&] {
        std::error_code ec;
        for (fs::directory_iterator it(dir.file("f"), ec), end; !ec && it != end; it.increment(ec))
            if (it->path().filename().string().find(".tmp.") != std::string::npos) return true;
        return false;
    };
    while (!staged() && std::chrono::steady_clock::now() < deadline && !ended(pid))
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ASSERT_FALSE(ended(pid)) << "the first batch ended before the second started";
    ToolRun second = runTool("batch m.jsonl --backend vulkan --force", dir.file(""));
    EXPECT_EQ(second.exitCode, 0) << second.stderrText;
    EXPECT_EQ(summaryOf(second)["removed_temporaries"], 0);
    while (!ended(pid) && std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ASSERT_TRUE(ended(pid));
    std::ifstream log(dir.file("first.log"));
    const std::string firstLog((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
    EXPECT_EQ(firstLog, "");
    std::ifstream first(dir.file("first.json"));
    const json firstSummary = json::parse(first, nullptr, false);
    ASSERT_FALSE(firstSummary.is_discarded()) << firstLog;
    EXPECT_EQ(firstSummary["failed"], 0) << firstSummary.dump();
    EXPECT_EQ(firstSummary["rendered"], kFrames);
    EXPECT_EQ(countFiles(dir.file("f"), ".job.json"), size_t(kFrames));
    for (const auto& entry : fs::directory_iterator(dir.file("f")))
        EXPECT_EQ(entry.path().filename().string().find(".tmp."), std::string::npos) << entry.path();
}

// kill -9 in the middle of a batch: every final PNG that exists decodes, and a rerun skips exactly the
// jobs with a sidecar, renders the rest, removes the temporary files and ends with every frame equal to
// the direct turntable render.
TEST(BatchTool, KilledBatchResumesWithoutTruncatedFiles)
{
    bool skip = false;
    if (!openBackend("vulkan", skip)) {
        if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
        return;
    }
    ScratchDir dir("batch-kill");
    constexpr int kFrames = 12;
    writeText(dir.file("m.jsonl"),
              fmt::format("{{\"scene\": \"builtin\", \"orbit\": \"0:330\", \"frames\": {}, "
                          "\"width\": 96, \"height\": 64, \"output\": \"f/t_%02d.png\"}}\n",
                          kFrames));
    // Each frame pauses between its temporary PNG and the rename, so the kill lands with work in flight.
    const std::string pidFile = dir.file("pid");
    const std::string command = fmt::format(
        "cd '{}' && exec '{}' batch m.jsonl --backend vulkan --io-threads 1 --queue 1 --io-delay-ms 250 "
        ">first.log 2>&1 & echo $! > '{}'",
        dir.file(""), raster(), pidFile);
    ASSERT_EQ(std::system(command.c_str()), 0);
    int pid = 0;
    std::ifstream(pidFile) >> pid;
    ASSERT_GT(pid, 0);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while ((!fs::exists(dir.file("f")) || countFiles(dir.file("f"), ".job.json") < 2) &&
           std::chrono::steady_clock::now() < deadline && !ended(pid))
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ASSERT_FALSE(ended(pid)) << "the batch ended before it could be killed";
    ASSERT_EQ(kill(pid, SIGKILL), 0);
    while (!ended(pid)) std::this_thread::sleep_for(std::chrono::milliseconds(10));

    const size_t done = countFiles(dir.file("f"), ".job.json");
    EXPECT_GE(done, 2u);
    EXPECT_LT(done, size_t(kFrames)) << "the kill came too late to test anything";
    for (const auto& entry : fs::directory_iterator(dir.file("f"))) {
        const std::string name = entry.path().filename().string();
        if (name.size() > 4 && name.compare(name.size() - 4, 4, ".png") == 0) {
            EXPECT_TRUE(readPng(entry.path().string()).ok()) << name << " is not a whole PNG";
        }
    }

    ToolRun rerun = runTool("batch m.jsonl --backend vulkan", dir.file(""));
    ASSERT_EQ(rerun.exitCode, 0) << rerun.stderrText;
    json summary = summaryOf(rerun);
    EXPECT_EQ(summary["jobs"]["skipped"], done);
    EXPECT_EQ(summary["rendered"], kFrames - int(done));
    EXPECT_EQ(countFiles(dir.file("f"), ".job.json"), size_t(kFrames));
    for (const auto& entry : fs::directory_iterator(dir.file("f")))
        EXPECT_EQ(entry.path().filename().string().find(".tmp."), std::string::npos) << entry.path();

    ToolRun direct =
        runTool("render -q --backend vulkan --width 96 --height 64 --frames 12 --orbit 0:330 -o " +
                dir.file("d_%02d.png"));
    ASSERT_EQ(direct.exitCode, 0) << direct.stderrText;
    for (int k = 0; k < kFrames; ++k)
        EXPECT_TRUE(
            sameImages(dir.file(fmt::format("f/t_{:02}.png", k)), dir.file(fmt::format("d_{:02}.png", k))))
            << "frame " << k;
}

}  // namespace
}  // namespace sr::test
