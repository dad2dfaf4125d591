// SPDX-License-Identifier: Apache-2.0
// Writes a big binary PLY for the loading benchmarks (BENCHMARKS.md, "Loading big meshes") by
// tiling copies of a mesh on a square grid in the xz plane until the triangle count is reached:
//   ao_tile_mesh ../shared/data/meshes/refined_elephant.off 30000000 /tmp/elephant-30M.ply
// Without the input file (no ../shared), the built-in `displaced` scene's floor is tiled instead.
// The output is a benchmark input, not a test file: write it to /tmp, never into the repository.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include "ao/core/error.h"
#include "ao/io/mesh_io.h"
#include "ao/scene/procedural.h"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::cerr << "usage: ao_tile_mesh INPUT_MESH TRIANGLES OUTPUT.ply\n";
    return 2;
  }
  try {
    const std::filesystem::path input = argv[1];
    const long long wanted = std::atoll(argv[2]);
    ao::Scene scene = std::filesystem::exists(input) ? ao::load_scene_file(input) : ao::make_builtin_scene("displaced");
    ao::Mesh mesh = scene.meshes[0];
    for (std::size_t m = 1; m < scene.meshes.size(); ++m) ao::append_mesh(mesh, scene.meshes[m]);
    const long long per_copy = static_cast<long long>(mesh.triangle_count());
    const long long copies = std::max(1LL, (wanted + per_copy - 1) / per_copy);
    const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(copies))));
    const ao::Bounds3 b = mesh.bounds();
    const ao::Vec3 step = b.extent() * 1.1f;
    const long long vertices = copies * static_cast<long long>(mesh.positions.size());
    const long long triangles = copies * per_copy;
    std::ofstream out(argv[3], std::ios::binary);
    out << "ply\nformat binary_little_endian 1.0\ncomment " << copies << " copies of " << input.filename().string() << "\nelement vertex "
        << vertices << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << triangles
        << "\nproperty list uchar int vertex_indices\nend_header\n";
    for (long long c = 0; c < copies; ++c) {
      const ao::Vec3 shift{step.x * static_cast<float>(c % side), 0.0f, step.z * static_cast<float>(c / side)};
      for (const ao::Vec3& p : mesh.positions) {
        const float xyz[3] = {p.x + shift.x, p.y + shift.y, p.z + shift.z};
        out.write(reinterpret_cast<const char*>(xyz), sizeof xyz);
      }
    }
    for (long long c = 0; c < copies; ++c) {
      const auto base = static_cast<std::uint32_t>(c * static_cast<long long>(mesh.positions.size()));
      for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
        char face[13];
        face[0] = 3;
        const std::uint32_t idx[3] = {mesh.indices[t] + base, mesh.indices[t + 1] + base, mesh.indices[t + 2] + base};
        std::memcpy(face + 1, idx, 12);
        out.write(face, 13);
      }
    }
    if (!out) throw ao::SystemError(std::string("cannot write ") + argv[3]);
    std::printf("%s: %lld copies, %lld vertices, %lld triangles\n", argv[3], copies, vertices, triangles);
  } catch (const std::exception& e) {
    std::cerr << "ao_tile_mesh: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
