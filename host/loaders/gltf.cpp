// gltf.cpp - glTF 2.0 (.gltf, .glb) to the flat world-space triangle, segment and point lists,
// through tinygltf.
//
// Primitives of mode POINTS become Scene::points and those of the line modes (LINES, LINE_LOOP,
// LINE_STRIP) Scene::lines as segments, in document order, after the same attribute validation, node
// transform, COLOR_0 and material handling as triangles.
//
// tinygltf parses the JSON and resolves buffers (external files, data URIs, the GLB chunk); every
// index, offset and count it hands over is validated here before any byte is read, so a malformed
// file becomes a one-line error instead of an out-of-bounds read. The files themselves, the .gltf or
// .glb and every buffer and image it names, are read through readRegularFile (safe_file.h), never by
// tinygltf's own file functions, and the JSON's nesting depth is bounded before tinygltf parses it.
// The rules of the specification that tinygltf does not enforce are checked first (gltf_spec.h).
//
// Materials: base colour factor and texture (with KHR_texture_transform and its sampler), alpha mode,
// double-sidedness and emission (emissiveFactor, emissiveTexture without a transform,
// KHR_materials_emissive_strength); a primitive without a material gets glTF's default material (every
// property at its default: base colour 1), not defaultMaterial()'s grey. Images are decoded
// only when a used material needs them; an image that cannot be read or decoded is a warning (the material
// keeps its factor), one over the size limit an error.
#include "loaders/gltf_internal.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>

#include "base/warnings.h"
#include "loaders/gltf_spec.h"
#include "loaders/safe_file.h"
#include "scene/texture.h"

