// hostile_input_test.cpp - scene files that name what is not a readable file (issue 24): directories,
// FIFOs without a writer, /dev/zero, sparse files over the size limits, and JSON nested 20,000 deep.
//
// Each such input must be one warning (an image) or one one-line error (the scene or a buffer), never
// a signal or a wait. Every hostile file is first loaded by the raster tool in a child process under
// `timeout 20`, so that a crash or a hang fails the test there instead of killing or stalling the test
// binary; only then is it loaded in this process, where the result and the warnings are checked. A
// refused file of gigabytes is loaded in a child limited to 1 GiB of address space, which shows that
// it was refused before it was read.
#include <sys/stat.h>
#include <sys/types.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "loaders/safe_file.h"
#include "scene/scene.h"
#include "test_util.h"

namespace sr {
namespace {

using Json = nlohmann::json;

constexpr int kFloat = 5126;
const glm::vec4 kFactor(0.5f, 0.25f, 1.0f, 1.0f);  // every test material's base colour factor

void writeFile(const std::string& path, const std::string& bytes)
{
    std::ofstream(path, std::ios::binary) << bytes;
}

void makeFifo(const std::string& path)
{
    ASSERT_EQ(mkfifo(path.c_str(), 0600), 0) << path;
}

// A sparse file of `size` bytes: no disk is used, and reading it would return zeros.
void makeSparse(const std::string& path, uint64_t size)
{
    writeFile(path, "");
    std::filesystem::resize_file(path, size);
}

size_t occurrences(const std::string& text, const std::string& needle)
{
    size_t count = 0;
    for (size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + needle.size()))
        ++count;
    return count;
}

// The buffer triangleGltf's documents read: three VEC3 positions (the unit right triangle), then three
// VEC2 texture coordinates.
std::string triangleBin()
{
    const float values[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1};
    return std::string(reinterpret_cast<const char*>(values), sizeof values);
}

// A glTF with one textured triangle: its buffer is the file `bufferUri` (write triangleBin() there), its
// material has base colour factor kFactor and, unless `imageUri` is empty, a texture of that image.
Json triangleGltf(const std::string& bufferUri, const std::string& imageUri = "")
{
    Json doc;
    doc["asset"] = {{"version", "2.0"}};
    doc["buffers"] = Json::array({{{"byteLength", 60}, {"uri", bufferUri}}});
    doc["bufferViews"] = Json::array({{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}},
                                      {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 24}}});
    doc["accessors"] =
        Json::array({{{"bufferView", 0}, {"componentType", kFloat}, {"count", 3}, {"type", "VEC3"}},
                     {{"bufferView", 1}, {"componentType", kFloat}, {"count", 3}, {"type", "VEC2"}}});
    Json primitive = {{"attributes", {{"POSITION", 0}, {"TEXCOORD_0", 1}}}, {"material", 0}};
    doc["meshes"] = Json::array({{{"primitives", Json::array({primitive})}}});
    Json pbr = {{"baseColorFactor", {kFactor.r, kFactor.g, kFactor.b, kFactor.a}}};
    if (!imageUri.empty()) {
        pbr["baseColorTexture"] = {{"index", 0}};
        doc["images"] = Json::array({{{"uri", imageUri}}});
        doc["textures"] = Json::array({{{"source", 0}}});
    }
    doc["materials"] = Json::array({{{"pbrMetallicRoughness", pbr}}});
    doc["nodes"] = Json::array({{{"mesh", 0}}});
    doc["scenes"] = Json::array({{{"nodes", {0}}}});
    doc["scene"] = 0;
    return doc;
}

