// renderer.h - the pipeline, written once for every backend.
//
// Sizes every buffer from the scene and the resolution, uploads the scene, runs the stages of the stage
// table (STAGE_*, common/shared/stages.h) through a ComputeDevice, grows the triangle lists and redraws
// when the device reports an overflow, and gathers images, statistics and per-stage GPU times.
#ifndef RASTER_RENDERER_H
#define RASTER_RENDERER_H

#include <cstdint>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "camera/camera.h"
#include "render/compute_device.h"
#include "render/tessellate.h"
#include "io/image_io.h"
#include "raster_shared.h"
#include "base/result.h"
#include "scene/clusters.h"
#include "scene/lod.h"
#include "scene/scene.h"
#include "settings/render_settings.h"

namespace sr {

// Entries the compute pipeline's lists hold (RasterParams.setupCapacity, pieceCapacity, binCapacity).
struct ListCapacities {
    uint32_t records = 0;     // TriSetup records of clipped big sub-triangles (CPU devices: all big ones)
    uint32_t pieces = 0;      // pieces of big triangles
    uint32_t binEntries = 0;  // (big triangle, screen tile) bin entries
};

// Groups of the stages that walk device-counted lists (RasterParams.binGroups, rasterGroups).
struct GroupCounts {
    uint32_t raster = 0;       // raster_tiles
    uint32_t bin = 0;          // bin_count and bin_fill
    uint32_t rasterChunk = 0;  // RasterParams.rasterChunk: 0 on GPUs, bin entries per work item on a CPU
    uint32_t shadePixels = 1;  // output pixels per shade invocation: SHADE_CPU_PIXELS on a CPU (shade.comp)
};

// Which stages a frame runs, decided from the previous frame (all of them in the first): the binning
// stages only where it had big triangles, bin_count only where it had triangles of several pieces. A
// frame that turns out to need a skipped stage is drawn again with it, like an overflowing list.
struct FrameWork {
    GroupCounts groups;
    bool binBig = true;      // bin_count, the scans, bin_fill and raster_tiles
    bool countSplit = true;  // bin_count
    bool alphaTest = false;  // setup, clusters and raster_tiles with the alpha test: some triangle is MASK
    uint32_t rasterMethod = RASTER_FIXED8;  // RenderSettings::rasterMethod, for every dispatch
    bool shade = true;  // stage shade: not for a frame whose colour nobody reads (ids, depth, rasterize's)
};

struct StageTiming {
    std::string name;
    double minMs = 0.0, medianMs = 0.0, maxMs = 0.0;  // over the timed runs
};

struct RenderStats {
    uint64_t trianglesIn = 0;     // triangles handed to the GPU (generated ones when tessellating)
    uint64_t culled = 0;          // input primitives that produced nothing to rasterize
    uint64_t clipped = 0;         // input triangles that went through the clipper
    uint64_t invalid = 0;         // input primitives dropped on the GPU for NaN/Inf positions
    uint64_t rasterized = 0;      // (sub-)triangles set up for rasterization
    uint64_t smallTris = 0;       // of which rasterized by their setup thread
    uint64_t bigTris = 0;         // of which binned to screen tiles
    uint64_t linesIn = 0;         // line segments handed to the GPU
    uint64_t lines = 0;           // of which set up (the others culled, clipped away or invalid)
    uint64_t pointsIn = 0;        // points handed to the GPU
    uint64_t points = 0;          // of which rasterized (the others culled or invalid)
    uint64_t records = 0;         // TriSetup records: clipped big sub-triangles (CPU devices: all big ones)
    uint64_t pieces = 0;          // pieces the big triangles were cut into
    uint64_t binEntries = 0;      // (big triangle, screen tile) bin entries
    uint64_t tessVertices = 0;    // vertices tessellation generated (0 without it)
    uint64_t tessTriangles = 0;   // triangles it generated (they are trianglesIn)
    uint64_t tessCulled = 0;      // scene triangles it culled before refining
    uint64_t clusters = 0;        // clusters the triangles went through (stage clusters; 0: setup did)
    uint64_t clustersCulled = 0;  // of which culled whole (their triangles are in `culled`)
    // Level of detail (RenderSettings::lod): the triangles of the clusters the frame's cut drew (they are
    // trianglesIn), and the scene's own triangles, which --lod off would have drawn.
    uint64_t lodTriangles = 0;
    uint64_t lodSceneTriangles = 0;
    double lodBuildMs = 0.0;  // host time building the hierarchy and its scene (the frame that built them)
    double clusterBuildMs = 0.0;  // host time building the scene's clusters (the frame that built them)
    uint32_t redraws = 0;         // frames redrawn after growing an overflowing list or for a skipped stage
    ListCapacities capacities;    // final capacities of the lists
    // Whether the counts after the inputs (culled, clipped, rasterized, ...) were measured: false for
    // vulkan-graphics, whose fixed-function stages count nothing we read back; reports then say "n/a".
    bool pipelineCounts = true;
};

// Every sample of a frame (RenderSettings::aovSamples). The raster grid is rasterWidth x rasterHeight
// pixels (the output resolution times RenderSettings::ssaa per side), each with `samples` samples
// (RenderSettings::msaa) in Vulkan's standard order; sample s of raster pixel p is at index
// s * rasterWidth * rasterHeight + p.
struct SampleAovs {
    uint32_t rasterWidth = 0, rasterHeight = 0, samples = 0;
    std::vector<uint32_t> id;  // triangle id, EMPTY_ID where no triangle covers the sample
    std::vector<float> depth;  // window depth, 1.0 where empty
};

// The sample an output pixel's id and Z AOVs report: sample 0 (Vulkan's first standard location) of
// the raster pixel nearest the output pixel's centre, (ssaa / 2, ssaa / 2) within its ssaa x ssaa
// block. Index as in SampleAovs.
inline uint64_t aovSampleIndex(uint32_t x, uint32_t y, uint32_t rasterWidth, uint32_t ssaa)
{
    return uint64_t(y * ssaa + ssaa / 2) * rasterWidth + uint64_t(x) * ssaa + ssaa / 2;
}

struct RenderOutput {
    RgbaImage color;  // resolved: the mean linear colour of every sample of the pixel, then sRGB
    AovImage aov;     // id, Z and surface channels of aovSampleIndex's sample
    SampleAovs samples;
    // Covering triangles per sample of the raster grid (indexed as SampleAovs), only when counting hits
    // (SHADING_HIT_COUNT or countHits).
    std::vector<uint32_t> hitCount;
    RenderStats stats;
    std::vector<StageTiming> stages;  // in dispatch order
    StageTiming total;                // GPU time of the whole frame
    size_t peakDeviceBytes = 0;
    DeviceInfo device;
    RasterParams params{};
    CameraMatrices camera;  // the camera the frame was drawn with (--stats records it)
};

// The checks every backend makes on its inputs (sizes, repeat count, scene limits), one line each.
Status checkRenderInputs(const Scene& scene, const RenderSettings& settings);
// The scene's part of them (something to draw, counts within the devices' 32-bit indices, whole
// segments, one colour per vertex).
Status checkSceneInputs(const Scene& scene);

// A scene uploaded to a device once and rendered any number of times, with any camera and settings
// (turntables, the interactive viewer): the device's buffers are reused, the per-frame ones resized only
// when a frame needs another size, and each frame starts from the list capacities the previous one
// grew to, so a moving camera rarely overflows. The images do not depend on that history (the
// pipeline's results never depend on capacities: an overflowing frame is drawn again); the statistics
// (redraws, capacities) do.
//
// A device has one set of buffers, shared by every session made on it: a session claims them
// (ComputeDevice::claim) and uploads its scene again whenever another session drew there since its own
// last frame, so any number of sessions may alternate on one device, each drawing its own scene; only
// the first frame after a switch pays the upload. The scene and the device must outlive the session.
class AoBvh;

class RenderSession {
public:
    // Checks the scene (checkSceneInputs) and uploads it.
    static Result<RenderSession> create(ComputeDevice& device, const Scene& scene);

