// renderer.cpp - buffer sizing, stage dispatch, grow-and-redraw and timing statistics, shared by the
// CUDA and Vulkan backends.
#include "render/renderer.h"

#include "ao/ao_image.h"
#include "ao/ao_reference.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include <glm/gtc/matrix_inverse.hpp>

#include "render/aov.h"
#include "render/materials.h"
#include "scene/clusters.h"
#include "scene/texture.h"
#include "settings/schema.h"

namespace sr {
namespace {

uint32_t groupsFor(uint64_t threads, uint32_t groupSize)
{
    return uint32_t((threads + groupSize - 1) / groupSize);
}

template <typename T>
Status uploadVector(ComputeDevice& device, uint32_t buffer, const std::vector<T>& data)
{
    SR_TRY(device.resize(buffer, data.size() * sizeof(T)));
    return device.upload(buffer, data.data(), data.size() * sizeof(T));
}

// Materials, texture coordinates, textures and the sRGB decode table; a scene without materials
// allocates none of them (the stages do not read them when RasterParams.materialCount is 0).
Status uploadMaterials(ComputeDevice& device, const Scene& scene)
{
    if (scene.materials.empty()) return okStatus();
    SR_TRY(uploadVector(device, BUF_MATERIALS, gpuMaterials(scene)));
    if (scene.textures.empty()) return okStatus();
    std::vector<uint32_t> texels;
    auto textures = gpuTextures(scene, texels);
    if (!textures) return textures.error();
    SR_TRY(uploadVector(device, BUF_TEXTURES, *textures));
    SR_TRY(uploadVector(device, BUF_TEXELS, texels));
    SR_TRY(uploadVector(device, BUF_TEXCOORDS, scene.texcoords));
    return uploadVector(device, BUF_SRGB_TABLE, srgbDecodeTable());
}

// One material per primitive id: the triangles', then the line segments', then the points'.
std::vector<uint32_t> primitiveMaterials(const Scene& scene)
{
    std::vector<uint32_t> materials = scene.triMaterials;
    materials.insert(materials.end(), scene.lineMaterials.begin(), scene.lineMaterials.end());
    materials.insert(materials.end(), scene.pointMaterials.begin(), scene.pointMaterials.end());
    return materials;
}

// Screen tiles per row and per column for a width x height framebuffer (RasterParams.tilesX, tilesY).
glm::uvec2 tileGrid(uint32_t width, uint32_t height)
{
    return {(width + TILE_SIZE - 1) / TILE_SIZE, (height + TILE_SIZE - 1) / TILE_SIZE};
}

// Capacity for a list that needed `counted` entries: what was counted plus an eighth, so that a
// camera that moves a little does not overflow again, and no more (memory is budgeted per triangle).
uint64_t grownCapacity(uint64_t counted)
{
    return counted + counted / 8 + 64;
}

std::vector<Dispatch> frameDispatches(const RasterParams& p, const FrameWork& work)
{
    uint64_t samples = uint64_t(p.samplePlane) * p.sampleCount;
    uint64_t outputPixels = uint64_t(p.width / p.ssaa) * (p.height / p.ssaa);
    uint64_t tiles = uint64_t(p.tilesX) * p.tilesY;
    uint32_t scanGroups = groupsFor(tiles, SCAN_GROUP_SIZE);

    std::vector<Dispatch> dispatches = {
        {STAGE_CLEAR,
         groupsFor(std::max<uint64_t>({samples, tiles, COUNTER_COUNT}), GROUP_SIZE * CLEAR_SPAN)},
        {STAGE_VERTEX, p.transformInSetup ? 0u : groupsFor(p.vertexCount, GROUP_SIZE)},
        {STAGE_LOD_CUT, p.lodScale > 0.0f ? groupsFor(p.clusterCount, GROUP_SIZE) : 0u},
        // With level of detail a GPU's groups loop over the cut. On a CPU device (rasterChunk != 0) each
        // group takes its clusters once, as without: llvmpipe 22.3 ends a shader's loops after 65,535
        // turns in all, which a few rounds of big clusters reach (docs/benchmark.md).
        {STAGE_CLUSTERS,
         p.lodScale > 0.0f && work.groups.rasterChunk == 0
             ? std::min(groupsFor(p.clusterCount, CLUSTERS_PER_GROUP), uint32_t(LOD_CLUSTER_GROUPS))
             : groupsFor(p.clusterCount, CLUSTERS_PER_GROUP)},
        {STAGE_SETUP,
         groupsFor(uint64_t(p.triangleCount) + p.lineCount + p.pointCount - p.setupFirstPrimitive,
                   GROUP_SIZE)},
        {STAGE_BIN_COUNT, work.binBig && work.countSplit ? p.binGroups : 0u},
        {STAGE_SCAN_BLOCKS, work.binBig ? scanGroups : 0u},
        {STAGE_SCAN_SUMS, work.binBig ? 1u : 0u},
        {STAGE_BIN_FILL, work.binBig ? p.binGroups : 0u},
        {STAGE_RASTER_TILES, work.binBig ? p.rasterGroups : 0u},
        {STAGE_SHADE, groupsFor(outputPixels, GROUP_SIZE * work.groups.shadePixels)},
    };
    // Ambient occlusion's stages run before shade, and only with GTAO: a frame without them has exactly
    // the dispatches it had before AO existed (an empty dispatch still costs its two timer events).
    if (p.aoMode == AO_GTAO) {
        const uint32_t groups = groupsFor(p.samplePlane, GROUP_SIZE);
        std::vector<Dispatch> ao = {{STAGE_AO_GBUFFER, groups}, {STAGE_AO, groups}};
        if (p.aoPlane == AO_PLANE_DENOISED) ao.push_back({STAGE_AO_DENOISE, groups});
        dispatches.insert(dispatches.end() - 1, ao.begin(), ao.end());
    }
    // A frame whose colour nobody reads has no shade; one whose ids nobody reads has no aovs.
    if (!work.shade)
        dispatches.erase(std::find_if(dispatches.begin(), dispatches.end(),
                                      [](const Dispatch& d) { return d.stage == STAGE_SHADE; }));
    if (p.aovOutputs != 0u) dispatches.push_back({STAGE_AOVS, groupsFor(outputPixels, GROUP_SIZE)});
    for (Dispatch& d : dispatches) {
        d.alphaTest = work.alphaTest &&
                      (d.stage == STAGE_SETUP || d.stage == STAGE_CLUSTERS || d.stage == STAGE_RASTER_TILES);
        d.rasterMethod = work.rasterMethod;
    }
    return dispatches;
}

// No vertex shared on average: as many vertices as triangle corners.
bool transformsInSetup(const Scene& scene)
{
    return scene.vertexCount() >= scene.indices.size();
}

bool countsHits(const RenderSettings& s)
{
    return s.countHits || s.shadingMode == SHADING_HIT_COUNT;
}

// The id and depth AOVs of every output pixel from the downloaded visibility keys (the first sample
// plane at least, every plane with aovSamples), and with aovSamples every sample's (SampleAovs).
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

RasterParams frameParams(const Scene& scene, const CameraMatrices& camera, const RenderSettings& s,
                         const ListCapacities& capacities, const GroupCounts& groups)
{
    RasterParams p{};
    p.clipFromWorld = camera.clipFromWorld;
    p.viewFromWorld = camera.viewFromWorld;
    p.normalFromWorld = glm::inverseTranspose(camera.viewFromWorld);
    glm::vec3 l = glm::length(s.lightDirView) > 0.0f ? glm::normalize(s.lightDirView) : glm::vec3(0, 0, 1);
    p.lightDirView = glm::vec4(l, 0.0f);
    p.lightColor = glm::vec4(s.lightColor, s.ambient);
    p.background = glm::vec4(s.background, 1.0f);
    p.shadeExtra = glm::vec4(s.specularPower, camera.znear, camera.zfar, s.specular);
    // The raster grid: the output resolution times the SSAA factor per side.
    p.width = s.width * s.ssaa;
    p.height = s.height * s.ssaa;
    p.guardBand = glm::vec4(float(GUARD_BAND_PX) / (0.5f * float(p.width)),
                            float(GUARD_BAND_PX) / (0.5f * float(p.height)), 0.0f, 0.0f);
    p.vertexCount = uint32_t(scene.vertexCount());
    p.triangleCount = uint32_t(scene.triangleCount());
    p.cullMode = s.cullMode;
    p.shadingMode = s.shadingMode;
    p.hasColors = scene.colors.empty() ? 0u : 1u;
    p.setupCapacity = capacities.records;
    p.pieceCapacity = capacities.pieces;
    p.binCapacity = capacities.binEntries;
    glm::uvec2 grid = tileGrid(p.width, p.height);
    p.tilesX = grid.x;
    p.tilesY = grid.y;
    p.rasterChunk = groups.rasterChunk;
    p.rasterGroups = std::max(groups.raster, 1u);
    p.binGroups = std::clamp(groups.bin, 1u, std::max(groupsFor(capacities.pieces, GROUP_SIZE), 1u));
    p.debugFlags = countsHits(s) ? DEBUG_COUNT_HITS : 0u;
    p.transformInSetup = transformsInSetup(scene) ? 1u : 0u;
    p.materialCount = uint32_t(scene.materials.size());
    p.textureFilter = s.textureFilter;
    p.uvInterpolation = s.uvInterpolation;
    p.textureCount = uint32_t(scene.textures.size());
    p.sampleCount = s.msaa;
    p.sampleBounds = sampleBoundsOf(s.msaa);
    p.ssaa = s.ssaa;
    p.samplePlane = p.width * p.height;
    p.pointCount = uint32_t(scene.pointCount());
    p.pointSize = s.pointSize;
    p.lineCount = uint32_t(scene.lineCount());
    p.lineWidth = s.lineWidth;
    p.lineDepthBias = s.lineDepthBias;
    p.tessMode = s.tessellate;
    p.tessMaxLevel = s.tessMaxLevel;
    p.tessEdgePx = s.tessEdgePx;
    p.tessSourceTriangles = p.triangleCount;
    p.tessSourceVertices = p.vertexCount;
    p.tessBlocks = groupsFor(p.triangleCount, SCAN_GROUP_SIZE);
    // Generated vertices are shared by their triangles: the vertex stage transforms them once.
    if (s.tessellate != TESS_OFF) p.transformInSetup = 0u;
    if (s.ao != AO_OFF) {
        // View-space points from depth (shared/ao.h's aoViewPoint) need the projection alone; GLM's
        // matrices are [column][row].
        const glm::mat4& proj = camera.clipFromView;
        p.aoUnprojectX = glm::vec4(1.0f / proj[0][0], proj[2][0], proj[3][0], proj[2][3]);
        p.aoUnprojectY = glm::vec4(1.0f / proj[1][1], proj[2][1], proj[3][1], proj[3][3]);
        p.aoMode = s.ao;
        p.aoPlane = s.ao == AO_GTAO && s.aoDenoise == AO_DENOISE_ON ? AO_PLANE_DENOISED : AO_PLANE_RAW;
        p.aoSlices = s.aoSlices;
        p.aoSteps = s.aoSteps;
        p.aoRadius = float(aoWorldRadius(scene, s) * aoViewScale(camera.viewFromWorld));
        // Pixels per view unit at w = 1: half the raster's extent times the projection's scale, the
        // smaller of the two axes (they agree for square pixels).
        p.aoPixelScale =
            0.5f * std::min(float(p.width) * std::abs(proj[0][0]), float(p.height) * std::abs(proj[1][1]));
        p.aoInvSlices = recipDet(float(p.aoSlices));
        p.aoInvSteps = recipDet(float(p.aoSteps));
        p.aoInvFalloff = recipDet(AO_FALLOFF * p.aoRadius);
        p.aoInvWidth = recipDet(float(p.width));
        p.aoInvHeight = recipDet(float(p.height));
    }
    p.aovOutputs = aovOutputs(s);
    return p;
}

uint32_t aovOutputs(const RenderSettings& s)
{
    if (s.download != ImageDownload::All) return 0u;
    uint32_t bits = (s.outputs & (OUTPUT_ID | OUTPUT_DEPTH)) != 0u ? AOV_OUT_IDS_DEPTH : 0u;
    if (s.surfaceAovs) bits |= AOV_OUT_IDS_DEPTH | AOV_OUT_SURFACE;
    if ((s.outputs & OUTPUT_RAST) != 0u) bits |= AOV_OUT_IDS_DEPTH | AOV_OUT_RAST;
    return bits;
}

double aoStagesMs(const std::vector<StageTiming>& stages)
{
    double ms = 0.0;
    for (const StageTiming& t : stages)
        for (uint32_t stage : {STAGE_AO_GBUFFER, STAGE_AO, STAGE_AO_DENOISE})
            if (t.name == kStages[stage].name) ms += t.medianMs;
    return ms;
}

double aoWorldRadius(const Scene& scene, const RenderSettings& s)
{
    if (s.aoRadius > 0.0f) return s.aoRadius;
    const glm::dvec3 extent = glm::dvec3(scene.boundsMax) - glm::dvec3(scene.boundsMin);
    const double radius = 0.5 * glm::length(extent);
    return kAoRadiusFraction * (radius > 0.0 ? radius : 1.0);
}

double aoViewScale(const glm::mat4& viewFromWorld)
{
    return std::cbrt(std::abs(glm::determinant(glm::dmat3(glm::dmat4(viewFromWorld)))));
}

double median(std::vector<double> values)
{
    std::sort(values.begin(), values.end());
    size_t n = values.size();
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

std::vector<float> resolveAo(const std::vector<float>& raster, uint32_t width, uint32_t height, uint32_t ssaa)
{
    std::vector<float> out(uint64_t(width) * height);
    const uint64_t rasterWidth = uint64_t(width) * ssaa;
    for (uint32_t y = 0; y < height; ++y)
        for (uint32_t x = 0; x < width; ++x) {
            double sum = 0.0;
            for (uint32_t j = 0; j < ssaa; ++j)
                for (uint32_t i = 0; i < ssaa; ++i)
                    sum += raster[(uint64_t(y) * ssaa + j) * rasterWidth + uint64_t(x) * ssaa + i];
            out[uint64_t(y) * width + x] = float(sum / (double(ssaa) * ssaa));
        }
    return out;
}

Status checkRenderInputs(const Scene& scene, const RenderSettings& settings)
{
    // Each value and their combinations are checked by the settings schema, the one place that knows
    // their ranges.
    SR_TRY(checkSettings(settings));
    // Level of detail simplifies triangles: a display form (lines, points, the wireframe overlay) has
    // none of its own to simplify.
    if (settings.lod == LOD_ON && scene.display)
        return makeError(ExitCode::Usage,
                         "--lod on draws triangles; it does not combine with --primitive-mode "
                         "lines or points or --wireframe");
    // The device's triangles are then generated or simplified ones: the ids rasterize's output carries
    // would not be the scene's.
    if ((settings.outputs & OUTPUT_RAST) != 0u && (settings.tessellate != TESS_OFF || settings.lod == LOD_ON))
        return makeError(ExitCode::Usage,
                         "rasterize's output does not combine with --tessellate or --lod on");
    return checkSceneInputs(scene);
}

Status checkSceneInputs(const Scene& scene)
{
    if (scene.primitiveCount() == 0)
        return makeError(ExitCode::Usage, "the scene has nothing to draw (no triangles, lines or points)");
    // Primitive ids share 32 bits with EMPTY_ID and index math runs in uint.
    if (scene.triangleCount() >= (uint64_t(1) << 31) / 3 || scene.primitiveCount() >= (uint64_t(1) << 31) ||
        scene.vertexCount() >= (uint64_t(1) << 31))
        return makeError(ExitCode::Usage,
                         "the scene is too large ({} triangles, {} line segments, {} points, {} vertices)",
                         scene.triangleCount(), scene.lineCount(), scene.pointCount(), scene.vertexCount());
    // A scene that skipped finalizeScene (a library caller's own) could send the stages past the end of
    // its triangle flags.
    if (scene.triFlags.size() != scene.triangleCount())
        return makeError(ExitCode::Usage, "the scene has {} triangle flags for {} triangles",
                         scene.triFlags.size(), scene.triangleCount());
    if (scene.lines.size() % 2 != 0)
        return makeError(ExitCode::Usage, "the scene has an odd number ({}) of line indices",
                         scene.lines.size());
    if (!scene.colors.empty() && scene.colors.size() != scene.vertexCount())
        return makeError(ExitCode::Usage, "the scene has {} colours for {} vertices", scene.colors.size(),
                         scene.vertexCount());
    return okStatus();
}

RenderSession::RenderSession(ComputeDevice& device, const Scene& scene) : device_(&device), scene_(&scene)
{
    // Tokens are unique in the process, so a session never mistakes another's buffers for its own,
    // whichever device or thread made it.
    static std::atomic<uint64_t> nextId{1};
    id_ = nextId.fetch_add(1, std::memory_order_relaxed);
}

Result<RenderSession> RenderSession::create(ComputeDevice& device, const Scene& scene)
{
    SR_TRY(checkSceneInputs(scene));
    RenderSession session(device, scene);
    SR_TRY(session.claimDevice());
    return session;
}

Status RenderSession::claimDevice()
{
    if (device_->resident() != id_) {
        // Another session (another scene, or this one's level-of-detail or display scene) used the
        // buffers since this one did: everything it sized and uploaded there is gone.
        forgetDeviceBuffers();
        device_->claim(id_);
    }
    if (!uploaded_) {
        SR_TRY(upload());
        uploaded_ = true;
        viewPositions_ = false;
    }
    if (viewPositions_) {  // renderViews left a view's positions: the scene's go back
        SR_TRY(uploadVector(*device_, BUF_POSITIONS, scene_->positions));
        viewPositions_ = false;
    }
    return okStatus();
}

Status RenderSession::ensureSize(uint32_t buffer, size_t bytes)
{
    if (sizes_[buffer] == bytes) return okStatus();
    sizes_[buffer] = SIZE_MAX;  // unknown until the resize succeeds
    SR_TRY(device_->resize(buffer, bytes));
    sizes_[buffer] = bytes;
    return okStatus();
}

// (Re)allocates the lists. Work and memory grow with the scene: nothing here depends on a worst case
// such as pixels x triangles.
Status RenderSession::allocateLists()
{
    SR_TRY(ensureSize(BUF_SETUP_TRIS, size_t(capacities_.records) * sizeof(TriSetup)));
    SR_TRY(ensureSize(BUF_PIECES, size_t(capacities_.pieces) * 2 * sizeof(uint32_t)));
    return ensureSize(BUF_BIN_ENTRIES, size_t(capacities_.binEntries) * sizeof(uint32_t));
}

// The scene's triangles and the materials of every primitive, where the later stages read them (again
// after tessellated frames replaced them).
Status RenderSession::uploadTriangles()
{
    const Scene& scene = *scene_;
    for (uint32_t buffer : {BUF_INDICES, BUF_TRI_FLAGS, BUF_TRI_MATERIALS}) sizes_[buffer] = SIZE_MAX;
    SR_TRY(uploadVector(*device_, BUF_INDICES, scene.indices));
    SR_TRY(uploadVector(*device_, BUF_TRI_FLAGS, scene.triFlags));
    if (!scene.materials.empty())
        SR_TRY(uploadVector(*device_, BUF_TRI_MATERIALS, primitiveMaterials(scene)));
    trianglesReplaced_ = false;
    tessTriangleCapacity_ = 0;
    return okStatus();
}

Status RenderSession::prepareTessellation()
{
    if (tessPrepared_) return okStatus();
    const Scene& scene = *scene_;
    tessSources_ = tessSources(scene);
    SR_TRY(uploadVector(*device_, BUF_TESS_SOURCE, tessSources_.sources));
    if (!scene.materials.empty())
        SR_TRY(uploadVector(*device_, BUF_TESS_MATERIALS, primitiveMaterials(scene)));
    SR_TRY(ensureSize(BUF_TESS_COUNTS, std::max<size_t>(scene.triangleCount(), 1) * sizeof(glm::uvec4)));
    SR_TRY(ensureSize(BUF_TESS_SUMS,
                      (groupsFor(scene.triangleCount(), SCAN_GROUP_SIZE) + 1) * sizeof(glm::uvec4)));
    tessPrepared_ = true;
    return okStatus();
}

Status RenderSession::sizeTessellation(uint64_t vertices, uint64_t triangles)
{
    const Scene& scene = *scene_;
    const uint64_t v = scene.vertexCount();
    if (vertices > tessVertexCapacity_ || tessVertexCapacity_ == 0) {
        tessVertexCapacity_ = grownCapacity(vertices);
        const size_t bytes = (v + tessVertexCapacity_) * sizeof(glm::vec4);
        // A resize loses the contents: the scene's vertices go back in at the head.
        SR_TRY(ensureSize(BUF_POSITIONS, bytes));
        SR_TRY(device_->upload(BUF_POSITIONS, scene.positions.data(), v * sizeof(glm::vec4)));
        SR_TRY(ensureSize(BUF_NORMALS, bytes));
        SR_TRY(device_->upload(BUF_NORMALS, scene.normals.data(), v * sizeof(glm::vec4)));
        if (!scene.colors.empty()) {
            SR_TRY(ensureSize(BUF_COLORS, bytes));
            SR_TRY(device_->upload(BUF_COLORS, scene.colors.data(), v * sizeof(glm::vec4)));
        }
        if (!scene.textures.empty()) {
            SR_TRY(ensureSize(BUF_TEXCOORDS, bytes));
            SR_TRY(device_->upload(BUF_TEXCOORDS, scene.texcoords.data(), v * sizeof(glm::vec4)));
        }
        SR_TRY(ensureSize(BUF_CLIP_POS, bytes));
    }
    if (triangles > tessTriangleCapacity_ || !trianglesReplaced_) {
        tessTriangleCapacity_ = std::max(tessTriangleCapacity_, grownCapacity(triangles));
        const uint64_t t = tessTriangleCapacity_;
        SR_TRY(ensureSize(BUF_INDICES, 3 * t * sizeof(uint32_t)));
        SR_TRY(ensureSize(BUF_TRI_FLAGS, t * sizeof(uint32_t)));
        SR_TRY(ensureSize(BUF_TESS_IDS, t * sizeof(uint32_t)));
        if (!scene.materials.empty())
            SR_TRY(ensureSize(BUF_TRI_MATERIALS,
                              (t + scene.lineCount() + scene.pointCount()) * sizeof(uint32_t)));
        trianglesReplaced_ = true;
    }
    return okStatus();
}

Status RenderSession::upload()
{
    const Scene& scene = *scene_;
    ComputeDevice& device = *device_;
    SR_TRY(uploadVector(device, BUF_POSITIONS, scene.positions));
    SR_TRY(uploadVector(device, BUF_NORMALS, scene.normals));
    if (!scene.colors.empty()) SR_TRY(uploadVector(device, BUF_COLORS, scene.colors));
    if (!scene.points.empty()) SR_TRY(uploadVector(device, BUF_POINTS, scene.points));
    if (!scene.lines.empty()) SR_TRY(uploadVector(device, BUF_LINES, scene.lines));
    SR_TRY(uploadMaterials(device, scene));
    SR_TRY(uploadTriangles());
    // A vertex buffer of clip positions pays off only when vertices are shared; a triangle soup (every
    // corner its own vertex) is transformed in setup instead, and the buffer costs nothing.
    SR_TRY(ensureSize(BUF_CLIP_POS, transformsInSetup(scene) ? 16 : scene.vertexCount() * sizeof(glm::vec4)));
    SR_TRY(ensureSize(BUF_COUNTERS, COUNTER_COUNT * sizeof(uint32_t)));
    alphaTest_ =
        !scene.materials.empty() && std::any_of(scene.triFlags.begin(), scene.triFlags.end(),
                                                [](uint32_t f) { return (f & TRI_FLAG_ALPHA_MASK) != 0u; });
    return okStatus();
}

Status RenderSession::positionsChanged(bool normalsChanged)
{
    clustersBuilt_ = clustersUploaded_ = false;
    clusterSet_ = ClusterSet();
    clusterCount_ = 0;
    clusterTriangles_ = 0.0;
    lod_.reset();
    aoBvh_.reset();
    tessPrepared_ = false;
    // Buffers another session holds now are uploaded whole before this one's next frame anyway.
    if (!uploaded_ || device_->resident() != id_) return okStatus();
    // Same sizes: copied over the old ones, with no reallocation (a CUDA resize is a free and a malloc).
    const size_t bytes = scene_->positions.size() * sizeof(glm::vec4);
    SR_TRY(device_->upload(BUF_POSITIONS, scene_->positions.data(), bytes));
    return normalsChanged ? device_->upload(BUF_NORMALS, scene_->normals.data(), bytes) : okStatus();
}

Result<RenderOutput> renderScene(ComputeDevice& device, const Scene& scene, const CameraMatrices& camera,
                                 const RenderSettings& settings)
{
    // Every input is checked before anything is uploaded.
    SR_TRY(checkRenderInputs(scene, settings));
    auto session = RenderSession::create(device, scene);
    if (!session) return session.error();
    return session->render(camera, settings);
}

TessellatedDisplay tessellatedDisplay(const Scene& display, const CameraMatrices& camera,
                                      const RenderSettings& settings)
{
    const DisplayForm& form = *display.display;
    RenderSettings s = settings;
    s.cullMode = CULL_NONE;
    TessellatedScene mesh =
        tessellateOnHost(form.source, tessSources(form.source), frameParams(form.source, camera, s, {}, {}));
    TessellatedDisplay t;
    t.sourceTriangles = uint32_t(form.source.triangleCount());
    t.tessVertices = mesh.scene.vertexCount() - form.source.vertexCount();
    t.tessTriangles = mesh.scene.triangleCount();
    t.tessCulled = mesh.culled;
    t.sourceIds = std::move(mesh.sourceIds);
    t.scene = displayScene(std::move(mesh.scene), form.mode, form.wireframe);
    t.scene.display.reset();
    return t;
}

void finishTessellatedDisplay(const TessellatedDisplay& t, RenderOutput& out)
{
    if (t.scene.triangleCount() > 0) {
        mapToSourceIds(out.aov.id, t.sourceIds, t.sourceTriangles);
        mapToSourceIds(out.samples.id, t.sourceIds, t.sourceTriangles);
    }
    out.stats.tessVertices = t.tessVertices;
    out.stats.tessTriangles = t.tessTriangles;
    out.stats.tessCulled = t.tessCulled;
}

Result<RenderOutput> RenderSession::renderTessellatedDisplay(const CameraMatrices& camera,
                                                             const RenderSettings& settings)
{
    TessellatedDisplay t = tessellatedDisplay(*scene_, camera, settings);
    RenderSettings plain = settings;
    plain.tessellate = TESS_OFF;
    // A session of its own, which claims the device's buffers; this one uploads again when it next draws.
    auto out = renderScene(*device_, t.scene, camera, plain);
    if (out) finishTessellatedDisplay(t, *out);
    return out;
}

void RenderSession::forgetDeviceBuffers()
{
    uploaded_ = false;
    sizes_.assign(BUF_COUNT, SIZE_MAX);
    tessPrepared_ = false;
    clustersUploaded_ = false;
    trianglesReplaced_ = false;
    tessVertexCapacity_ = tessTriangleCapacity_ = 0;
}

struct RenderSession::LodState {
    LodHierarchy hierarchy;
    Scene scene;  // the session's scene with the simplified triangles (lodScene)
    std::optional<RenderSession> session;
};

Result<RenderOutput> RenderSession::renderLod(const CameraMatrices& camera, const RenderSettings& settings)
{
    double buildMs = 0.0;
    if (!lod_) {
        const auto start = std::chrono::steady_clock::now();
        auto state = std::make_shared<LodState>();
        state->hierarchy = buildLodHierarchy(*scene_);
        state->scene = lodScene(*scene_, state->hierarchy);
        buildMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        auto session = RenderSession::create(*device_, state->scene);
        if (!session) return session.error();
        state->session.emplace(std::move(*session));
        state->session->lodHierarchy_ = &state->hierarchy;
        lod_ = std::move(state);
    }
    auto out = lod_->session->render(camera, settings);
    if (!out) return out;
    for (uint32_t& id : out->aov.id) id = lodAovId(id, lod_->hierarchy);
    for (uint32_t& id : out->samples.id) id = lodAovId(id, lod_->hierarchy);
    out->stats.lodBuildMs = buildMs;
    return out;
}

// The state one render() call passes from step to step.
struct RenderSession::FrameState {
    uint64_t pixels = 0;        // output pixels
    uint64_t rasterPixels = 0;  // pixels of the raster grid: output pixels x ssaa^2
    uint64_t samples = 0;       // samples of the raster grid: raster pixels x msaa
    uint64_t tiles = 0;         // screen tiles of the raster grid
    bool tessellating = false;  // RenderSettings::tessellate is not TESS_OFF
    uint32_t clusters = 0;      // clusters the triangles go through (frameClusters); 0: setup
    FrameWork work;             // what the next frame runs
    uint32_t rasterChunk = 0;   // GroupCounts::rasterChunk
    // The last frame drawn: its parameters, its counters, and its tessellation totals (generated
    // vertices, triangles, culled scene triangles, overflow).
    RasterParams params{};
    uint32_t counters[COUNTER_COUNT] = {};
    glm::uvec4 tessTotals = glm::uvec4(0u);
    // The timed runs' GPU times per stage and per frame, and the last timed frame's dispatches in order.
    std::vector<std::vector<double>> stageMs = std::vector<std::vector<double>>(STAGE_COUNT);
    std::vector<double> totalMs;
    std::vector<Dispatch> lastDispatches;
    RenderOutput out;

    // Keeps a timed frame's GPU times: each dispatch's under its stage, and their sum.
    void keepTimes(const std::vector<Dispatch>& dispatches, const std::vector<double>& gpuMs)
    {
        lastDispatches = dispatches;
        double total = 0.0;
        for (size_t i = 0; i < dispatches.size(); ++i) {
            stageMs[dispatches[i].stage].push_back(gpuMs[i]);
            total += gpuMs[i];
        }
        totalMs.push_back(total);
    }
};

Result<RenderOutput> RenderSession::render(const CameraMatrices& camera, const RenderSettings& settings)
{
    SR_TRY(checkRenderInputs(*scene_, settings));
    if (settings.lod == LOD_ON && !lodHierarchy_) return renderLod(camera, settings);
    if (settings.tessellate != TESS_OFF && scene_->display) return renderTessellatedDisplay(camera, settings);
    SR_TRY(claimDevice());
    FrameState f;
    f.out.device = device_->info();
    f.out.camera = camera;
    SR_TRY(sizeFrame(settings, f));
    SR_TRY(draw(camera, settings, f));
    drawn_ = true;
    if (settings.ao == AO_REFERENCE) SR_TRY(shadeReferenceAo(settings, f));
    timings(f);
    statistics(f);
    SR_TRY(download(settings, f));
    if (settings.download == ImageDownload::All && f.tessellating) SR_TRY(remapTessellatedIds(f));
    return std::move(f.out);
}

// The frame's sizes, the list capacities it starts from, its per-frame buffers, and the triangles it
// draws: tessellation's sources, or the scene's (again, after a tessellated frame replaced them).
Status RenderSession::sizeFrame(const RenderSettings& settings, FrameState& f)
{
    const Scene& scene = *scene_;
    f.pixels = uint64_t(settings.width) * settings.height;
    f.rasterPixels = f.pixels * settings.ssaa * settings.ssaa;
    f.samples = f.rasterPixels * settings.msaa;
    const glm::uvec2 grid = tileGrid(settings.width * settings.ssaa, settings.height * settings.ssaa);
    f.tiles = uint64_t(grid.x) * grid.y;
    const uint64_t tris = scene.triangleCount() + 2 * scene.lineCount();  // a segment draws as two
    // Start small: one piece per eighth of the triangles (most of a mesh is culled or small, and small
    // triangles need no memory), four bin entries per piece, and records for one clipped triangle in 64
    // (on a CPU device, where setup stores every big triangle as a record, one per piece).
    // A scene that needs more overflows once, in its first frame, and is grown and redrawn; nothing is
    // sized for the worst case. Later frames of the session start where the previous one ended.
    ListCapacities& capacity = capacities_;
    if (settings.initialListCapacity) {
        capacity.records = capacity.pieces = capacity.binEntries = settings.initialListCapacity;
    } else if (!drawn_) {
        capacity.pieces = uint32_t(tris / 8 + 1024);
        capacity.binEntries = uint32_t(std::min<uint64_t>(4 * uint64_t(capacity.pieces) + f.tiles, 1u << 30));
        capacity.records = device_->info().isCpu ? capacity.pieces : uint32_t(tris / 64 + 64);
    }

    // One key per sample: memory grows with the sample count asked for, and 1x has no sample buffers.
    SR_TRY(ensureSize(BUF_VISIBILITY, f.samples * sizeof(uint64_t)));
    // The colours, then stage aovs's arrays, only those the host asked for.
    aovPixels_ = f.pixels;
    aovOutputs_ = aovOutputs(settings);
    framebufferColour_ = settings.download != ImageDownload::All || (settings.outputs & OUTPUT_COLOR) != 0u;
    SR_TRY(ensureSize(BUF_FRAMEBUFFER, uint64_t(aovsLayout(uint32_t(f.pixels), aovOutputs_).words) * 4));
    // The debug counter costs memory only when it is asked for.
    SR_TRY(ensureSize(BUF_HIT_COUNT, countsHits(settings) ? f.samples * sizeof(uint32_t) : 16));
    SR_TRY(ensureSize(BUF_TILE_BINS, f.tiles * sizeof(uint32_t)));
    SR_TRY(ensureSize(BUF_ACTIVE_TILES, f.tiles * sizeof(uint32_t)));
    SR_TRY(ensureSize(BUF_SCAN_SUMS, size_t(groupsFor(f.tiles, SCAN_GROUP_SIZE)) * sizeof(uint32_t)));
    // Ambient occlusion's planes (BUF_AO), only when it is on: all of them for GTAO's stages, the one
    // AO_PLANE_RAW for --ao reference (the frame's own shade reads it before the host has filled it, and
    // shadeReferenceAo shades again).
    const uint64_t aoPlanes = settings.ao == AO_GTAO ? AO_PLANES : settings.ao == AO_REFERENCE ? 1 : 0;
    SR_TRY(ensureSize(BUF_AO, aoPlanes > 0 ? aoPlanes * f.rasterPixels * sizeof(float) : 16));
    SR_TRY(allocateLists());

    f.tessellating = settings.tessellate != TESS_OFF;
    if (f.tessellating)
        SR_TRY(prepareTessellation());
    else if (trianglesReplaced_)
        SR_TRY(uploadTriangles());
    Result<uint32_t> clusters = frameClusters(settings, f.tessellating);
    if (!clusters) return clusters.error();
    f.clusters = *clusters;
    f.out.stats.clusterBuildMs = std::exchange(clusterBuildMs_, 0.0);
    return okStatus();
}

// Clusters pay where a cluster's vertices are shared by about twice as many triangles (a closed mesh
// has 124 triangles on 64 vertices at best) and where there are enough of them to fill the GPU: auto
// takes them from this many triangles per cluster and this many triangles on (on the H100 the 70k-triangle
// bunny drew 1.35x slower through clusters, a warp per 94 triangles leaving most of the GPU idle).
constexpr double kAutoClusterTriangles = 32.0;
constexpr uint64_t kAutoClusterMinTriangles = uint64_t(1) << 20;

Result<uint32_t> RenderSession::frameClusters(const RenderSettings& settings, bool tessellating)
{
    if (lodHierarchy_) {  // a level-of-detail scene: its clusters are the hierarchy's, always drawn
        if (lodHierarchy_->clusters.clusters.empty()) return 0u;
        if (!clustersUploaded_) {
            std::vector<GpuCluster> records;
            std::vector<uint32_t> data;
            gpuClusters(lodHierarchy_->clusters, scene_->triFlags, records, data, &lodHierarchy_->bounds);
            SR_TRY(uploadVector(*device_, BUF_CLUSTERS, records));
            SR_TRY(uploadVector(*device_, BUF_CLUSTER_DATA, data));
            sizes_[BUF_CLUSTERS] = records.size() * sizeof(GpuCluster);
            sizes_[BUF_CLUSTER_DATA] = data.size() * sizeof(uint32_t);
            SR_TRY(ensureSize(BUF_LOD_CUT, records.size() * sizeof(uint32_t)));
            clustersUploaded_ = true;
        }
        return uint32_t(lodHierarchy_->clusters.clusters.size());
    }
    // Generated triangles change every frame; clusters are built once, from the scene's.
    if (settings.clusters == CLUSTERS_OFF || tessellating || scene_->triangleCount() == 0) return 0u;
    // A CPU device runs a group that synchronizes as one coroutine per invocation: setup's thread per
    // triangle serves it better, and auto leaves it there.
    const bool automatic = settings.clusters == CLUSTERS_AUTO;
    if (automatic && (device_->info().isCpu || scene_->triangleCount() < kAutoClusterMinTriangles)) return 0u;
    if (!clustersBuilt_) {
        const auto start = std::chrono::steady_clock::now();
        clusterSet_ = buildClusters(*scene_);
        clusterBuildMs_ =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        clusterCount_ = uint32_t(clusterSet_.clusters.size());
        clusterTriangles_ = clusterCount_ == 0 ? 0.0 : double(scene_->triangleCount()) / clusterCount_;
        clustersBuilt_ = true;
    }
    if (clusterCount_ == 0 || (automatic && clusterTriangles_ < kAutoClusterTriangles)) return 0u;
    if (!clustersUploaded_) {  // memory only for clusters that are drawn
        std::vector<GpuCluster> records;
        std::vector<uint32_t> data;
        gpuClusters(clusterSet_, scene_->triFlags, records, data);
        SR_TRY(uploadVector(*device_, BUF_CLUSTERS, records));
        SR_TRY(uploadVector(*device_, BUF_CLUSTER_DATA, data));
        sizes_[BUF_CLUSTERS] = records.size() * sizeof(GpuCluster);
        sizes_[BUF_CLUSTER_DATA] = data.size() * sizeof(uint32_t);
        clustersUploaded_ = true;
    }
    return clusterCount_;
}

// Draws the frame settings.warmup + settings.repeat times, each of them again for as long as it
// overflows a list or needs a stage it skipped, and keeps the GPU times of the timed ones.
Status RenderSession::draw(const CameraMatrices& camera, const RenderSettings& settings, FrameState& f)
{
    // Every call starts with every stage on every tile, as a fresh render does, even in a session: the
    // previous call's choice fits its own camera, and carried over to a turntable's next frame on
    // lavapipe it made half of the frames draw twice (too few raster groups for the new view).
    startWork(settings, f);
    for (uint32_t run = 0; run < settings.warmup + settings.repeat;) {
        f.params = frameParams(*scene_, camera, settings, capacities_, f.work.groups);
        setClusterParams(f.params, f.clusters, settings.rasterMethod);
        // The clusters transform their own vertices; the stages that set a triangle up again from the
        // scene (bin_count, bin_fill, raster_tiles) transform its three, with the same function.
        if (f.clusters > 0) f.params.transformInSetup = 1u;
        if (lodHierarchy_ && f.clusters > 0) setLodParams(f.params, settings.lodErrorPx);
        std::vector<Dispatch> dispatches;  // every dispatch of the frame, in order, and its GPU times
        std::vector<double> gpuMs;
        SR_TRY(runFrame(f, dispatches, gpuMs));
        Result<bool> skippedNeeded = nextWork(f);
        if (!skippedNeeded) return skippedNeeded.error();
        Result<bool> grown = growLists(f.counters);
        if (!grown) return grown.error();
        if (*grown || *skippedNeeded) {
            ++f.out.stats.redraws;
            continue;
        }
        if (run >= settings.warmup) f.keepTimes(dispatches, gpuMs);
        ++run;
    }
    return okStatus();
}

void RenderSession::startWork(const RenderSettings& settings, FrameState& f) const
{
    f.rasterChunk = device_->info().isCpu ? std::max(32u, uint32_t(RASTER_CPU_CHUNK) / settings.msaa) : 0u;
    f.work.groups = GroupCounts{uint32_t(f.tiles), groupsFor(capacities_.pieces, GROUP_SIZE), f.rasterChunk,
                                device_->info().isCpu ? uint32_t(SHADE_CPU_PIXELS) : 1u};
    f.work.binBig = f.work.countSplit = !settings.firstFrameSkipsBinning;
    f.work.rasterMethod = settings.rasterMethod;
    f.work.alphaTest = alphaTest_;
    f.work.shade = settings.download != ImageDownload::All || (settings.outputs & OUTPUT_COLOR) != 0u;
}

// Runs one frame with f.params and f.work, tessellation first when it is on, and reads its counters.
Status RenderSession::runFrame(FrameState& f, std::vector<Dispatch>& dispatches, std::vector<double>& gpuMs)
{
    // Tessellation counts first and sizes the generated buffers from the totals (its own submission:
    // the host reads them), then writes at the head of the frame.
    std::vector<Dispatch> frame;
    if (f.tessellating) {
        Result<Dispatch> emit = tessellate(f, dispatches, gpuMs);
        if (!emit) return emit.error();
        frame.push_back(*emit);
    }
    for (const Dispatch& d : frameDispatches(f.params, f.work)) frame.push_back(d);
    std::vector<double> frameMs;
    SR_TRY(device_->run(f.params, frame, frameMs));
    dispatches.insert(dispatches.end(), frame.begin(), frame.end());
    gpuMs.insert(gpuMs.end(), frameMs.begin(), frameMs.end());
    return device_->download(BUF_COUNTERS, f.counters, sizeof f.counters);
}

// tess_count and the scans, in a submission of their own (dispatches, gpuMs); then the totals, the
// generated buffers sized to them and the frame's counts. Returns the frame's tess_emit dispatch.
Result<Dispatch> RenderSession::tessellate(FrameState& f, std::vector<Dispatch>& dispatches,
                                           std::vector<double>& gpuMs)
{
    RasterParams& params = f.params;
    dispatches = {{STAGE_TESS_COUNT, groupsFor(params.tessSourceTriangles, GROUP_SIZE)},
                  {STAGE_TESS_SCAN_BLOCKS, params.tessBlocks},
                  {STAGE_TESS_SCAN_SUMS, 1u}};
    SR_TRY(device_->run(params, dispatches, gpuMs));
    SR_TRY(device_->download(BUF_TESS_SUMS, &f.tessTotals, sizeof f.tessTotals));
    if (f.tessTotals.w != 0u)
        return makeError(ExitCode::Runtime,
                         "tessellation would generate over 2^31 vertices or triangles: raise "
                         "--tess-edge-px or lower --tess-max-level");
    SR_TRY(sizeTessellation(f.tessTotals.x, f.tessTotals.y));
    params.vertexCount = params.tessSourceVertices + f.tessTotals.x;
    params.triangleCount = f.tessTotals.y;
    const uint64_t scenePrimitives =
        uint64_t(params.tessSourceTriangles) + params.lineCount + params.pointCount;
    return Dispatch{STAGE_TESS_EMIT, groupsFor(scenePrimitives, GROUP_SIZE)};
}

// The next frame's work from this frame's counters; returns whether this frame skipped a stage it
// needed (it must be drawn again).
Result<bool> RenderSession::nextWork(FrameState& f) const
{
    const uint32_t* counters = f.counters;
    FrameWork& work = f.work;
    const uint64_t items = uint64_t(counters[COUNTER_ACTIVE_TILES]) *
                           rasterChunksPerTile(f.rasterChunk, counters[COUNTER_MAX_BIN]);
    if (items >= (uint64_t(1) << 31))
        return makeError(ExitCode::Runtime, "too much raster work: {} raster_tiles work items", items);
    const auto rasterItems = uint32_t(items);
    bool skippedNeeded = (!work.binBig && counters[COUNTER_BIG] > 0) ||
                         (!work.countSplit && counters[COUNTER_SPLIT] > 0) ||
                         (f.rasterChunk != 0 && work.binBig && rasterItems > work.groups.raster);
    work.binBig = counters[COUNTER_BIG] > 0;
    work.countSplit = counters[COUNTER_SPLIT] > 0;
    work.groups.raster = std::max(rasterItems, 1u);
    work.groups.bin = groupsFor(std::min(counters[COUNTER_PIECES], capacities_.pieces), GROUP_SIZE);
    if (counters[COUNTER_WORK_OVERFLOW])
        return makeError(ExitCode::Runtime,
                         "too much raster work: more than 2^31 pieces or bin entries in one frame");
    return skippedNeeded;
}

// Grows every list that overflowed in the frame with these counters; returns whether any did.
Result<bool> RenderSession::growLists(const uint32_t* counters)
{
    // A list that overflowed leaves the frame incomplete: grow every list that did and draw it again
    // (bins counted from incomplete pieces may need a second round).
    ListCapacities& capacity = capacities_;
    bool grown = false;
    for (auto [count, cap] : {std::pair<uint32_t, uint32_t*>{counters[COUNTER_SETUP], &capacity.records},
                              {counters[COUNTER_PIECES], &capacity.pieces},
                              {counters[COUNTER_BIN_ENTRIES], &capacity.binEntries}}) {
        if (count <= *cap) continue;
        uint64_t wanted = grownCapacity(count);
        if (wanted >= (uint64_t(1) << 31))
            return makeError(ExitCode::Runtime, "triangle lists would need {} entries", wanted);
        *cap = uint32_t(wanted);
        grown = true;
    }
    if (grown) SR_TRY(allocateLists());
    return grown;
}

// --ao reference: the ground truth of every raster pixel computed on the host from the frame's
// visibility keys (host/ao/ao_image.h), uploaded to plane AO_PLANE_RAW of BUF_AO, and the frame shaded
// again with it. Not timed: the rays are the host's.
Status RenderSession::shadeReferenceAo(const RenderSettings& settings, FrameState& f)
{
    if (!aoBvh_) aoBvh_ = std::make_shared<AoBvh>(*scene_);
    std::vector<uint64_t> visibility(f.samples);
    SR_TRY(device_->download(BUF_VISIBILITY, visibility.data(), visibility.size() * sizeof(uint64_t)));
    const std::vector<float> ao = referenceAoImage(
        *scene_, *aoBvh_, f.params, visibility, aoWorldRadius(*scene_, settings), settings.aoReferenceRays);
    static_assert(AO_PLANE_RAW == 0, "the reference is uploaded to the head of BUF_AO");
    SR_TRY(device_->upload(BUF_AO, ao.data(), ao.size() * sizeof(float)));
    std::vector<Dispatch> shade;
    for (const Dispatch& d : frameDispatches(f.params, f.work))
        if (d.stage == STAGE_SHADE) shade.push_back(d);
    std::vector<double> ms;
    return device_->run(f.params, shade, ms);
}

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

Result<std::vector<uint32_t>> RenderSession::renderViews(const std::vector<CameraMatrices>& cameras,
                                                         const RenderSettings& requested,
                                                         const ViewInputs& views, size_t count,
                                                         const std::vector<ViewTarget>& targets)
{
    RenderSettings settings = requested;
    settings.clusters = CLUSTERS_OFF;
    settings.download = ImageDownload::All;
    settings.outputs = 0u;
    for (const ViewTarget& t : targets) settings.outputs |= t.output;
    settings.keptOutputs = settings.outputs;
    SR_TRY(checkRenderInputs(*scene_, settings));
    if (settings.tessellate != TESS_OFF || settings.lod != LOD_OFF || settings.ao == AO_REFERENCE ||
        settings.aovSamples || settings.surfaceAovs)
        return makeError(ExitCode::Usage,
                         "views: tessellation, level of detail, reference AO and per-sample or surface AOVs "
                         "are drawn one frame at a time");
    if (views.positions != nullptr && views.bytes != scene_->positions.size() * sizeof(glm::vec4))
        return makeError(ExitCode::Usage, "views: {} bytes of positions per view for a scene of {} vertices",
                         views.bytes, scene_->positions.size());
    if (cameras.size() != 1 && cameras.size() != count)
        return makeError(ExitCode::Usage, "views: {} cameras for {} views", cameras.size(), count);
    std::vector<uint32_t> invalid(count, 0u);
    if (count == 0) return invalid;
    SR_TRY(claimDevice());
    if (views.positions != nullptr) viewPositions_ = true;
    auto cameraOf = [&](size_t b) -> const CameraMatrices& { return cameras[cameras.size() == 1 ? 0 : b]; };
    FrameState f;
    SR_TRY(sizeFrame(settings, f));
    auto copies = viewCopies(targets);
    if (!copies) return copies.error();
    // View b alone, as render() draws a frame: again until nothing overflows.
    auto drawAlone = [&](size_t b) -> Status {
        SR_TRY(device_->uploadView(views, b));
        SR_TRY(draw(cameraOf(b), settings, f));
        invalid[b] = f.counters[COUNTER_INVALID];
        for (const ViewCopy& c : *copies) SR_TRY(device_->copyView(c, b));
        return okStatus();
    };
    size_t first = 0;
    // The session's first frame sizes its lists. A CPU device sizes raster_tiles' work items from the
    // frame before, per view: every view is drawn alone there.
    while (first < count && (!drawn_ || device_->info().isCpu)) {
        SR_TRY(drawAlone(first++));
        drawn_ = true;
    }
    if (first == count) return invalid;
    // The others in one submission, with every stage on and the list-walking stages sized for the lists'
    // capacities, so that any view within them is drawn whole; the counters say which were not.
    startWork(settings, f);
    f.work.binBig = f.work.countSplit = true;
    f.work.groups.bin = groupsFor(capacities_.pieces, GROUP_SIZE);
    // One set of parameters for views of one camera, one per view otherwise (the dispatches are the same:
    // they follow the lists and the tiles, not the camera).
    std::vector<RasterParams> params;
    for (size_t b = first; b < (cameras.size() == 1 ? first + 1 : count); ++b) {
        params.push_back(frameParams(*scene_, cameraOf(b), settings, capacities_, f.work.groups));
        setClusterParams(params.back(), 0u, settings.rasterMethod);
    }
    const FrameWork batch = f.work;
    std::vector<uint32_t> counters((count - first) * COUNTER_COUNT);
    SR_TRY(device_->runViews(params, frameDispatches(params[0], f.work), views, first, count - first, *copies,
                             counters.data()));
    for (size_t b = first; b < count; ++b) {
        std::copy_n(&counters[(b - first) * COUNTER_COUNT], COUNTER_COUNT, f.counters);
        invalid[b] = f.counters[COUNTER_INVALID];
        f.work = batch;
        Result<bool> skippedNeeded = nextWork(f);
        if (!skippedNeeded) return skippedNeeded.error();
        Result<bool> grown = growLists(f.counters);
        if (!grown) return grown.error();
        if (*grown || *skippedNeeded) SR_TRY(drawAlone(b));
    }
    return invalid;
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
