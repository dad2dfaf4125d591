// SPDX-License-Identifier: Apache-2.0
// Meshes through assimp (see assimp_internal.h): OBJ files beyond obj_reader's shape, STL and
// glTF/GLB, each after a check of our own (obj_check.h, stl_check.h, gltf_check.h), because
// assimp 5.2's readers fail the SPEC's bad-input rules (measured with libassimp 5.2.5):
//  - OBJ: `vt nan` is taken as a UV; one out-of-range UV index drops every UV of the file.
//  - ASCII STL: a file cut inside a facet loads the facets before the cut (stl_check.cpp).
//  - glTF/GLB: stack overflows on deep JSON or node chains, GLB chunk lengths trusted before the
//    file size, out-of-range indices and bad accessors read silently.
// The raw data assimp returns is checked here (non-finite data, index ranges, empty faces, node
// transforms) before post-processing can merge, hide or trip over it; validate_and_prepare then
// runs on the Scene.
#include <assimp/DefaultIOSystem.h>
#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <new>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "ao/core/error.h"
#include "ao/io/asset_path.h"
#include "ao/io/assimp_internal.h"
#include "ao/io/io_error_internal.h"
#include "ao/io/ply_reader.h"

namespace ao::io_detail {
namespace {

namespace fs = std::filesystem;

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

Vec3 material_albedo(const aiMaterial& material, bool format_has_materials) {
  const Vec3 fallback = Mesh{}.albedo;
  if (!format_has_materials) return fallback;
  aiString name;
  // assimp invents "DefaultMaterial" (grey 0.6, or white) for files that name no material; that is
  // not the author's colour, so the Mesh default applies.
  if (material.Get(AI_MATKEY_NAME, name) == aiReturn_SUCCESS && std::string_view(name.C_Str()) == AI_DEFAULT_MATERIAL_NAME) return fallback;
  aiColor4D c;
  // glTF's baseColorFactor arrives as BASE_COLOR (and usually also DIFFUSE); prefer it where present.
  if (material.Get(AI_MATKEY_BASE_COLOR, c) == aiReturn_SUCCESS || material.Get(AI_MATKEY_COLOR_DIFFUSE, c) == aiReturn_SUCCESS)
    return {c.r, c.g, c.b};
  return fallback;
}

/// Running out of memory inside assimp: the sizes were checked against the file before (PLY, OFF),
/// so this is the machine's limit, a SystemError (exit 3), not bad input.
[[noreturn]] void out_of_memory(const fs::path& path) {
  throw SystemError(path.string() + ": out of memory while reading the mesh");
}

std::string mesh_label(const aiMesh& m, unsigned index) {
  return m.mName.length > 0 ? "mesh '" + std::string(m.mName.C_Str()) + "'" : "mesh " + std::to_string(index);
}

/// Faces without indices, and non-finite values (of the UV set that is loaded), checked before JoinIdenticalVertices can merge or hide them (it joins NaN
/// vertices with their neighbours, which turns the error into a "degenerate triangle").
void check_raw_meshes(const fs::path& path, const aiScene& scene, unsigned uv_set) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh& mesh = *scene.mMeshes[m];
    const std::string where = scene.mNumMeshes > 1 ? " of " + mesh_label(mesh, m) : "";
    // ValidateDataStructure lets faces with no indices through, and assimp's Triangulate step then
    // aborts the process on an assertion (seen on a corrupted binary PLY), so they stop here.
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices == 0 || face.mIndices == nullptr) fail(path, "face " + std::to_string(f) + where + " has no vertices");
      for (unsigned k = 0; k < face.mNumIndices; ++k)
        if (face.mIndices[k] >= mesh.mNumVertices)
          fail(path, "face " + std::to_string(f) + where + " uses vertex " + std::to_string(face.mIndices[k]) + ", the mesh has " +
                         std::to_string(mesh.mNumVertices));
    }
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D p = mesh.mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        fail(path, "vertex " + std::to_string(v) + where + " has a non-finite coordinate");
      if (mesh.HasNormals()) {
        const aiVector3D n = mesh.mNormals[v];
        if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z))
          fail(path, "normal " + std::to_string(v) + where + " is not finite");
      }
      if (uv_set < AI_MAX_NUMBER_OF_TEXTURECOORDS && mesh.HasTextureCoords(uv_set)) {
        const aiVector3D t = mesh.mTextureCoords[uv_set][v];
        if (!std::isfinite(t.x) || !std::isfinite(t.y))
          fail(path, "UV " + std::to_string(v) + (uv_set ? " of UV set " + std::to_string(uv_set) : std::string()) + where + " is not finite");
      }
    }
  }
}

