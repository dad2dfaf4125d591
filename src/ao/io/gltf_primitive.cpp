// SPDX-License-Identifier: Apache-2.0
// A glTF primitive's accessors read into a Mesh (gltf_document_internal.h). tinygltf checks
// little of what it parses (check_gltf covers the structure first), so every accessor, bufferView
// and sparse block read here is bounds-checked again: a hostile file ends in one InputError.
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>

#include "ao/io/gltf_document_internal.h"
#include "ao/io/io_error_internal.h"

namespace ao::io_detail {

namespace fs = std::filesystem;

namespace {

/// The accessors of one document, read with every offset, stride and count checked.
struct AccessorReader {
  const tinygltf::Model& model;
  const fs::path& path;

  // Reads accessor `index` as `comps` floats per element. Integer components count as glTF
  // specifies: normalized ones scaled to [0, 1] or [-1, 1], others as their value. Sparse values
  // are applied; an accessor without a bufferView starts as zeros.
  std::vector<float> read_floats(int index, int comps, const std::string& what) const {
    const tinygltf::Accessor& a = accessor(index, what);
    if (tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type)) != comps)
      fail(path, what + ": accessor " + std::to_string(index) + " has " + std::to_string(tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type))) +
                     " components, " + std::to_string(comps) + " expected");
    std::vector<float> out(a.count * static_cast<std::size_t>(comps), 0.0f);
    auto convert = [&](const unsigned char* src, int type, float* dst, int n) {
      for (int k = 0; k < n; ++k) {
        float v = 0;
        switch (type) {
          case TINYGLTF_COMPONENT_TYPE_FLOAT: std::memcpy(&v, src + 4 * k, 4); break;
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: v = src[k]; if (a.normalized) v /= 255.0f; break;
          case TINYGLTF_COMPONENT_TYPE_BYTE: v = static_cast<float>(static_cast<std::int8_t>(src[k])); if (a.normalized) v = std::max(v / 127.0f, -1.0f); break;
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { std::uint16_t u; std::memcpy(&u, src + 2 * k, 2); v = u; if (a.normalized) v /= 65535.0f; break; }
          case TINYGLTF_COMPONENT_TYPE_SHORT: { std::int16_t s; std::memcpy(&s, src + 2 * k, 2); v = s; if (a.normalized) v = std::max(v / 32767.0f, -1.0f); break; }
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { std::uint32_t u; std::memcpy(&u, src + 4 * k, 4); v = static_cast<float>(u); break; }
          default: fail(path, what + ": accessor " + std::to_string(index) + " has component type " + std::to_string(type) + ", not a vertex attribute type");
        }
        dst[k] = v;
      }
    };
    const std::size_t elem = static_cast<std::size_t>(comps) * component_size(a.componentType, index, what);
    if (a.bufferView >= 0) {
      const auto [data, stride] = view_range(a, index, elem, what);
      for (std::size_t i = 0; i < a.count; ++i) convert(data + i * stride, a.componentType, &out[i * static_cast<std::size_t>(comps)], comps);
    }
    if (a.sparse.isSparse && a.sparse.count > 0) {
      const std::size_t n = static_cast<std::size_t>(a.sparse.count);
      const std::vector<std::uint32_t> at = read_indices_raw(a.sparse.indices.bufferView, static_cast<std::size_t>(a.sparse.indices.byteOffset), a.sparse.indices.componentType, n, index, what);
      const unsigned char* values = raw_view(a.sparse.values.bufferView, static_cast<std::size_t>(a.sparse.values.byteOffset), n * elem, index, what);
      for (std::size_t k = 0; k < n; ++k) {
        if (at[k] >= a.count) fail(path, what + ": sparse index " + std::to_string(at[k]) + " of accessor " + std::to_string(index) + " is past its " + std::to_string(a.count) + " elements");
        convert(values + k * elem, a.componentType, &out[at[k] * static_cast<std::size_t>(comps)], comps);
      }
    }
    return out;
  }

  std::vector<std::uint32_t> read_indices(int index, const std::string& what) const {
    const tinygltf::Accessor& a = accessor(index, what);
    if (a.type != TINYGLTF_TYPE_SCALAR) fail(path, what + ": index accessor " + std::to_string(index) + " is not SCALAR");
    if (a.sparse.isSparse) fail(path, what + ": sparse index accessor " + std::to_string(index) + " is not supported");
    if (a.bufferView < 0) return std::vector<std::uint32_t>(a.count, 0);
    const std::size_t elem = component_size(a.componentType, index, what);
    const auto [data, stride] = view_range(a, index, elem, what);
    std::vector<std::uint32_t> out(a.count);
    for (std::size_t i = 0; i < a.count; ++i) out[i] = load_index(data + i * stride, a.componentType, index, what);
    return out;
  }

  const tinygltf::Accessor& accessor(int index, const std::string& what) const {
    if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size()) fail(path, what + " uses accessor " + std::to_string(index) + ", the file has " + std::to_string(model.accessors.size()));
    return model.accessors[static_cast<std::size_t>(index)];
  }
  std::size_t component_size(int type, int index, const std::string& what) const {
    const int s = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(type));
    if (s <= 0 || s > 4) fail(path, what + ": accessor " + std::to_string(index) + " has an unsupported component type " + std::to_string(type));
    return static_cast<std::size_t>(s);
  }
  std::uint32_t load_index(const unsigned char* p, int type, int index, const std::string& what) const {
    switch (type) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return *p;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { std::uint16_t u; std::memcpy(&u, p, 2); return u; }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { std::uint32_t u; std::memcpy(&u, p, 4); return u; }
      default: fail(path, what + ": index accessor " + std::to_string(index) + " is not unsigned byte, short or int");
    }
  }
  /// `bytes` bytes at `offset` in buffer view `view`, checked against the view and its buffer.
  const unsigned char* raw_view(int view, std::size_t offset, std::size_t bytes, int index, const std::string& what) const {
    if (view < 0 || static_cast<std::size_t>(view) >= model.bufferViews.size()) fail(path, what + ": accessor " + std::to_string(index) + " uses a missing bufferView");
    const tinygltf::BufferView& v = model.bufferViews[static_cast<std::size_t>(view)];
    if (v.buffer < 0 || static_cast<std::size_t>(v.buffer) >= model.buffers.size()) fail(path, what + ": bufferView " + std::to_string(view) + " uses a missing buffer");
    const std::size_t size = model.buffers[static_cast<std::size_t>(v.buffer)].data.size();
    if (v.byteOffset > size || v.byteLength > size - v.byteOffset || offset > v.byteLength || bytes > v.byteLength - offset)
      fail(path, what + ": accessor " + std::to_string(index) + " reads past the end of bufferView " + std::to_string(view));
    return model.buffers[static_cast<std::size_t>(v.buffer)].data.data() + v.byteOffset + offset;
  }
  std::pair<const unsigned char*, std::size_t> view_range(const tinygltf::Accessor& a, int index, std::size_t elem, const std::string& what) const {
    if (static_cast<std::size_t>(a.bufferView) >= model.bufferViews.size()) fail(path, what + ": accessor " + std::to_string(index) + " uses a missing bufferView");
    const std::size_t stride = model.bufferViews[static_cast<std::size_t>(a.bufferView)].byteStride ? model.bufferViews[static_cast<std::size_t>(a.bufferView)].byteStride : elem;
    if (stride < elem) fail(path, what + ": accessor " + std::to_string(index) + " has a byteStride smaller than its elements");
    if (a.count == 0) return {nullptr, stride};
    if (a.count - 1 > (std::numeric_limits<std::size_t>::max() - elem) / stride) fail(path, what + ": accessor " + std::to_string(index) + " is too long");
    return {raw_view(a.bufferView, a.byteOffset, (a.count - 1) * stride + elem, index, what), stride};
  }
  std::vector<std::uint32_t> read_indices_raw(int view, std::size_t offset, int type, std::size_t n, int index, const std::string& what) const {
    const std::size_t elem = component_size(type, index, what);
    const unsigned char* p = raw_view(view, offset, n * elem, index, what);
    std::vector<std::uint32_t> out(n);
    for (std::size_t i = 0; i < n; ++i) out[i] = load_index(p + i * elem, type, index, what);
    return out;
  }
};

}  // namespace

