// scenes.cpp - see scenes.h.
#include "study/scenes.h"

#include <filesystem>
#include <random>

#include "study/geometry.h"

namespace sr {
namespace {

// The window the synthetic scenes are laid out in: a power of two, so windowToClip is exact.
constexpr uint32_t kNominalSize = 256;

// Saturated, well separated linear colours: neighbouring triangles differ by at least half the range
// in some channel, so a misplaced edge costs a visible error.
const glm::vec4 kPalette[] = {{0.9f, 0.15f, 0.1f, 1.0f},  {0.1f, 0.6f, 0.15f, 1.0f},
                              {0.1f, 0.2f, 0.9f, 1.0f},   {0.95f, 0.8f, 0.1f, 1.0f},
                              {0.75f, 0.15f, 0.8f, 1.0f}, {0.05f, 0.75f, 0.8f, 1.0f}};
constexpr uint32_t kPaletteSize = sizeof(kPalette) / sizeof(kPalette[0]);

// Gives the scene the palette as materials and each triangle the colour `colour(t)`; marks every
// triangle double-sided, so that the layout's winding does not matter under back-face culling (the
// study renders with the render command's defaults), and finalizes it.
template <typename Colour>
Result<Scene> paletted(Scene scene, const char* what, Colour colour)
{
    for (uint32_t k = 0; k < kPaletteSize; ++k) {
        SceneMaterial m;
        m.name = "palette" + std::to_string(k);
        m.baseColorFactor = kPalette[k];
        scene.materials.push_back(m);
    }
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) scene.triMaterials.push_back(colour(t));
    scene.triFlags.assign(scene.triangleCount(), TRI_FLAG_DOUBLE_SIDED);
    SR_TRY(finalizeScene(scene, what));
    return scene;
}

}  // namespace

const std::vector<std::string>& studySceneNames()
{
    static const std::vector<std::string> names = {"builtin",    "checker-grazing", "dense",         "bunny",
                                                   "sliver-fan", "jittered-grid",   "lowpoly-sphere"};
    return names;
}

// The 10^3 case of the slivers stress axis (hub on a pixel centre of the nominal window, radius 0.4 of
// it). Colours cycle through the palette, so consecutive slivers always differ.
Result<Scene> sliverFanScene()
{
    const glm::dvec2 hub(kNominalSize / 2 + 0.5, kNominalSize / 2 + 0.5);
    const std::vector<glm::dvec2> rim = fanRim(hub, 0.4 * kNominalSize, kSliverFanTriangles);
    return paletted(fanScene(hub, rim, kNominalSize, 0.5), "sliver fan",
                    [](uint32_t t) { return t % kPaletteSize; });
}

// Cells of 224 / 24 = 9.3 px over [16, 240]^2 of the nominal window; each interior vertex moves by a
// uniform draw in +-r cells per coordinate (mt19937, seed 12) and is rounded to the 1/256 grid. r =
// 0.15 keeps every triangle's winding, so the mesh never folds over itself: the doubled area of a
// cell's triangle is at least (1 - 2r)^2 - 2r (1 + 2r) = 1 - 6r cells^2 (one side shrunk by both of its
// ends' draws, the other side's skew at its largest). Each triangle draws its colour from the palette
// again until it differs from the triangle before it, so the two halves of every cell differ.
Result<Scene> jitteredGridScene()
{
    const double origin = 16.0, step = (kNominalSize - 2.0 * origin) / kJitterCells;
    std::mt19937 rng(12);
    std::uniform_real_distribution<double> jitter(-0.15 * step, 0.15 * step);
    std::vector<std::vector<glm::dvec2>> grid(kJitterCells + 1, std::vector<glm::dvec2>(kJitterCells + 1));
    for (int j = 0; j <= kJitterCells; ++j)
        for (int i = 0; i <= kJitterCells; ++i) {
            const bool inner = i > 0 && i < kJitterCells && j > 0 && j < kJitterCells;
            const double dx = inner ? jitter(rng) : 0.0, dy = inner ? jitter(rng) : 0.0;
            grid[j][i] = {onGrid(origin + i * step + dx), onGrid(origin + j * step + dy)};
        }
    Scene scene;
    addGrid(scene, grid, kNominalSize, 0.5);
    std::vector<uint32_t> colours;
    return paletted(std::move(scene), "jittered grid", [&](uint32_t) {
        uint32_t c = rng() % kPaletteSize;
        while (!colours.empty() && c == colours.back()) c = rng() % kPaletteSize;
        colours.push_back(c);
        return c;
    });
}

Result<StudyScene> makeStudyScene(const std::string& name, unsigned width, unsigned height,
                                  const std::string& bunnyPath)
{
    Result<Scene> scene = makeError(ExitCode::Usage, "no scene");
    CameraSpec spec;
    bool identityCamera = false;
    if (name == "builtin") {
        scene = builtinScene();
    } else if (name == "checker-grazing") {
        // The textured plane at a grazing angle, where texture filtering matters most.
        scene = builtinSceneNamed("builtin:checker");
        auto grazing = parseCameraSpec("orbit:0,6,12");
        if (!grazing) return grazing.error();
        spec = *grazing;
    } else if (name == "dense") {
        scene = builtinSceneNamed("builtin:dense");
    } else if (name == "bunny") {
        scene = loadScene(bunnyPath);
    } else if (name == "sliver-fan") {
        scene = sliverFanScene();
        identityCamera = true;
    } else if (name == "jittered-grid") {
        scene = jitteredGridScene();
        identityCamera = true;
    } else if (name == "lowpoly-sphere") {
        // A sphere of 4 x 8 facets with its exact normals, against the 128 x 256 one (builtin:dense).
        scene = tessellatedSphere(4);
    } else {
        std::string known;
        for (const std::string& n : studySceneNames()) known += (known.empty() ? "" : ", ") + n;
        return makeError(ExitCode::Usage, "unknown study scene '{}' (expected {})", name, known);
    }
    if (!scene) return scene.error();
    StudyScene s;
    s.name = name;
    s.scene = std::move(*scene);
    s.camera = clipCamera();
    s.textured = !s.scene.textures.empty();
    if (name == "lowpoly-sphere") {
        s.tessellation = true;
        s.referenceScene = tessellatedSphere(128);
    }
    if (!identityCamera) {
        auto camera = resolveCamera(spec, s.scene, width, height);
        if (!camera) return camera.error();
        s.camera = *camera;
    }
    return s;
}

std::string studySceneNameFor(const std::string& scenePath)
{
    const std::string prefix = kStudyScenePrefix;
    if (scenePath.empty()) return "builtin";
    if (scenePath.compare(0, prefix.size(), prefix) == 0) return scenePath.substr(prefix.size());
    if (scenePath.compare(0, 8, "builtin:") == 0) return scenePath.substr(8);
    if (scenePath == "builtin") return scenePath;
    return std::filesystem::path(scenePath).stem().string();
}

}  // namespace sr
