// ao_study.cpp - see ao_study.h.
#include "study/ao_study.h"

#include <algorithm>
#include <cmath>

#include "scene/scene.h"

namespace sr {

const std::vector<std::string>& aoSceneNames()
{
    static const std::vector<std::string> names = {"builtin", "bunny-plane", "stress-grazing", "stress-near"};
    return names;
}

Scene standingOnFloor(Scene mesh)
{
    const glm::vec3 lo = mesh.boundsMin, hi = mesh.boundsMax;
    const glm::vec3 centre = 0.5f * (lo + hi);
    const float half = 1.5f * std::max(hi.x - lo.x, hi.z - lo.z);
    const auto base = uint32_t(mesh.positions.size());
    for (const glm::vec2& c : {glm::vec2(-1, -1), glm::vec2(-1, 1), glm::vec2(1, 1), glm::vec2(1, -1)}) {
        mesh.positions.emplace_back(centre.x + half * c.x, lo.y, centre.z + half * c.y, 1.0f);
        mesh.normals.emplace_back(0.0f, 1.0f, 0.0f, 0.0f);
        if (!mesh.colors.empty()) mesh.colors.emplace_back(0.7f, 0.7f, 0.7f, 1.0f);
        if (!mesh.texcoords.empty()) mesh.texcoords.emplace_back(0.0f);
    }
    // Counter-clockwise seen from +y: (-1,-1) -> (-1,1) -> (1,1) winds with the normal up.
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) mesh.indices.push_back(base + i);
    if (!mesh.triFlags.empty()) mesh.triFlags.insert(mesh.triFlags.end(), 2, 0u);
    if (!mesh.triMaterials.empty())
        mesh.triMaterials.insert(mesh.triMaterials.end(), 2, mesh.triMaterials.back());
    Status status = finalizeScene(mesh, "bunny on a floor");
    (void)status;
    return mesh;
}

Result<AoStudyScene> makeAoScene(const std::string& name, unsigned width, unsigned height,
                                 const std::string& bunnyPath)
{
    AoStudyScene s;
    s.name = name;
    s.cameraSpec = "auto";
    if (name == "builtin") {
        s.scene = builtinScene();
    } else if (name == "bunny-plane") {
        auto bunny = loadScene(bunnyPath);
        if (!bunny) return bunny.error();
        s.scene = standingOnFloor(std::move(*bunny));
    } else if (name == "stress-grazing" || name == "stress-near") {
        auto scene = builtinSceneNamed("builtin:ao");
        if (!scene) return scene.error();
        s.scene = std::move(*scene);
        s.cameraSpec = name == "stress-grazing" ? "orbit:20,7,0.75r" : "orbit:35,20,0.12r,0.3,0,0.8";
    } else {
        std::string known;
        for (const std::string& n : aoSceneNames()) known += (known.empty() ? "" : ", ") + n;
        return makeError(ExitCode::Usage, "unknown AO study scene '{}' (expected {})", name, known);
    }
    auto spec = parseCameraSpec(s.cameraSpec);
    if (!spec) return spec.error();
    auto camera = resolveCamera(*spec, s.scene, width, height);
    if (!camera) return camera.error();
    s.camera = *camera;
    return s;
}

std::vector<AoSetting> aoStudySettings()
{
    std::vector<AoSetting> settings;
    for (bool denoise : {true, false})
        for (uint32_t slices : {1u, 2u, 3u, 4u})
            for (uint32_t steps : {2u, 4u, 8u}) settings.push_back({slices, steps, 1.0f, denoise});
    for (float scale : {0.5f, 2.0f}) settings.push_back({1, 8, scale, true});
    return settings;
}

AoImageError aoImageError(const AovImage& image, const AovImage& reference)
{
    AoImageError e;
    double squares = 0.0;
    const size_t n = std::min({image.ao.size(), reference.ao.size(), reference.id.size()});
    for (size_t i = 0; i < n; ++i) {
        if (reference.id[i] == EMPTY_ID) continue;
        const double d = std::abs(double(image.ao[i]) - double(reference.ao[i]));
        e.meanError += d;
        e.maxError = std::max(e.maxError, d);
        squares += d * d;
        ++e.pixels;
    }
    if (e.pixels == 0) return e;
    e.meanError /= double(e.pixels);
    const double mse = squares / double(e.pixels);
    e.psnr = mse > 0.0 ? std::min(kAoPsnrCap, 10.0 * std::log10(1.0 / mse)) : kAoPsnrCap;
    return e;
}

}  // namespace sr
