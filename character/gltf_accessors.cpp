#include <cmath>
#include <cstring>
#include <initializer_list>

#include "character/gltf_character.hpp"
#include "character/gltf_detail.hpp"
#include "runtime/errors/import_error.hpp"

namespace marionette::character::detail {

namespace {
// Where an accessor's elements lie, every byte of them checked to be inside its
// buffer view and the view inside its buffer.
struct Located {
    const unsigned char* data = nullptr;
    std::size_t count = 0;
    std::size_t stride = 0;
    int component_type = 0;
    bool normalized = false;
};

const char* type_name(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR: return "SCALAR";
        case TINYGLTF_TYPE_VEC2: return "VEC2";
        case TINYGLTF_TYPE_VEC3: return "VEC3";
        case TINYGLTF_TYPE_VEC4: return "VEC4";
        case TINYGLTF_TYPE_MAT4: return "MAT4";
        default: return "another type";
    }
}

const char* component_name(int c) {
    switch (c) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: return "byte";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "unsigned byte";
        case TINYGLTF_COMPONENT_TYPE_SHORT: return "short";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "unsigned short";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "unsigned int";
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return "float";
        default: return "an unknown component type";
    }
}

std::size_t component_bytes(int c) {
    switch (c) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
        default: return 4;
    }
}

Located locate(const tinygltf::Model& m, int index, const std::string& what, const std::string& file, int type,
               int components, std::initializer_list<int> component_types) {
    const std::string name = "accessor " + std::to_string(index) + " (" + what + ")";
    if (index < 0 || static_cast<std::size_t>(index) >= m.accessors.size())
        throw ImportError(file, 0, what + ": accessor index " + std::to_string(index) + " is out of range (the file has " +
                                       std::to_string(m.accessors.size()) + ")");
    const tinygltf::Accessor& a = m.accessors[static_cast<std::size_t>(index)];
    if (a.sparse.isSparse) throw ImportError(file, 0, name + ": sparse accessors are not supported");
    if (a.type != type)
        throw ImportError(file, 0, name + ": expected type " + type_name(type) + ", found " + type_name(a.type));
    bool ok = false;
    for (int c : component_types) ok = ok || a.componentType == c;
    if (!ok) throw ImportError(file, 0, name + ": component type " + component_name(a.componentType) + " is not accepted here");
    if (a.bufferView < 0 || static_cast<std::size_t>(a.bufferView) >= m.bufferViews.size())
        throw ImportError(file, 0, name + ": no buffer view (index " + std::to_string(a.bufferView) + ")");
    const tinygltf::BufferView& v = m.bufferViews[static_cast<std::size_t>(a.bufferView)];
    if (v.buffer < 0 || static_cast<std::size_t>(v.buffer) >= m.buffers.size())
        throw ImportError(file, 0, name + ": buffer view " + std::to_string(a.bufferView) + " names a missing buffer");
    const std::vector<unsigned char>& buffer = m.buffers[static_cast<std::size_t>(v.buffer)].data;
    if (v.byteOffset > buffer.size() || v.byteLength > buffer.size() - v.byteOffset)
        throw ImportError(file, 0, name + ": buffer view " + std::to_string(a.bufferView) + " (" +
                                       std::to_string(v.byteLength) + " bytes at " + std::to_string(v.byteOffset) +
                                       ") runs past its buffer's " + std::to_string(buffer.size()) + " bytes");
    const std::size_t element = component_bytes(a.componentType) * static_cast<std::size_t>(components);
    const std::size_t stride = v.byteStride ? v.byteStride : element;
    if (stride < element) throw ImportError(file, 0, name + ": byte stride " + std::to_string(stride) + " is smaller than an element");
    if (a.count == 0) throw ImportError(file, 0, name + ": count is 0");
    // count ≤ (byteLength − byteOffset − element) / stride + 1, without overflow.
    if (a.byteOffset > v.byteLength || v.byteLength - a.byteOffset < element ||
        a.count - 1 > (v.byteLength - a.byteOffset - element) / stride)
        throw ImportError(file, 0, name + ": " + std::to_string(a.count) + " elements at byte " +
                                       std::to_string(a.byteOffset) + " do not fit in buffer view " +
                                       std::to_string(a.bufferView) + " (" + std::to_string(v.byteLength) + " bytes)");
    return {buffer.data() + v.byteOffset + a.byteOffset, a.count, stride, a.componentType, a.normalized};
}

float float_at(const unsigned char* p) {
    float f;
    std::memcpy(&f, p, sizeof f);
    return f;
}

