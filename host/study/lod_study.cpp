// lod_study.cpp - see lod_study.h.
#include "study/lod_study.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <unordered_map>

#include <fmt/format.h>

#include "raster_shared.h"
#include "settings/schema.h"

namespace sr {
namespace {

// The vertex at the middle of edge (a, b) of `scene`, appended the first time the edge is asked for
// (either way round) and shared after that (subdivideMidpoints).
class Midpoints {
public:
    explicit Midpoints(Scene& scene) : scene_(scene) { ids_.reserve(scene.indices.size()); }

    uint32_t at(uint32_t a, uint32_t b)
    {
        const uint64_t key = a < b ? uint64_t(a) << 32 | b : uint64_t(b) << 32 | a;
        auto [it, added] = ids_.emplace(key, uint32_t(scene_.positions.size()));
        if (!added) return it->second;
        // Copies: the pushes below may move the vectors. The sum of two floats does not depend on their
        // order, so the two sides of an edge get the same position bit for bit even as different vertices.
        const glm::vec4 pa = scene_.positions[a], pb = scene_.positions[b];
        const glm::vec4 na = scene_.normals[a], nb = scene_.normals[b];
        scene_.positions.push_back(0.5f * (pa + pb));
        const glm::vec3 sum = glm::vec3(na) + glm::vec3(nb);
        const float length = glm::length(sum);
        scene_.normals.push_back(length > 0.0f ? glm::vec4(sum / length, 0.0f) : na);
        if (!scene_.colors.empty()) {
            const glm::vec4 ca = scene_.colors[a], cb = scene_.colors[b];
            scene_.colors.push_back(0.5f * (ca + cb));
        }
        if (!scene_.texcoords.empty()) {
            const glm::vec4 ta = scene_.texcoords[a], tb = scene_.texcoords[b];
            scene_.texcoords.push_back(0.5f * (ta + tb));
        }
        return it->second;
    }

private:
    Scene& scene_;
    std::unordered_map<uint64_t, uint32_t> ids_;
};

bool covered(const AovImage& aov, size_t i)
{
    return i < aov.id.size() && aov.id[i] != EMPTY_ID;
}

}  // namespace

const std::vector<std::string>& lodSceneNames()
{
    static const std::vector<std::string> names = {"sphere", "bunny", "bunny-fine"};
    return names;
}

Result<Scene> makeLodScene(const std::string& name, int rings, const std::string& bunnyPath)
{
    if (name == "sphere") return builtinSceneNamed(fmt::format("builtin:dense:{}", rings));
    if (name == "bunny") return loadScene(bunnyPath);
    if (name == "bunny-fine") {
        auto bunny = loadScene(bunnyPath);
        if (!bunny) return bunny.error();
        return subdivideMidpoints(*bunny, kLodFineSubdivisions);
    }
    return makeError(ExitCode::Usage, "unknown study LOD scene '{}' (expected {})", name,
                     fmt::format("{}", fmt::join(lodSceneNames(), ", ")));
}

Result<Scene> subdivideMidpoints(const Scene& scene, int times)
{
    Scene out = scene;
    for (int pass = 0; pass < times; ++pass) {
        // Vertex indices and ids are 32-bit: 4 triangles per triangle, up to 3 new vertices each.
        if (4 * uint64_t(out.indices.size()) + out.positions.size() > uint64_t(INT32_MAX))
            return makeError(ExitCode::Usage, "cannot subdivide {} triangles {} times: too many triangles",
                             scene.triangleCount(), times);
        const size_t triangles = out.triangleCount();
        const bool materials = out.triMaterials.size() == triangles;
        std::vector<uint32_t> indices, flags, triMaterials;
        indices.reserve(12 * triangles);
        flags.reserve(4 * triangles);
        if (materials) triMaterials.reserve(4 * triangles);
        Midpoints midpoints(out);
        for (size_t t = 0; t < triangles; ++t) {
            const uint32_t a = out.indices[3 * t], b = out.indices[3 * t + 1], c = out.indices[3 * t + 2];
            const uint32_t ab = midpoints.at(a, b), bc = midpoints.at(b, c), ca = midpoints.at(c, a);
            indices.insert(indices.end(), {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca});
            const uint32_t f = t < out.triFlags.size() ? out.triFlags[t] : 0u;
            flags.insert(flags.end(), {f, f, f, f});
            if (materials) triMaterials.insert(triMaterials.end(), 4, out.triMaterials[t]);
        }
        out.indices = std::move(indices);
        out.triFlags = std::move(flags);
        if (materials) out.triMaterials = std::move(triMaterials);
    }
    SR_TRY(finalizeScene(out, "subdivided scene"));
    return out;
}

std::vector<LodCamera> lodCameras(const Scene& scene, unsigned width, unsigned height)
{
    const BoundingSphere sphere = boundingSphere(scene);
    LodCamera nearCamera{"near", autoOrbitPose(sphere, width, height), {}};
    LodCamera farCamera{"far", nearCamera.pose, {}};
    farCamera.pose.distance *= kLodFarFactor;
    nearCamera.camera = orbitCameraMatrices(nearCamera.pose, sphere, width, height);
    farCamera.camera = orbitCameraMatrices(farCamera.pose, sphere, width, height);
    return {nearCamera, farCamera};
}

LodImageDiff lodImageDiff(const AovImage& image, const AovImage& baseline)
{
    LodImageDiff d;
    const int w = int(baseline.width), h = int(baseline.height);
    const size_t pixels = size_t(w) * size_t(h);
    std::vector<uint8_t> base(pixels), silhouette(pixels, 0);
    for (size_t i = 0; i < pixels; ++i) base[i] = covered(baseline, i);
    const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            for (int k = 0; k < 4; ++k) {
                const int nx = x + dx[k], ny = y + dy[k];
                if (nx >= 0 && nx < w && ny >= 0 && ny < h && base[size_t(ny) * w + nx] != base[i])
                    silhouette[i] = 1;
            }
            d.silhouettePx += silhouette[i];
        }
    double depthSum = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            const bool drawn = covered(image, i);
            if (drawn != bool(base[i])) {
                ++d.coveragePx;
                bool nearSilhouette = false;
                for (int ny = std::max(0, y - 1); ny <= std::min(h - 1, y + 1); ++ny)
                    for (int nx = std::max(0, x - 1); nx <= std::min(w - 1, x + 1); ++nx)
                        nearSilhouette = nearSilhouette || silhouette[size_t(ny) * w + nx];
                d.beyondSilhouettePx += !nearSilhouette;
            } else if (drawn && i < image.depth.size() && i < baseline.depth.size()) {
                const double e = std::abs(double(image.depth[i]) - double(baseline.depth[i]));
                ++d.bothCoveredPx;
                d.depthMaxError = std::max(d.depthMaxError, e);
                depthSum += e;
            }
        }
    d.depthMeanError = d.bothCoveredPx > 0 ? depthSum / double(d.bothCoveredPx) : 0.0;
    return d;
}

Result<std::vector<float>> parseLodErrors(const std::string& text)
{
    std::vector<float> errors;
    std::istringstream in(text);
    for (std::string item; std::getline(in, item, ',');) {
        if (item.empty()) continue;
        auto error = parseSettingText(setting("lod-error-px"), item, "--lod-errors entry");
        if (!error) return error.error();
        errors.push_back(error->get<float>());
    }
    return errors;
}

}  // namespace sr
