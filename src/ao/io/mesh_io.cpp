// SPDX-License-Identifier: Apache-2.0
// Mesh loading: the file's format chosen by content and extension, and each handed to its reader.
// OFF, PLY and one-mesh OBJ files have readers of our own (off_reader.h, ply_reader.h,
// obj_reader.h); other OBJ files, STL and glTF/GLB go through assimp (assimp_reader.cpp) after a
// check of our own (obj_check.h, stl_check.h, gltf_check.h), because assimp 5.2's readers fail the
// SPEC's bad-input rules. Every reader ends in validate_and_prepare. Found by tests and by
// fuzzing (fuzz/).
#include "ao/io/mesh_io.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cstdint>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>

#include "ao/core/error.h"
#include "ao/core/memory.h"
#include "ao/io/assimp_internal.h"
#include "ao/io/gltf_check.h"
#include "ao/io/io_error_internal.h"
#include "ao/io/obj_check.h"
#include "ao/io/obj_reader.h"
#include "ao/io/off_reader.h"
#include "ao/io/ply_reader.h"
#include "ao/io/stl_check.h"

namespace ao {
namespace {

namespace fs = std::filesystem;
using io_detail::fail;
using io_detail::uv_set_error;

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

/// A file's whole content, mapped read-only: big meshes are hundreds of MB, and a mapping costs
/// neither a copy nor memory of our own (the pages are the page cache's).
class MappedFile {
 public:
  /// Checks that the path is a readable, non-empty regular file and maps it.
  explicit MappedFile(const fs::path& path) {
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (!fs::exists(st)) fail(path, "no such file");
    if (fs::is_directory(st)) fail(path, "is a directory, not a mesh file");
    if (!fs::is_regular_file(st)) fail(path, "is not a regular file");
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) fail(path, "cannot be opened for reading");
    struct stat info {};
    if (::fstat(fd, &info) != 0) {
      ::close(fd);
      fail(path, "cannot read its size");
    }
    size_ = static_cast<std::size_t>(info.st_size);
    if (size_ == 0) {
      ::close(fd);
      fail(path, "the file is empty");
    }
    void* addr = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
    ::close(fd);  // the mapping keeps the file
    if (addr == MAP_FAILED) throw SystemError(path.string() + ": cannot map the file into memory (" + std::to_string(size_) + " bytes)");
    data_ = static_cast<const char*>(addr);
  }
  ~MappedFile() { ::munmap(const_cast<char*>(data_), size_); }
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  std::string_view view() const { return {data_, size_}; }

 private:
  const char* data_ = nullptr;
  std::size_t size_ = 0;
};

/// Refuses, before assimp reads anything, a glTF whose meshes (shared accessors, meshes used by
/// many nodes) expand beyond the memory available: assimp's copy of every mesh, its world-space
/// copies when flattening, and the Scene's arrays (positions, normals and UVs 32 bytes per vertex,
/// 12 per triangle). Instancing keeps each mesh once, and an instance costs next to nothing.
/// Flattening costs assimp about 7 times GltfSize's bytes of the world-space copies (pre-transform,
/// then joining each copy's vertices, and a heap block per face): measured, a 7,442-triangle grid
/// used by 300 nodes (2.2 M triangles, 121 MB of GltfSize bytes) needs between 854 and 884 MB
/// (it fails to load under an address-space limit of 920 MB, of which 854 MB were available at
/// the check, and loads under 950 MB); 8 times keeps a margin (1.03 GB), where twice those bytes
/// let such a load pass the check and then fail. Files of many small meshes need less: a
/// 100k-instance file reached 8.1 GB when flattened (issue 27), about twice its bytes, so the
/// bound refuses such a file at about a quarter of the memory it would need.
void check_gltf_memory(const fs::path& path, const GltfSize& size, const LoadOptions& options) {
  const GltfSize::Counts& placed = options.flatten_instances ? size.world : size.stored;
  const std::uint64_t scene_bytes = placed.vertices * 32 + placed.triangles * 12;
  const std::uint64_t assimp_factor = options.flatten_instances ? 8 : 2;
  const std::uint64_t bytes = 2 * size.stored.bytes + assimp_factor * placed.bytes + scene_bytes;
  check_memory(bytes, path.string() + ": loading " + std::to_string(placed.triangles) + " triangles (" + std::to_string(size.uses) +
                          " mesh uses" + (options.flatten_instances ? ", each a copy" : "") + ")");
}

}  // namespace

Scene load_scene_file(const fs::path& path, const LoadOptions& options) {
  if (options.uv_set < 0) fail(path, "--uv-set " + std::to_string(options.uv_set) + " asked for, UV sets count from 0");
  // The whole file is mapped up front: our readers and checks need it, and the size checks of
  // counts need its length.
  const MappedFile file(path);
  const std::string_view data = file.view();
  const std::string ext = lower(path.extension().string());
  if (ext == ".off" || looks_like_off(data)) {
    if (options.uv_set > 0) fail(path, uv_set_error(0, options.uv_set));  // OFF has no UVs
    return read_off(path, data);
  }
  if (ext == ".ply" || looks_like_ply(data)) {
    if (!looks_like_ply(data)) fail(path, "not a PLY file: it does not start with 'ply'");
    try {
      Scene scene = read_ply(path, data);
      if (options.uv_set > 0) fail(path, uv_set_error(scene.meshes[0].uvs.empty() ? 0 : 1, options.uv_set));
      validate_and_prepare(scene);
      return scene;
    } catch (const std::bad_alloc&) {
      // The reader allocates no more than the checked counts need, so this is a real shortage.
      throw SystemError(path.string() + ": out of memory loading the mesh (" + std::to_string(data.size()) + " bytes of file)");
    }
  }
  const bool is_gltf = looks_like_gltf(path, data);
  if (is_gltf) check_gltf_memory(path, check_gltf(path, data, options.asset_root), options);
  else if (ext == ".obj") {
    if (std::optional<Scene> scene = read_simple_obj(path, data, options)) return std::move(*scene);
    check_obj(path, data, options.asset_root);
  }
  else if (is_ascii_stl(data)) check_ascii_stl(path, data);
  else if (ext == ".stl") check_binary_stl(path, data);
  return io_detail::read_with_assimp(path, data, options, is_gltf);
}

}  // namespace ao
