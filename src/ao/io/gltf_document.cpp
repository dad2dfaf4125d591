// SPDX-License-Identifier: Apache-2.0
// glTF load-modify-save with tinygltf (see gltf_document.h). The structure is checked by
// check_gltf before tinygltf parses anything (tinygltf trusts counts, offsets and nesting), and
// every accessor read here is bounds-checked again, so a hostile file ends in one InputError.
// tinygltf's file system is replaced: it may read files of the input's own folder and nothing
// else, and it cannot write at all (the GLB is serialised to memory and written atomically here).
#include "ao/io/gltf_document.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "ao/core/error.h"
#include "ao/io/asset_path.h"
#include "ao/io/atomic_file.h"
#include "ao/io/gltf_check.h"
#include "ao/io/gltf_document_internal.h"
#include "ao/io/io_error_internal.h"
#include "ao/io/tiny_gltf_internal.h"
#include "ao/version.h"

namespace ao {

namespace fs = std::filesystem;

namespace {

using io_detail::fail;
using io_detail::one_line;  // tinygltf's messages are several lines

// --- tinygltf's file system: the input's folder, read only ------------------------------------

struct Folder {
  fs::path dir;  ///< asset_folder of the input: what its references must lie inside
};

/// True when `file` is a regular file in the asset's folder or below it (after resolving "..",
/// "." and symbolic links).
bool in_folder(const std::string& file, const Folder& f) {
  std::error_code ec;
  return fs::is_regular_file(fs::path(file), ec) && inside_folder(fs::path(file), f.dir);
}

bool fs_exists(const std::string& file, void* user) { return in_folder(file, *static_cast<Folder*>(user)); }
std::string fs_expand(const std::string& file, void*) { return file; }  // no ~ or $VAR expansion
bool fs_read(std::vector<unsigned char>* out, std::string* err, const std::string& file, void* user) {
  if (!in_folder(file, *static_cast<Folder*>(user))) {
    if (err) *err = "not a file in the glTF's folder";
    return false;
  }
  std::ifstream in(file, std::ios::binary);
  out->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (in.bad()) {
    if (err) *err = "cannot be read";
    return false;
  }
  return true;
}
bool fs_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err = "ao does not write through tinygltf";
  return false;
}

/// Image "loader": images in a bufferView stay there; bytes of a data: URI or a file are kept
/// encoded in Image::image (moved into the binary chunk after the load).
bool keep_encoded(tinygltf::Image* image, const int, std::string*, std::string*, int, int, const unsigned char* bytes, int size, void*) {
  if (image->bufferView >= 0) return true;
  image->image.assign(bytes, bytes + size);
  image->as_is = true;
  return true;
}

std::string sniff_mime(const std::vector<unsigned char>& b) {
  if (b.size() >= 8 && std::memcmp(b.data(), "\x89PNG\r\n\x1a\n", 8) == 0) return "image/png";
  if (b.size() >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF) return "image/jpeg";
  return {};
}

// --- matrices (column-major, as glTF) ----------------------------------------------------------

using Mat4 = std::array<double, 16>;
constexpr Mat4 kIdentity{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

Mat4 mul(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a[k * 4 + row] * b[c * 4 + k];
      r[c * 4 + row] = s;
    }
  return r;
}

/// The node's local matrix: `matrix`, or T * R * S (glTF 2.0 spec, "Transformations").
Mat4 local_matrix(const tinygltf::Node& n) {
  if (n.matrix.size() == 16) {
    Mat4 m;
    std::copy(n.matrix.begin(), n.matrix.end(), m.begin());
    return m;
  }
  Mat4 t = kIdentity, r = kIdentity, s = kIdentity;
  if (n.translation.size() == 3) t[12] = n.translation[0], t[13] = n.translation[1], t[14] = n.translation[2];
  if (n.scale.size() == 3) s[0] = n.scale[0], s[5] = n.scale[1], s[10] = n.scale[2];
  if (n.rotation.size() == 4) {
    double x = n.rotation[0], y = n.rotation[1], z = n.rotation[2], w = n.rotation[3];
    const double len = std::sqrt(x * x + y * y + z * z + w * w);
    if (len > 0) x /= len, y /= len, z /= len, w /= len;  // the spec asks for unit quaternions; exporters round
    r = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),     0,
         2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),     0,
         2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y), 0,
         0,                       0,                       0,                       1};
  }
  return mul(t, mul(r, s));
}

