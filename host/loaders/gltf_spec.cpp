// gltf_spec.cpp - the glTF 2.0 rules that tinygltf leaves unchecked (see gltf_spec.h).
#include "loaders/gltf_spec.h"

#include <cstddef>
#include <cstdint>

namespace sr {
namespace {

using Json = nlohmann::json;

// "<path> <what> (glTF 2.0 requires <rule>)", one line.
Error invalid(const std::string& path, const std::string& what, const std::string& rule)
{
    return Error{fmt::format("{} {} (glTF 2.0 requires {})", path, what, rule), ExitCode::Usage};
}

// How `value` reads in a message: the JSON as written, shortened.
std::string shown(const Json& value)
{
    std::string text = value.dump();
    return text.size() <= 40 ? text : text.substr(0, 37) + "...";
}

std::string shownOrMissing(const Json* value)
{
    return value ? shown(*value) : "missing";
}

// The named array of `doc`, or an empty one where it is absent or not an array (tinygltf has already
// refused a file whose top-level arrays are of the wrong type).
const Json& arrayOf(const Json& doc, const char* name)
{
    static const Json empty = Json::array();
    auto it = doc.find(name);
    return it != doc.end() && it->is_array() ? *it : empty;
}

const Json* member(const Json& object, const char* name)
{
    if (!object.is_object()) return nullptr;
    auto it = object.find(name);
    return it == object.end() ? nullptr : &*it;
}

bool isIndexBelow(const Json& value, size_t count)
{
    return value.is_number_integer() && value.get<int64_t>() >= 0 && uint64_t(value.get<int64_t>()) < count;
}

// An error unless `value`, at `path`, indexes one of the `count` entries of the top-level array
// `array` ("scenes", "skins", "nodes"), whose entries the message calls `entry`.
Status checkIndex(const std::string& path, const Json& value, size_t count, const char* array,
                  const char* entry)
{
    if (isIndexBelow(value, count)) return okStatus();
    return invalid(path, fmt::format("is {}, but the file has {} {}(s)", shown(value), count, entry),
                   fmt::format("the index of a {} in `{}`", entry, array));
}

bool isPositive(const Json& value)
{
    return value.is_number() && value.get<double>() > 0.0;
}

// Bytes per component of an accessor's componentType, 0 for an unknown type.
size_t componentBytes(const Json& type)
{
    if (!type.is_number_integer()) return 0;
    switch (type.get<int64_t>()) {
    case 5120:  // BYTE
    case 5121:  // UNSIGNED_BYTE
        return 1;
    case 5122:  // SHORT
    case 5123:  // UNSIGNED_SHORT
        return 2;
    case 5125:  // UNSIGNED_INT
    case 5126:  // FLOAT
        return 4;
    default: return 0;
    }
}

// Bytes one element of an accessor occupies, 0 for an unknown type. Matrix columns start on 4-byte
// boundaries (spec 3.6.2.4, data alignment), so a MAT2 of bytes takes 8 bytes, a MAT3 of bytes 12 and
// a MAT3 of shorts 24.
size_t elementBytes(const Json& accessor)
{
    const Json* typeJson = member(accessor, "type");
    const Json* componentJson = member(accessor, "componentType");
    if (!typeJson || !typeJson->is_string() || !componentJson) return 0;
    size_t component = componentBytes(*componentJson);
    const std::string type = typeJson->get<std::string>();
    size_t columns = 1, rows = 0;
    if (type == "SCALAR")
        rows = 1;
    else if (type == "VEC2")
        rows = 2;
    else if (type == "VEC3")
        rows = 3;
    else if (type == "VEC4")
        rows = 4;
    else if (type == "MAT2")
        columns = rows = 2;
    else if (type == "MAT3")
        columns = rows = 3;
    else if (type == "MAT4")
        columns = rows = 4;
    size_t column = rows * component;
    if (columns > 1) column = (column + 3) / 4 * 4;
    return columns * column;
}

Status checkScene(const Json& doc)
{
    const Json* scene = member(doc, "scene");
    if (!scene) return okStatus();
    return checkIndex("scene", *scene, arrayOf(doc, "scenes").size(), "scenes", "scene");
}

Status checkNodes(const Json& doc)
{
    const Json& nodes = arrayOf(doc, "nodes");
    size_t skins = arrayOf(doc, "skins").size();
    for (size_t i = 0; i < nodes.size(); ++i) {
        if (const Json* matrix = member(nodes[i], "matrix")) {
            bool valid = matrix->is_array() && matrix->size() == 16;
            for (size_t k = 0; valid && k < 16; ++k) valid = (*matrix)[k].is_number();
            if (!valid)
                return invalid(fmt::format("nodes[{}].matrix", i), "is " + shown(*matrix),
                               "16 numbers, a column-major 4x4 matrix");
        }
        if (const Json* skin = member(nodes[i], "skin"))
            SR_TRY(checkIndex(fmt::format("nodes[{}].skin", i), *skin, skins, "skins", "skin"));
    }
    return okStatus();
}

Status checkMeshes(const Json& doc, size_t& morphed)
{
    const Json& meshes = arrayOf(doc, "meshes");
    for (size_t m = 0; m < meshes.size(); ++m) {
        const Json* primitives = member(meshes[m], "primitives");
        if (!primitives || !primitives->is_array()) continue;
        for (size_t p = 0; p < primitives->size(); ++p) {
            const Json& primitive = (*primitives)[p];
            if (const Json* mode = member(primitive, "mode");
                mode &&
                !(mode->is_number_integer() && mode->get<int64_t>() >= 0 && mode->get<int64_t>() <= 6))
                return invalid(fmt::format("meshes[{}].primitives[{}].mode", m, p), "is " + shown(*mode),
                               "0 (POINTS) to 6 (TRIANGLE_FAN)");
            if (const Json* targets = member(primitive, "targets");
                targets && targets->is_array() && !targets->empty())
                ++morphed;
        }
    }
    return okStatus();
}

Status checkStrides(const Json& doc)
{
    const Json& views = arrayOf(doc, "bufferViews");
    for (size_t v = 0; v < views.size(); ++v) {
        const Json* stride = member(views[v], "byteStride");
        if (stride &&
            !(stride->is_number_integer() && stride->get<int64_t>() >= 4 && stride->get<int64_t>() <= 252))
            return invalid(fmt::format("bufferViews[{}].byteStride", v), "is " + shown(*stride), "4 to 252");
    }
    const Json& accessors = arrayOf(doc, "accessors");
    for (size_t a = 0; a < accessors.size(); ++a) {
        const Json* view = member(accessors[a], "bufferView");
        if (!view || !isIndexBelow(*view, views.size())) continue;  // the loader names a missing view
        size_t v = size_t(view->get<int64_t>());
        const Json* stride = member(views[v], "byteStride");
        size_t element = elementBytes(accessors[a]);
        if (stride && element > 0 && size_t(stride->get<int64_t>()) < element)
            return invalid(
                fmt::format("bufferViews[{}].byteStride", v),
                fmt::format("is {}, less than the {}-byte elements of accessors[{}] that step through it",
                            stride->get<int64_t>(), element, a),
                "a stride of at least the element size");
    }
    return okStatus();
}

Status checkCameras(const Json& doc)
{
    const Json& cameras = arrayOf(doc, "cameras");
    for (size_t c = 0; c < cameras.size(); ++c) {
        std::string at = fmt::format("cameras[{}].", c);
        if (const Json* p = member(cameras[c], "perspective")) {
            const Json* aspect = member(*p, "aspectRatio");
            if (aspect && !isPositive(*aspect))
                return invalid(at + "perspective.aspectRatio", "is " + shown(*aspect),
                               "a number above 0, or no aspectRatio (the viewport's)");
            const Json* yfov = member(*p, "yfov");
            if (!yfov || !isPositive(*yfov))
                return invalid(at + "perspective.yfov", "is " + shownOrMissing(yfov), "an angle above 0");
            const Json* znear = member(*p, "znear");
            if (!znear || !isPositive(*znear))
                return invalid(at + "perspective.znear", "is " + shownOrMissing(znear), "a distance above 0");
            const Json* zfar = member(*p, "zfar");
            if (zfar && !(zfar->is_number() && zfar->get<double>() > znear->get<double>()))
                return invalid(at + "perspective.zfar", "is " + shown(*zfar),
                               "a distance beyond znear, or no zfar (infinite)");
        }
        if (const Json* o = member(cameras[c], "orthographic")) {
            for (const char* name : {"xmag", "ymag"}) {
                const Json* mag = member(*o, name);
                if (!mag || !mag->is_number() || mag->get<double>() == 0.0)
                    return invalid(at + "orthographic." + name, "is " + shownOrMissing(mag),
                                   "a number other than 0");
            }
            const Json* znear = member(*o, "znear");
            if (!znear || !znear->is_number() || znear->get<double>() < 0.0)
                return invalid(at + "orthographic.znear", "is " + shownOrMissing(znear),
                               "a distance of 0 or more");
            const Json* zfar = member(*o, "zfar");
            if (!zfar || !(zfar->is_number() && zfar->get<double>() > znear->get<double>()))
                return invalid(at + "orthographic.zfar", "is " + shownOrMissing(zfar),
                               "a distance beyond znear");
        }
    }
    return okStatus();
}

Status checkSkins(const Json& doc)
{
    const Json& skins = arrayOf(doc, "skins");
    size_t nodes = arrayOf(doc, "nodes").size();
    for (size_t s = 0; s < skins.size(); ++s) {
        const Json* joints = member(skins[s], "joints");
        if (!joints || !joints->is_array() || joints->empty())
            return invalid(fmt::format("skins[{}].joints", s), "is " + shownOrMissing(joints),
                           "at least one node index");
        for (size_t j = 0; j < joints->size(); ++j)
            SR_TRY(
                checkIndex(fmt::format("skins[{}].joints[{}]", s, j), (*joints)[j], nodes, "nodes", "node"));
        if (const Json* skeleton = member(skins[s], "skeleton"))
            SR_TRY(checkIndex(fmt::format("skins[{}].skeleton", s), *skeleton, nodes, "nodes", "node"));
    }
    return okStatus();
}

}  // namespace

namespace {

// Geometry compression raster does not decode. A file that requires one cannot be drawn: without this
// check tinygltf fails later on the compressed primitives' accessors, which have no bufferView
// ("accessor[0] invalid bufferView"), a message that does not name the cause.
bool isCompressionExtension(const std::string& name)
{
    return name == "KHR_draco_mesh_compression" || name == "EXT_meshopt_compression" ||
           name == "KHR_meshopt_compression";
}

// A required compression extension is an error naming it. One that is only used (the file also carries
// the uncompressed data, as the extensions allow) is drawn from that data with one warning, unless a
// compressed primitive lacks it: then the error names the primitive and the extension.
Status checkCompression(const Json& doc, std::vector<std::string>& warnings)
{
    for (const Json& name : arrayOf(doc, "extensionsRequired")) {
        if (name.is_string() && isCompressionExtension(name.get<std::string>()))
            return Error{fmt::format("the file requires the extension {} (compressed geometry), which is not "
                                     "supported: decompress it first (e.g. gltf-transform copy)",
                                     name.get<std::string>()),
                         ExitCode::Usage};
    }
    const Json& accessors = arrayOf(doc, "accessors");
    auto hasData = [&](const Json& index) {
        return isIndexBelow(index, accessors.size()) && member(accessors[index.get<size_t>()], "bufferView");
    };
    const char* kDraco = "KHR_draco_mesh_compression";
    size_t compressed = 0;
    const Json& meshes = arrayOf(doc, "meshes");
    for (size_t m = 0; m < meshes.size(); ++m) {
        const Json& primitives = arrayOf(meshes[m], "primitives");
        for (size_t p = 0; p < primitives.size(); ++p) {
            const Json* extensions = member(primitives[p], "extensions");
            if (!extensions || !member(*extensions, kDraco)) continue;
            ++compressed;
            std::vector<const Json*> used;
            if (const Json* attributes = member(primitives[p], "attributes");
                attributes && attributes->is_object())
                for (const Json& index : *attributes) used.push_back(&index);
            if (const Json* indices = member(primitives[p], "indices")) used.push_back(indices);
            for (const Json* index : used) {
                if (!hasData(*index))
                    return Error{
                        fmt::format("meshes[{}].primitives[{}] is compressed with {}, which is not "
                                    "supported, and has no uncompressed fallback (accessor {} has no "
                                    "bufferView)",
                                    m, p, kDraco, shown(*index)),
                        ExitCode::Usage};
            }
        }
    }
    if (compressed > 0)
        warnings.push_back(
            fmt::format("{} is not supported: {} primitive(s) drawn from their uncompressed "
                        "fallback data",
                        kDraco, compressed));
    return okStatus();
}

}  // namespace

Status checkGltfSpec(const Json& doc, std::vector<std::string>& warnings)
{
    if (!doc.is_object()) return Error{"the document is not a JSON object", ExitCode::Usage};
    SR_TRY(checkCompression(doc, warnings));
    size_t morphed = 0;
    SR_TRY(checkScene(doc));
    SR_TRY(checkNodes(doc));
    SR_TRY(checkMeshes(doc, morphed));
    SR_TRY(checkStrides(doc));
    SR_TRY(checkCameras(doc));
    SR_TRY(checkSkins(doc));

    size_t skinned = 0;
    for (const Json& node : arrayOf(doc, "nodes"))
        if (member(node, "skin")) ++skinned;
    if (skinned > 0)
        warnings.push_back(
            fmt::format("skins are not supported: {} skinned node(s) drawn unskinned, as "
                        "their meshes store them",
                        skinned));
    if (morphed > 0)
        warnings.push_back(
            fmt::format("morph targets are not supported: {} primitive(s) drawn in their base "
                        "shape, without target weights",
                        morphed));
    return okStatus();
}

}  // namespace sr