namespace sr {
namespace gltf {

void GltfFlattener::warnOnce(bool& done, const std::string& message)
{
    if (done) return;
    done = true;
    warn("{}: {}", path_, message);
}

Status GltfFlattener::run()
{
    // Required extensions that compress geometry were refused by checkGltfSpec, before tinygltf.
    std::vector<int> roots;
    if (!model_.scenes.empty()) {
        // checkGltfSpec has refused a `scene` that names no scene; without one, the first is drawn.
        int sceneIndex = model_.defaultScene < 0 ? 0 : model_.defaultScene;
        roots = model_.scenes[size_t(sceneIndex)].nodes;
    } else {
        // No scenes: every node that is nobody's child is a root, in document order.
        std::vector<bool> isChild(model_.nodes.size(), false);
        for (const tinygltf::Node& node : model_.nodes)
            for (int child : node.children)
                if (child >= 0 && size_t(child) < isChild.size()) isChild[size_t(child)] = true;
        for (size_t i = 0; i < model_.nodes.size(); ++i)
            if (!isChild[i]) roots.push_back(int(i));
    }

    visited_.assign(model_.nodes.size(), false);
    materialIndex_.assign(model_.materials.size(), -1);
    textureIndex_.assign(model_.textures.size(), -1);
    textureTried_.assign(model_.textures.size(), false);
    for (int root : roots) SR_TRY(visitTree(root));

    if (oddLinePrimitives_ > 0) {
        warn(
            "{}: dropped the unpaired last vertex of {} LINES primitive(s) with an odd "
            "vertex count",
            path_, oddLinePrimitives_);
    }
    if (skippedWithoutPositions_ > 0) {
        warn("{}: skipping {} primitive(s) without POSITION", path_, skippedWithoutPositions_);
    }
    if (!anyNonWhite_) scene_.colors.clear();

    return okStatus();
}

// Depth-first, children in listed order; an explicit stack so that deep hierarchies cannot
// overflow the call stack.
Status GltfFlattener::visitTree(int root)
{
    struct Pending {
        int node;
        glm::dmat4 parentWorld;
    };
    std::vector<Pending> stack{{root, glm::dmat4(1.0)}};
    while (!stack.empty()) {
        Pending item = stack.back();
        stack.pop_back();
        if (item.node < 0 || size_t(item.node) >= model_.nodes.size())
            return fail(fmt::format("node {} does not exist", item.node));
        // The spec requires disjoint trees; a node reached twice means a cycle or a shared child.
        if (visited_[size_t(item.node)])
            return fail(
                fmt::format("node {} is reached twice (the node hierarchy must be a set "
                            "of disjoint trees)",
                            item.node));
        visited_[size_t(item.node)] = true;
        const tinygltf::Node& node = model_.nodes[size_t(item.node)];
        Result<glm::dmat4> local = localMatrix(node, item.node);
        if (!local) return local.error();
        glm::dmat4 world = item.parentWorld * *local;
        if (node.mesh >= 0) SR_TRY(addMesh(node.mesh, world));
        if (node.camera >= 0) SR_TRY(addCamera(node.camera, item.node, world));
        for (auto it = node.children.rbegin(); it != node.children.rend(); ++it)
            stack.push_back({*it, world});
    }
    return okStatus();
}

Status GltfFlattener::addMesh(int meshIndex, const glm::dmat4& world)
{
    if (size_t(meshIndex) >= model_.meshes.size())
        return fail(fmt::format("mesh {} does not exist", meshIndex));
    glm::dmat3 linear(world);
    double det = glm::determinant(linear);
    // Inverse transpose up to a positive factor, written as the cofactor matrix so that it stays
    // defined for singular (zero-scale) transforms; the sign keeps mirrored normals pointing out.
    glm::dmat3 cofactor(glm::cross(linear[1], linear[2]), glm::cross(linear[2], linear[0]),
                        glm::cross(linear[0], linear[1]));
    glm::dmat3 normalMatrix = det < 0.0 ? -cofactor : cofactor;
    const tinygltf::Mesh& mesh = model_.meshes[size_t(meshIndex)];
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
        std::string where = fmt::format("mesh {} primitive {}", meshIndex, p);
        SR_TRY(addPrimitive(mesh.primitives[p], where, world, normalMatrix, det < 0.0));
    }
    return okStatus();
}

void GltfFlattener::pushVertex(const glm::vec3& p, const glm::vec3& n, const glm::vec4& c,
                               const glm::vec4& uv)
{
    scene_.positions.emplace_back(p, 1.0f);
    scene_.normals.emplace_back(n, 0.0f);
    scene_.colors.push_back(c);
    scene_.texcoords.push_back(uv);
    if (c != glm::vec4(1.0f)) anyNonWhite_ = true;
}

Status GltfFlattener::addPrimitive(const tinygltf::Primitive& prim, const std::string& where,
                                   const glm::dmat4& world, const glm::dmat3& normalMatrix, bool flip)
{
    int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    bool lineMode =
        mode == TINYGLTF_MODE_LINE || mode == TINYGLTF_MODE_LINE_LOOP || mode == TINYGLTF_MODE_LINE_STRIP;
    if (mode != TINYGLTF_MODE_POINTS && !lineMode && mode != TINYGLTF_MODE_TRIANGLES &&
        mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN)
        return fail(fmt::format("{} has unknown mode {}", where, mode));

    auto attribute = [&](const char* name) {
        auto it = prim.attributes.find(name);
        return it == prim.attributes.end() ? -1 : it->second;
    };
    int positionIndex = attribute("POSITION");
    if (positionIndex < 0) {
        ++skippedWithoutPositions_;
        return okStatus();
    }
    Result<AccessorView> positions = viewAccessor(model_, positionIndex);
    if (!positions) return positions.error();
    if (positions->type != TINYGLTF_TYPE_VEC3 || positions->componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
        return fail(fmt::format("{}: POSITION must be VEC3 float", where));
    size_t vertexCount = positions->count;

    AccessorView normals;
    bool hasNormals = attribute("NORMAL") >= 0;
    if (hasNormals) {
        Result<AccessorView> view = viewAccessor(model_, attribute("NORMAL"));
        if (!view) return view.error();
        normals = *view;
        if (normals.type != TINYGLTF_TYPE_VEC3 || normals.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
            return fail(fmt::format("{}: NORMAL must be VEC3 float", where));
        if (normals.count != vertexCount)
            return fail(fmt::format("{}: {} normals for {} positions", where, normals.count, vertexCount));
    }

    AccessorView colors;
    bool hasColors = attribute("COLOR_0") >= 0;
    if (hasColors) {
        Result<AccessorView> view = viewAccessor(model_, attribute("COLOR_0"));
        if (!view) return view.error();
        colors = *view;
        bool typeOk = colors.type == TINYGLTF_TYPE_VEC3 || colors.type == TINYGLTF_TYPE_VEC4;
        bool componentOk = colors.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT ||
                           colors.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                           colors.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
        if (!typeOk || !componentOk)
            return fail(
                fmt::format("{}: COLOR_0 must be VEC3 or VEC4 of float, unsigned byte or "
                            "unsigned short",
                            where));
        if (colors.count != vertexCount)
            return fail(fmt::format("{}: {} colours for {} positions", where, colors.count, vertexCount));
    }

    // TEXCOORD_0 and TEXCOORD_1: float, or normalised unsigned byte / short (glTF 2.0, 3.7.2.1).
    std::array<AccessorView, 2> uvSets;
    std::array<bool, 2> hasUv{};
    for (int set = 0; set < 2; ++set) {
        std::string name = fmt::format("TEXCOORD_{}", set);
        int accessor = attribute(name.c_str());
        if (accessor < 0) continue;
        Result<AccessorView> view = viewAccessor(model_, accessor);
        if (!view) return view.error();
        bool componentOk = view->componentType == TINYGLTF_COMPONENT_TYPE_FLOAT ||
                           view->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                           view->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
        if (view->type != TINYGLTF_TYPE_VEC2 || !componentOk)
            return fail(
                fmt::format("{}: {} must be VEC2 of float, unsigned byte or unsigned short", where, name));
        if (view->count != vertexCount)
            return fail(fmt::format("{}: {} texture coordinates in {} for {} positions", where, view->count,
                                    name, vertexCount));
        uvSets[size_t(set)] = *view;
        hasUv[size_t(set)] = true;
    }

    bool doubleSided = false;
    if (prim.material >= 0) {
        if (size_t(prim.material) >= model_.materials.size())
            return fail(fmt::format("{} uses material {}, which does not exist", where, prim.material));
        doubleSided = model_.materials[size_t(prim.material)].doubleSided;
    }
    Result<uint32_t> materialId = useMaterial(prim.material);
    if (!materialId) return materialId.error();
    SceneMaterial& material = scene_.materials[*materialId];
    if (material.baseColorTexture >= 0 && !hasUv[material.texCoord]) {
        // The material is shared by every primitive that uses it, so it loses its texture everywhere.
        if (!texCoordWarned_[*materialId])
            warn(
                "{}: material '{}' uses TEXCOORD_{}, which {} does not have; drawn without "
                "its texture",
                path_, material.name, material.texCoord, where);
        texCoordWarned_[*materialId] = true;
        material.baseColorTexture = -1;
    }
    if (material.emissiveTexture >= 0 && !hasUv[material.emissiveTexCoord]) {
        warn(
            "{}: material '{}' uses TEXCOORD_{} for emission, which {} does not have; drawn "
            "without its emissive texture",
            path_, material.name, material.emissiveTexCoord, where);
        material.emissiveTexture = -1;
    }
    // The base colour factor stays in the material (the shading stage multiplies it in), so the vertex
    // colours are COLOR_0 alone.
    auto colorOf = [&](size_t v) {
        glm::vec4 c(1.0f);
        if (hasColors) {
            c = glm::vec4(colors.component(v, 0), colors.component(v, 1), colors.component(v, 2), 1.0f);
            if (colors.type == TINYGLTF_TYPE_VEC4) c.w = colors.component(v, 3);
        }
        return c;
    };
    auto uvOf = [&](size_t v) {
        glm::vec4 uv(0.0f);
        if (hasUv[0]) uv.x = uvSets[0].component(v, 0), uv.y = uvSets[0].component(v, 1);
        if (hasUv[1]) uv.z = uvSets[1].component(v, 0), uv.w = uvSets[1].component(v, 1);
        return uv;
    };

    // The primitive's vertex sequence: its indices, or 0..count-1 without them.
    std::vector<uint32_t> sequence;
    if (prim.indices >= 0) {
        Result<AccessorView> view = viewAccessor(model_, prim.indices);
        if (!view) return view.error();
        bool indexType = view->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                         view->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
                         view->componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
        if (view->type != TINYGLTF_TYPE_SCALAR || !indexType)
            return fail(fmt::format("{}: indices must be SCALAR unsigned byte, short or int", where));
        sequence.resize(view->count);
        for (size_t i = 0; i < view->count; ++i) sequence[i] = view->index(i);
    } else {
        sequence.resize(vertexCount);
        for (size_t i = 0; i < vertexCount; ++i) sequence[i] = uint32_t(i);
    }

    auto worldPosition = [&](size_t v) {
        return glm::vec3(world * glm::dvec4(glm::dvec3(positions->vec3(v)), 1.0));
    };
    size_t base = scene_.positions.size();

    // Points and segments use the primitive's vertices stored once. They are shaded unlit, so a
    // primitive without NORMAL gets zero normals rather than invented ones.
    auto pushUnlitVertices = [&]() -> Status {
        if (vertexCount > kMaxVertices - base)
            return fail(fmt::format("{}: the scene has more than {} vertices", where, kMaxVertices));
        for (size_t v = 0; v < vertexCount; ++v) {
            glm::vec3 normal(0.0f);
            if (hasNormals) normal = safeNormalize(normalMatrix * glm::dvec3(normals.vec3(v)));
            pushVertex(worldPosition(v), normal, colorOf(v), uvOf(v));
        }
        return okStatus();
    };
    auto sceneIndex = [&](uint32_t local) {
        return local < vertexCount ? uint32_t(base + local) : kInvalidIndex;
    };

    if (mode == TINYGLTF_MODE_POINTS) {
        // One point per element of the sequence.
        SR_TRY(pushUnlitVertices());
        for (uint32_t local : sequence) scene_.points.push_back(sceneIndex(local));
        scene_.pointMaterials.insert(scene_.pointMaterials.end(), sequence.size(), *materialId);
        return okStatus();
    }
    if (lineMode) {
        if (mode == TINYGLTF_MODE_LINE && sequence.size() % 2 != 0) ++oddLinePrimitives_;
        std::vector<uint32_t> segments = lineSegments(mode, sequence);
        if (segments.empty()) return okStatus();
        SR_TRY(pushUnlitVertices());
        for (uint32_t local : segments) scene_.lines.push_back(sceneIndex(local));
        scene_.lineMaterials.insert(scene_.lineMaterials.end(), segments.size() / 2, *materialId);
        return okStatus();
    }

    // Triangle lists, with the vertex order of the glTF spec (section 3.7.2.1).
    std::vector<uint32_t> tris;
    size_t n = sequence.size();
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        tris.assign(sequence.begin(), sequence.begin() + ptrdiff_t(n / 3 * 3));
    } else if (n >= 3) {
        tris.reserve(3 * (n - 2));
        for (size_t i = 0; i + 2 < n; ++i) {
            if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                // Odd triangles swap their last two vertices so every triangle keeps the winding.
                size_t odd = i % 2;
                tris.insert(tris.end(), {sequence[i], sequence[i + 1 + odd], sequence[i + 2 - odd]});
            } else {
                tris.insert(tris.end(), {sequence[i + 1], sequence[i + 2], sequence[0]});
            }
        }
    }
    if (flip) {
        // A mirroring transform turns counter-clockwise into clockwise; the spec asks for the
        // winding to be reversed so the front faces stay front faces.
        for (size_t t = 0; t + 2 < tris.size(); t += 3) std::swap(tris[t + 1], tris[t + 2]);
    }

    size_t triangleCount = tris.size() / 3;
    uint32_t flags = (doubleSided ? TRI_FLAG_DOUBLE_SIDED : 0u) |
                     (material.alphaMode == ALPHA_MASK ? TRI_FLAG_ALPHA_MASK : 0u);
    size_t added = hasNormals ? vertexCount : 3 * triangleCount;
    if (added > kMaxVertices - base)
        return fail(fmt::format("{}: the scene has more than {} vertices", where, kMaxVertices));

    if (hasNormals) {
        for (size_t v = 0; v < vertexCount; ++v) {
            glm::vec3 normal = safeNormalize(normalMatrix * glm::dvec3(normals.vec3(v)));
            pushVertex(worldPosition(v), normal, colorOf(v), uvOf(v));
        }
        for (uint32_t local : tris)
            scene_.indices.push_back(local < vertexCount ? uint32_t(base + local) : kInvalidIndex);
    } else {
        // Flat shading: each triangle gets its own three vertices carrying the face normal.
        for (size_t t = 0; t < triangleCount; ++t) {
            const uint32_t* tri = &tris[3 * t];
            if (tri[0] >= vertexCount || tri[1] >= vertexCount || tri[2] >= vertexCount) {
                scene_.indices.insert(scene_.indices.end(), 3, kInvalidIndex);
                continue;
            }
            glm::vec3 p[3] = {worldPosition(tri[0]), worldPosition(tri[1]), worldPosition(tri[2])};
            glm::dvec3 e1 = glm::dvec3(p[1]) - glm::dvec3(p[0]);
            glm::dvec3 e2 = glm::dvec3(p[2]) - glm::dvec3(p[0]);
            glm::vec3 normal = safeNormalize(glm::cross(e1, e2));
            for (int k = 0; k < 3; ++k) {
                scene_.indices.push_back(uint32_t(scene_.positions.size()));
                pushVertex(p[k], normal, colorOf(tri[k]), uvOf(tri[k]));
            }
        }
    }
    scene_.triFlags.insert(scene_.triFlags.end(), triangleCount, flags);
    scene_.triMaterials.insert(scene_.triMaterials.end(), triangleCount, *materialId);
    return okStatus();
}

Status GltfFlattener::addCamera(int cameraIndex, int nodeIndex, const glm::dmat4& world)
{
    if (size_t(cameraIndex) >= model_.cameras.size())
        return fail(fmt::format("node {} uses camera {}, which does not exist", nodeIndex, cameraIndex));
    const tinygltf::Camera& cam = model_.cameras[size_t(cameraIndex)];
    SceneCamera out;
    out.name = !cam.name.empty() ? cam.name : model_.nodes[size_t(nodeIndex)].name;
    // Cameras ignore scale (spec); normalising the axes keeps a rigid view transform.
    glm::dmat4 m = world;
    for (int axis = 0; axis < 3; ++axis) {
        glm::dvec3 column(m[axis]);
        double len = glm::length(column);
        if (!(len > 0.0) || !std::isfinite(len))
            return fail(fmt::format("camera node {} has a degenerate transform", nodeIndex));
        m[axis] = glm::dvec4(column / len, 0.0);
    }
    out.worldFromView = glm::mat4(m);
    bool valid = false;
    if (cam.type == "perspective") {
        const tinygltf::PerspectiveCamera& p = cam.perspective;
        out.perspective = true;
        out.yfov = float(p.yfov);
        out.aspectRatio = float(p.aspectRatio);
        out.znear = float(p.znear);
        out.zfar = float(p.zfar);
        valid = out.yfov > 0.0f && out.yfov < 3.14159f && out.aspectRatio >= 0.0f && out.znear > 0.0f &&
                (out.zfar == 0.0f || out.zfar > out.znear);
    } else if (cam.type == "orthographic") {
        const tinygltf::OrthographicCamera& o = cam.orthographic;
        out.perspective = false;
        out.xmag = float(std::fabs(o.xmag));
        out.ymag = float(std::fabs(o.ymag));
        out.znear = float(o.znear);
        out.zfar = float(o.zfar);
        valid = out.xmag > 0.0f && out.ymag > 0.0f && out.znear >= 0.0f &&
                (out.zfar == 0.0f || out.zfar > out.znear);
    } else {
        return fail(fmt::format("camera {} has unknown type '{}'", cameraIndex, cam.type));
    }
    if (!valid || !std::isfinite(out.zfar))
        return fail(fmt::format("camera {} has invalid projection parameters", cameraIndex));
    scene_.cameras.push_back(out);
    return okStatus();
}

}  // namespace gltf