/// Cofactor matrix of the upper 3x3 (the inverse transpose times the determinant): maps normals;
/// its scale does not matter, normals are normalised after.
std::array<double, 9> normal_matrix(const Mat4& m, double& det) {
  auto a = [&](int row, int col) { return m[col * 4 + row]; };
  std::array<double, 9> c{};  // row-major
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) {
      const int r1 = (row + 1) % 3, r2 = (row + 2) % 3, c1 = (col + 1) % 3, c2 = (col + 2) % 3;
      c[row * 3 + col] = a(r1, c1) * a(r2, c2) - a(r1, c2) * a(r2, c1);
    }
  det = a(0, 0) * c[0] + a(0, 1) * c[1] + a(0, 2) * c[2];
  return c;
}

}  // namespace

// --- the document -------------------------------------------------------------------------------

// Hidden, as the tinygltf model it holds (tiny_gltf_internal.h): nothing outside libao sees either.
struct __attribute__((visibility("hidden"))) GltfDocument::Impl {
  fs::path path;
  int uv_set = 0;
  tinygltf::Model model;
  std::vector<std::string> warnings;
  /// Instances of the displayed scene: (node, mesh, world matrix), depth first.
  struct Instance {
    int node, mesh;
    Mat4 world;
  };
  std::vector<Instance> instances;
  std::map<int, int> map_texture;  ///< mesh -> texture index of its AO map
  bool materials_done = false;
  std::vector<std::string> save_warnings;

  std::string uv_attribute() const { return "TEXCOORD_" + std::to_string(uv_set); }
  static bool is_triangles(const tinygltf::Primitive& p) { return io_detail::gltf_is_triangles(p); }
  bool bakes(const tinygltf::Primitive& p) const { return is_triangles(p) && p.attributes.count("POSITION") && p.attributes.count(uv_attribute()); }

  std::string label(int mesh) const { return io_detail::gltf_mesh_label(model, mesh); }
  std::string plain_name(int mesh) const { return io_detail::gltf_plain_name(model, mesh); }
  int map_sampler = -1;  ///< The sampler of the AO maps, added with the first.

  /// A node that places triangles needs a transform ao can trace (transform_problem: finite, not
  /// flattening, not squashing beyond kMaxSquashRatio), the rule of validate_and_prepare for
  /// instances and of load_scene_file for every glTF node.
  void check_transform(int node, int mesh, const Mat4& world) const {
    bool triangles = false;
    for (const tinygltf::Primitive& p : model.meshes[static_cast<std::size_t>(mesh)].primitives) triangles = triangles || is_triangles(p);
    if (!triangles) return;
    const tinygltf::Node& n = model.nodes[static_cast<std::size_t>(node)];
    const std::string label = n.name.empty() ? "node " + std::to_string(node) : "node '" + one_line(n.name.substr(0, 64)) + "'";
    for (double v : world)
      if (!std::isfinite(v)) fail(path, label + " has a non-finite transform");
    // The rule of every loader (transform_problem), on the float matrix the scene will carry.
    const auto f = [&](int i) { return static_cast<float>(world[static_cast<std::size_t>(i)]); };
    const Affine3 t{{f(0), f(1), f(2)}, {f(4), f(5), f(6)}, {f(8), f(9), f(10)}, {f(12), f(13), f(14)}};
    if (const std::string problem = transform_problem(t); !problem.empty()) fail(path, label + " " + problem);
  }

