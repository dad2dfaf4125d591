// SPDX-License-Identifier: Apache-2.0
#include "ao/io/ply_export.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "ao/core/error.h"
#include "ao/io/atomic_file.h"

namespace ao {

namespace {

template <class T>
void put(std::string& out, T v) {
  static_assert(std::endian::native == std::endian::little, "PLY writer assumes a little-endian host");
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  out.append(b, sizeof(T));
}

}  // namespace

void write_vertex_ao_ply(const std::filesystem::path& path, const Scene& scene, const std::vector<float>& values) {
  if (values.size() != scene.vertex_count())
    throw InputError(path.string() + ": " + std::to_string(values.size()) + " AO values for " + std::to_string(scene.vertex_count()) + " vertices");
  std::string body;
  body.reserve(scene.vertex_count() * 31 + scene.triangle_count() * 13);
  std::size_t index = 0;
  for (const Mesh& m : scene.meshes)
    for (std::size_t v = 0; v < m.positions.size(); ++v) {
      const float value = values[index++];
      const Vec3 p = m.positions[v], n = m.normals.empty() ? Vec3{0, 0, 1} : m.normals[v];
      for (float f : {p.x, p.y, p.z, n.x, n.y, n.z}) put(body, f);
      const float c = std::isfinite(value) ? std::clamp(value, 0.0f, 1.0f) : 0.0f;
      const auto g = static_cast<std::uint8_t>(std::lround(c * 255.0f));
      for (int k = 0; k < 3; ++k) put(body, g);
      put(body, value);
    }
  std::uint32_t base = 0;
  for (const Mesh& m : scene.meshes) {
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      put(body, std::uint8_t{3});
      for (int k = 0; k < 3; ++k) put(body, static_cast<std::int32_t>(base + m.indices[3 * t + k]));
    }
    base += static_cast<std::uint32_t>(m.positions.size());
  }
  const std::string header = "ply\nformat binary_little_endian 1.0\ncomment ambient occlusion baked by ao: quality = V in [0,1], colour = V as grey\n"
                             "element vertex " + std::to_string(scene.vertex_count()) +
                             "\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
                             "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty float quality\n"
                             "element face " + std::to_string(scene.triangle_count()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  write_file_atomically(path, [&](const std::filesystem::path& temp) {
    std::FILE* f = open_temporary(temp, path);
    const bool written = std::fwrite(header.data(), 1, header.size(), f) == header.size() && std::fwrite(body.data(), 1, body.size(), f) == body.size();
    if (!written) {
      std::fclose(f);
      throw SystemError(path.string() + ": cannot write");
    }
    close_temporary(f, path);
  });
}

}  // namespace ao
