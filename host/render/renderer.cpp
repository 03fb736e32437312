// renderer.cpp - the session and its frames: buffer sizing, uploads, stage dispatch, grow-and-redraw,
// tessellation and level of detail, shared by the CUDA and Vulkan backends (a frame's parameters and checks:
// frame_params.cpp; what comes back: frame_readback.cpp).
#include "render/renderer.h"
#include "render/renderer_internal.h"

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
         groupsFor(std::max<uint64_t>({samples, tiles, COUNTER_WORDS}), GROUP_SIZE * CLEAR_SPAN)},
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

}  // namespace

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
    SR_TRY(ensureSize(BUF_COUNTERS, COUNTER_WORDS * sizeof(uint32_t)));
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
    return device_->downloadCounters(f.counters);
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

}  // namespace sr
