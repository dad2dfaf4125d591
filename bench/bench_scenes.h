// Scenes the benchmarks share, built once outside the timed loops.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "ao/core/camera.h"
#include "ao/io/mesh_io.h"
#include "ao/scene/procedural.h"

namespace ao::bench {

/// A mesh from ../shared/data/meshes standing on a ground plane three times its footprint, or
/// nullopt when the shared data is absent (the benchmark then skips).
inline std::optional<Scene> mesh_on_ground(const std::string& file) {
  const std::filesystem::path path = std::filesystem::path(AO_SHARED_MESHES) / file;
  if (!std::filesystem::exists(path)) return std::nullopt;
  Scene s = load_scene_file(path);
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