Result<Scene> loadGltf(const std::string& path)
{
    using namespace gltf;  // the loader's parts (gltf_internal.h)
    tinygltf::Model model;
    ImageFailures imageFailures;
    {
        // Read here rather than by tinygltf, like every file the glTF names (readWholeFile): a clear
        // "No such file" beats tinygltf's wording, and the JSON's depth is checked before it is parsed.
        Result<std::vector<unsigned char>> file = readRegularFile(path, kMaxSceneFileBytes, "load");
        if (!file) return file.error();
        const std::vector<unsigned char>& bytes = *file;
        if (bytes.empty()) return makeError(ExitCode::Usage, "cannot load '{}': the file is empty", path);
        // The magic number decides between .glb and .gltf whatever the extension says.
        bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
        auto [json, jsonSize] = jsonText(bytes, binary);
        Status shallow = checkJsonDepth(json, jsonSize);
        if (!shallow)
            return makeError(ExitCode::Usage, "cannot load '{}': {}", path, shallow.error().message);
        // The spec's rules first, so that what breaks them is named by its path in the document; JSON
        // that does not parse is left to tinygltf, which says where.
        nlohmann::json doc = nlohmann::json::parse(json, json + jsonSize, nullptr, false);
        std::vector<std::string> unsupported;
        if (!doc.is_discarded()) {
            Status valid = checkGltfSpec(doc, unsupported);
            if (!valid)
                return makeError(ExitCode::Usage, "cannot load '{}': {}", path, valid.error().message);
        }

        tinygltf::TinyGLTF loader;
        loader.SetImageLoader(&keepEncodedImage, &imageFailures);
        loader.SetFsCallbacks({&fileExists, &expandFilePath, &readWholeFile, &writeNothing, nullptr});
        // Buffers and images are found relative to the file's folder, as tinygltf's own LoadFromFile
        // functions do (but "/" for a file in the root, where they would take the current folder).
        size_t slash = path.find_last_of('/');
        std::string baseDir =
            slash == std::string::npos ? std::string() : path.substr(0, std::max<size_t>(slash, 1));
        std::string err, warn;
        // kMaxSceneFileBytes keeps the length within tinygltf's unsigned int.
        auto length = static_cast<unsigned int>(bytes.size());
        bool ok =
            binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), length, baseDir)
                   : loader.LoadASCIIFromString(&model, &err, &warn,
                                                reinterpret_cast<const char*>(bytes.data()), length, baseDir);
        if (!ok) {
            std::string reason =
                flattenMessage(withoutReadErrorPrefixes(err.empty() ? warn : err + "\n" + warn));
            if (reason.empty()) reason = "tinygltf could not parse the file";
            return makeError(ExitCode::Usage, "cannot load '{}': {}", path, reason);
        }
        warn = withoutImageFileWarnings(warn, imageFailures);
        if (!warn.empty()) sr::warn("{}: {}", path, flattenMessage(warn));

        for (const std::string& line : unsupported) sr::warn("{}: {}", path, line);
    }

    GltfFlattener flattener(model, imageFailures, path);
    Status flattened = flattener.run();
    if (!flattened)
        return makeError(ExitCode::Usage, "cannot load '{}': {}", path, flattened.error().message);
    Scene& scene = flattener.scene();
    SR_TRY(finalizeLoadedScene(scene, path));
    return std::move(scene);
}

}  // namespace sr
