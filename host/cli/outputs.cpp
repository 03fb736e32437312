// outputs.cpp - PNG or NPY, EXR and JSON of a rendered frame.
#include "cli/outputs.h"

#include <chrono>

#include "api/stats_json.h"
#include "io/image_io.h"
#include "render/aov.h"
#include "scene/camera.h"
#include "settings/schema.h"
#include "study/scenes.h"

namespace sr {

OutputPaths savePaths(const std::string& prefix)
{
    return {prefix + ".png", prefix + ".exr", prefix + ".json"};
}

std::string pngCompressionHelp()
{
    return "PNG encoder: fast (zlib level 1, no row filter: several times quicker, files 1.5-2x larger), "
           "default (level 6, adaptive filters) or small (level 9, every filter tried per row: slowest, "
           "under 2% smaller); the pixels are the same";
}

std::string exrCompressionHelp()
{
    return "EXR codec, all lossless: none (quick, largest), rle (about as quick, several times smaller: the "
           "fast choice), zips (zlib per scanline), zip (zlib per 16 scanlines, the default) or piz "
           "(wavelet)";
}

std::string absoluteCamera(const RenderOptions& options, const Scene& scene, const std::string& sceneName)
{
    auto spec = parseCameraSpec(options.camera);
    if (!spec) return "";
    if (spec->kind == CameraSpec::Kind::Auto && sceneName.rfind(kStudyScenePrefix, 0) == 0) return "";
    return resolvedCameraSpec(*spec, scene, options.settings.width, options.settings.height);
}

std::vector<std::string> viewWarnings(const Scene& scene, const CameraMatrices& camera,
                                      const RenderSettings& settings)
{
    std::vector<std::string> warnings;
    if ((settings.shadingMode == SHADING_TEXCOORD || settings.shadingMode == SHADING_MIP) &&
        scene.textures.empty())
        warnings.push_back(fmt::format(
            "--shading {} shows the base colour texture's {}, but the scene has no textures: every surface "
            "shows the same colour",
            choiceName(setting("shading"), settings.shadingMode),
            settings.shadingMode == SHADING_TEXCOORD ? "coordinates" : "level of detail"));
    if (scene.triangleCount() > 0 && eyeInsideScene(scene, camera))
        warnings.push_back(
            "the camera is inside the scene's geometry, so it sees the inside of its surfaces (culled back "
            "faces, or the wrong side): move it out, e.g. --camera orbit:AZ,EL,2.5r (2.5 bounding radii)");
    return warnings;
}

ImageOrigin outputOrigin(const RenderOutput& out)
{
    return {out.device.backend, out.device.name};
}

Status stageOutputs(FileGroup& files, RenderOutput& out, const Scene& scene, const RenderOptions& options,
                    const OutputPaths& paths, const std::string& sceneName, const ImageEncoding& encoding,
                    OutputTimes* times)
{
    using Clock = std::chrono::steady_clock;
    OutputTimes spent;
    auto since = [](Clock::time_point start) {
        return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    };
    // Each file is staged as soon as it is encoded, so that its bytes are freed before the next one.
    auto stage = [&](const std::string& path, const std::vector<unsigned char>& bytes) {
        const auto start = Clock::now();
        Status staged = files.stage(path, bytes.data(), bytes.size());
        spent.write += since(start);
        return staged;
    };
    const RenderSettings settings = options.resolved();
    const ImageOrigin origin = outputOrigin(out);
    if (!paths.png.empty()) {
        const auto start = Clock::now();
        // NPY has no room for the origin: it is the array alone, as numpy.save writes one.
        auto png = isNpyPath(paths.png) ? encodeNpy(out.color) : encodePng(out.color, origin, encoding.png);
        if (!png) return png.error();
        spent.encode = since(start);
        SR_TRY(stage(paths.png, *png));
    }
    if (!paths.aov.empty()) {
        const auto start = Clock::now();
        if (!out.aov.hasBary()) fillSurfaceAovs(scene, out.params, out.aov);
        if (settings.aovSamples && out.aov.sampleId.empty())
            fillSampleAovs(out.samples, settings.ssaa, out.aov);
        if (!out.aov.hasColor()) linearColorAov(out.color, out.aov);
        auto exr = encodeAovExr(out.aov, origin, paths.aov, encoding.exr);
        if (!exr) return exr.error();
        spent.aux += since(start);
        SR_TRY(stage(paths.aov, *exr));
    }
    if (!paths.stats.empty()) {
        const auto start = Clock::now();
        const std::string text =
            statsJson(out, options, sceneName, absoluteCamera(options, scene, sceneName)).dump(2) + "\n";
        spent.aux += since(start);
        SR_TRY(stage(paths.stats, std::vector<unsigned char>(text.begin(), text.end())));
    }
    if (times) *times = spent;
    return okStatus();
}

Status writeOutputs(RenderOutput& out, const Scene& scene, const RenderOptions& options,
                    const OutputPaths& paths, const std::string& sceneName, const ImageEncoding& encoding)
{
    FileGroup files;
    SR_TRY(stageOutputs(files, out, scene, options, paths, sceneName, encoding));
    return files.commit();
}

}  // namespace sr