// Binary glTF of `json`: 12-byte header, a JSON chunk padded with spaces and, unless `bin` is empty, a
// BIN chunk padded with zeros.
std::string glb(const std::string& json, std::string bin = "")
{
    std::string jsonChunk = json;
    while (jsonChunk.size() % 4 != 0) jsonChunk += ' ';
    while (bin.size() % 4 != 0) bin += '\0';
    std::string out;
    auto u32 = [&](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
    u32(0x46546C67u);  // "glTF"
    u32(2);
    u32(uint32_t(12 + 8 + jsonChunk.size() + (bin.empty() ? 0 : 8 + bin.size())));
    u32(uint32_t(jsonChunk.size()));
    u32(0x4E4F534Au);  // "JSON"
    out += jsonChunk;
    if (bin.empty()) return out;
    u32(uint32_t(bin.size()));
    u32(0x004E4942u);  // "BIN\0"
    return out + bin;
}

// An OBJ triangle with texture coordinates, drawn with material "m" of m.mtl: Kd kFactor, map_Kd `image`.
void writeObj(const test::ScratchDir& dir, const std::string& image)
{
    writeFile(dir.file("m.mtl"), "newmtl m\nKd 0.5 0.25 1\nmap_Kd " + image + "\n");
    writeFile(dir.file("tri.obj"),
              "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
              "usemtl m\nf 1/1 2/2 3/3\n");
}

// `raster render SCENE` at 8 x 8 in a child process that may run 20 seconds at most, run by `limits`
// (a command such as prlimit, or nothing) when given.
test::ToolRun renderInChild(const std::string& scene, const std::string& limits = "")
{
    test::ScratchDir out("sr_hostile_out");
    return test::runTool("render '" + scene + "' -q --width 8 --height 8 -o " + out.file("o.png"), "",
                         (limits.empty() ? "" : limits + " ") + "timeout 20");
}

::testing::AssertionResult childFailure(const std::string& scene, const test::ToolRun& run)
{
    return ::testing::AssertionFailure()
           << scene << ": exit code " << run.exitCode << (run.exitCode == 124 ? " (timed out)" : "")
           << (run.exitCode > 128 ? " (killed by a signal)" : "") << ", stderr:\n"
           << run.stderrText;
}

// The raster tool loads `scene` and renders it, exit code 0 (or 2 where a missing Vulkan device is
// allowed): no signal (exit code 128 + n), no timeout (124).
::testing::AssertionResult loadsInChild(const std::string& scene)
{
    test::ToolRun run = renderInChild(scene);
    const char* allowed = std::getenv("SR_ALLOW_MISSING_BACKENDS");
    bool vulkanOptional = allowed && std::string(allowed).find("vulkan") != std::string::npos;
    if (run.exitCode == 0 || (vulkanOptional && run.exitCode == 2)) return ::testing::AssertionSuccess();
    return childFailure(scene, run);
}

// The raster tool fails to load `scene` with exit code 2 and one line on stderr, the error naming the
// file and containing `reason`.
::testing::AssertionResult failsInChild(const std::string& scene, const std::string& reason,
                                        const std::string& limits = "")
{
    test::ToolRun run = renderInChild(scene, limits);
    if (run.exitCode != 2 || occurrences(run.stderrText, "\n") != 1 ||
        run.stderrText.find("error: cannot load '" + scene + "': ") == std::string::npos ||
        run.stderrText.find(reason) == std::string::npos)
        return childFailure(scene, run);
    return ::testing::AssertionSuccess();
}

// Limits a child to 1 GiB of address space: a file of gigabytes that it refuses must be refused
// without being read. AddressSanitizer reserves terabytes of address space for its shadow memory and
// cannot start under such a limit; there, its allocator refuses (and reports, failing the child) any
// single allocation over 1 GiB instead.
#if defined(__SANITIZE_ADDRESS__)
std::string smallAddressSpace()
{
    const char* options = std::getenv("ASAN_OPTIONS");
    return "env ASAN_OPTIONS=" + std::string(options ? options : "") +
           ":max_allocation_size_mb=1024:allocator_may_return_null=0";
}
const std::string kSmallAddressSpace = smallAddressSpace();
#else
const std::string kSmallAddressSpace = "prlimit --as=1073741824";
#endif

// `path` loaded in this process, with the warnings it printed.
std::pair<Result<Scene>, std::string> loadCapturingWarnings(const std::string& path)
{
    ::testing::internal::CaptureStderr();
    Result<Scene> scene = loadScene(path);
    std::string warnings = ::testing::internal::GetCapturedStderr();
    return {std::move(scene), std::move(warnings)};
}

// The load of `path` failed with one line that names the file and contains `reason`.
void expectOneLineError(const Result<Scene>& result, const std::string& path, const std::string& reason)
{
    ASSERT_FALSE(result.ok()) << path;
    const std::string& message = result.error().message;
    EXPECT_EQ(message.rfind("cannot load '" + path + "': ", 0), 0u) << message;
    EXPECT_TRUE(test::isOneLine(message)) << message;
    EXPECT_NE(message.find(reason), std::string::npos) << message;
    EXPECT_EQ(result.error().code, ExitCode::Usage);
}

// The scene loaded with exactly one warning, naming the scene file and containing `reason`, and its one
// material kept its base colour factor without a texture.
void expectImageWarning(const std::pair<Result<Scene>, std::string>& loaded, const std::string& path,
                        const std::string& reason)
{
    const auto& [result, warnings] = loaded;
    ASSERT_TRUE(result.ok()) << result.error().message;
    const Scene& scene = result.value();
    EXPECT_EQ(occurrences(warnings, "warning: "), 1u) << warnings;
    EXPECT_EQ(occurrences(warnings, "\n"), 1u) << warnings;
    EXPECT_EQ(warnings.rfind("warning: " + path + ": ", 0), 0u) << warnings;
    EXPECT_NE(warnings.find(reason), std::string::npos) << warnings;
    EXPECT_EQ(scene.triangleCount(), 1u);
    ASSERT_EQ(scene.materials.size(), 1u);
    EXPECT_EQ(scene.materials[0].baseColorTexture, -1);
    EXPECT_EQ(scene.materials[0].baseColorFactor, kFactor);
    EXPECT_TRUE(scene.textures.empty());
}

// ---- readRegularFile ------------------------------------------------------------------------------

TEST(SafeFile, ReadsRegularFilesWhole)
{
    test::ScratchDir dir("sr_hostile");
    std::string content(200000, 'x');  // more than one read's worth
    content[123456] = 'y';
    writeFile(dir.file("a"), content);
    Result<std::vector<unsigned char>> bytes = readRegularFile(dir.file("a"), content.size(), "read");
    ASSERT_TRUE(bytes.ok()) << bytes.error().message;
    EXPECT_EQ(std::string(bytes->begin(), bytes->end()), content);

    writeFile(dir.file("empty"), "");
    Result<std::vector<unsigned char>> empty = readRegularFile(dir.file("empty"), 0, "read");
    ASSERT_TRUE(empty.ok()) << empty.error().message;
    EXPECT_TRUE(empty->empty());

    // A symbolic link is followed: what counts is the file it names.
    std::filesystem::create_symlink(dir.file("a"), dir.file("link"));
    EXPECT_TRUE(readRegularFile(dir.file("link"), content.size(), "read").ok());
}

TEST(SafeFile, RefusesWhatIsNotARegularFileWithOneLine)
{
    test::ScratchDir dir("sr_hostile");
    std::filesystem::create_directory(dir.file("sub"));
    makeFifo(dir.file("fifo"));
    std::filesystem::create_symlink(dir.file("sub"), dir.file("link"));
    const std::pair<std::string, std::string> cases[] = {
        {dir.file("missing"), "cannot read image '" + dir.file("missing") + "': No such file or directory"},
        {dir.file("sub"),
         "cannot read image '" + dir.file("sub") + "': it is a directory, not a regular file"},
        {dir.file("sub/"), "it is a directory"},
        {dir.file("link"), "it is a directory"},
        {dir.file("fifo"),
         "cannot read image '" + dir.file("fifo") + "': it is a FIFO (named pipe), not a regular file"},
        {"/dev/zero", "cannot read image '/dev/zero': it is a character device, not a regular file"},
        {"/dev/null", "it is a character device"},
    };
    for (const auto& [path, expected] : cases) {
        Result<std::vector<unsigned char>> bytes = readRegularFile(path, 1000, "read image");
        ASSERT_FALSE(bytes.ok()) << path;
        EXPECT_TRUE(test::isOneLine(bytes.error().message)) << bytes.error().message;
        EXPECT_NE(bytes.error().message.find(expected), std::string::npos) << bytes.error().message;
        EXPECT_EQ(bytes.error().code, ExitCode::Usage);
    }
}

TEST(SafeFile, RefusesAnOverLimitSizeBeforeReading)
{
    test::ScratchDir dir("sr_hostile");
    writeFile(dir.file("eleven"), "hello world");
    EXPECT_TRUE(readRegularFile(dir.file("eleven"), 11, "read").ok());
    Result<std::vector<unsigned char>> over = readRegularFile(dir.file("eleven"), 10, "read");
    ASSERT_FALSE(over.ok());
    EXPECT_EQ(over.error().message,
              "cannot read '" + dir.file("eleven") + "': it is 11 bytes, over the limit of 10 bytes");

    // 1 TiB, sparse: reading it would take minutes and more memory than the machine has, so the answer
    // coming at once shows that the size was checked first.
    makeSparse(dir.file("huge"), uint64_t(1) << 40);
    Result<std::vector<unsigned char>> huge = readRegularFile(dir.file("huge"), kMaxSceneFileBytes, "read");
    ASSERT_FALSE(huge.ok());
    EXPECT_NE(huge.error().message.find("it is 1099511627776 bytes, over the limit of 4294967295 bytes"),
              std::string::npos)
        << huge.error().message;
}

// ---- glTF -----------------------------------------------------------------------------------------

TEST(HostileGltf, ImageUriNamingADirectoryIsOneWarning)
{
    test::ScratchDir dir("sr_hostile");
    writeFile(dir.file("tri.bin"), triangleBin());
    std::filesystem::create_directory(dir.file("sub"));
    for (const std::string uri : {".", "..", "sub/", "sub"}) {
        SCOPED_TRACE(uri);
        std::string path = dir.file("image_dir.gltf");
        writeFile(path, triangleGltf("tri.bin", uri).dump());
        ASSERT_TRUE(loadsInChild(path));
        expectImageWarning(loadCapturingWarnings(path), path, "it is a directory, not a regular file");
    }
}

TEST(HostileGltf, BufferUriNamingADirectoryIsOneError)
{
    test::ScratchDir dir("sr_hostile");
    std::filesystem::create_directory(dir.file("sub"));
    for (const std::string uri : {"sub/", ".", ".."}) {
        SCOPED_TRACE(uri);
        std::string path = dir.file("buffer_dir.gltf");
        writeFile(path, triangleGltf(uri).dump());
        ASSERT_TRUE(failsInChild(path, "it is a directory, not a regular file"));
        expectOneLineError(loadScene(path), path, "it is a directory, not a regular file");
    }
    // The same from a GLB's external buffer.
    std::string path = dir.file("buffer_dir.glb");
    writeFile(path, glb(triangleGltf("sub/").dump()));
    ASSERT_TRUE(failsInChild(path, "it is a directory"));
    expectOneLineError(loadScene(path), path, "cannot read '" + dir.file("sub/") + "': it is a directory");
}

TEST(HostileGltf, FifoUrisAreRefusedWithoutWaiting)
{
    test::ScratchDir dir("sr_hostile");
    writeFile(dir.file("tri.bin"), triangleBin());
    makeFifo(dir.file("fifo"));

    std::string imagePath = dir.file("image_fifo.gltf");
    writeFile(imagePath, triangleGltf("tri.bin", "fifo").dump());
    ASSERT_TRUE(loadsInChild(imagePath));
    expectImageWarning(loadCapturingWarnings(imagePath), imagePath, "it is a FIFO (named pipe)");

    std::string bufferPath = dir.file("buffer_fifo.gltf");
    writeFile(bufferPath, triangleGltf("fifo").dump());
    ASSERT_TRUE(failsInChild(bufferPath, "it is a FIFO (named pipe)"));
    expectOneLineError(loadScene(bufferPath), bufferPath, "it is a FIFO (named pipe)");

    // The scene file itself.
    std::string scenePath = dir.file("scene_fifo.gltf");
    makeFifo(scenePath);
    ASSERT_TRUE(failsInChild(scenePath, "it is a FIFO (named pipe)"));
    expectOneLineError(loadScene(scenePath), scenePath, "it is a FIFO (named pipe), not a regular file");
}

TEST(HostileGltf, OverLimitFilesAreRefusedBeforeReading)
{
    test::ScratchDir dir("sr_hostile");
    writeFile(dir.file("tri.bin"), triangleBin());
    // 5 GiB, sparse: over the 4 GiB - 1 limit for every file a glTF names.
    makeSparse(dir.file("big"), uint64_t(5) << 30);
    const std::string tooBig = "it is 5368709120 bytes, over the limit of 4294967295 bytes";

    std::string bufferPath = dir.file("big_buffer.gltf");
    writeFile(bufferPath, triangleGltf("big").dump());
    ASSERT_TRUE(failsInChild(bufferPath, tooBig, kSmallAddressSpace));
    expectOneLineError(loadScene(bufferPath), bufferPath, tooBig);

    std::string imagePath = dir.file("big_image.gltf");
    writeFile(imagePath, triangleGltf("tri.bin", "big").dump());
    ASSERT_TRUE(loadsInChild(imagePath));
    expectImageWarning(loadCapturingWarnings(imagePath), imagePath, tooBig);

    std::string scenePath = dir.file("big_scene.gltf");
    makeSparse(scenePath, uint64_t(5) << 30);
    ASSERT_TRUE(failsInChild(scenePath, tooBig, kSmallAddressSpace));
    expectOneLineError(loadScene(scenePath), scenePath, tooBig);
}

// The JSON of a document `depth` arrays and objects deep: the top-level object, then `extras` arrays.
std::string nestedGltf(size_t depth)
{
    std::string doc = triangleGltf("tri.bin").dump();
    doc.pop_back();  // the closing brace
    return doc + ",\"extras\":" + std::string(depth - 1, '[') + std::string(depth - 1, ']') + "}";
}

TEST(HostileGltf, DeepJsonNestingIsOneErrorNotAStackOverflow)
{
    test::ScratchDir dir("sr_hostile");
    writeFile(dir.file("tri.bin"), triangleBin());
    const std::string tooDeep = "its JSON nests arrays and objects more than 512 levels deep";

    std::string path = dir.file("deep.gltf");
    writeFile(path, nestedGltf(20000));
    ASSERT_TRUE(failsInChild(path, tooDeep));
    expectOneLineError(loadScene(path), path, tooDeep);

    std::string glbPath = dir.file("deep.glb");
    writeFile(glbPath, glb(nestedGltf(20000)));
    ASSERT_TRUE(failsInChild(glbPath, tooDeep));
    expectOneLineError(loadScene(glbPath), glbPath, tooDeep);

    // One level over the bound is refused; at the bound the document loads.
    writeFile(path, nestedGltf(513));
    expectOneLineError(loadScene(path), path, tooDeep);
    writeFile(path, nestedGltf(512));
    Result<Scene> atBound = loadScene(path);
    ASSERT_TRUE(atBound.ok()) << atBound.error().message;
    EXPECT_EQ(atBound->triangleCount(), 1u);
}

TEST(HostileGltf, BracketsInStringsDoNotCountAsNesting)
{
    test::ScratchDir dir("sr_hostile");
    writeFile(dir.file("tri.bin"), triangleBin());
    // Escaped quotes and backslashes, then brackets, all inside strings: a scan that ended the string
    // at an escaped quote would count thousands of levels.
    Json doc = triangleGltf("tri.bin");
    doc["asset"]["generator"] = "\"" + std::string(2000, '[') + "\\\"" + std::string(2000, '{');
    doc["nodes"][0]["name"] = "\\" + std::string(2000, '[');
    std::string path = dir.file("strings.gltf");
    writeFile(path, doc.dump());
    Result<Scene> scene = loadScene(path);
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    EXPECT_EQ(scene->triangleCount(), 1u);

    // Only a GLB's JSON chunk is JSON: brackets in its BIN chunk are data.
    Json binary = triangleGltf("");
    binary["buffers"][0].erase("uri");
    binary["buffers"][0]["byteLength"] = 60 + 2000;
    std::string glbPath = dir.file("brackets.glb");
    writeFile(glbPath, glb(binary.dump(), triangleBin() + std::string(2000, '[')));
    Result<Scene> fromGlb = loadScene(glbPath);
    ASSERT_TRUE(fromGlb.ok()) << fromGlb.error().message;
    EXPECT_EQ(fromGlb->triangleCount(), 1u);
}

// ---- OBJ ------------------------------------------------------------------------------------------

TEST(HostileObj, MapKdOfDevZeroIsOneWarningAndTheMaterialKeepsKd)
{
    test::ScratchDir dir("sr_hostile");
    writeObj(dir, "/dev/zero");
    std::string path = dir.file("tri.obj");
    ASSERT_TRUE(loadsInChild(path));
    expectImageWarning(loadCapturingWarnings(path), path,
                       "cannot read image '/dev/zero': it is a character device, not a regular file");
}

TEST(HostileObj, FifosAreRefusedWithoutWaiting)
{
    test::ScratchDir dir("sr_hostile");
    makeFifo(dir.file("fifo.png"));
    writeObj(dir, "fifo.png");
    std::string path = dir.file("tri.obj");
    ASSERT_TRUE(loadsInChild(path));
    expectImageWarning(loadCapturingWarnings(path), path, "it is a FIFO (named pipe), not a regular file");

    // A FIFO as the .mtl: one warning, and the faces are drawn without materials.
    std::string mtlPath = dir.file("fifo_mtl.obj");
    makeFifo(dir.file("fifo.mtl"));
    writeFile(mtlPath, "mtllib fifo.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    ASSERT_TRUE(loadsInChild(mtlPath));
    auto [scene, warnings] = loadCapturingWarnings(mtlPath);
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    EXPECT_EQ(occurrences(warnings, "warning: "), 1u) << warnings;
    EXPECT_NE(warnings.find("cannot read material file '" + dir.file("fifo.mtl") + "': it is a FIFO"),
              std::string::npos)
        << warnings;
    EXPECT_EQ(scene->triangleCount(), 1u);

    // The .obj itself.
    std::string objFifo = dir.file("scene_fifo.obj");
    makeFifo(objFifo);
    ASSERT_TRUE(failsInChild(objFifo, "it is a FIFO (named pipe)"));
    expectOneLineError(loadScene(objFifo), objFifo, "it is a FIFO (named pipe), not a regular file");
}

TEST(HostileObj, OverLimitFilesAreRefusedBeforeReading)
{
    test::ScratchDir dir("sr_hostile");
    // 3 GiB, sparse: over the 2 GiB - 1 limit for an image file (not over the one for scene files).
    makeSparse(dir.file("big.png"), uint64_t(3) << 30);
    writeObj(dir, "big.png");
    std::string path = dir.file("tri.obj");
    ASSERT_TRUE(loadsInChild(path));
    expectImageWarning(loadCapturingWarnings(path), path,
                       "it is 3221225472 bytes, over the limit of 2147483647 bytes");

    std::string bigMtl = dir.file("big_mtl.obj");
    makeSparse(dir.file("big.mtl"), uint64_t(5) << 30);
    writeFile(bigMtl, "mtllib big.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    ASSERT_TRUE(loadsInChild(bigMtl));
    auto [scene, warnings] = loadCapturingWarnings(bigMtl);
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    EXPECT_EQ(occurrences(warnings, "warning: "), 1u) << warnings;
    EXPECT_NE(warnings.find("it is 5368709120 bytes, over the limit of 4294967295 bytes"), std::string::npos)
        << warnings;

    std::string bigObj = dir.file("big.obj");
    makeSparse(bigObj, uint64_t(5) << 30);
    ASSERT_TRUE(failsInChild(bigObj, "over the limit of 4294967295 bytes", kSmallAddressSpace));
    expectOneLineError(loadScene(bigObj), bigObj,
                       "it is 5368709120 bytes, over the limit of 4294967295 bytes");
}

TEST(HostileObj, DirectoriesAreRefused)
{
    test::ScratchDir dir("sr_hostile");
    std::filesystem::create_directory(dir.file("sub"));
    writeObj(dir, "sub/");
    std::string path = dir.file("tri.obj");
    ASSERT_TRUE(loadsInChild(path));
    expectImageWarning(loadCapturingWarnings(path), path, "it is a directory, not a regular file");

    std::string dirObj = dir.file("dir.obj");
    std::filesystem::create_directory(dirObj);
    ASSERT_TRUE(failsInChild(dirObj, "it is a directory"));
    expectOneLineError(loadScene(dirObj), dirObj, "it is a directory, not a regular file");
}

// ---- glTF the specification calls invalid, and what it allows but raster does not draw ------------

// Spec-invalid documents: each is one one-line error that starts with the path of the offending value
// in the document. Before issue 24 each of them loaded without a word (and drew the background, the
// wrong scene, or nothing).
TEST(InvalidGltf, SpecViolationsAreOneLineErrorsNamingTheirPath)
{
    test::ScratchDir dir("sr_invalid_gltf");
    writeFile(dir.file("tri.bin"), triangleBin());
    struct Case {
        const char* name;
        void (*edit)(Json& doc);
        const char* reason;
    };
    const Case cases[] = {
        {"stride_below_element", [](Json& d) { d["bufferViews"][0]["byteStride"] = 4; },
         "bufferViews[0].byteStride is 4, less than the 12-byte elements of accessors[0]"},
        {"stride_out_of_range", [](Json& d) { d["bufferViews"][0]["byteStride"] = 256; },
         "bufferViews[0].byteStride is 256 (glTF 2.0 requires 4 to 252)"},
        {"scene_out_of_range", [](Json& d) { d["scene"] = 3; }, "scene is 3, but the file has 1 scene(s)"},
        {"scene_negative", [](Json& d) { d["scene"] = -1; }, "scene is -1, but the file has 1 scene(s)"},
        {"scene_without_scenes",
         [](Json& d) {
             d.erase("scenes");
             d["scene"] = 0;
         },
         "scene is 0, but the file has 0 scene(s)"},
        {"mode_9", [](Json& d) { d["meshes"][0]["primitives"][0]["mode"] = 9; },
         "meshes[0].primitives[0].mode is 9 (glTF 2.0 requires 0 (POINTS) to 6 (TRIANGLE_FAN))"},
        {"mode_negative", [](Json& d) { d["meshes"][0]["primitives"][0]["mode"] = -1; },
         "meshes[0].primitives[0].mode is -1"},
        {"matrix_5",
         [](Json& d) {
             d["nodes"][0]["matrix"] = {1, 0, 0, 0, 1};
         },
         "nodes[0].matrix is [1,0,0,0,1] (glTF 2.0 requires 16 numbers"},
        {"matrix_empty", [](Json& d) { d["nodes"][0]["matrix"] = Json::array(); }, "nodes[0].matrix is []"},
        {"aspect_0",
         [](Json& d) {
             d["cameras"] = {{{"type", "perspective"},
                              {"perspective", {{"yfov", 0.8}, {"znear", 0.1}, {"aspectRatio", 0}}}}};
         },
         "cameras[0].perspective.aspectRatio is 0 (glTF 2.0 requires a number above 0"},
        {"yfov_missing",
         [](Json& d) {
             d["cameras"] = {{{"type", "perspective"}, {"perspective", {{"znear", 0.1}}}}};
         },
         "cameras[0].perspective.yfov is missing"},
        {"joint_out_of_range",
         [](Json& d) {
             d["skins"] = {{{"joints", {0, 7}}}};
             d["nodes"][0]["skin"] = 0;
         },
         "skins[0].joints[1] is 7, but the file has 1 node(s)"},
        {"skin_out_of_range", [](Json& d) { d["nodes"][0]["skin"] = 2; },
         "nodes[0].skin is 2, but the file has 0 skin(s)"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        Json doc = triangleGltf("tri.bin");
        c.edit(doc);
        std::string path = dir.file(std::string(c.name) + ".gltf");
        writeFile(path, doc.dump());
        expectOneLineError(loadScene(path), path, c.reason);
        // A .glb carries the same JSON: the same error.
        std::string glbPath = dir.file(std::string(c.name) + ".glb");
        doc["buffers"][0].erase("uri");
        writeFile(glbPath, glb(doc.dump(), triangleBin()));
        expectOneLineError(loadScene(glbPath), glbPath, c.reason);
    }
    // And through the tool: exit code 2, the one line.
    Json doc = triangleGltf("tri.bin");
    doc["meshes"][0]["primitives"][0]["mode"] = 9;
    std::string path = dir.file("mode_tool.gltf");
    writeFile(path, doc.dump());
    EXPECT_TRUE(failsInChild(path, "meshes[0].primitives[0].mode is 9"));
}

// What the spec allows but raster does not draw: skins and morph targets are one warning each, and the
// mesh is drawn as stored (the same triangle as without them).
TEST(InvalidGltf, SkinsAndMorphTargetsAreOneWarningEach)
{
    test::ScratchDir dir("sr_invalid_gltf");
    writeFile(dir.file("tri.bin"), triangleBin());
    Json doc = triangleGltf("tri.bin");
    doc["nodes"].push_back({{"name", "joint"}});
    doc["scenes"][0]["nodes"].push_back(1);
    doc["skins"] = {{{"joints", {1}}}};
    doc["nodes"][0]["skin"] = 0;
    doc["meshes"][0]["primitives"][0]["targets"] = {{{"POSITION", 0}}, {{"POSITION", 0}}};
    doc["meshes"][0]["weights"] = {0.5, 0.5};
    std::string path = dir.file("skin_morph.gltf");
    writeFile(path, doc.dump());
    auto [scene, warnings] = loadCapturingWarnings(path);
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    EXPECT_EQ(occurrences(warnings, "\n"), 2u) << warnings;
    EXPECT_EQ(occurrences(warnings, "warning: " + path + ": skins are not supported: 1 skinned node(s)"), 1u)
        << warnings;
    EXPECT_EQ(occurrences(warnings, "warning: " + path + ": morph targets are not supported: 1 primitive(s)"),
              1u)
        << warnings;
    ASSERT_EQ(scene->triangleCount(), 1u);
    EXPECT_EQ(glm::vec3(scene->positions[1]), glm::vec3(1, 0, 0));

    // Without them: no warning at all.
    std::string plain = dir.file("plain.gltf");
    writeFile(plain, triangleGltf("tri.bin").dump());
    auto [plainScene, plainWarnings] = loadCapturingWarnings(plain);
    ASSERT_TRUE(plainScene.ok()) << plainScene.error().message;
    EXPECT_EQ(plainWarnings, "");
}

}  // namespace
}  // namespace sr