    // Runs the whole pipeline `settings.warmup + settings.repeat` times and returns the last frame.
    Result<RenderOutput> render(const CameraMatrices& camera, const RenderSettings& settings);

    // The scene's vertex positions (and normals, with normalsChanged) changed in place (same vertices, same
    // primitives): they are uploaded again, and what was derived from them (clusters, the level-of-detail
    // hierarchy, the AO reference's BVH, tessellation's sources) is built again when a frame needs it.
    // Nothing else is.
    Status positionsChanged(bool normalsChanged = true);

    // Copies one image of the last frame (an OUTPUT_* bit it was drawn with) from the device into
    // `destination`, which holds `bytes` (the image's: 4 per pixel, 16 for OUTPUT_RAST): host memory, or
    // with onDevice memory of the device (ComputeDevice::allocateMemory). The public API's image targets
    // and the Python module's batch of rasterize write their arrays so, with no copy in between.
    Status readImage(uint32_t output, void* destination, size_t bytes, bool onDevice);

    // Frames of the scene that differ in their vertex positions (nvdiffrast's batch) or in their camera,
    // `count` of them: view b has cameras[b] (or cameras[0] for every view) and, where views.positions is
    // not null, the scene's vertices at views.positions + b * views.bytes (the scene's layout, a vec4 per
    // vertex). Each image of `targets` (an OUTPUT_* bit and where it goes) is written straight there,
    // view b's at destination + b x its size, with no host work between views: CUDA queues every view
    // and waits once. The first frame of a session is drawn alone, as render() draws it, to size the
    // lists; a view that overflows a list or needs a stage the batch skipped is drawn again alone.
    // Clusters are off (theirs are built from the scene's own positions); tessellation, level of
    // detail, reference AO and per-sample or surface AOVs are refused. Returns per view the triangles
    // dropped for a non-finite clip coordinate.
    struct ViewTarget {
        uint32_t output = 0;
        void* destination = nullptr;
        bool onDevice = false;
    };
    Result<std::vector<uint32_t>> renderViews(const std::vector<CameraMatrices>& cameras,
                                              const RenderSettings& settings, const ViewInputs& views,
                                              size_t count, const std::vector<ViewTarget>& targets);

