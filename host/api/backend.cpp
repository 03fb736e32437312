// backend.cpp - the one place where the backend is chosen at run time.
#include "api/backend.h"

#include "render/tessellate.h"
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

Result<RenderOutput> renderGraphics(const Scene& scene, const CameraMatrices& camera, const RenderSettings& s,
                                    int device)
{
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
