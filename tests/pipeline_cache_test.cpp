// pipeline_cache_test.cpp - the compute pipelines' cache file (host/vulkan/pipeline_cache.h): its
// format refuses damaged files, it is named by device and driver under the chosen folder, and the
// raster tool writes it, reuses it, rebuilds a damaged one with one warning and survives concurrent
// writers, with the same image every time.
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_util.h"
#include "vulkan/pipeline_cache.h"

namespace sr {
namespace {

using test::fileBytes;

void writeBytes(const std::string& path, const std::vector<unsigned char>& bytes)
{
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

// Sets an environment variable for the life of the object, restoring the old value after.
class ScopedEnv {
public:
    ScopedEnv(const char* name, const char* value) : name_(name)
    {
        const char* old = std::getenv(name);
        had_ = old != nullptr;
        if (had_) old_ = old;
        if (value)
            setenv(name, value, 1);
        else
            unsetenv(name);
    }
    ~ScopedEnv()
    {
        if (had_)
            setenv(name_, old_.c_str(), 1);
        else
            unsetenv(name_);
    }

private:
    const char* name_;
    bool had_ = false;
    std::string old_;
};

TEST(PipelineCacheFile, RoundTripsAndRefusesDamage)
{
    const std::vector<unsigned char> data = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 200, 201};
    const std::vector<unsigned char> file = pipelineCacheFileBytes(data);
    std::string why;
    EXPECT_EQ(pipelineCacheData(file, why), data);
    EXPECT_EQ(why, "");
    // An empty cache is a valid file too.
    EXPECT_TRUE(pipelineCacheData(pipelineCacheFileBytes({}), why).empty());
    EXPECT_EQ(why, "");

    struct Damage {
        const char* name;
        std::vector<unsigned char> bytes;
        const char* why;
    };
    std::vector<Damage> damaged;
    damaged.push_back(
        {"truncated", std::vector<unsigned char>(file.begin(), file.end() - 3), "bytes of data"});
    damaged.push_back({"header only", std::vector<unsigned char>(file.begin(), file.begin() + 20),
                       "not a raster pipeline cache"});
    std::vector<unsigned char> flipped = file;
    flipped.at(35) ^= 0x40;  // a byte of the data, after the 32-byte header
    damaged.push_back({"a flipped data bit", flipped, "checksum"});
    std::vector<unsigned char> magic = file;
    magic[0] = 'X';
    damaged.push_back({"another magic", magic, "not a raster pipeline cache"});
    std::vector<unsigned char> version = file;
    version[8] = 7;
    damaged.push_back({"another version", version, "format version 7"});
    std::vector<unsigned char> longer(file.size() + 1, 0);
    std::copy(file.begin(), file.end(), longer.begin());
    damaged.push_back({"a byte appended", longer, "bytes of data"});
    for (const Damage& d : damaged) {
        SCOPED_TRACE(d.name);
        why.clear();
        EXPECT_TRUE(pipelineCacheData(d.bytes, why).empty());
        EXPECT_NE(why.find(d.why), std::string::npos) << why;
        EXPECT_FALSE(olderPipelineCacheFormat(d.bytes));
    }
    // A file of an earlier format (version 1 held the driver's bytes alone) is not used either, but it
    // is no damage: the cache replaces it without a warning.
    std::vector<unsigned char> older = file;
    older[8] = 1;
    why.clear();
    EXPECT_TRUE(pipelineCacheData(older, why).empty());
    EXPECT_NE(why.find("format version 1"), std::string::npos) << why;
    EXPECT_TRUE(olderPipelineCacheFormat(older));
    EXPECT_FALSE(olderPipelineCacheFormat(file));
}

TEST(PipelineCacheFile, DataHoldsTheDriversBytesAndTheModulesAndRefusesPartsThatDoNotAddUp)
{
    PipelineCacheContents contents;
    contents.driverData = {9, 8, 7, 6, 5};
    contents.modules["v1 12 0123 1=0"] = {0x07230203u, 1u, 2u};
    contents.modules["v1 12 0123 1=1"] = {0x07230203u, 0xffffffffu};
    contents.modules["empty"] = {};
    const std::vector<unsigned char> data = pipelineCacheDataBytes(contents);
    // 8 + 5 driver bytes, 4 for the count, and per module 4 + key + 4 + 4 per word.
    EXPECT_EQ(data.size(), 8u + 5 + 4 + (4 + 14 + 4 + 12) + (4 + 14 + 4 + 8) + (4 + 5 + 4));
    PipelineCacheContents back;
    std::string why;
    ASSERT_TRUE(pipelineCacheContents(data, back, why)) << why;
    EXPECT_EQ(back.driverData, contents.driverData);
    EXPECT_EQ(back.modules, contents.modules);
    // No modules and no driver bytes: valid too.
    ASSERT_TRUE(pipelineCacheContents(pipelineCacheDataBytes({}), back, why)) << why;
    EXPECT_TRUE(back.driverData.empty() && back.modules.empty());

    // Cut anywhere, or with a byte more, the parts no longer add up (the file's checksum catches damage
    // first; these are files of the right checksum written wrong).
    for (size_t keep = 0; keep < data.size(); ++keep) {
        why.clear();
        EXPECT_FALSE(
            pipelineCacheContents(std::vector<unsigned char>(data.begin(), data.begin() + keep), back, why))
            << keep;
        EXPECT_NE(why, "");
        EXPECT_TRUE(back.driverData.empty() && back.modules.empty());
    }
    std::vector<unsigned char> longer = data;
    longer.push_back(0);
    why.clear();
    EXPECT_FALSE(pipelineCacheContents(longer, back, why));
    EXPECT_NE(why.find("after the last module"), std::string::npos) << why;
    // A driver length far past the end (the 8 bytes read as 2^64 - 1) is refused, not allocated.
    std::vector<unsigned char> huge = data;
    std::fill(huge.begin(), huge.begin() + 8, 0xff);
    why.clear();
    EXPECT_FALSE(pipelineCacheContents(huge, back, why));
    EXPECT_NE(why.find("driver"), std::string::npos) << why;
}

TEST(PipelineCacheFile, NamedByDeviceAndDriverUnderTheChosenFolder)
{
    VkPhysicalDeviceProperties p{};
    p.vendorID = 0x10de;
    p.deviceID = 0x2330;
    p.driverVersion = 0x91000000;
    for (uint32_t i = 0; i < VK_UUID_SIZE; ++i) p.pipelineCacheUUID[i] = uint8_t(i);
    const std::string name = "compute-10de-2330-91000000-000102030405060708090a0b0c0d0e0f.bin";
    {
        ScopedEnv chosen("RASTER_PIPELINE_CACHE", "/some/folder");
        EXPECT_EQ(pipelineCacheFile(p), "/some/folder/" + name);
    }
    {
        ScopedEnv off("RASTER_PIPELINE_CACHE", "off");
        EXPECT_EQ(pipelineCacheFile(p), "");
    }
    {
        ScopedEnv unset("RASTER_PIPELINE_CACHE", nullptr);
        ScopedEnv xdg("XDG_CACHE_HOME", "/xdg");
        EXPECT_EQ(pipelineCacheFile(p), "/xdg/raster/" + name);
        ScopedEnv noXdg("XDG_CACHE_HOME", nullptr);
        ScopedEnv home("HOME", "/home/u");
        EXPECT_EQ(pipelineCacheFile(p), "/home/u/.cache/raster/" + name);
        // Relative values name no folder the user chose on purpose: the XDG rule is absolute paths only.
        ScopedEnv relative("XDG_CACHE_HOME", "cache");
        EXPECT_EQ(pipelineCacheFile(p), "/home/u/.cache/raster/" + name);
    }
    // Another driver version or device: another file, never data of another driver.
    VkPhysicalDeviceProperties q = p;
    q.driverVersion += 1;
    ScopedEnv chosen("RASTER_PIPELINE_CACHE", "/f");
    EXPECT_NE(pipelineCacheFile(p), pipelineCacheFile(q));
}

// The one file in `folder`, or "" when there is not exactly one.
std::string onlyFile(const std::string& folder)
{
    std::vector<std::string> files;
    if (std::filesystem::exists(folder))
        for (const auto& entry : std::filesystem::directory_iterator(folder)) files.push_back(entry.path());
    return files.size() == 1 ? files[0] : "";
}

TEST(PipelineCacheTool, WrittenReusedRebuiltAndSharedByConcurrentRuns)
{
    bool skip = false;
    if (!test::openBackend("vulkan", skip)) {
        if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
        FAIL() << "no Vulkan device";
    }
    test::ScratchDir dir("sr_pipeline_cache");
    const std::string folder = dir.file("cache");
    auto render = [&](const std::string& cache, const std::string& png) {
        return test::runTool("render builtin -q --backend vulkan --width 24 --height 16 -o " + png, "",
                             "env RASTER_PIPELINE_CACHE=" + cache);
    };

    // Without a cache: the reference image.
    test::ToolRun off = render("off", dir.file("off.png"));
    ASSERT_EQ(off.exitCode, 0) << off.stderrText;
    EXPECT_EQ(off.stderrText, "");
    const std::vector<unsigned char> reference = fileBytes(dir.file("off.png"));
    ASSERT_FALSE(reference.empty());

    // First run: the folder and the file are made, and the file is intact.
    test::ToolRun first = render(folder, dir.file("first.png"));
    ASSERT_EQ(first.exitCode, 0) << first.stderrText;
    EXPECT_EQ(first.stderrText, "");
    const std::string file = onlyFile(folder);
    ASSERT_NE(file, "");
    EXPECT_EQ(std::filesystem::path(file).filename().string().rfind("compute-", 0), 0u) << file;
    std::string why;
    std::vector<unsigned char> data = pipelineCacheData(fileBytes(file), why);
    EXPECT_EQ(why, "");
    EXPECT_EQ(fileBytes(dir.file("first.png")), reference);
    // A CPU device keeps its specialized modules there too (host/vulkan/spirv_specialize.h), a GPU none.
    PipelineCacheContents contents;
    ASSERT_TRUE(pipelineCacheContents(data, contents, why)) << why;
    auto device = test::openBackend("vulkan", skip);
    ASSERT_TRUE(device);
    if (device->info().isCpu)
        EXPECT_GE(contents.modules.size(), 5u);
    else
        EXPECT_TRUE(contents.modules.empty());

    // Second run: loads it, no warning, the same image.
    test::ToolRun second = render(folder, dir.file("second.png"));
    ASSERT_EQ(second.exitCode, 0) << second.stderrText;
    EXPECT_EQ(second.stderrText, "");
    EXPECT_EQ(fileBytes(dir.file("second.png")), reference);

    // A damaged file (half of it, then garbage): one warning, the same image, and an intact file again.
    const std::vector<unsigned char> whole = fileBytes(file);
    const std::vector<unsigned char> half(whole.begin(), whole.begin() + whole.size() / 2);
    for (const std::vector<unsigned char>& damage : {half, std::vector<unsigned char>(100, 0xab)}) {
        writeBytes(file, damage);
        test::ToolRun rebuilt = render(folder, dir.file("rebuilt.png"));
        ASSERT_EQ(rebuilt.exitCode, 0) << rebuilt.stderrText;
        EXPECT_EQ(std::count(rebuilt.stderrText.begin(), rebuilt.stderrText.end(), '\n'), 1)
            << rebuilt.stderrText;
        EXPECT_EQ(rebuilt.stderrText.rfind("warning: pipeline cache '" + file + "' not used (", 0), 0u)
            << rebuilt.stderrText;
        EXPECT_EQ(fileBytes(dir.file("rebuilt.png")), reference);
        why.clear();
        pipelineCacheData(fileBytes(file), why);
        EXPECT_EQ(why, "");
    }

    // Four runs at once into a new folder: all succeed with the reference image, and one intact file
    // and no temporary is left.
    const std::string shared = dir.file("shared");
    const char* exe = std::getenv("SR_RASTER_EXE");
    std::string command = "set -e; pids=''; for i in 0 1 2 3; do RASTER_PIPELINE_CACHE=" + shared + " " +
                          std::string(exe ? exe : SR_RASTER_EXE) +
                          " render builtin -q --backend vulkan --width 24 --height 16 -o " + dir.file("c") +
                          "$i.png & pids=\"$pids $!\"; done; for p in $pids; do wait $p; done";
    int status = std::system(("sh -c '" + command + "'").c_str());
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << command;
    for (int i = 0; i < 4; ++i)
        EXPECT_EQ(fileBytes(dir.file("c" + std::to_string(i) + ".png")), reference) << i;
    const std::string sharedFile = onlyFile(shared);
    ASSERT_NE(sharedFile, "") << "one file, no temporaries";
    why.clear();
    pipelineCacheData(fileBytes(sharedFile), why);
    EXPECT_EQ(why, "");
}

}  // namespace
}  // namespace sr
