// backend.cpp - the one place where the backend is chosen at run time.
#include "api/backend.h"

#include <algorithm>

#include "render/tessellate.h"
#include "scene/lod.h"
#include "vulkan/vulkan_graphics.h"

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

namespace {

// The graphics pipeline's frame with level of detail: the host builds the same hierarchy, takes the same
// cut with the same shared test (clusterLodDrawn, from the same parameters as the compute stages), and
// draws the cut's triangles in the order of their ids in lodScene (the compute pipeline's visibility
// keeps the lower id on equal depth; the graphics pipeline keeps the first drawn), then names them as
// the compute path does (lodAovId).
Result<RenderOutput> renderGraphicsLod(const Scene& scene, const CameraMatrices& camera,
                                       const RenderSettings& s, int device)
{
    SR_TRY(checkRenderInputs(scene, s));
    const LodHierarchy lod = buildLodHierarchy(scene);
    const Scene full = lodScene(scene, lod);
    RasterParams p = frameParams(full, camera, s, {}, {});
    setClusterParams(p, uint32_t(lod.clusters.clusters.size()), s.rasterMethod);
    setLodParams(p, s.lodErrorPx);
    std::vector<uint32_t> cut;  // ids in `full`
    if (lod.clusters.clusters.empty()) {
        cut.resize(scene.triangleCount());
        for (uint32_t t = 0; t < cut.size(); ++t) cut[t] = t;
    }
    for (size_t k = 0; k < lod.clusters.clusters.size(); ++k) {
        if (!lodClusterDrawn(p, lod, k)) continue;
        const Cluster& c = lod.clusters.clusters[k];
        cut.insert(cut.end(), lod.clusters.triangleIds.begin() + c.triangleOffset,
                   lod.clusters.triangleIds.begin() + c.triangleOffset + c.triangleCount);
    }
    std::sort(cut.begin(), cut.end());
    Scene drawn = full;
    drawn.indices.clear();
    drawn.triFlags.clear();
    drawn.triMaterials.clear();
    for (uint32_t id : cut) {
        drawn.indices.insert(drawn.indices.end(), full.indices.begin() + 3 * size_t(id),
                             full.indices.begin() + 3 * size_t(id) + 3);
        drawn.triFlags.push_back(full.triFlags[id]);
        if (!full.materials.empty()) drawn.triMaterials.push_back(full.triMaterials[id]);
    }
    RenderSettings plain = s;
    plain.lod = LOD_OFF;
    auto out = renderVulkanGraphics(drawn, camera, plain, device);
    if (!out) return out;
    const auto drawnTriangles = uint32_t(cut.size());
    auto name = [&](uint32_t id) {
        if (id == EMPTY_ID) return id;
        return id < drawnTriangles ? lodAovId(cut[id], lod) : id - drawnTriangles + lod.sceneTriangles;
    };
    for (uint32_t& id : out->aov.id) id = name(id);
    for (uint32_t& id : out->samples.id) id = name(id);
    out->stats.lodTriangles = out->stats.trianglesIn = cut.size();
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
