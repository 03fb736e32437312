// render_outputs_test.cpp - what `raster render` and `raster batch` write and warn about (issue 26): the
// files name the backend that made them, the EXR carries the linear colour, --stats reproduces the render,
// --aov alone writes no PNG, vulkan-graphics says which counts it lacks, and a texture view of an
// untextured scene or a camera inside the model gets one warning on stderr.
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/image_io.h"
#include "raster_shared.h"
#include "test_util.h"

namespace sr::test {
namespace {

bool exists(const std::string& path)
{
    struct stat st {};
    return stat(path.c_str(), &st) == 0;
}

nlohmann::json readJson(const std::string& path)
{
    std::ifstream in(path);
    return nlohmann::json::parse(in, nullptr, false);
}

size_t count(const std::string& text, const std::string& what)
{
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

// The bunny of docs/batch.md's example (Debian's glmark2-data), where installed.
const std::string kBunny = glmark2Model("bunny.obj");

TEST(RenderOutputs, AnAovAloneWritesNoPng)
{
    ScratchDir dir("sr_outputs");
    ToolRun r = runTool("render builtin --width 16 --height 12 --msaa 1 -q --aov a.exr", dir.file(""));
    ASSERT_EQ(r.exitCode, 0) << r.stderrText;
    EXPECT_TRUE(exists(dir.file("a.exr")));
    EXPECT_FALSE(exists(dir.file("render.png")));
    // Without --aov the PNG keeps its default name.
    ASSERT_EQ(runTool("render builtin --width 16 --height 12 --msaa 1 -q", dir.file("")).exitCode, 0);
    EXPECT_TRUE(exists(dir.file("render.png")));
}

TEST(RenderOutputs, FilesNameTheirBackendAndTheExrHoldsThePngsColourInLinearLight)
{
    ScratchDir dir("sr_outputs");
    for (const std::string backend : {"vulkan", "vulkan-graphics"}) {
        const std::string png = dir.file(backend + ".png"), exr = dir.file(backend + ".exr");
        ToolRun r = runTool("render builtin:checker --width 48 --height 32 --msaa 1 -q --backend " + backend +
                            " -o " + png + " --aov " + exr + " --stats " + dir.file(backend + ".json"));
        ASSERT_EQ(r.exitCode, 0) << r.stderrText;
        const std::string device = readJson(dir.file(backend + ".json"))["device"].get<std::string>();
        auto pngOrigin = readPngOrigin(png);
        auto exrOrigin = readExrOrigin(exr);
        ASSERT_TRUE(pngOrigin.ok() && exrOrigin.ok());
        EXPECT_EQ(pngOrigin->backend, backend);
        EXPECT_EQ(exrOrigin->backend, backend);
        EXPECT_EQ(pngOrigin->device, device);
        EXPECT_EQ(exrOrigin->device, device);

        // Encoded again with the shaders' encode, the EXR's colour is the PNG, pixel for pixel.
        auto image = readPng(png);
        auto aov = readAovExr(exr);
        ASSERT_TRUE(image.ok() && aov.ok());
        ASSERT_TRUE(aov->hasColor());
        size_t differing = 0;
        for (size_t i = 0; i < image->pixels.size(); ++i) {
            const uint32_t rgb = packRgba8(vec3(aov->colorR[i], aov->colorG[i], aov->colorB[i])) & 0xffffffu;
            if (rgb != (image->pixels[i] & 0xffffffu) ||
                aov->colorA[i] != float(image->pixels[i] >> 24) / 255.0f)
                ++differing;
        }
        EXPECT_EQ(differing, 0u) << backend;
    }
}

// --stats names every setting of the schema and the camera: a render made again from the JSON alone (its
// scene and settings) is the same image, and the resolved camera spec gives the same camera.
TEST(RenderOutputs, StatsReproduceTheRender)
{
    ScratchDir dir("sr_outputs");
    ToolRun first = runTool(
        "render builtin:checker --width 40 --height 30 --msaa 1 --camera orbit:20,15,2.5r --shading lambert "
        "--texture-filter bilinear --ambient 0.3 --light-dir 0.2,0.9,0.4 --cull none -q -o " +
        dir.file("a.png") + " --aov " + dir.file("a.exr") + " --stats " + dir.file("a.json"));
    ASSERT_EQ(first.exitCode, 0) << first.stderrText;
    const nlohmann::json stats = readJson(dir.file("a.json"));
    ASSERT_FALSE(stats.is_discarded());

    // The camera: its spec, the spec in scene units, the matrices, the eye 2.5 bounding radii from the
    // target. builtin:checker's bounds are read back from the radius the resolved spec implies.
    const nlohmann::json& camera = stats["camera"];
    EXPECT_EQ(camera["spec"], "orbit:20,15,2.5r");
    ASSERT_TRUE(camera["resolved_spec"].is_string());
    ASSERT_EQ(camera["view_from_world"].size(), 16u);
    ASSERT_EQ(camera["clip_from_view"].size(), 16u);
    glm::mat4 view, proj, clip;
    for (int k = 0; k < 16; ++k) {
        view[k / 4][k % 4] = camera["view_from_world"][k].get<float>();
        proj[k / 4][k % 4] = camera["clip_from_view"][k].get<float>();
        clip[k / 4][k % 4] = stats["clip_from_world"][k].get<float>();
    }
    const glm::mat4 product = proj * view;
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            EXPECT_NEAR(product[c][r], clip[c][r], 1e-5f * (1.0f + std::abs(clip[c][r])));
    const std::string resolved = camera["resolved_spec"].get<std::string>();
    ASSERT_EQ(resolved.rfind("orbit:20,15,", 0), 0u) << resolved;
    const float distance = std::stof(resolved.substr(12));
    const glm::vec3 eye(glm::inverse(view)[3]);
    EXPECT_NEAR(eye.x, camera["eye"][0].get<float>(), 1e-5f);
    // The eye looks at the target from `distance` away: the target is the point `distance` in front.
    const glm::vec3 target = eye - distance * glm::vec3(glm::inverse(view)[2]);
    EXPECT_NEAR(glm::length(view * glm::vec4(target, 1.0f) - glm::vec4(0, 0, -distance, 1)), 0.0f, 1e-4f);

    // Again from the JSON's scene and settings alone, with the camera as given and as resolved.
    std::string args = "render " + stats["scene"].get<std::string>();
    for (const auto& [key, value] : stats["settings"].items()) {
        std::string name = key;
        std::replace(name.begin(), name.end(), '_', '-');
        if (name == "camera") continue;
        if (value.is_boolean()) {
            if (value.get<bool>()) args += " --" + name;
            continue;
        }
        std::string text = value.is_string() ? value.get<std::string>() : value.dump();
        if (value.is_array()) text = value[0].dump() + "," + value[1].dump() + "," + value[2].dump();
        args += " --" + name + " " + text;
    }
    const std::string given = stats["settings"]["camera"].get<std::string>();
    ToolRun again =
        runTool(args + " --camera " + given + " -q -o " + dir.file("b.png") + " --aov " + dir.file("b.exr"));
    ASSERT_EQ(again.exitCode, 0) << args << ": " << again.stderrText;
    ToolRun absolute = runTool(args + " --camera " + resolved + " -q -o " + dir.file("c.png"));
    ASSERT_EQ(absolute.exitCode, 0) << absolute.stderrText;
    auto a = readPng(dir.file("a.png")), b = readPng(dir.file("b.png")), c = readPng(dir.file("c.png"));
    ASSERT_TRUE(a.ok() && b.ok() && c.ok());
    EXPECT_EQ(a->pixels, b->pixels);
    EXPECT_EQ(a->pixels, c->pixels);
    auto aAov = readAovExr(dir.file("a.exr")), bAov = readAovExr(dir.file("b.exr"));
    ASSERT_TRUE(aAov.ok() && bAov.ok());
    EXPECT_EQ(aAov->id, bAov->id);
    EXPECT_EQ(aAov->depth, bAov->depth);
}

TEST(RenderOutputs, GraphicsBackendSaysItsCountsAreNotAvailable)
{
    ScratchDir dir("sr_outputs");
    ToolRun r = runTool("render builtin --width 32 --height 24 --msaa 1 --backend vulkan-graphics -o " +
                        dir.file("g.png") + " --stats " + dir.file("g.json"));
    ASSERT_EQ(r.exitCode, 0) << r.stderrText;
    EXPECT_EQ(r.stdoutText.find("0 triangles rasterized"), std::string::npos) << r.stdoutText;
    EXPECT_NE(r.stdoutText.find("culled, clipped and rasterized n/a"), std::string::npos) << r.stdoutText;
    const nlohmann::json stats = readJson(dir.file("g.json"));
    EXPECT_GT(stats["triangles"]["in"].get<uint64_t>(), 0u);
    for (const char* key : {"culled", "clipped", "rasterized"})
        EXPECT_TRUE(stats["triangles"][key].is_null()) << key;
    // The compute backend counts them.
    ToolRun compute = runTool("render builtin --width 32 --height 24 --msaa 1 --backend vulkan -o " +
                              dir.file("v.png") + " --stats " + dir.file("v.json"));
    ASSERT_EQ(compute.exitCode, 0);
    EXPECT_GT(readJson(dir.file("v.json"))["triangles"]["rasterized"].get<uint64_t>(), 0u);
}

TEST(RenderWarnings, TextureViewsOfAnUntexturedScene)
{
    ScratchDir dir("sr_outputs");
    for (const std::string mode : {"texcoord", "mip"}) {
        ToolRun plain = runTool("render builtin --width 16 --height 12 --msaa 1 -q --shading " + mode +
                                " -o " + dir.file("p.png"));
        EXPECT_EQ(plain.exitCode, 0);
        EXPECT_EQ(count(plain.stderrText, "\n"), 1u) << plain.stderrText;
        EXPECT_EQ(
            plain.stderrText.rfind("warning: --shading " + mode + " shows the base colour texture's", 0), 0u)
            << plain.stderrText;
        ToolRun textured = runTool("render builtin:checker --width 16 --height 12 --msaa 1 -q --shading " +
                                   mode + " -o " + dir.file("t.png"));
        EXPECT_EQ(textured.exitCode, 0);
        EXPECT_EQ(textured.stderrText, "");
    }
}

TEST(RenderWarnings, CameraInsideTheModel)
{
    ScratchDir dir("sr_outputs");
    const std::string warning = "warning: the camera is inside the scene's geometry";
    // builtin:dense is a closed sphere: from its centre region, inside; from 2.5 radii, outside.
    ToolRun inside =
        runTool("render builtin:dense --width 16 --height 12 --msaa 1 -q --camera orbit:0,0,0.2r -o " +
                dir.file("i.png"));
    EXPECT_EQ(inside.exitCode, 0);
    EXPECT_EQ(count(inside.stderrText, warning), 1u) << inside.stderrText;
    ToolRun outside =
        runTool("render builtin:dense --width 16 --height 12 --msaa 1 -q --camera orbit:0,0,2.5r -o " +
                dir.file("o.png"));
    EXPECT_EQ(outside.exitCode, 0);
    EXPECT_EQ(outside.stderrText, "");

    // docs/batch.md's example before its fix (then in the README): the bunny at orbit:30,20,0.4 (scene
    // units), once per job.
    ASSERT_TRUE(exists(kBunny)) << kBunny << " is missing: ci/setup installs glmark2-data";
    std::ofstream(dir.file("m.jsonl"))
        << "{\"defaults\": {\"width\": 24, \"height\": 16, \"msaa\": 1}}\n"
        << "{\"scene\": \"" << kBunny << "\", \"camera\": \"orbit:30,20,0.4\", \"output\": \""
        << dir.file("in.png") << "\"}\n"
        << "{\"scene\": \"" << kBunny
        << "\", \"camera\": \"orbit:30,20,0.4\", \"orbit\": \"0:90\", \"frames\": 3, "
        << "\"output\": \"" << dir.file("in_%d.png") << "\"}\n"
        << "{\"scene\": \"" << kBunny << "\", \"camera\": \"orbit:30,20,2.5r\", \"output\": \""
        << dir.file("out.png") << "\"}\n";
    ToolRun batch = runTool("batch " + dir.file("m.jsonl") + " --backend vulkan");
    EXPECT_EQ(batch.exitCode, 0) << batch.stderrText;
    const std::string what = warning.substr(std::string("warning: ").size());
    EXPECT_EQ(count(batch.stderrText, what), 2u) << batch.stderrText;
    EXPECT_NE(batch.stderrText.find("m.jsonl:2: " + what), std::string::npos) << batch.stderrText;
    EXPECT_NE(batch.stderrText.find("m.jsonl:3: " + what), std::string::npos) << batch.stderrText;
    EXPECT_TRUE(exists(dir.file("out.png")));
}

}  // namespace
}  // namespace sr::test