    ComputeDevice& device() const { return *device_; }
    const Scene& scene() const { return *scene_; }

private:
    RenderSession(ComputeDevice& device, const Scene& scene);
    // Takes the device's buffers over (ComputeDevice::claim), forgetting what this session had there when
    // another one used them since, and uploads the scene where they do not hold it.
    Status claimDevice();
    // renderViews' copies of its targets' images out of BUF_FRAMEBUFFER, for the last frame's layout.
    Result<std::vector<ViewCopy>> viewCopies(const std::vector<ViewTarget>& targets) const;
    Status upload();
    // A tessellated frame of a display scene (tessellatedDisplay), drawn by a session of its own on this
    // device, after which this session's buffers are uploaded again before its next frame.
    Result<RenderOutput> renderTessellatedDisplay(const CameraMatrices& camera,
                                                  const RenderSettings& settings);
    // A frame with level of detail: the scene's hierarchy and the scene with its simplified triangles
    // (built by the first such frame, kept in lod_), drawn by a session of their own on this device; the
    // ids mapped back to the scene's (lodAovId).
    Result<RenderOutput> renderLod(const CameraMatrices& camera, const RenderSettings& settings);
    // Another session used the device: this one forgets what it sized and uploaded there.
    void forgetDeviceBuffers();
    // Resizes `buffer` unless this session already gave it exactly `bytes` (a CUDA resize reallocates).
    Status ensureSize(uint32_t buffer, size_t bytes);
    Status allocateLists();
    Status uploadTriangles();
    // Tessellation: the scene triangles' records (once per session), and the generated buffers sized to
    // a frame's totals (grown, never shrunk; the scene's vertices uploaded again after a reallocation).
    Status prepareTessellation();
    Status sizeTessellation(uint64_t vertices, uint64_t triangles);
    // Clusters: built from the scene once per session (buildClusters) and uploaded the first time a frame
    // draws through them; returns the number of clusters a frame with `settings` draws through, 0 for
    // setup alone.
    Result<uint32_t> frameClusters(const RenderSettings& settings, bool tessellating);

    // render()'s steps, in order (renderer.cpp), and the state they pass along.
    struct FrameState;
    Status sizeFrame(const RenderSettings& settings, FrameState& f);
    // The work a frame starts from: every stage on every tile, the list-walking stages sized to the lists.
    void startWork(const RenderSettings& settings, FrameState& f) const;
    Status draw(const CameraMatrices& camera, const RenderSettings& settings, FrameState& f);
    Status runFrame(FrameState& f, std::vector<Dispatch>& dispatches, std::vector<double>& gpuMs);
    Result<Dispatch> tessellate(FrameState& f, std::vector<Dispatch>& dispatches, std::vector<double>& gpuMs);
    Result<bool> nextWork(FrameState& f) const;
    Result<bool> growLists(const uint32_t* counters);
    void timings(FrameState& f) const;
    void statistics(FrameState& f) const;
    Status shadeReferenceAo(const RenderSettings& settings, FrameState& f);
    Status download(const RenderSettings& settings, FrameState& f);
    Status remapTessellatedIds(FrameState& f);

