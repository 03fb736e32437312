// encoders_test.cpp - the output encoders: every PNG speed decodes to the rendered frame's pixels and the
// three sizes come in their order, the NPY parsed here by its specification holds the same bytes, every
// EXR codec is lossless and the one asked for, and the settings reach the files through `raster render`
// and `raster batch` (bad values: one line, exit code 2).
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <tinyexr.h>

#include "io/image_io.h"
#include "raster_shared.h"
#include "test_util.h"

namespace sr {
namespace {

namespace fs = std::filesystem;
using test::runTool;
using test::ScratchDir;
using test::ToolRun;

using test::fileBytes;

// The builtin scene rendered on Vulkan (lavapipe on a machine without a GPU), or nothing after a skip.
class EncoderTest : public ::testing::Test {
protected:
    void SetUp() override
    {
        bool skip = false;
        device_ = test::openBackend("vulkan", skip);
        if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
        ASSERT_TRUE(device_);
        test::FramedScene f = test::framedBuiltin(320, 180);
        auto out = renderScene(*device_, f.scene, f.camera, f.settings);
        ASSERT_TRUE(out.ok()) << out.error().message;
        frame_ = out->color;
        // A frame with both the scene and the background in it: something to compress.
        size_t background = 0;
        for (uint32_t p : frame_.pixels) background += p == frame_.pixels[0];
        ASSERT_GT(background, 0u);
        ASSERT_LT(background, frame_.pixels.size());
    }