std::uint32_t uint_at(const unsigned char* p, int component_type) {
    if (component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) return *p;
    if (component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
        std::uint16_t v;
        std::memcpy(&v, p, sizeof v);
        return v;
    }
    std::uint32_t v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

template <std::size_t N>
std::vector<std::array<float, N>> read_floats(const tinygltf::Model& m, int accessor, const std::string& what,
                                              const std::string& file, int type) {
    const Located l = locate(m, accessor, what, file, type, static_cast<int>(N), {TINYGLTF_COMPONENT_TYPE_FLOAT});
    std::vector<std::array<float, N>> out(l.count);
    for (std::size_t i = 0; i < l.count; ++i)
        for (std::size_t c = 0; c < N; ++c) {
            const float f = float_at(l.data + i * l.stride + c * 4);
            if (!std::isfinite(f))
                throw ImportError(file, 0, "accessor " + std::to_string(accessor) + " (" + what + "): element " +
                                               std::to_string(i) + " is not a finite number");
            out[i][c] = f;
        }
    return out;
}
}  // namespace

std::vector<std::array<float, 3>> read_vec3(const tinygltf::Model& m, int accessor, const std::string& what,
                                            const std::string& file) {
    return read_floats<3>(m, accessor, what, file, TINYGLTF_TYPE_VEC3);
}

std::vector<std::array<float, 16>> read_mat4(const tinygltf::Model& m, int accessor, const std::string& what,
                                             const std::string& file) {
    return read_floats<16>(m, accessor, what, file, TINYGLTF_TYPE_MAT4);
}

std::vector<std::array<std::uint16_t, 4>> read_joints(const tinygltf::Model& m, int accessor, const std::string& what,
                                                      const std::string& file) {
    const Located l = locate(m, accessor, what, file, TINYGLTF_TYPE_VEC4, 4,
                             {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
    const std::size_t bytes = component_bytes(l.component_type);
    std::vector<std::array<std::uint16_t, 4>> out(l.count);
    for (std::size_t i = 0; i < l.count; ++i)
        for (std::size_t c = 0; c < 4; ++c)
            out[i][c] = static_cast<std::uint16_t>(uint_at(l.data + i * l.stride + c * bytes, l.component_type));
    return out;
}

std::vector<std::array<float, 4>> read_weights(const tinygltf::Model& m, int accessor, const std::string& what,
                                               const std::string& file) {
    const Located l = locate(m, accessor, what, file, TINYGLTF_TYPE_VEC4, 4,
                             {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                              TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
    if (l.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT && !l.normalized)
        throw ImportError(file, 0, "accessor " + std::to_string(accessor) + " (" + what +
                                       "): integer weights must be normalized");
    if (l.component_type == TINYGLTF_COMPONENT_TYPE_FLOAT) {
        std::vector<std::array<float, 4>> out = read_floats<4>(m, accessor, what, file, TINYGLTF_TYPE_VEC4);
        for (std::size_t i = 0; i < out.size(); ++i)
            for (float w : out[i])
                if (w < 0.0f)
                    throw ImportError(file, 0, "accessor " + std::to_string(accessor) + " (" + what + "): element " +
                                                   std::to_string(i) + " has a negative weight");
        return out;
    }
    const std::size_t bytes = component_bytes(l.component_type);
    const float scale = l.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ? 1.0f / 255.0f : 1.0f / 65535.0f;
    std::vector<std::array<float, 4>> out(l.count);
    for (std::size_t i = 0; i < l.count; ++i)
        for (std::size_t c = 0; c < 4; ++c)
            out[i][c] = static_cast<float>(uint_at(l.data + i * l.stride + c * bytes, l.component_type)) * scale;
    return out;
}

std::vector<std::uint32_t> read_indices(const tinygltf::Model& m, int accessor, const std::string& what,
                                        const std::string& file) {
    const Located l = locate(m, accessor, what, file, TINYGLTF_TYPE_SCALAR, 1,
                             {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                              TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT});
    if (l.count > gltf_limits::kMaxIndices)
        throw ImportError(file, 0, "accessor " + std::to_string(accessor) + " (" + what + "): " + std::to_string(l.count) +
                                       " indices, over the limit of " + std::to_string(gltf_limits::kMaxIndices));
    std::vector<std::uint32_t> out(l.count);
    for (std::size_t i = 0; i < l.count; ++i) out[i] = uint_at(l.data + i * l.stride, l.component_type);
    return out;
}

}  // namespace marionette::character::detail
