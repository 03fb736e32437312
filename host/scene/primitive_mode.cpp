// primitive_mode.cpp - see primitive_mode.h.
#include "scene/primitive_mode.h"

namespace sr {

Scene meshAsPoints(Scene scene)
{
    const bool materials = !scene.materials.empty();
    constexpr uint32_t kUnused = 0xFFFFFFFFu;
    std::vector<uint32_t> material(scene.vertexCount(), kUnused);  // per vertex: first user's material
    for (size_t t = 0; t < scene.triangleCount(); ++t)
        for (size_t c = 0; c < 3; ++c) {
            uint32_t v = scene.indices[3 * t + c];
            if (v < material.size() && material[v] == kUnused)
                material[v] = materials ? scene.triMaterials[t] : 0u;
        }
    std::vector<uint32_t> points, pointMaterials;
    for (uint32_t v = 0; v < material.size(); ++v) {
        if (material[v] == kUnused) continue;
        points.push_back(v);
        if (materials) pointMaterials.push_back(material[v]);
    }
    points.insert(points.end(), scene.points.begin(), scene.points.end());
    pointMaterials.insert(pointMaterials.end(), scene.pointMaterials.begin(), scene.pointMaterials.end());
    scene.points = std::move(points);
    scene.pointMaterials = std::move(pointMaterials);
    scene.indices.clear();
    scene.triFlags.clear();
    scene.triMaterials.clear();
    return scene;
}

}  // namespace sr