Affine3 to_affine(const aiMatrix4x4& m) {
  // aiMatrix4x4 is row-major with the translation in the fourth column (a4, b4, c4).
  return {{m.a1, m.b1, m.c1}, {m.a2, m.b2, m.c2}, {m.a3, m.b3, m.c3}, {m.a4, m.b4, m.c4}};
}

/// Every use of a mesh by the node tree: the mesh and its node's world transform (the product of
/// the transforms from the root down), in depth-first node order. Iterative: the depth is bounded
/// by check_gltf, but an explicit stack does not depend on that.
struct MeshUse {
  unsigned mesh;
  aiMatrix4x4 world;
  const aiNode* node;
};
std::vector<MeshUse> mesh_uses(const aiScene& scene) {
  std::vector<MeshUse> uses;
  if (scene.mRootNode == nullptr) return uses;
  std::vector<std::pair<const aiNode*, aiMatrix4x4>> stack{{scene.mRootNode, scene.mRootNode->mTransformation}};
  while (!stack.empty()) {
    const auto [node, world] = stack.back();
    stack.pop_back();
    for (unsigned i = 0; i < node->mNumMeshes; ++i)
      if (node->mMeshes[i] < scene.mNumMeshes) uses.push_back({node->mMeshes[i], world, node});
    // Children pushed in reverse so that they are visited in the file's order.
    for (unsigned c = node->mNumChildren; c-- > 0;)
      if (node->mChildren[c] != nullptr) stack.emplace_back(node->mChildren[c], world * node->mChildren[c]->mTransformation);
  }
  return uses;
}

