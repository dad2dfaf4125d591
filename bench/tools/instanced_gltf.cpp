// SPDX-License-Identifier: Apache-2.0
// Generator of the instanced glTF of BENCHMARKS.md ("Instanced glTF"): one mesh used by COUNT
// nodes, so that loading it with and without LoadOptions::flatten_instances compares copies with
// Embree instances.
//   ao_instanced_gltf MESH COUNT OUT.gltf
// MESH is any mesh ao reads (its first mesh is used; hand.off of ../shared has 2,390 triangles), or
// "sphere" for the built-in sphere-on-plane's sphere. The nodes stand on a square grid with a
// spacing of 1.1 mesh diagonals, each turned about y by its own angle and scaled by 0.8 to 1.2, so
// that no two are the same copy. The buffer is embedded as a base64 data URI. Write OUT to /tmp:
// the file is not part of the repository.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/io/mesh_io.h"
#include "ao/scene/procedural.h"

namespace {

std::string base64(const std::string& bytes) {
  static const char* const kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < 3; ++k) v = v << 8 | (k < n ? static_cast<std::uint8_t>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k) out += k <= n ? kAlphabet[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fputs("usage: ao_instanced_gltf MESH|sphere COUNT OUT.gltf\n", stderr);
    return 2;
  }
  try {
    const std::string input = argv[1];
    const ao::Scene scene = input == "sphere" ? ao::make_builtin_scene("sphere-on-plane") : ao::load_scene_file(input, {.flatten_instances = true});
    const ao::Mesh& m = input == "sphere" ? scene.meshes.back() : scene.meshes.front();
    const long count = std::atol(argv[2]);
    if (count < 1) throw std::runtime_error("COUNT must be at least 1");

    std::string bytes;
    for (const ao::Vec3& p : m.positions) bytes.append(reinterpret_cast<const char*>(&p), sizeof p);
    const std::size_t index_offset = bytes.size();
    bytes.append(reinterpret_cast<const char*>(m.indices.data()), m.indices.size() * sizeof(std::uint32_t));
    const ao::Bounds3 b = m.bounds();
    using nlohmann::json;
    json nodes = json::array(), roots = json::array();
    const auto side = static_cast<long>(std::ceil(std::sqrt(static_cast<double>(count))));
    const double spacing = 1.1 * b.diagonal();
    for (long i = 0; i < count; ++i) {
      const double angle = 0.5 * static_cast<double>(i), scale = 0.8 + 0.4 * static_cast<double>(i % 7) / 6.0;
      nodes.push_back({{"name", "copy" + std::to_string(i)},
                       {"mesh", 0},
                       {"translation", {spacing * static_cast<double>(i % side), 0.0, spacing * static_cast<double>(i / side)}},
                       {"rotation", {0.0, std::sin(angle), 0.0, std::cos(angle)}},
                       {"scale", {scale, scale, scale}}});
      roots.push_back(i);
    }
    const json j = {
        {"asset", {{"version", "2.0"}, {"generator", "ao_instanced_gltf"}}},
        {"scene", 0},
        {"scenes", json::array({{{"nodes", roots}}})},
        {"nodes", nodes},
        {"meshes", json::array({{{"name", m.name.empty() ? "mesh" : m.name},
                                 {"primitives", json::array({{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}})}}})},
        {"buffers", json::array({{{"byteLength", bytes.size()}, {"uri", "data:application/octet-stream;base64," + base64(bytes)}}})},
        {"bufferViews", json::array({{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", index_offset}},
                                     {{"buffer", 0}, {"byteOffset", index_offset}, {"byteLength", bytes.size() - index_offset}}})},
        {"accessors", json::array({{{"bufferView", 0},
                                    {"componentType", 5126},
                                    {"count", m.positions.size()},
                                    {"type", "VEC3"},
                                    {"min", {b.lo.x, b.lo.y, b.lo.z}},
                                    {"max", {b.hi.x, b.hi.y, b.hi.z}}},
                                   {{"bufferView", 1}, {"componentType", 5125}, {"count", m.indices.size()}, {"type", "SCALAR"}}})}};
    std::ofstream(argv[3]) << j.dump();
    std::printf("%s: %ld instances of a %zu-triangle mesh (%zu triangles flattened)\n", argv[3], count, m.triangle_count(),
                static_cast<std::size_t>(count) * m.triangle_count());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ao_instanced_gltf: %s\n", e.what());
    return 1;
  }
}