    ComputeDevice* device_;
    const Scene* scene_;
    uint64_t id_ = 0;  // this session's token on the device (ComputeDevice::resident)
    std::vector<size_t> sizes_ = std::vector<size_t>(BUF_COUNT, SIZE_MAX);  // SIZE_MAX: not sized by us
    bool alphaTest_ = false;  // some triangle is alphaMode MASK (FrameWork::alphaTest)
    bool drawn_ = false;      // a frame was drawn: capacities_ hold what its lists grew to
    ListCapacities capacities_;
    bool tessPrepared_ = false;  // BUF_TESS_SOURCE and BUF_TESS_MATERIALS hold tessSources_
    TessSources tessSources_;
    bool trianglesReplaced_ = false;  // BUF_INDICES etc. hold generated triangles, not the scene's
    uint64_t tessVertexCapacity_ = 0, tessTriangleCapacity_ = 0;
    bool uploaded_ = false;          // the device's buffers hold this session's scene
    bool clustersBuilt_ = false;     // the scene's clusters were built: clusterCount_, clusterTriangles_
    ClusterSet clusterSet_;          // and kept here, to upload again after another session's frames
    bool clustersUploaded_ = false;  // BUF_CLUSTERS and BUF_CLUSTER_DATA hold them
    uint32_t clusterCount_ = 0;      // clusters (0: the scene has none, its triangles go through setup)
    double clusterTriangles_ = 0.0;  // triangles per cluster, on average
    double clusterBuildMs_ = 0.0;    // the build's host time, until a frame's statistics take it
    struct LodState;
    std::shared_ptr<LodState> lod_;               // renderLod's hierarchy, scene and session
    const LodHierarchy* lodHierarchy_ = nullptr;  // on LodState's session: its scene's clusters
    std::shared_ptr<AoBvh> aoBvh_;  // --ao reference's BVH of the scene, built by its first frame
    // The last frame's output pixels and what stage aovs wrote after its colours (AOV_OUT_* bits).
    uint64_t aovPixels_ = 0;
    uint32_t aovOutputs_ = 0;
    bool framebufferColour_ = false;  // and whether shade wrote its colours
    bool viewPositions_ = false;      // BUF_POSITIONS holds a view's positions (renderViews), not the scene's
};

// One frame of a fresh session: checks the inputs, uploads the scene, runs the whole pipeline
// `settings.warmup + settings.repeat` times and returns the last frame.
Result<RenderOutput> renderScene(ComputeDevice& device, const Scene& scene, const CameraMatrices& camera,
                                 const RenderSettings& settings);

// A frame of a display scene (Scene::display: lines or points mode, the wireframe overlay) with
// tessellation on. The display form is taken from the tessellated mesh, so that lines mode draws the
// generated triangles' edges and the overlay lies exactly on the curved surface: the source scene is
// tessellated on the host (tessellateOnHost, bit for bit the devices' mesh) for the frame's camera and
// settings, but with culling off, since lines and points show the back of the mesh too (the overlay's
// back faces are still culled where they are drawn), and displayScene is applied to the result. `scene`
// is drawn with tessellation off.
struct TessellatedDisplay {
    Scene scene;
    std::vector<uint32_t> sourceIds;  // per generated triangle: its source scene triangle
    uint32_t sourceTriangles = 0;     // triangles of the source scene
    uint64_t tessVertices = 0, tessTriangles = 0, tessCulled = 0;
};
TessellatedDisplay tessellatedDisplay(const Scene& display, const CameraMatrices& camera,
                                      const RenderSettings& settings);
// A frame of `t.scene` as a frame of the display scene: where triangles were drawn (the overlay), their
// ids mapped to the source's triangles and the overlay's segments shifted to follow them
// (mapToSourceIds); lines and points keep the ids of what was drawn. The tessellation statistics filled.
void finishTessellatedDisplay(const TessellatedDisplay& t, RenderOutput& out);

// The per-frame constants every backend uses for this scene, camera and settings, with the compute
// pipeline's list capacities and the group counts of its list-walking stages.
// Ambient occlusion's radius in world units (RenderSettings::aoRadius, or kAoRadiusFraction of the
// scene's bounding radius when that is 0), and how many view-space units a world unit is under
// viewFromWorld (1 unless --model scales the scene): RasterParams.aoRadius is their product.
double aoWorldRadius(const Scene& scene, const RenderSettings& settings);
// The output resolution's AO (width x height) from the raster's (ssaa times that per side): the mean of
// each pixel's ssaa x ssaa raster pixels, as its colour is resolved.
std::vector<float> resolveAo(const std::vector<float>& raster, uint32_t width, uint32_t height,
                             uint32_t ssaa);
double aoViewScale(const glm::mat4& viewFromWorld);
// The median GPU time of a frame's AO stages (ao_gbuffer + ao + ao_denoise; 0 without them), as `raster
// bench` and `raster study` report it.
double aoStagesMs(const std::vector<StageTiming>& stages);

RasterParams frameParams(const Scene& scene, const CameraMatrices& camera, const RenderSettings& settings,
                         const ListCapacities& capacities, const GroupCounts& groups);
// What stage aovs writes for a frame with these settings (RasterParams.aovOutputs, AOV_OUT_* bits): the
// ids and depths where the host asked for them, the surface AOVs, rasterize's output; 0: it does not run.
uint32_t aovOutputs(const RenderSettings& settings);

// Median of a non-empty list (mean of the two middle values for even sizes).
double median(std::vector<double> values);

}  // namespace sr

#endif  // RASTER_RENDERER_H
