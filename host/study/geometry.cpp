// geometry.cpp - see geometry.h.
#include "study/geometry.h"

#include <cmath>

namespace sr {

CameraMatrices clipCamera()
{
    CameraMatrices camera;
    camera.znear = 0.0f;
    camera.zfar = 1.0f;
    return camera;
}

double onGrid(double v)
{
    return std::nearbyint(v * SUBPIXEL_SCALE) / SUBPIXEL_SCALE;
}

// p * 2 / size is a multiple of 2^-7 / size below 2^16 / size: 23 significant bits, 24 after
// subtracting 1, so the conversion to float loses nothing.
glm::vec4 windowToClip(glm::dvec2 p, uint32_t size, double z)
{
    return {float(p.x * 2.0 / size - 1.0), float(p.y * 2.0 / size - 1.0), float(z), 1.0f};
}

uint32_t addVertex(Scene& scene, glm::vec4 position)
{
    scene.positions.push_back(position);
    scene.normals.push_back(glm::vec4(0.0f, 0.0f, 1.0f, 0.0f));
    return uint32_t(scene.positions.size() - 1);
}

void addTriangle(Scene& scene, uint32_t a, uint32_t b, uint32_t c)
{
    scene.indices.insert(scene.indices.end(), {a, b, c});
    scene.triFlags.push_back(0u);
}

void computeBounds(Scene& scene)
{
    scene.boundsMin = glm::vec3(scene.positions.front());
    scene.boundsMax = scene.boundsMin;
    for (const glm::vec4& p : scene.positions) {
        scene.boundsMin = glm::min(scene.boundsMin, glm::vec3(p));
        scene.boundsMax = glm::max(scene.boundsMax, glm::vec3(p));
    }
}

std::vector<glm::dvec2> fanRim(glm::dvec2 hub, double radius, int n)
{
    std::vector<glm::dvec2> rim;
    auto cross = [&](glm::dvec2 a, glm::dvec2 b) {
        return (a.x - hub.x) * (b.y - hub.y) - (a.y - hub.y) * (b.x - hub.x);
    };
    for (int i = 0; i < n; ++i) {
        double angle = 2.0 * M_PI * i / n;
        glm::dvec2 p(onGrid(hub.x + radius * std::cos(angle)), onGrid(hub.y + radius * std::sin(angle)));
        if (!rim.empty() && cross(rim.back(), p) < 0.0) p = rim.back();
        rim.push_back(p);
    }
    // The last vertices may have rounded past rim[0]: they collapse onto it, closing the fan.
    for (int i = n - 1; i > 0 && cross(rim[i], rim[0]) < 0.0; --i) rim[i] = rim[0];
    return rim;
}

Scene fanScene(glm::dvec2 hub, const std::vector<glm::dvec2>& rim, uint32_t size, double z)
{
    Scene scene;
    uint32_t h = addVertex(scene, windowToClip(hub, size, z));
    uint32_t first = uint32_t(scene.positions.size());
    for (glm::dvec2 p : rim) addVertex(scene, windowToClip(p, size, z));
    const uint32_t n = uint32_t(rim.size());
    for (uint32_t i = 0; i < n; ++i) addTriangle(scene, h, first + i, first + (i + 1) % n);
    computeBounds(scene);
    return scene;
}

void addGridCell(Scene& scene, uint32_t a, uint32_t cols, bool flip)
{
    uint32_t b = a + 1, d = a + cols, c = d + 1;
    if (!flip) {
        addTriangle(scene, a, b, c);
        addTriangle(scene, a, c, d);
    } else {
        addTriangle(scene, a, b, d);
        addTriangle(scene, b, c, d);
    }
}

void addGrid(Scene& scene, const std::vector<std::vector<glm::dvec2>>& grid, uint32_t size, double z)
{
    const uint32_t base = uint32_t(scene.positions.size());
    const uint32_t rows = uint32_t(grid.size()), cols = rows > 0 ? uint32_t(grid[0].size()) : 0;
    for (const auto& row : grid)
        for (glm::dvec2 p : row) addVertex(scene, windowToClip(p, size, z));
    for (uint32_t j = 0; j + 1 < rows; ++j)
        for (uint32_t i = 0; i + 1 < cols; ++i)
            addGridCell(scene, base + j * cols + i, cols, (i + j) % 2 != 0);
}

}  // namespace sr
