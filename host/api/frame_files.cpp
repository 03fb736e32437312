// frame_files.cpp - PNG or NPY, EXR and JSON of a rendered frame.
#include "api/frame_files.h"

#include <chrono>
#include <cstring>

#include "render/aov.h"

namespace sr {

bool littleEndianHost()
{
    const uint32_t word = 1;
    uint8_t first = 0;
    std::memcpy(&first, &word, 1);
    return first == 1;
}

RgbaImage colorImage(const raster::Frame& f)
{
    RgbaImage image;
    image.width = f.width;
    image.height = f.height;
    image.pixels.assign(f.color.size() / 4, 0u);
    // A word holds R in its low byte: on a little-endian host the bytes are the words' memory already.
    if (littleEndianHost() && !image.pixels.empty()) {
        std::memcpy(image.pixels.data(), f.color.data(), image.pixels.size() * 4);
        return image;
    }
    for (size_t i = 0; i < image.pixels.size(); ++i)
        for (size_t c = 0; c < 4; ++c) image.pixels[i] |= uint32_t(f.color[4 * i + c]) << (8 * c);
    return image;
}

AovImage aovImage(const raster::Frame& f, bool withColor, AovImage* surfacePlanes)
{
    const size_t n = size_t(f.width) * f.height;
    AovImage aov;
    if (surfacePlanes && surfacePlanes->baryU.size() == n) aov = std::move(*surfacePlanes);
    aov.width = f.width;
    aov.height = f.height;
    aov.id = f.id;
    aov.depth = f.depth;
    if (f.ao.size() == n) aov.ao = f.ao;
    if (!aov.hasBary() && f.bary.size() == 2 * n && f.uv.size() == 2 * n && f.normal.size() == 3 * n) {
        for (auto* plane :
             {&aov.baryU, &aov.baryV, &aov.uvU, &aov.uvV, &aov.normalX, &aov.normalY, &aov.normalZ})
            plane->resize(n);
        for (size_t i = 0; i < n; ++i) {
            aov.baryU[i] = f.bary[2 * i];
            aov.baryV[i] = f.bary[2 * i + 1];
            aov.uvU[i] = f.uv[2 * i];
            aov.uvV[i] = f.uv[2 * i + 1];
            aov.normalX[i] = f.normal[3 * i];
            aov.normalY[i] = f.normal[3 * i + 1];
            aov.normalZ[i] = f.normal[3 * i + 2];
        }
    }
    if (!f.sampleId.empty() && f.width > 0) {
        SampleAovs samples;
        samples.rasterWidth = f.rasterWidth;
        samples.rasterHeight = f.rasterHeight;
        samples.samples = f.samples;
        samples.id = f.sampleId;
        samples.depth = f.sampleDepth;
        fillSampleAovs(samples, f.rasterWidth / f.width, aov);
    }
    if (withColor && f.color.size() == 4 * n) linearColorAov(colorImage(f), aov);
    return aov;
}

ImageOrigin outputOrigin(const raster::Frame& frame)
{
    return {raster::backendName(frame.device.backend), frame.device.name};
}

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point start)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

Status stageFrame(FileGroup& files, const raster::Frame& frame, const OutputPaths& paths,
                  const ImageEncoding& encoding, OutputTimes* times, AovImage* surfacePlanes)
{
    OutputTimes spent;
    // Each file is staged as soon as it is encoded, so that its bytes are freed before the next one.
    auto stage = [&](const std::string& path, const std::vector<unsigned char>& bytes) {
        const auto start = Clock::now();
        Status staged = files.stage(path, bytes.data(), bytes.size());
        spent.write += since(start);
        return staged;
    };
    const ImageOrigin origin = outputOrigin(frame);
    if (!paths.png.empty()) {
        const auto start = Clock::now();
        const RgbaImage color = colorImage(frame);
        // NPY has no room for the origin: it is the array alone, as numpy.save writes one.
        auto png = isNpyPath(paths.png) ? encodeNpy(color) : encodePng(color, origin, encoding.png);
        if (!png) return png.error();
        spent.encode = since(start);
        SR_TRY(stage(paths.png, *png));
    }
    if (!paths.aov.empty()) {
        const auto start = Clock::now();
        auto exr = encodeAovExr(aovImage(frame, true, surfacePlanes), origin, paths.aov, encoding.exr);
        if (!exr) return exr.error();
        spent.aux += since(start);
        SR_TRY(stage(paths.aov, *exr));
    }
    if (!paths.stats.empty()) {
        const std::string text = frame.statsJson + "\n";
        SR_TRY(stage(paths.stats, std::vector<unsigned char>(text.begin(), text.end())));
    }
    if (times) *times = spent;
    return okStatus();
}

}  // namespace sr
