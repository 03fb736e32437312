// frame_params.cpp - a frame's parameters (RasterParams) from the scene, camera and settings, the AO
// helpers, and the checks every backend makes before a frame.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include <glm/gtc/matrix_inverse.hpp>

#include "render/aov.h"
#include "render/materials.h"
#include "render/renderer_internal.h"
#include "scene/clusters.h"
#include "scene/texture.h"
#include "settings/schema.h"

namespace sr {

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

}  // namespace sr