/// Every node that places triangles has a finite transform that does not flatten them
/// (determinant 0 makes every triangle degenerate, a mesh used once as much as an instance): the
/// rule validate_and_prepare applies to instances, here for every use, flattened or not.
void check_node_transforms(const fs::path& path, const aiScene& scene) {
  for (const MeshUse& u : mesh_uses(scene)) {
    if ((scene.mMeshes[u.mesh]->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0 && scene.mMeshes[u.mesh]->mPrimitiveTypes != 0) continue;
    std::string name;
    for (char c : std::string_view(u.node->mName.C_Str()).substr(0, 64)) name += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
    const std::string label = name.empty() ? "a node" : "node '" + name + "'";
    if (const std::string problem = transform_problem(to_affine(u.world)); !problem.empty()) fail(path, label + " " + problem);
  }
}

/// True when the node tree uses some mesh more than once.
bool uses_a_mesh_twice(const aiScene& scene) {
  std::vector<unsigned> refs(scene.mNumMeshes, 0);
  for (const MeshUse& u : mesh_uses(scene))
    if (++refs[u.mesh] > 1) return true;
  return false;
}

/// One assimp mesh as a Mesh, in the coordinates the file gives it.
Mesh convert_mesh(const aiScene& ai, const aiMesh& in, unsigned uv_set, bool format_has_materials) {
  Mesh mesh;
  mesh.name = in.mName.C_Str();
  mesh.positions.reserve(in.mNumVertices + kVertexPadding);  // see kVertexPadding
  for (unsigned v = 0; v < in.mNumVertices; ++v) mesh.positions.push_back({in.mVertices[v].x, in.mVertices[v].y, in.mVertices[v].z});
  if (in.HasNormals()) {
    mesh.normals.reserve(in.mNumVertices);
    for (unsigned v = 0; v < in.mNumVertices; ++v) mesh.normals.push_back({in.mNormals[v].x, in.mNormals[v].y, in.mNormals[v].z});
  }
  if (uv_set < AI_MAX_NUMBER_OF_TEXTURECOORDS && in.HasTextureCoords(uv_set)) {
    mesh.uvs.reserve(in.mNumVertices);
    for (unsigned v = 0; v < in.mNumVertices; ++v) mesh.uvs.push_back({in.mTextureCoords[uv_set][v].x, in.mTextureCoords[uv_set][v].y});
  }
  mesh.indices.reserve(static_cast<std::size_t>(in.mNumFaces) * 3);
  for (unsigned f = 0; f < in.mNumFaces; ++f) {
    const aiFace& face = in.mFaces[f];
    if (face.mNumIndices != 3) continue;  // SortByPType leaves triangles only; be safe anyway
    mesh.indices.insert(mesh.indices.end(), face.mIndices, face.mIndices + 3);
  }
  if (in.mMaterialIndex < ai.mNumMaterials) mesh.albedo = material_albedo(*ai.mMaterials[in.mMaterialIndex], format_has_materials);
  return mesh;
}

/// The meshes of a node tree that uses some mesh several times: a mesh used once is moved to
/// world space (normals through the cofactor matrix, so they stay on the side the transformed
/// winding faces); a mesh used more often is kept once in object space, and each use becomes an
/// Instance named after its node. Meshes no node uses are left out (as pre-transforming does).
void convert_instanced(const aiScene& ai, unsigned uv_set, bool format_has_materials, Scene& scene) {
  const std::vector<MeshUse> uses = mesh_uses(ai);
  std::vector<unsigned> refs(ai.mNumMeshes, 0);
  for (const MeshUse& u : uses) ++refs[u.mesh];
  std::vector<std::uint32_t> index(ai.mNumMeshes, SceneObject::kNoInstance);
  for (const MeshUse& u : uses) {
    const aiMesh& in = *ai.mMeshes[u.mesh];
    if ((in.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) continue;
    const Affine3 t = to_affine(u.world);
    if (refs[u.mesh] == 1) {
      Mesh mesh = convert_mesh(ai, in, uv_set, format_has_materials);
      const Affine3 n = cofactor(t);
      for (Vec3& p : mesh.positions) p = t.point(p);
      for (Vec3& v : mesh.normals) v = normalize(n.vector(v));
      scene.meshes.push_back(std::move(mesh));
      continue;
    }
    if (index[u.mesh] == SceneObject::kNoInstance) {
      index[u.mesh] = static_cast<std::uint32_t>(scene.meshes.size());
      scene.meshes.push_back(convert_mesh(ai, in, uv_set, format_has_materials));
    }
    scene.instances.push_back({index[u.mesh], t, u.node->mName.C_Str()});
  }
}

/// One assimp step (reading or post-processing) with its failures in ao's words: running out of
/// memory is the machine's limit, anything else the file's fault. `ext`: the file's extension when
/// the step reads it, empty for a post-processing step.
template <class Step>
const aiScene* assimp_step(const fs::path& path, Assimp::Importer& importer, std::string_view ext, Step&& step) {
  const aiScene* result = nullptr;
  try {
    result = step();
  } catch (const std::bad_alloc&) {
    out_of_memory(path);
  } catch (const std::exception& e) {
    fail(path, explain_assimp_error(e.what()));
  }
  if (result != nullptr) return result;
  const std::string error = importer.GetErrorString();
  if (assimp_ran_out_of_memory(error)) out_of_memory(path);
  // "No suitable reader" for a file named like a format assimp reads means damaged content.
  if (error.find("No suitable reader found") != std::string::npos && !ext.empty() && importer.IsExtensionSupported(std::string(ext)))
    fail(path, "malformed or truncated " + printable(ext.substr(1)) + " file: its content is not recognised");
  fail(path, explain_assimp_error(error));
}

/// assimp's file system for a glTF: the files it references are named by URIs, percent-encoded
/// ("m%2Ebin" is m.bin; glTF 2.0 spec, "URIs"), which assimp 5.2 opens as written. The part of a
/// name after the model's folder is decoded (check_gltf has checked that the decoded file lies in
/// the asset's folder); the model itself and names elsewhere are opened as given.
class GltfUriFileSystem : public Assimp::DefaultIOSystem {
 public:
  explicit GltfUriFileSystem(const fs::path& model) : model_(model.string()), folder_(model.parent_path().string()) {}
  bool Exists(const char* file) const override { return DefaultIOSystem::Exists(decoded(file).c_str()); }
  Assimp::IOStream* Open(const char* file, const char* mode) override { return DefaultIOSystem::Open(decoded(file).c_str(), mode); }

 private:
  std::string decoded(const char* file) const {
    const std::string name(file);
    if (name == model_) return name;
    const std::size_t from = !folder_.empty() && name.starts_with(folder_) ? folder_.size() : 0;
    return name.substr(0, from) + percent_decode(std::string_view(name).substr(from));
  }
  std::string model_, folder_;
};

/// The UV set asked for: a set above 0 that no mesh has is a mistake worth stopping on (set 0
/// missing is the "no UVs" case the callers report in their own terms).
void check_uv_set(const fs::path& path, const aiScene& ai, int asked) {
  const auto uv_set = static_cast<unsigned>(asked);
  if (uv_set == 0) return;
  unsigned sets = 0;
  bool found = false;
  for (unsigned m = 0; m < ai.mNumMeshes; ++m) {
    sets = std::max(sets, ai.mMeshes[m]->GetNumUVChannels());
    found = found || (uv_set < AI_MAX_NUMBER_OF_TEXTURECOORDS && ai.mMeshes[m]->HasTextureCoords(uv_set));
  }
  if (!found) fail(path, uv_set_error(sets, asked));
}
}  // namespace

Scene read_with_assimp(const fs::path& path, std::string_view data, const LoadOptions& options, bool is_gltf) {
  const std::string ext = lower(path.extension().string());
  const bool is_stl = ext == ".stl" || data.starts_with("solid");
  // STL, PLY and OFF carry no materials; assimp's stand-in colour for them is white.
  const bool format_has_materials = !(is_stl || looks_like_ply(data));

  Assimp::Importer importer;
  if (is_gltf) importer.SetIOHandler(new GltfUriFileSystem(path));  // the importer owns it
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  // STL stores one normal per facet, which would keep every triangle's corners apart; dropping them
  // lets JoinIdenticalVertices weld the soup, and validate_and_prepare makes smooth normals.
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS);

  // Read with validation only, check the raw data, then post-process.
  const aiScene* raw = assimp_step(path, importer, ext, [&] { return importer.ReadFile(path.string(), aiProcess_ValidateDataStructure); });
  check_raw_meshes(path, *raw, static_cast<unsigned>(options.uv_set));
  if (is_gltf) check_node_transforms(path, *raw);
  // A glTF whose node tree uses a mesh several times keeps the mesh once, with instances
  // (convert_instanced); everything else is pre-transformed into world space by assimp, which
  // also joins the meshes that share a material and vertex format into one.
  const bool instanced = is_gltf && !options.flatten_instances && uses_a_mesh_twice(*raw);

  // No GenNormals / GenSmoothNormals (validate_and_prepare makes normals), and no FindInvalidData or
  // FixInfacingNormals, which would change the data without telling anyone.
  unsigned steps = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType;
  if (!instanced) steps |= aiProcess_PreTransformVertices;
  if (is_stl) steps |= aiProcess_RemoveComponent;
  const aiScene* ai = assimp_step(path, importer, {}, [&] { return importer.ApplyPostProcessing(steps); });
  check_uv_set(path, *ai, options.uv_set);

  const unsigned uv_set = static_cast<unsigned>(options.uv_set);
  Scene scene;
  scene.name = path.filename().string();
  if (instanced) {
    convert_instanced(*ai, uv_set, format_has_materials, scene);
  } else {
    for (unsigned m = 0; m < ai->mNumMeshes; ++m) {
      const aiMesh& in = *ai->mMeshes[m];
      if ((in.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) continue;
      scene.meshes.push_back(convert_mesh(*ai, in, uv_set, format_has_materials));
    }
  }
  if (scene.meshes.empty()) fail(path, "the file has no triangles");
  validate_and_prepare(scene);
  return scene;
}

}  // namespace ao::io_detail