    std::unique_ptr<ComputeDevice> device_;
    RgbaImage frame_;
};

TEST_F(EncoderTest, EveryPngSpeedDecodesToTheFrameAndTheSizesComeInOrder)
{
    ScratchDir dir("encoders");
    const ImageOrigin origin{"vulkan", "llvmpipe (LLVM 15)"};
    size_t sizes[3] = {};
    for (PngCompression c : {PngCompression::Fast, PngCompression::Default, PngCompression::Small}) {
        const std::string path = dir.file(std::string(pngCompressionName(c)) + ".png");
        ASSERT_TRUE(writePng(path, frame_, origin, c).ok());
        auto back = readPng(path);  // stb's decoder: not the library that wrote it
        ASSERT_TRUE(back.ok()) << back.error().message;
        EXPECT_EQ(back->width, frame_.width);
        EXPECT_EQ(back->height, frame_.height);
        EXPECT_TRUE(back->pixels == frame_.pixels) << pngCompressionName(c);
        auto tags = readPngOrigin(path);
        ASSERT_TRUE(tags.ok());
        EXPECT_EQ(tags->backend, origin.backend) << pngCompressionName(c);
        EXPECT_EQ(tags->device, origin.device) << pngCompressionName(c);
        sizes[size_t(c)] = fs::file_size(path);
        // The in-memory encoder is the file's bytes.
        auto memory = encodePng(frame_, origin, c);
        ASSERT_TRUE(memory.ok());
        EXPECT_TRUE(*memory == fileBytes(path));
    }
    // Each step works harder for a smaller file (the settings differ, so the files do too).
    EXPECT_GT(sizes[0], sizes[1]);
    EXPECT_GT(sizes[1], sizes[2]);
}

// The NPY format 1.0 (numpy's format.py and NEP 1): magic, version, little-endian uint16 header length, a
// dict literal padded with spaces and ended by '\n' so the data starts at a multiple of 64, then the data.
TEST_F(EncoderTest, NpyHeaderAndDataFollowTheFormat)
{
    ScratchDir dir("encoders");
    const std::string path = dir.file("frame.npy");
    ASSERT_TRUE(writeNpy(path, frame_).ok());
    const std::vector<unsigned char> file = fileBytes(path);
    ASSERT_GT(file.size(), 10u);
    EXPECT_EQ(std::string(file.begin(), file.begin() + 6), "\x93NUMPY");
    EXPECT_EQ(file[6], 1);  // major
    EXPECT_EQ(file[7], 0);  // minor
    const size_t headerLength = size_t(file[8]) | size_t(file[9]) << 8;
    const size_t dataStart = 10 + headerLength;
    EXPECT_EQ(dataStart % 64, 0u);
    ASSERT_LE(dataStart, file.size());
    const std::string header(file.begin() + 10, file.begin() + std::ptrdiff_t(dataStart));
    EXPECT_EQ(header.back(), '\n');
    // The dict's entries, in any order and spacing, as Python's literal_eval would read them.
    std::smatch m;
    EXPECT_TRUE(std::regex_search(header, std::regex(R"('descr'\s*:\s*'\|u1')"))) << header;
    EXPECT_TRUE(std::regex_search(header, std::regex(R"('fortran_order'\s*:\s*False)"))) << header;
    ASSERT_TRUE(std::regex_search(header, m, std::regex(R"('shape'\s*:\s*\((\d+),\s*(\d+),\s*(\d+)\))")))
        << header;
    EXPECT_EQ(std::stoul(m[1]), frame_.height);
    EXPECT_EQ(std::stoul(m[2]), frame_.width);
    EXPECT_EQ(std::stoul(m[3]), 4u);
    EXPECT_TRUE(std::regex_match(header, std::regex(R"(\{.*\} *\n)"))) << header;
    ASSERT_EQ(file.size() - dataStart, size_t(frame_.width) * frame_.height * 4);
    // C order: row y, column x, channel c at ((y * W) + x) * 4 + c; R in the pixel's low byte.
    size_t mismatches = 0;
    for (size_t i = 0; i < frame_.pixels.size(); ++i)
        for (size_t c = 0; c < 4; ++c)
            mismatches += file[dataStart + 4 * i + c] != ((frame_.pixels[i] >> (8 * c)) & 0xffu);
    EXPECT_EQ(mismatches, 0u);
    auto memory = encodeNpy(frame_);
    ASSERT_TRUE(memory.ok());
    EXPECT_TRUE(*memory == file);
}

// The compression the file's header records, read by tinyexr.
int exrCompressionOf(const std::string& path)
{
    EXRVersion version;
    EXPECT_EQ(ParseEXRVersionFromFile(&version, path.c_str()), TINYEXR_SUCCESS);
    EXRHeader header;
    InitEXRHeader(&header);
    const char* err = nullptr;
    EXPECT_EQ(ParseEXRHeaderFromFile(&header, &version, path.c_str(), &err), TINYEXR_SUCCESS);
    if (err) FreeEXRErrorMessage(err);
    const int compression = header.compression_type;
    FreeEXRHeader(&header);
    return compression;
}

TEST(Encoders, EveryExrCodecIsLosslessAndTheOneAskedFor)
{
    AovImage aov;
    aov.width = 61;  // not a multiple of ZIP's 16 or PIZ's 32 scanlines, nor of any row alignment
    aov.height = 37;
    const size_t n = size_t(aov.width) * aov.height;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (size_t i = 0; i < n; ++i) {
        const bool empty = i % 5 == 0;
        aov.id.push_back(empty ? EMPTY_ID : rng() % 1000);
        aov.depth.push_back(empty ? 1.0f : unit(rng));
    }
    for (auto* plane : {&aov.baryU, &aov.baryV, &aov.uvU, &aov.uvV, &aov.normalX, &aov.normalY, &aov.normalZ})
        for (size_t i = 0; i < n; ++i) plane->push_back(unit(rng));
    RgbaImage color;
    color.width = aov.width;
    color.height = aov.height;
    for (size_t i = 0; i < n; ++i) color.pixels.push_back(rng());
    linearColorAov(color, aov);
    ScratchDir dir("encoders");
    const int expected[] = {TINYEXR_COMPRESSIONTYPE_NONE, TINYEXR_COMPRESSIONTYPE_RLE,
                            TINYEXR_COMPRESSIONTYPE_ZIPS, TINYEXR_COMPRESSIONTYPE_ZIP,
                            TINYEXR_COMPRESSIONTYPE_PIZ};
    ASSERT_EQ(exrCompressionNames().size(), std::size(expected));
    // The colour is HALF in the file: each 8-bit code's linear value comes back as the half nearest it,
    // whatever the codec, so as the default codec gives it back.
    ASSERT_TRUE(writeAovExr(dir.file("reference.exr"), aov).ok());
    auto reference = readAovExr(dir.file("reference.exr"));
    ASSERT_TRUE(reference.ok()) << reference.error().message;
    EXPECT_EQ(exrCompressionOf(dir.file("reference.exr")), TINYEXR_COMPRESSIONTYPE_ZIP);
    for (size_t k = 0; k < std::size(expected); ++k) {
        const ExrCompression codec = ExrCompression(k);
        const std::string path = dir.file(std::string(exrCompressionName(codec)) + ".exr");
        ASSERT_TRUE(writeAovExr(path, aov, {}, codec).ok()) << exrCompressionName(codec);
        EXPECT_EQ(exrCompressionOf(path), expected[k]) << exrCompressionName(codec);
        auto back = readAovExr(path);
        ASSERT_TRUE(back.ok()) << back.error().message;
        EXPECT_EQ(back->id, aov.id) << exrCompressionName(codec);
        EXPECT_EQ(std::memcmp(back->depth.data(), aov.depth.data(), n * sizeof(float)), 0);
        EXPECT_EQ(std::memcmp(back->normalZ.data(), aov.normalZ.data(), n * sizeof(float)), 0);
        EXPECT_EQ(std::memcmp(back->uvU.data(), aov.uvU.data(), n * sizeof(float)), 0);
        for (auto plane : {&AovImage::colorR, &AovImage::colorG, &AovImage::colorB, &AovImage::colorA})
            EXPECT_EQ((*back).*plane, (*reference).*plane) << exrCompressionName(codec);
    }
    // The uncompressed file is the largest: the codecs did compress.
    EXPECT_GT(fs::file_size(dir.file("none.exr")), fs::file_size(dir.file("zip.exr")));
}

TEST(Encoders, NamesParseAndBadOnesAreOneLine)
{
    for (const std::string& name : pngCompressionNames()) {
        auto parsed = parsePngCompression(name, "--png-compression");
        ASSERT_TRUE(parsed.ok());
        EXPECT_EQ(pngCompressionName(*parsed), name);
    }
    auto bad = parsePngCompression("turbo", "--png-compression");
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.error().message, "--png-compression must be fast, default or small, not 'turbo'");
    auto badExr = parseExrCompression("b44", "--exr-compression");
    ASSERT_FALSE(badExr.ok());
    EXPECT_EQ(badExr.error().message, "--exr-compression must be none, rle, zips, zip or piz, not 'b44'");
    EXPECT_TRUE(checkColorExtension("-o", "a.PNG").ok());
    EXPECT_TRUE(checkColorExtension("-o", "a.npy").ok());
    EXPECT_FALSE(checkColorExtension("-o", "a.bmp").ok());
}

// ---- the command line -------------------------------------------------------------------------

// One line on stderr, exit code 2, naming `needle`.
void expectUsageError(const ToolRun& run, const std::string& needle)
{
    EXPECT_EQ(run.exitCode, 2) << run.stderrText;
    EXPECT_EQ(std::count(run.stderrText.begin(), run.stderrText.end(), '\n'), 1) << run.stderrText;
    EXPECT_NE(run.stderrText.find(needle), std::string::npos) << run.stderrText;
}

TEST(EncoderCli, BadValuesAreOneLineUsageErrors)
{
    ScratchDir dir("encoders-cli");
    expectUsageError(runTool("render --png-compression turbo -q", dir.file("")),
                     "--png-compression must be fast, default or small, not 'turbo'");
    expectUsageError(runTool("render -o x.bmp -q", dir.file("")), "-o 'x.bmp' must end in .png or .npy");
    expectUsageError(runTool("render --exr-compression lzw --aov a.exr -q", dir.file("")),
                     "--exr-compression must be none, rle, zips, zip or piz, not 'lzw'");
    // A setting that would change nothing is refused, not ignored.
    expectUsageError(runTool("render -o a.npy --png-compression fast -q", dir.file("")),
                     "--png-compression needs a PNG output");
    expectUsageError(runTool("render --exr-compression none -q", dir.file("")),
                     "--exr-compression needs --aov");
    std::ofstream(dir.file("m.jsonl")) << "{\"scene\": \"builtin\", \"output\": \"a.bmp\"}\n";
    expectUsageError(runTool("batch m.jsonl -q", dir.file("")),
                     "m.jsonl:1: output 'a.bmp' must end in .png or .npy");
    std::ofstream(dir.file("m.jsonl"))
        << "{\"scene\": \"builtin\", \"output\": \"a.png\", \"png_compression\": "
           "\"turbo\"}\n";
    expectUsageError(runTool("batch m.jsonl -q", dir.file("")),
                     "m.jsonl:1: 'png_compression' must be fast, default or small, not 'turbo'");
    std::ofstream(dir.file("m.jsonl"))
        << "{\"scene\": \"builtin\", \"output\": \"a.npy\", \"png_compression\": "
           "\"fast\"}\n";
    expectUsageError(runTool("batch m.jsonl -q", dir.file("")), "'png_compression' needs a PNG 'output'");
    std::ofstream(dir.file("m.jsonl")) << "{\"scene\": \"builtin\", \"output\": \"a.png\"}\n";
    expectUsageError(runTool("batch m.jsonl -q --png-compression turbo", dir.file("")),
                     "command line: 'png_compression' must be fast, default or small, not 'turbo'");
    expectUsageError(runTool("batch m.jsonl -q --exr-compression none", dir.file("")),
                     "m.jsonl:1: 'exr_compression' needs an 'aov' file");
    EXPECT_FALSE(fs::exists(dir.file("a.png")));
}

class EncoderCliTest : public ::testing::Test {
protected:
    void SetUp() override
    {
        bool skip = false;
        if (!test::openBackend("vulkan", skip)) {
            if (skip) GTEST_SKIP() << "vulkan absent and allowed to be (SR_ALLOW_MISSING_BACKENDS)";
            FAIL() << "no Vulkan device";
        }
    }
};

// `raster render` writes the NPY and the PNGs of every speed with the same pixels; the EXR codec asked
// for is the file's.
TEST_F(EncoderCliTest, RenderWritesEveryFormatWithTheSamePixels)
{
    ScratchDir dir("encoders-cli");
    const std::string common = " --backend vulkan --width 96 --height 64 -q";
    for (const std::string& speed : pngCompressionNames()) {
        ToolRun run =
            runTool("render -o " + speed + ".png --png-compression " + speed + common, dir.file(""));
        ASSERT_EQ(run.exitCode, 0) << run.stderrText;
    }
    ToolRun npy = runTool("render -o frame.npy --aov none.exr --exr-compression none" + common, dir.file(""));
    ASSERT_EQ(npy.exitCode, 0) << npy.stderrText;
    EXPECT_EQ(exrCompressionOf(dir.file("none.exr")), TINYEXR_COMPRESSIONTYPE_NONE);
    auto reference = readPng(dir.file("default.png"));
    ASSERT_TRUE(reference.ok());
    for (const char* speed : {"fast", "small"}) {
        auto other = readPng(dir.file(std::string(speed) + ".png"));
        ASSERT_TRUE(other.ok());
        EXPECT_TRUE(other->pixels == reference->pixels) << speed;
    }
    EXPECT_NE(fs::file_size(dir.file("fast.png")), fs::file_size(dir.file("default.png")));
    auto expectedNpy = encodeNpy(*reference);
    ASSERT_TRUE(expectedNpy.ok());
    EXPECT_TRUE(fileBytes(dir.file("frame.npy")) == *expectedNpy);
}

// A batch writes what its manifest's keys and its command line ask for (at 320x180, large enough for the
// speeds to give files of different sizes in their order), records a non-default encoder in
// the sidecar, and writes a job again when its encoder changes.
TEST_F(EncoderCliTest, BatchTakesTheEncodersFromTheManifestAndTheCommandLine)
{
    ScratchDir dir("encoders-batch");
    std::ofstream(dir.file("m.jsonl"))
        << "{\"defaults\": {\"width\": 320, \"height\": 180}}\n"
           "{\"scene\": \"builtin\", \"output\": \"fast.png\", \"png_compression\": \"fast\"}\n"
           "{\"scene\": \"builtin\", \"output\": \"plain.png\", \"aov\": \"plain.exr\", \"exr_compression\": "
           "\"none\"}\n"
           "{\"scene\": \"builtin\", \"output\": \"raw.npy\"}\n";
    ToolRun run = runTool("batch m.jsonl -q --backend vulkan", dir.file(""));
    ASSERT_EQ(run.exitCode, 0) << run.stderrText;
    auto fast = readPng(dir.file("fast.png")), plain = readPng(dir.file("plain.png"));
    ASSERT_TRUE(fast.ok() && plain.ok());
    EXPECT_TRUE(fast->pixels == plain->pixels);
    EXPECT_GT(fs::file_size(dir.file("fast.png")), fs::file_size(dir.file("plain.png")));
    EXPECT_EQ(exrCompressionOf(dir.file("plain.exr")), TINYEXR_COMPRESSIONTYPE_NONE);
    EXPECT_TRUE(fileBytes(dir.file("raw.npy")) == *encodeNpy(*plain));
    std::ifstream sidecar(dir.file("fast.png.job.json"));
    EXPECT_EQ(nlohmann::json::parse(sidecar)["job"]["png_compression"], "fast");
    EXPECT_TRUE(fs::exists(dir.file("raw.npy.job.json")));

    // The command line's value sits under the jobs': the job that names none now encodes small and is
    // written again; the others keep theirs and are skipped.
    std::ofstream(dir.file("m.jsonl"))
        << "{\"defaults\": {\"width\": 320, \"height\": 180}}\n"
           "{\"scene\": \"builtin\", \"output\": \"fast.png\", \"png_compression\": \"fast\"}\n"
           "{\"scene\": \"builtin\", \"output\": \"plain.png\", \"aov\": \"plain.exr\", \"exr_compression\": "
           "\"none\"}\n";
    const auto before = fs::file_size(dir.file("plain.png"));
    ToolRun again = runTool("batch m.jsonl --backend vulkan --png-compression small", dir.file(""));
    ASSERT_EQ(again.exitCode, 0) << again.stderrText;
    nlohmann::json summary = nlohmann::json::parse(again.stdoutText, nullptr, false);
    ASSERT_FALSE(summary.is_discarded()) << again.stdoutText;
    EXPECT_EQ(summary["rendered"], 1);
    EXPECT_EQ(summary["jobs"]["skipped"], 1);
    EXPECT_LT(fs::file_size(dir.file("plain.png")), before);
    auto small = readPng(dir.file("plain.png"));
    ASSERT_TRUE(small.ok());
    EXPECT_TRUE(small->pixels == plain->pixels);
}

}  // namespace
}  // namespace sr