  void collect_instances() {
    std::vector<int> roots;
    const int scene = model.defaultScene >= 0 ? model.defaultScene : (model.scenes.empty() ? -1 : 0);
    if (scene >= 0 && static_cast<std::size_t>(scene) < model.scenes.size()) {
      roots = model.scenes[static_cast<std::size_t>(scene)].nodes;
    } else {
      // No scene: every node that is nobody's child (check_gltf made the graph a forest).
      std::vector<bool> child(model.nodes.size(), false);
      for (const tinygltf::Node& n : model.nodes)
        for (int c : n.children)
          if (c >= 0 && static_cast<std::size_t>(c) < child.size()) child[static_cast<std::size_t>(c)] = true;
      for (std::size_t i = 0; i < child.size(); ++i)
        if (!child[i]) roots.push_back(static_cast<int>(i));
    }
    // Explicit stack: check_gltf bounds the depth, but nothing here needs recursion.
    std::vector<std::pair<int, Mat4>> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, kIdentity});
    while (!stack.empty()) {
      const auto [node, parent] = stack.back();
      stack.pop_back();
      if (node < 0 || static_cast<std::size_t>(node) >= model.nodes.size()) fail(path, "scene uses node " + std::to_string(node) + ", the file has " + std::to_string(model.nodes.size()));
      const tinygltf::Node& n = model.nodes[static_cast<std::size_t>(node)];
      const Mat4 world = mul(parent, local_matrix(n));
      if (n.mesh >= 0) {
        if (static_cast<std::size_t>(n.mesh) >= model.meshes.size()) fail(path, "node " + std::to_string(node) + " uses mesh " + std::to_string(n.mesh) + ", the file has " + std::to_string(model.meshes.size()));
        check_transform(node, n.mesh, world);
        instances.push_back({node, n.mesh, world});
      }
      for (auto c = n.children.rbegin(); c != n.children.rend(); ++c) stack.push_back({*c, world});
    }
  }

  /// All buffers into buffer 0 (GLB has one binary chunk), each at a multiple of 16 bytes so every
  /// accessor keeps its alignment; images given by URI are appended as bufferViews.
  void merge_buffers() {
    if (model.buffers.size() == 1) {
      model.buffers[0].uri.clear();  // a lone buffer becomes the binary chunk as it is, without a copy
    } else {
      merge_several_buffers();
    }
    embed_images();
  }
  void merge_several_buffers() {
    std::vector<unsigned char> bin;
    std::vector<std::size_t> base;
    for (const tinygltf::Buffer& b : model.buffers) {
      bin.resize((bin.size() + 15) / 16 * 16, 0);
      base.push_back(bin.size());
      bin.insert(bin.end(), b.data.begin(), b.data.end());
    }
    for (tinygltf::BufferView& v : model.bufferViews) {
      if (v.buffer < 0 || static_cast<std::size_t>(v.buffer) >= base.size()) fail(path, "a bufferView uses a missing buffer");
      v.byteOffset += base[static_cast<std::size_t>(v.buffer)];
      v.buffer = 0;
    }
    tinygltf::Buffer merged;
    if (!model.buffers.empty()) {
      merged.name = model.buffers.front().name;
      merged.extras = model.buffers.front().extras;
      merged.extensions = model.buffers.front().extensions;
    }
    merged.data = std::move(bin);
    model.buffers.assign(1, std::move(merged));
  }
  void embed_images() {
    if (model.buffers.empty()) model.buffers.emplace_back();
    for (std::size_t i = 0; i < model.images.size(); ++i) {
      tinygltf::Image& im = model.images[i];
      if (im.bufferView >= 0) continue;
      if (im.image.empty()) {
        warnings.push_back("image " + std::to_string(i) + " ('" + one_line(im.uri.substr(0, 60)) + "') could not be read beside the input; its URI is kept as is");
        continue;
      }
      if (im.mimeType.empty()) im.mimeType = sniff_mime(im.image);
      if (im.mimeType.empty()) im.mimeType = "image/png";
      im.bufferView = append_view(im.image.data(), im.image.size(), 0);
      im.image.clear();
      im.uri.clear();
      im.as_is = false;
    }
  }

  int append_view(const unsigned char* data, std::size_t size, int target) {
    std::vector<unsigned char>& bin = model.buffers.at(0).data;
    bin.resize((bin.size() + 15) / 16 * 16, 0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = bin.size();
    v.byteLength = size;
    v.target = target;
    bin.insert(bin.end(), data, data + size);
    model.bufferViews.push_back(std::move(v));
    return static_cast<int>(model.bufferViews.size() - 1);
  }

  /// Occlusion textures onto the materials of baked primitives (gltf_document.h, add_occlusion_map).
  void assign_materials() {
    if (materials_done || map_texture.empty()) return;
    materials_done = true;
    io_detail::assign_occlusion_maps(model, map_texture, uv_set, save_warnings);
  }
};

