// output_files_test.cpp - outputs on failing disks and hostile paths (issue 24, points 4-6): a write that
// fails is an error with nothing partial left under the final name, a final name that is not a regular
// file is refused and left as it was, and two spellings of one file are one output.
#include <algorithm>
#include <filesystem>
#include <fstream>

#include <sys/stat.h>
#include <sys/types.h>

#include <gtest/gtest.h>

#include "io/file_write.h"
#include "io/image_io.h"
#include "test_util.h"

namespace sr {
namespace {

namespace fs = std::filesystem;
using test::runTool;
using test::ScratchDir;
using test::ToolRun;

bool isOneLine(const std::string& text)
{
    return !text.empty() && text.find('\n') == text.size() - 1;
}

// A disk with room for 1 KiB per file in the scratch folder, past which a write fails with ENOSPC
// (test::fullDisk): the 32 x 32 PNG (about 600 bytes) fits, its EXR (about 6 KB) does not.
const std::string kSmallDisk = test::fullDisk(1024);

TEST(OutputFiles, AFailedWriteIsAnErrorAndLeavesNothing)
{
    ScratchDir dir("outputs");
    ToolRun run = runTool("render --backend vulkan -q --width 32 --height 32 -o a.png --aov a.exr",
                          dir.file(""), kSmallDisk);
    EXPECT_EQ(run.exitCode, 2);
    EXPECT_TRUE(isOneLine(run.stderrText)) << run.stderrText;
    EXPECT_NE(run.stderrText.find("cannot write"), std::string::npos) << run.stderrText;
    EXPECT_FALSE(fs::exists(dir.file("a.exr"))) << "no partial EXR under the final name";
    EXPECT_FALSE(fs::exists(dir.file("a.png"))) << "a failed command leaves none of its outputs";
    for (const auto& entry : fs::directory_iterator(dir.file("")))
        EXPECT_EQ(entry.path().filename().string().find(".tmp."), std::string::npos) << entry.path();

    // The same through the library call every writer uses, and for `raster compare -o`.
    ToolRun image =
        runTool("render --backend vulkan -q --width 64 --height 64 -o b.png", dir.file(""), kSmallDisk);
    EXPECT_EQ(image.exitCode, 2) << image.stderrText;
    EXPECT_FALSE(fs::exists(dir.file("b.png")));
    ASSERT_EQ(runTool("render --backend vulkan -q --width 256 --height 256 -o c.png --shading normals",
                      dir.file(""))
                  .exitCode,
              0);
    ASSERT_EQ(runTool("render --backend vulkan -q --width 256 --height 256 -o d.png", dir.file("")).exitCode,
              0);
    ToolRun diff = runTool("compare c.png d.png -o diff.png", dir.file(""), kSmallDisk);
    EXPECT_EQ(diff.exitCode, 2) << diff.stderrText;
    EXPECT_FALSE(fs::exists(dir.file("diff.png")));
}

// A batch job whose EXR cannot be written leaves neither its PNG nor its sidecar; the job beside it,
// whose PNG fits, is written whole.
TEST(OutputFiles, AFailedBatchJobLeavesNoneOfItsFiles)
{
    ScratchDir dir("outputs");
    std::ofstream(dir.file("jobs.jsonl"))
        << "{\"scene\": \"builtin\", \"width\": 32, \"height\": 32, \"output\": \"a.png\", \"aov\": "
           "\"a.exr\"}\n"
           "{\"scene\": \"builtin\", \"width\": 32, \"height\": 32, \"output\": \"b.png\"}\n";
    // 2 KiB: the PNG (about 900 bytes) and the sidecar (about 1.1 kB) fit, the EXR does not.
    ToolRun run = runTool("batch jobs.jsonl --backend vulkan -q", dir.file(""), test::fullDisk(2048));
    EXPECT_EQ(run.exitCode, 1) << run.stderrText;
    EXPECT_NE(run.stderrText.find("cannot write 'a.exr'"), std::string::npos) << run.stderrText;
    for (const char* name : {"a.png", "a.exr", "a.png.job.json"})
        EXPECT_FALSE(fs::exists(dir.file(name))) << name;
    EXPECT_TRUE(readPng(dir.file("b.png")).ok());
    EXPECT_TRUE(fs::exists(dir.file("b.png.job.json")));
    for (const auto& entry : fs::directory_iterator(dir.file("")))
        EXPECT_EQ(entry.path().filename().string().find(".tmp."), std::string::npos) << entry.path();
}

// The files of a group appear together or not at all.
TEST(OutputFiles, AFileGroupCommitsAllOrNone)
{
    ScratchDir dir("outputs");
    const std::string a = dir.file("a.txt"), b = dir.file("b.txt");
    {
        FileGroup files;
        ASSERT_TRUE(files.stage(a, "a", 1).ok());
        ASSERT_TRUE(files.stage(b, "b", 1).ok());
        EXPECT_TRUE(fs::exists(temporaryPath(a)));
        EXPECT_FALSE(fs::exists(a));
    }  // never committed
    EXPECT_TRUE(fs::is_empty(dir.file(""))) << "an abandoned group leaves nothing";
    {
        FileGroup files;
        ASSERT_TRUE(files.stage(a, "a", 1).ok());
        ASSERT_TRUE(files.stage(b, "b", 1).ok());
        fs::create_directories(dir.file("b.txt/inside"));  // b's name taken before the commit
        auto committed = files.commit();
        ASSERT_FALSE(committed.ok());
        EXPECT_NE(committed.error().message.find("it exists and is a folder"), std::string::npos)
            << committed.error().message;
        EXPECT_FALSE(fs::exists(a)) << "nothing renamed when one target cannot take its file";
        EXPECT_FALSE(fs::exists(temporaryPath(a)));
        EXPECT_FALSE(fs::exists(temporaryPath(b)));
    }
    fs::remove_all(dir.file("b.txt"));
    FileGroup files;
    ASSERT_TRUE(files.stage(a, "a", 1).ok());
    ASSERT_TRUE(files.stage(b, "bb", 2).ok());
    ASSERT_TRUE(files.commit().ok());
    EXPECT_EQ(fs::file_size(a), 1u);
    EXPECT_EQ(fs::file_size(b), 2u);
}

// A job's sidecar path taken by a folder (empty or not): that job fails with one line and leaves nothing,
// the folder stays, and the other jobs render (the campaign's batch aborted on it: exit 134, nothing
// rendered).
TEST(OutputFiles, ABatchJobWhoseSidecarIsAFolderFailsAlone)
{
    ScratchDir dir("outputs");
    fs::create_directories(dir.file("out/a.png.job.json"));
    fs::create_directories(dir.file("out/c.png.job.json/inside"));
    std::ofstream(dir.file("jobs.jsonl"))
        << "{\"scene\": \"builtin\", \"width\": 16, \"height\": 16, \"output\": \"out/a.png\"}\n"
           "{\"scene\": \"builtin\", \"width\": 16, \"height\": 16, \"output\": \"out/b.png\"}\n"
           "{\"scene\": \"builtin\", \"width\": 16, \"height\": 16, \"output\": \"out/c.png\"}\n";
    ToolRun run = runTool("batch jobs.jsonl --backend vulkan -q", dir.file(""));
    EXPECT_EQ(run.exitCode, 1) << run.stderrText;
    EXPECT_EQ(std::count(run.stderrText.begin(), run.stderrText.end(), '\n'), 2) << run.stderrText;
    EXPECT_NE(run.stderrText.find("cannot write 'out/a.png.job.json': it exists and is a folder"),
              std::string::npos)
        << run.stderrText;
    EXPECT_FALSE(fs::exists(dir.file("out/a.png")));
    EXPECT_FALSE(fs::exists(dir.file("out/c.png")));
    EXPECT_TRUE(fs::is_directory(dir.file("out/a.png.job.json")));
    EXPECT_TRUE(readPng(dir.file("out/b.png")).ok());
}

TEST(OutputFiles, ANameThatIsNoRegularFileIsRefusedAndKept)
{
    ScratchDir dir("outputs");
    ASSERT_EQ(mkfifo(dir.file("fifo.png").c_str(), 0644), 0);
    fs::create_directory(dir.file("folder.png"));
    fs::create_symlink(dir.file("elsewhere.png"), dir.file("link.png"));
    for (const char* name : {"fifo.png", "folder.png", "link.png"}) {
        SCOPED_TRACE(name);
        ToolRun run = runTool(std::string("render --backend vulkan -q --width 16 --height 16 -o ") + name,
                              dir.file(""));
        EXPECT_EQ(run.exitCode, 2);
        EXPECT_TRUE(isOneLine(run.stderrText)) << run.stderrText;
        EXPECT_NE(run.stderrText.find("not a regular file"), std::string::npos) << run.stderrText;
    }
    EXPECT_TRUE(fs::is_fifo(dir.file("fifo.png")));
    EXPECT_TRUE(fs::is_directory(dir.file("folder.png")));
    EXPECT_TRUE(fs::is_symlink(dir.file("link.png")));
    EXPECT_FALSE(fs::exists(dir.file("elsewhere.png")));

    // raster batch renames its temporary files into place: never over such a name.
    std::ofstream(dir.file("jobs.jsonl"))
        << "{\"scene\": \"builtin\", \"width\": 16, \"height\": 16, \"output\": "
           "\"fifo.png\"}\n";
    ToolRun batch = runTool("batch jobs.jsonl --backend vulkan -q", dir.file(""));
    EXPECT_EQ(batch.exitCode, 1) << batch.stderrText;
    EXPECT_NE(batch.stderrText.find("not a regular file"), std::string::npos) << batch.stderrText;
    EXPECT_TRUE(fs::is_fifo(dir.file("fifo.png")));
    // A device node is refused by name first: it is no PNG file name.
    ToolRun device = runTool("render --backend vulkan -q --width 16 --height 16 -o /dev/full", dir.file(""));
    EXPECT_EQ(device.exitCode, 2);
    struct stat st {};
    ASSERT_EQ(stat("/dev/full", &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode));
    EXPECT_FALSE(checkOutputTarget("/dev/full").ok());
}

TEST(OutputFiles, TwoSpellingsOfOneFileAreOneOutput)
{
    ScratchDir dir("outputs");
    struct Case {
        std::string args, message;
    };
    for (const Case& c : std::vector<Case>{
             {"-o s.png --aov s.png", "--aov 's.png' must end in .exr"},
             {"-o s.exr", "-o 's.exr' must end in .png or .npy"},
             {"-o s.png --stats ./s.png", "-o 's.png' and --stats './s.png' name the same file"},
             {"-o sub/../t.png --stats t.png", "-o 'sub/../t.png' and --stats 't.png' name the same file"},
         }) {
        SCOPED_TRACE(c.args);
        ToolRun run = runTool("render --backend vulkan -q --width 16 --height 16 " + c.args, dir.file(""));
        EXPECT_EQ(run.exitCode, 2);
        EXPECT_EQ(run.stderrText, "raster: error: " + c.message + "\n");
    }
    EXPECT_TRUE(fs::is_empty(dir.file(""))) << "nothing written";

    std::ofstream(dir.file("jobs.jsonl")) << "{\"scene\": \"builtin\", \"output\": \"a.png\"}\n"
                                             "{\"scene\": \"builtin\", \"output\": \"./a.png\"}\n";
    ToolRun batch = runTool("batch jobs.jsonl --backend vulkan -q", dir.file(""));
    EXPECT_EQ(batch.exitCode, 2);
    EXPECT_NE(batch.stderrText.find("also written by line 1"), std::string::npos) << batch.stderrText;
    EXPECT_FALSE(fs::exists(dir.file("a.png")));
    std::ofstream(dir.file("exr.jsonl"))
        << "{\"scene\": \"builtin\", \"output\": \"a.png\", \"aov\": \"a.png\"}\n";
    ToolRun exr = runTool("batch exr.jsonl --backend vulkan -q", dir.file(""));
    EXPECT_EQ(exr.exitCode, 2);
    EXPECT_NE(exr.stderrText.find("aov 'a.png' must end in .exr"), std::string::npos) << exr.stderrText;

    // An output on the scene being rendered.
    const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    std::ofstream(dir.file("s.obj")) << obj;
    ToolRun scene = runTool(
        "render s.obj --backend vulkan -q --width 16 --height 16 -o s.png --stats ./s.obj", dir.file(""));
    EXPECT_EQ(scene.exitCode, 2);
    EXPECT_EQ(scene.stderrText, "raster: error: --stats './s.obj' would overwrite the scene\n");
    std::ifstream kept(dir.file("s.obj"));
    EXPECT_EQ(std::string((std::istreambuf_iterator<char>(kept)), std::istreambuf_iterator<char>()), obj);

    EXPECT_EQ(resolvedPath(dir.file("x/../y.png")), resolvedPath(dir.file("y.png")));
    EXPECT_TRUE(hasExtension("A.PNG", ".png"));
    EXPECT_FALSE(hasExtension("png", ".png"));
}

}  // namespace
}  // namespace sr
