// gltf_spec.h - the rules of the glTF 2.0 specification that tinygltf does not enforce, checked on the
// document's JSON before the scene is built from it.
//
// tinygltf parses what it understands and fills in defaults for what it does not, so a file the
// specification calls invalid (a byteStride smaller than the element it steps over, a default scene
// that does not exist, a primitive mode of 9, a node matrix of 5 numbers, a perspective aspectRatio of
// 0) would load silently and draw something else than its author meant, or nothing. Those are errors
// that name where in the document they are ("meshes[0].primitives[0].mode is 9; ..."). What is valid
// but not supported (skins, morph targets) is drawn without it, with one warning each.
#ifndef RASTER_GLTF_SPEC_H
#define RASTER_GLTF_SPEC_H

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/result.h"

namespace sr {

// Checks the parsed glTF JSON `doc` (the .gltf file, or the JSON chunk of a .glb) against the rules
// above. Returns the first invalid part as an error whose one-line message starts with its path in the
// document; appends one line per unsupported feature the document uses to `warnings`.
Status checkGltfSpec(const nlohmann::json& doc, std::vector<std::string>& warnings);

}  // namespace sr

#endif  // RASTER_GLTF_SPEC_H
