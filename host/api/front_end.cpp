// front_end.cpp - a view's warnings.
#include "api/front_end.h"

#include "settings/schema.h"

namespace sr {

std::vector<std::string> viewWarnings(const Scene& scene, const CameraMatrices& camera,
                                      const RenderSettings& settings)
{
    std::vector<std::string> warnings;
    if ((settings.shadingMode == SHADING_TEXCOORD || settings.shadingMode == SHADING_MIP) &&
        scene.textures.empty())
        warnings.push_back(fmt::format(
            "--shading {} shows the base colour texture's {}, but the scene has no textures: every surface "
            "shows the same colour",
            choiceName(setting("shading"), settings.shadingMode),
            settings.shadingMode == SHADING_TEXCOORD ? "coordinates" : "level of detail"));
    if (scene.triangleCount() > 0 && eyeInsideScene(scene, camera))
        warnings.push_back(
            "the camera is inside the scene's geometry, so it sees the inside of its surfaces (culled back "
            "faces, or the wrong side): move it out, e.g. --camera orbit:AZ,EL,2.5r (2.5 bounding radii)");
    return warnings;
}

}  // namespace sr