GltfDocument::GltfDocument(const fs::path& path, int uv_set, const fs::path& asset_root) : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  d.path = path;
  d.uv_set = uv_set;
  if (uv_set < 0) fail(path, "--uv-set " + std::to_string(uv_set) + " asked for, UV sets count from 0");
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) fail(path, fs::exists(path, ec) ? "is not a regular file" : "no such file");
  std::string err, warn;
  bool ok = false;
  Folder folder;
  folder.dir = asset_folder(path, asset_root);
  const fs::path base = fs::weakly_canonical(fs::absolute(path, ec).parent_path(), ec);
  {
    // The file's bytes live only for the parse: tinygltf copies the buffers out of them.
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(path, "cannot be opened for reading");
    const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) fail(path, "cannot be read");
    if (data.empty()) fail(path, "the file is empty");
    if (data.size() > std::numeric_limits<std::uint32_t>::max()) fail(path, "larger than 4 GB, more than glTF and GLB can address");
    // Structure, sizes, nesting and file references first: tinygltf trusts them.
    const GltfSize size = check_gltf(path, data, asset_root);
    if (!size.indices_without_data.empty())
      fail(path, size.indices_without_data + " has no bufferView (its indices would all be 0, no triangle); ao rewrites only documents whose indices are stored");

    tinygltf::TinyGLTF loader;
    loader.SetFsCallbacks({&fs_exists, &fs_expand, &fs_read, &fs_write, &folder});
    loader.SetImageLoader(&keep_encoded, nullptr);
    try {
      if (data.size() >= 4 && data.compare(0, 4, "glTF") == 0)
        ok = loader.LoadBinaryFromMemory(&d.model, &err, &warn, reinterpret_cast<const unsigned char*>(data.data()), static_cast<unsigned>(data.size()), base.string());
      else
        ok = loader.LoadASCIIFromString(&d.model, &err, &warn, data.data(), static_cast<unsigned>(data.size()), base.string());
    } catch (const std::bad_alloc&) {
      throw SystemError(path.string() + ": out of memory while reading the glTF document");
    } catch (const std::exception& e) {
      fail(path, "malformed glTF (" + one_line(e.what()) + ")");
    }
  }
  if (!ok) fail(path, "malformed glTF (" + one_line(err.empty() ? warn : err) + ")");
  // Indices this code follows (check_gltf covers the node graph, buffers, views and accessors).
  for (std::size_t m = 0; m < d.model.meshes.size(); ++m)
    for (std::size_t p = 0; p < d.model.meshes[m].primitives.size(); ++p) {
      const int mat = d.model.meshes[m].primitives[p].material;
      if (mat < -1 || mat >= static_cast<int>(d.model.materials.size()))
        fail(path, "mesh " + d.label(static_cast<int>(m)) + " primitive " + std::to_string(p) + " uses material " + std::to_string(mat) + ", the file has " +
                       std::to_string(d.model.materials.size()));
    }
  d.merge_buffers();
  d.collect_instances();

  // The UV set: a set above 0 that no primitive has is a mistake worth stopping on, as in load_scene_file.
  if (uv_set > 0) {
    int sets = 0;
    bool found = false;
    for (const tinygltf::Mesh& m : d.model.meshes)
      for (const tinygltf::Primitive& p : m.primitives) {
        while (p.attributes.count("TEXCOORD_" + std::to_string(sets))) ++sets;
        found = found || p.attributes.count(d.uv_attribute());
      }
    if (!found) fail(path, "has " + std::to_string(sets) + " UV set" + (sets == 1 ? "" : "s") + ", --uv-set " + std::to_string(uv_set) + " asked for");
  }
  if (instanced_meshes(false).empty()) fail(path, "the file has no triangles in its scene");
}

GltfDocument::~GltfDocument() = default;
GltfDocument::GltfDocument(GltfDocument&&) noexcept = default;
GltfDocument& GltfDocument::operator=(GltfDocument&&) noexcept = default;

const std::vector<std::string>& GltfDocument::warnings() const { return impl_->warnings; }

std::vector<int> GltfDocument::instanced_meshes(bool with_uv_set) const {
  const Impl& d = *impl_;
  std::set<int> used;
  for (const Impl::Instance& i : d.instances) used.insert(i.mesh);
  std::vector<int> out;
  for (int m : used) {
    const auto& prims = d.model.meshes[static_cast<std::size_t>(m)].primitives;
    if (std::any_of(prims.begin(), prims.end(), [&](const tinygltf::Primitive& p) {
          return with_uv_set ? d.bakes(p) : Impl::is_triangles(p) && p.attributes.count("POSITION");
        }))
      out.push_back(m);
  }
  return out;
}

std::string GltfDocument::mesh_label(int mesh) const { return impl_->label(mesh); }

int GltfDocument::instance_count(int mesh) const {
  return static_cast<int>(std::count_if(impl_->instances.begin(), impl_->instances.end(), [&](const Impl::Instance& i) { return i.mesh == mesh; }));
}

