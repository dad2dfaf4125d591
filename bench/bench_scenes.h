// SPDX-License-Identifier: Apache-2.0
// Scenes the benchmarks share, built once outside the timed loops.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>

#include "ao/core/camera.h"
#include "ao/io/mesh_io.h"
#include "ao/scene/procedural.h"

namespace ao::bench {

/// Where the real meshes are: $AO_SHARED_MESHES when set (to check the fallbacks, point it at a
/// folder that does not exist), else ../shared/data/meshes beside the repository.
inline std::filesystem::path shared_meshes_dir() {
  const char* env = std::getenv("AO_SHARED_MESHES");
  return env ? std::filesystem::path(env) : std::filesystem::path(AO_SHARED_MESHES);
}

/// A stand-in of about the size of the shared meshes (88k triangles, like refined_elephant) for
/// runs without ../shared: a torus, smooth and closed, with self-occlusion in its hole.
inline Scene stand_in_scene(const std::string& file) {
  std::fprintf(stderr, "bench: %s not found in %s, using a stand-in torus\n", file.c_str(), shared_meshes_dir().c_str());
  Scene s;
  s.name = "torus (stand-in for " + file + ": ../shared/data/meshes not found)";
  s.meshes.push_back(make_torus({0, 0.35f, 0}, 1.0f, 0.35f, 512, 86));
  validate_and_prepare(s);
  return s;
}

/// A stand-in UV-mapped mesh (88k triangles) for the bake benchmarks without ../shared: a 211 x 211
/// vertex grid of smooth bumps over [0,4]^2 whose UVs are its xz coordinates / 4 (one chart).
inline Scene stand_in_uv_scene(const std::string& file) {
  std::fprintf(stderr, "bench: %s not found in %s, using a stand-in bump grid\n", file.c_str(), shared_meshes_dir().c_str());
  constexpr int n = 211;
  Mesh m;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const float u = static_cast<float>(i) / (n - 1), v = static_cast<float>(j) / (n - 1);
      const float h = 0.25f * std::sin(6.2831853f * 3 * u) * std::sin(6.2831853f * 3 * v);
      m.positions.push_back({4 * u, h, 4 * v});
      m.uvs.push_back({u, v});
    }
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const auto a = static_cast<std::uint32_t>(j * n + i), b = a + 1, c = a + n, d = a + n + 1;
      m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
    }
  Scene s;
  s.name = "bump grid (stand-in for " + file + ": ../shared/data/meshes not found)";
  s.meshes.push_back(std::move(m));
  validate_and_prepare(s);
  return s;
}

/// A mesh from ../shared/data/meshes (or, without it, stand_in_scene) standing on a ground plane
/// three times its footprint. Always has a value; Scene::name says when it is the stand-in.
inline std::optional<Scene> mesh_on_ground(const std::string& file) {
  const std::filesystem::path path = shared_meshes_dir() / file;
  Scene s = std::filesystem::exists(path) ? load_scene_file(path) : stand_in_scene(file);
  const Bounds3 b = s.bounds();
  const Vec3 c = b.center(), e = b.extent() * 1.5f;
  const float y = b.lo.y;
  s.meshes.push_back(make_quad({c.x - e.x, y, c.z + e.z}, {c.x + e.x, y, c.z + e.z}, {c.x + e.x, y, c.z - e.z}, {c.x - e.x, y, c.z - e.z}));
  validate_and_prepare(s);
  return s;
}

/// The CLI's auto-framing at the given size.
inline Camera framed(const Scene& s, int width, int height) {
  return s.preferred_view ? [&] {
    Camera c = *s.preferred_view;
    c.width = width;
    c.height = height;
    return c;
  }()
                          : frame_bounds(s.bounds(), {0.55f, 0.5f, 1.0f}, 40.0f, width, height);
}

}  // namespace ao::bench