std::string gltf_mesh_label(const tinygltf::Model& model, int mesh) {
  const std::string& n = model.meshes[static_cast<std::size_t>(mesh)].name;
  return n.empty() ? "mesh " + std::to_string(mesh) : "'" + n + "'";
}

std::string gltf_plain_name(const tinygltf::Model& model, int mesh) {
  const std::string& n = model.meshes[static_cast<std::size_t>(mesh)].name;
  return n.empty() ? "mesh " + std::to_string(mesh) : n;
}

Mesh read_gltf_primitive(const tinygltf::Model& model, const fs::path& path, int mesh, int prim, const std::string& uv_attribute) {
  const AccessorReader reader{model, path};
  const tinygltf::Primitive& p = model.meshes[static_cast<std::size_t>(mesh)].primitives[static_cast<std::size_t>(prim)];
  const std::string what = "mesh " + gltf_mesh_label(model, mesh) + " primitive " + std::to_string(prim);
  Mesh m;
  m.name = model.meshes[static_cast<std::size_t>(mesh)].name;
  const std::vector<float> pos = reader.read_floats(p.attributes.at("POSITION"), 3, what + " POSITION");
  const std::size_t n = pos.size() / 3;
  m.positions.reserve(n + kVertexPadding);  // see kVertexPadding
  for (std::size_t v = 0; v < n; ++v) m.positions.push_back({pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]});
  if (const auto it = p.attributes.find("NORMAL"); it != p.attributes.end()) {
    const std::vector<float> nor = reader.read_floats(it->second, 3, what + " NORMAL");
    if (nor.size() != pos.size()) fail(path, what + ": NORMAL and POSITION have different counts");
    m.normals.reserve(n);
    for (std::size_t v = 0; v < n; ++v) m.normals.push_back({nor[3 * v], nor[3 * v + 1], nor[3 * v + 2]});
  }
  if (const auto it = p.attributes.find(uv_attribute); !uv_attribute.empty() && it != p.attributes.end()) {
    const std::vector<float> uv = reader.read_floats(it->second, 2, what + " " + uv_attribute);
    if (uv.size() / 2 != n) fail(path, what + ": " + uv_attribute + " and POSITION have different counts");
    m.uvs.reserve(n);
    for (std::size_t v = 0; v < n; ++v) m.uvs.push_back({uv[2 * v], 1.0f - uv[2 * v + 1]});  // glTF's v runs down the image
  }
  std::vector<std::uint32_t> idx;
  if (p.indices >= 0) {
    idx = reader.read_indices(p.indices, what + " indices");
  } else {
    idx.resize(n);
    for (std::size_t v = 0; v < n; ++v) idx[v] = static_cast<std::uint32_t>(v);
  }
  for (std::uint32_t i : idx)
    if (i >= n) fail(path, what + " uses vertex " + std::to_string(i) + ", it has " + std::to_string(n));
  if (p.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
    for (std::size_t k = 0; k + 2 < idx.size(); ++k) {
      const bool odd = k % 2;  // every other strip triangle is listed clockwise
      m.indices.insert(m.indices.end(), {idx[k + (odd ? 1 : 0)], idx[k + (odd ? 0 : 1)], idx[k + 2]});
    }
  } else if (p.mode == TINYGLTF_MODE_TRIANGLE_FAN) {
    for (std::size_t k = 1; k + 1 < idx.size(); ++k) m.indices.insert(m.indices.end(), {idx[k], idx[k + 1], idx[0]});
  } else {
    idx.resize(idx.size() / 3 * 3);
    m.indices = std::move(idx);
  }
  return m;
}

}  // namespace ao::io_detail