std::size_t GltfDocument::world_triangle_count() const {
  const Impl& d = *impl_;
  std::size_t n = 0;
  for (const Impl::Instance& i : d.instances)
    for (const tinygltf::Primitive& p : d.model.meshes[static_cast<std::size_t>(i.mesh)].primitives) {
      if (!Impl::is_triangles(p) || !p.attributes.count("POSITION")) continue;
      const int a = p.indices >= 0 ? p.indices : p.attributes.at("POSITION");
      if (a < 0 || static_cast<std::size_t>(a) >= d.model.accessors.size()) continue;
      const std::size_t count = d.model.accessors[static_cast<std::size_t>(a)].count;
      n += p.mode == TINYGLTF_MODE_TRIANGLE_STRIP || p.mode == TINYGLTF_MODE_TRIANGLE_FAN ? (count > 2 ? count - 2 : 0) : count / 3;
    }
  return n;
}

std::size_t GltfDocument::world_vertex_count() const {
  const Impl& d = *impl_;
  std::size_t n = 0;
  for (const Impl::Instance& i : d.instances)
    for (const tinygltf::Primitive& p : d.model.meshes[static_cast<std::size_t>(i.mesh)].primitives) {
      if (!Impl::is_triangles(p) || !p.attributes.count("POSITION")) continue;
      const int a = p.attributes.at("POSITION");
      if (a >= 0 && static_cast<std::size_t>(a) < d.model.accessors.size()) n += d.model.accessors[static_cast<std::size_t>(a)].count;
    }
  return n;
}

GltfWorldScene GltfDocument::world_scene(int baked_mesh) const {
  const Impl& d = *impl_;
  GltfWorldScene out;
  out.scene.name = d.path.filename().string();
  std::set<int> seen;
  // Each primitive is read once per world scene, then transformed per instance.
  std::map<std::pair<int, int>, Mesh> local;
  for (const Impl::Instance& inst : d.instances) {
    const bool first = seen.insert(inst.mesh).second;
    const auto& prims = d.model.meshes[static_cast<std::size_t>(inst.mesh)].primitives;
    double det = 0;
    const std::array<double, 9> nm = normal_matrix(inst.world, det);
    const Mat4& w = inst.world;
    for (std::size_t pi = 0; pi < prims.size(); ++pi) {
      const tinygltf::Primitive& p = prims[pi];
      if (!Impl::is_triangles(p) || !p.attributes.count("POSITION")) continue;
      const auto key = std::make_pair(inst.mesh, static_cast<int>(pi));
      auto it = local.find(key);
      if (it == local.end()) it = local.emplace(key, io_detail::read_gltf_primitive(d.model, d.path, inst.mesh, static_cast<int>(pi), inst.mesh == baked_mesh ? d.uv_attribute() : std::string())).first;
      Mesh m;
      m.name = it->second.name;
      m.positions.reserve(it->second.positions.size() + kVertexPadding);
      for (const Vec3& v : it->second.positions) {
        const double x = v.x, y = v.y, z = v.z;
        m.positions.push_back({static_cast<float>(w[0] * x + w[4] * y + w[8] * z + w[12]), static_cast<float>(w[1] * x + w[5] * y + w[9] * z + w[13]),
                               static_cast<float>(w[2] * x + w[6] * y + w[10] * z + w[14])});
      }
      m.normals.reserve(it->second.normals.size());
      for (const Vec3& n : it->second.normals) {
        const double x = n.x, y = n.y, z = n.z;
        Vec3 t{static_cast<float>(nm[0] * x + nm[1] * y + nm[2] * z), static_cast<float>(nm[3] * x + nm[4] * y + nm[5] * z),
               static_cast<float>(nm[6] * x + nm[7] * y + nm[8] * z)};
        if (det < 0) t = t * -1.0f;  // the cofactor matrix carries the determinant's sign
        m.normals.push_back(t);
      }
      m.indices = it->second.indices;
      if (det < 0)  // a mirroring transform reverses the winding (glTF 2.0 spec, "Transformations")
        for (std::size_t k = 0; k + 2 < m.indices.size(); k += 3) std::swap(m.indices[k + 1], m.indices[k + 2]);
      if (first && inst.mesh == baked_mesh) m.uvs = it->second.uvs;
      out.scene.meshes.push_back(std::move(m));
      out.sources.push_back({inst.mesh, static_cast<int>(pi), inst.node, first});
    }
  }
  // validate_and_prepare drops meshes left without triangles: names that tell the instances apart
  // (also in its warnings) keep track of the sources.
  std::vector<std::string> names;
  std::map<std::string, std::size_t> index_of;
  for (std::size_t i = 0; i < out.scene.meshes.size(); ++i) {
    names.push_back(out.scene.meshes[i].name);
    const GltfWorldScene::Source& s = out.sources[i];
    const std::string& node = d.model.nodes[static_cast<std::size_t>(s.node)].name;
    out.scene.meshes[i].name = names[i] + (names[i].empty() ? "" : " ") + "[mesh " + std::to_string(s.mesh) + ", primitive " + std::to_string(s.primitive) + ", node " +
                               std::to_string(s.node) + (node.empty() ? "" : " " + node) + "]";
    index_of[out.scene.meshes[i].name] = i;
  }
  validate_and_prepare(out.scene);
  std::vector<GltfWorldScene::Source> kept;
  for (Mesh& m : out.scene.meshes) {
    const std::size_t i = index_of.at(m.name);
    kept.push_back(out.sources[i]);
    m.name = names[i];
  }
  out.sources = std::move(kept);
  return out;
}

