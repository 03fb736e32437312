// frame_readback.cpp - what a frame brings back: its stage timings and statistics, its images and AOVs
// (every sample's where asked), the images written in place (readImage, renderViews' copies), and the
// tessellated frames' ids mapped back to the scene's triangles.
#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "render/aov.h"
#include "render/renderer_internal.h"
#include "settings/schema.h"

namespace sr {
namespace {

// Every sample's id and depth (RenderSettings::aovSamples) from their visibility keys.
void sampleAovs(const std::vector<uint64_t>& visibility, const RenderSettings& settings,
                const RasterParams& params, SampleAovs& all)
{
    all.rasterWidth = params.width;
    all.rasterHeight = params.height;
    all.samples = settings.msaa;
    all.id.resize(visibility.size());
    all.depth.resize(visibility.size());
    for (uint64_t i = 0; i < visibility.size(); ++i) {
        all.id[i] = visibilityId(visibility[i]);
        all.depth[i] = visibilityDepth(visibility[i]);
    }
}

StageTiming summarize(std::string name, const std::vector<double>& ms)
{
    StageTiming t;
    t.name = std::move(name);
    t.minMs = *std::min_element(ms.begin(), ms.end());
    t.maxMs = *std::max_element(ms.begin(), ms.end());
    t.medianMs = median(ms);
    return t;
}

}  // namespace

// The timed runs' GPU times per stage and in all, the last frame's parameters, the device's peak memory.
void RenderSession::timings(FrameState& f) const
{
    RenderOutput& out = f.out;
    // Every stage of the frame in dispatch order (one with no work at 0 ms): the tess_* stages first when
    // they ran.
    for (const Dispatch& d : f.lastDispatches)
        out.stages.push_back(summarize(stageName(d.stage), f.stageMs[d.stage]));
    out.total = summarize("total", f.totalMs);
    out.params = f.params;
    out.peakDeviceBytes = device_->peakAllocatedBytes();
}

// RenderStats from the last frame's counters and tessellation totals.
void RenderSession::statistics(FrameState& f) const
{
    const Scene& scene = *scene_;
    const uint32_t* counters = f.counters;
    RenderStats& st = f.out.stats;
    st.trianglesIn = f.tessellating ? f.tessTotals.y : scene.triangleCount();
    st.tessVertices = f.tessTotals.x;
    st.tessTriangles = f.tessTotals.y;
    st.tessCulled = f.tessTotals.z;
    st.culled = counters[COUNTER_CULLED];
    st.clipped = counters[COUNTER_CLIPPED];
    st.invalid = counters[COUNTER_INVALID];
    st.rasterized = uint64_t(counters[COUNTER_SMALL]) + counters[COUNTER_BIG];
    st.smallTris = counters[COUNTER_SMALL];
    st.bigTris = counters[COUNTER_BIG];
    st.linesIn = scene.lineCount();
    st.lines = counters[COUNTER_LINES];
    st.pointsIn = scene.pointCount();
    st.points = counters[COUNTER_POINTS];
    st.records = counters[COUNTER_SETUP];
    st.pieces = counters[COUNTER_PIECES];
    st.binEntries = counters[COUNTER_BIN_ENTRIES];
    st.capacities = capacities_;
    st.clusters = f.clusters;
    st.clustersCulled = counters[COUNTER_CLUSTERS_CULLED];
    if (lodHierarchy_) {
        st.lodSceneTriangles = lodHierarchy_->sceneTriangles;
        st.lodTriangles = f.clusters > 0 ? counters[COUNTER_LOD_TRIANGLES] : scene.triangleCount();
        st.trianglesIn = st.lodTriangles;
    }
}

// What RenderSettings::download asks for: the colour image; with All also the hit counts when counted
// and the id and depth AOVs from the visibility buffer, every sample's when asked for.
Status RenderSession::download(const RenderSettings& settings, FrameState& f)
{
    RenderOutput& out = f.out;
    ComputeDevice& device = *device_;
    out.color.width = out.aov.width = settings.width;
    out.color.height = out.aov.height = settings.height;
    if (settings.download == ImageDownload::None) return okStatus();
    const uint32_t copied = settings.outputs & ~settings.keptOutputs;
    if (settings.download == ImageDownload::Colour || (copied & OUTPUT_COLOR) != 0u) {
        out.color.pixels.resize(f.pixels);
        SR_TRY(device.download(BUF_FRAMEBUFFER, out.color.pixels.data(), f.pixels * sizeof(uint32_t)));
    }
    if (settings.download == ImageDownload::Colour) return okStatus();
    if (countsHits(settings)) {
        out.hitCount.resize(f.samples);
        SR_TRY(device.download(BUF_HIT_COUNT, out.hitCount.data(), f.samples * sizeof(uint32_t)));
    }
    if (settings.ao != AO_OFF) {
        // The plane shade read, at the raster's resolution (the planes up to it, the head of BUF_AO); an
        // output pixel takes the mean of its ssaa x ssaa raster pixels, as its colour does.
        std::vector<float> planes((uint64_t(f.params.aoPlane) + 1) * f.rasterPixels);
        SR_TRY(device.download(BUF_AO, planes.data(), planes.size() * sizeof(float)));
        planes.erase(planes.begin(), planes.begin() + int64_t(f.params.aoPlane * f.rasterPixels));
        for (float& v : planes) v = aoShaded(v);
        out.aov.ao = resolveAo(planes, settings.width, settings.height, settings.ssaa);
    }
    // Every sample's key only when asked for; the pixels' AOVs come from stage aovs, already unpacked.
    if (settings.aovSamples) {
        std::vector<uint64_t> visibility(f.samples);
        SR_TRY(device.download(BUF_VISIBILITY, visibility.data(), visibility.size() * sizeof(uint64_t)));
        sampleAovs(visibility, settings, f.params, out.samples);
    }
    const AovsLayout l = aovsLayout(uint32_t(f.pixels), aovOutputs_);
    auto plane = [&](auto& values, uint32_t word) {
        values.resize(f.pixels);
        return device.download(BUF_FRAMEBUFFER, values.data(), f.pixels * 4, uint64_t(word) * 4);
    };
    if ((copied & OUTPUT_ID) != 0u) SR_TRY(plane(out.aov.id, l.ids));
    if ((copied & OUTPUT_DEPTH) != 0u) SR_TRY(plane(out.aov.depth, l.depths));
    if (settings.surfaceAovs) {
        uint32_t word = l.surface;
        for (std::vector<float>* p : {&out.aov.baryU, &out.aov.baryV, &out.aov.uvU, &out.aov.uvV,
                                      &out.aov.normalX, &out.aov.normalY, &out.aov.normalZ}) {
            SR_TRY(plane(*p, word));
            word += uint32_t(f.pixels);
        }
    }
    return okStatus();
}

Result<std::vector<ViewCopy>> RenderSession::viewCopies(const std::vector<ViewTarget>& targets) const
{
    const AovsLayout l = aovsLayout(uint32_t(aovPixels_), aovOutputs_);
    std::vector<ViewCopy> copies;
    for (const ViewTarget& t : targets) {
        uint64_t word = 0;
        switch (t.output) {
        case OUTPUT_COLOR: break;
        case OUTPUT_ID: word = l.ids; break;
        case OUTPUT_DEPTH: word = l.depths; break;
        case OUTPUT_RAST: word = l.rast; break;
        default: return makeError(ExitCode::Usage, "views: no image {} to write", t.output);
        }
        if (t.destination == nullptr)
            return makeError(ExitCode::Usage, "views: image {} has nowhere to go", t.output);
        copies.push_back({word * 4, (t.output == OUTPUT_RAST ? 16 : 4) * aovPixels_,
                          static_cast<char*>(t.destination), t.onDevice});
    }
    return copies;
}

Status RenderSession::readImage(uint32_t output, void* destination, size_t bytes, bool onDevice)
{
    const AovsLayout l = aovsLayout(uint32_t(aovPixels_), aovOutputs_);
    bool drawn = false;
    uint64_t word = 0;
    switch (output) {
    case OUTPUT_COLOR: drawn = framebufferColour_; break;
    case OUTPUT_ID: drawn = aovOutputs_ != 0u, word = l.ids; break;
    case OUTPUT_DEPTH: drawn = aovOutputs_ != 0u, word = l.depths; break;
    case OUTPUT_RAST: drawn = (aovOutputs_ & AOV_OUT_RAST) != 0u, word = l.rast; break;
    default: break;
    }
    const uint64_t expected = (output == OUTPUT_RAST ? 16 : 4) * aovPixels_;
    if (!drawn || bytes != expected || device_->resident() != id_)
        return makeError(ExitCode::Usage,
                         "no image {} of {} bytes to read: the session's last frame was not drawn with it, "
                         "or another session drew since",
                         output, bytes);
    return onDevice ? device_->downloadToDevice(BUF_FRAMEBUFFER, destination, bytes, word * 4)
                    : device_->download(BUF_FRAMEBUFFER, destination, bytes, word * 4);
}

// With tessellation, the ids of generated triangles mapped back to the scene's triangles.
Status RenderSession::remapTessellatedIds(FrameState& f)
{
    std::vector<uint32_t> sourceIds(f.tessTotals.y);
    SR_TRY(device_->download(BUF_TESS_IDS, sourceIds.data(), sourceIds.size() * sizeof(uint32_t)));
    const auto sceneTriangles = uint32_t(scene_->triangleCount());
    mapToSourceIds(f.out.aov.id, sourceIds, sceneTriangles);
    mapToSourceIds(f.out.samples.id, sourceIds, sceneTriangles);
    return okStatus();
}

}  // namespace sr
