// gltf_accessors.cpp - glTF accessors (every index, offset and count validated before a byte is read),
// node transforms and the line modes' segments.
#include "loaders/gltf_internal.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sr::gltf {

int componentSize(int componentType)
{
    switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_INT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
    }
}

Result<AccessorView> viewAccessor(const tinygltf::Model& model, int index)
{
    if (index < 0 || size_t(index) >= model.accessors.size())
        return fail(fmt::format("accessor {} does not exist", index));
    const tinygltf::Accessor& a = model.accessors[size_t(index)];
    if (a.sparse.isSparse)
        return fail(fmt::format("accessor {} is sparse (sparse accessors are not supported)", index));
    int components = tinygltf::GetNumComponentsInType(uint32_t(a.type));
    int size = componentSize(a.componentType);
    if (components <= 0 || size <= 0)
        return fail(fmt::format("accessor {} has an unsupported type or component type", index));
    if (a.count > kMaxVertices)
        return fail(fmt::format("accessor {} has too many elements ({})", index, a.count));

    AccessorView view;
    view.count = a.count;
    view.type = a.type;
    view.componentType = a.componentType;
    if (a.bufferView < 0) return view;
    if (size_t(a.bufferView) >= model.bufferViews.size())
        return fail(
            fmt::format("accessor {} uses buffer view {}, which does not exist", index, a.bufferView));
    const tinygltf::BufferView& bv = model.bufferViews[size_t(a.bufferView)];
    if (bv.buffer < 0 || size_t(bv.buffer) >= model.buffers.size())
        return fail(
            fmt::format("buffer view {} uses buffer {}, which does not exist", a.bufferView, bv.buffer));
    const std::vector<unsigned char>& data = model.buffers[size_t(bv.buffer)].data;
    if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset)
        return fail(
            fmt::format("buffer view {} (offset {}, length {}) lies outside buffer {} "
                        "({} bytes)",
                        a.bufferView, bv.byteOffset, bv.byteLength, bv.buffer, data.size()));
    int stride = a.ByteStride(bv);
    if (stride <= 0)
        return fail(fmt::format("accessor {} has an invalid byte stride {}", index, bv.byteStride));
    view.stride = size_t(stride);
    if (a.count == 0) return view;
    // Written to avoid overflow: offset + (count - 1) * stride + element size <= view length.
    size_t element = size_t(components) * size_t(size);
    bool inside = a.byteOffset <= bv.byteLength && bv.byteLength - a.byteOffset >= element &&
                  (a.count - 1) <= (bv.byteLength - a.byteOffset - element) / view.stride;
    if (inside) view.base = data.data() + bv.byteOffset + a.byteOffset;
    if (!inside)
        return fail(
            fmt::format("accessor {} ({} elements, offset {}, stride {}) reads past the end "
                        "of buffer view {} ({} bytes)",
                        index, a.count, a.byteOffset, view.stride, a.bufferView, bv.byteLength));
    return view;
}

// Local transform of a node: its matrix, or T * R * S.
Result<glm::dmat4> localMatrix(const tinygltf::Node& node, int index)
{
    glm::dmat4 m(1.0);
    if (!node.matrix.empty()) {
        if (node.matrix.size() != 16)
            return fail(fmt::format("node {} has a matrix with {} values", index, node.matrix.size()));
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) m[c][r] = node.matrix[size_t(c * 4 + r)];
        return m;
    }
    if ((!node.translation.empty() && node.translation.size() != 3) ||
        (!node.rotation.empty() && node.rotation.size() != 4) ||
        (!node.scale.empty() && node.scale.size() != 3))
        return fail(fmt::format("node {} has a malformed translation, rotation or scale", index));
    glm::dmat4 r(1.0);
    if (!node.rotation.empty()) {
        double x = node.rotation[0], y = node.rotation[1], z = node.rotation[2];
        double w = node.rotation[3];
        double len = std::sqrt(x * x + y * y + z * z + w * w);
        if (!(len > 0.0) || !std::isfinite(len))
            return fail(fmt::format("node {} has a zero or non-finite rotation", index));
        x /= len, y /= len, z /= len, w /= len;
        // Unit quaternion (x, y, z, w) to a rotation matrix, indexed [column][row] like glm.
        r[0][0] = 1 - 2 * (y * y + z * z);
        r[0][1] = 2 * (x * y + w * z);
        r[0][2] = 2 * (x * z - w * y);
        r[1][0] = 2 * (x * y - w * z);
        r[1][1] = 1 - 2 * (x * x + z * z);
        r[1][2] = 2 * (y * z + w * x);
        r[2][0] = 2 * (x * z + w * y);
        r[2][1] = 2 * (y * z - w * x);
        r[2][2] = 1 - 2 * (x * x + y * y);
    }
    glm::dmat4 s(1.0);
    if (!node.scale.empty()) {
        s[0][0] = node.scale[0];
        s[1][1] = node.scale[1];
        s[2][2] = node.scale[2];
    }
    glm::dmat4 t(1.0);
    if (!node.translation.empty())
        t[3] = glm::dvec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
    return t * r * s;
}

glm::vec3 safeNormalize(glm::dvec3 v)
{
    double len = glm::length(v);
    if (!(len > 0.0) || !std::isfinite(len)) return {0.0f, 0.0f, 1.0f};
    return glm::vec3(v / len);
}

// A line primitive's vertex sequence as segments, two sequence elements each, following the glTF spec
// (section 3.7.2.1): LINES pairs elements (a trailing odd one is left out), LINE_STRIP joins neighbours
// and LINE_LOOP adds the closing segment last. Fewer than two elements make no segment.
std::vector<uint32_t> lineSegments(int mode, const std::vector<uint32_t>& sequence)
{
    std::vector<uint32_t> segments;
    size_t n = sequence.size();
    if (n < 2) return segments;
    if (mode == TINYGLTF_MODE_LINE) {
        segments.assign(sequence.begin(), sequence.begin() + ptrdiff_t(n / 2 * 2));
        return segments;
    }
    segments.reserve(2 * n);
    for (size_t i = 0; i + 1 < n; ++i) segments.insert(segments.end(), {sequence[i], sequence[i + 1]});
    if (mode == TINYGLTF_MODE_LINE_LOOP) segments.insert(segments.end(), {sequence[n - 1], sequence[0]});
    return segments;
}

}  // namespace sr::gltf