void GltfDocument::add_occlusion_map(int mesh, const std::string& png) {
  Impl& d = *impl_;
  if (d.materials_done) throw std::logic_error("add_occlusion_map after save_glb");
  tinygltf::Image im;
  im.name = "ao " + d.plain_name(mesh);
  im.mimeType = "image/png";
  im.bufferView = d.append_view(reinterpret_cast<const unsigned char*>(png.data()), png.size(), 0);
  d.model.images.push_back(std::move(im));
  if (d.map_sampler < 0) {
    tinygltf::Sampler s;  // linear, mipmapped: the map is smooth data
    s.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
    s.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
    s.wrapS = s.wrapT = TINYGLTF_TEXTURE_WRAP_REPEAT;
    d.model.samplers.push_back(s);
    d.map_sampler = static_cast<int>(d.model.samplers.size() - 1);
  }
  tinygltf::Texture t;
  t.source = static_cast<int>(d.model.images.size() - 1);
  t.sampler = d.map_sampler;
  d.model.textures.push_back(std::move(t));
  d.map_texture[mesh] = static_cast<int>(d.model.textures.size() - 1);
}

void GltfDocument::set_vertex_ao(int mesh, int primitive, const std::vector<float>& ao) {
  Impl& d = *impl_;
  tinygltf::Primitive& p = d.model.meshes.at(static_cast<std::size_t>(mesh)).primitives.at(static_cast<std::size_t>(primitive));
  std::vector<float> rgb;
  rgb.reserve(ao.size() * 3);
  for (float v : ao) rgb.insert(rgb.end(), {v, v, v});  // linear: glTF multiplies the base colour by COLOR_0
  tinygltf::Accessor a;
  a.bufferView = d.append_view(reinterpret_cast<const unsigned char*>(rgb.data()), rgb.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER);
  a.byteOffset = 0;
  a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  a.count = ao.size();
  a.type = TINYGLTF_TYPE_VEC3;
  d.model.accessors.push_back(std::move(a));
  if (p.attributes.count("COLOR_0"))
    d.save_warnings.push_back("mesh " + d.label(mesh) + " primitive " + std::to_string(primitive) + ": its COLOR_0 is replaced by the per-vertex AO");
  p.attributes["COLOR_0"] = static_cast<int>(d.model.accessors.size() - 1);
}

std::vector<std::string> GltfDocument::save_glb(const fs::path& path) {
  Impl& d = *impl_;
  d.assign_materials();
  if (d.model.buffers.at(0).data.size() > std::numeric_limits<std::uint32_t>::max() - 1024)
    fail(path, "the binary chunk would be " + std::to_string(d.model.buffers[0].data.size()) + " bytes, more than GLB's 4 GB");
  if (d.model.asset.generator.empty()) d.model.asset.generator = "ao bake " AO_VERSION_STRING;
  std::ostringstream glb;
  tinygltf::TinyGLTF writer;
  Folder nowhere;  // an empty folder: the writer may read nothing either
  writer.SetFsCallbacks({&fs_exists, &fs_expand, &fs_read, &fs_write, &nowhere});
  if (!writer.WriteGltfSceneToStream(&d.model, glb, false, true)) throw SystemError(path.string() + ": cannot serialise the glTF document");
  const std::string bytes = glb.str();
  write_bytes_atomically(path, bytes);
  std::vector<std::string> w = std::move(d.save_warnings);
  d.save_warnings.clear();
  return w;
}

}  // namespace ao
