// backend.cpp - the one place where the backend is chosen at run time.
#include "api/backend.h"

#include <optional>

#include "render/tessellate.h"
#include "scene/lod.h"
#include "vulkan/vulkan_graphics.h"
#include "vulkan/vulkan_present_source.h"

namespace sr {

Result<std::unique_ptr<ComputeDevice>> makeComputeDevice(BackendKind kind, int index)
{
    switch (kind) {
    case BackendKind::Cuda: return makeCudaDevice(index);
    case BackendKind::Vulkan: return makeVulkanDevice(index);
    case BackendKind::Auto: break;
    }
    // Auto: a CUDA GPU when there is one, otherwise Vulkan (a GPU first, else lavapipe).
    auto cuda = makeCudaDevice(index);
    if (cuda.ok()) return cuda;
    auto vulkan = makeVulkanDevice(index);
    if (vulkan.ok()) return vulkan;
    return makeError(vulkan.error().code, "no device opened: {}; {}", cuda.error().message,
                     vulkan.error().message);
}

Result<std::vector<std::unique_ptr<ComputeDevice>>> makeSwitchableDevices(BackendKind preferred, int index,
                                                                          const PresentTarget* window)
{
    const std::vector<BackendKind> order =
        preferred == BackendKind::Vulkan ? std::vector<BackendKind>{BackendKind::Vulkan, BackendKind::Cuda}
                                         : std::vector<BackendKind>{BackendKind::Cuda, BackendKind::Vulkan};
    std::vector<std::unique_ptr<ComputeDevice>> devices;
    std::optional<Error> first;
    for (BackendKind kind : order) {
        auto d = kind == BackendKind::Vulkan && window != nullptr ? makeVulkanPresentingDevice(index, *window)
                                                                  : makeComputeDevice(kind, index);
        if (!d && kind == BackendKind::Vulkan && window != nullptr) d = makeComputeDevice(kind, index);
        if (d) {
            devices.push_back(std::move(*d));
        } else if (!first) {
            first = d.error();
        }
    }
    const char* named = preferred == BackendKind::Cuda     ? "cuda"
                        : preferred == BackendKind::Vulkan ? "vulkan"
                                                           : "";
    if (devices.empty() || (*named != '\0' && devices.front()->info().backend != named)) {
        if (first) return *first;
        return makeError(ExitCode::Usage, "no compute backend opened");
    }
    return devices;
}

namespace {

// The graphics pipeline's frame with level of detail: the host builds the same hierarchy, takes the same
// cut with the same shared test (clusterLodDrawn, from the same parameters as the compute stages), and
// draws the cut's triangles in the order of their ids in lodScene (the compute pipeline's visibility
// keeps the lower id on equal depth; the graphics pipeline keeps the first drawn), each at its place in
// lodScene, then names them as the compute path does (lodAovId).
Result<RenderOutput> renderGraphicsLod(const Scene& scene, const CameraMatrices& camera,
                                       const RenderSettings& s, int device)
{
    SR_TRY(checkRenderInputs(scene, s));
    const LodHierarchy lod = buildLodHierarchy(scene);
    const Scene full = lodScene(scene, lod);
    RasterParams p = frameParams(full, camera, s, {}, {});
    setClusterParams(p, uint32_t(lod.clusters.clusters.size()), s.rasterMethod);
    setLodParams(p, s.lodErrorPx);
    // Every triangle of `full` keeps its place, so that the graphics pipeline's primitive ids are the
    // compute pipeline's (the id view colours by them); a triangle outside the cut is drawn as its first
    // corner three times, which covers nothing.
    std::vector<bool> inCut(full.triangleCount(), lod.clusters.clusters.empty());
    uint64_t cutTriangles = lod.clusters.clusters.empty() ? scene.triangleCount() : 0;
    for (size_t k = 0; k < lod.clusters.clusters.size(); ++k) {
        if (!lodClusterDrawn(p, lod, k)) continue;
        const Cluster& c = lod.clusters.clusters[k];
        for (uint32_t t = 0; t < c.triangleCount; ++t)
            inCut[lod.clusters.triangleIds[c.triangleOffset + t]] = true;
        cutTriangles += c.triangleCount;
    }
    Scene drawn = full;
    for (size_t t = 0; t < inCut.size(); ++t)
        if (!inCut[t]) drawn.indices[3 * t + 1] = drawn.indices[3 * t + 2] = drawn.indices[3 * t];
    RenderSettings plain = s;
    plain.lod = LOD_OFF;
    auto out = renderVulkanGraphics(drawn, camera, plain, device);
    if (!out) return out;
    for (uint32_t& id : out->aov.id) id = lodAovId(id, lod);
    for (uint32_t& id : out->samples.id) id = lodAovId(id, lod);
    out->stats.lodTriangles = out->stats.trianglesIn = cutTriangles;
    out->stats.lodSceneTriangles = scene.triangleCount();
    return out;
}

}  // namespace

Result<RenderOutput> renderGraphics(const Scene& scene, const CameraMatrices& camera, const RenderSettings& s,
                                    int device)
{
    if (s.lod == LOD_ON) return renderGraphicsLod(scene, camera, s, device);
    if (s.tessellate == TESS_OFF) return renderVulkanGraphics(scene, camera, s, device);
    SR_TRY(checkRenderInputs(scene, s));
    RenderSettings plain = s;
    plain.tessellate = TESS_OFF;
    if (scene.display) {
        TessellatedDisplay t = tessellatedDisplay(scene, camera, s);
        auto out = renderVulkanGraphics(t.scene, camera, plain, device);
        if (out) finishTessellatedDisplay(t, *out);
        return out;
    }
    const TessSources sources = tessSources(scene);
    TessellatedScene t = tessellateOnHost(scene, sources, frameParams(scene, camera, s, {}, {}));
    auto out = renderVulkanGraphics(t.scene, camera, plain, device);
    if (!out) return out;
    const auto sceneTriangles = uint32_t(scene.triangleCount());
    mapToSourceIds(out->aov.id, t.sourceIds, sceneTriangles);
    mapToSourceIds(out->samples.id, t.sourceIds, sceneTriangles);
    out->stats.tessVertices = t.scene.vertexCount() - scene.vertexCount();
    out->stats.tessTriangles = t.scene.triangleCount();
    out->stats.tessCulled = t.culled;
    return out;
}

}  // namespace sr
