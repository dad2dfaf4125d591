// Open meshes (sheets and containers) for the cone method's open-surface voxelization, generated
// so that the tests and bench/tools/open_sheets.cpp (which writes them as OBJ for `ao compare`)
// need no files. Each is one mesh whose fronts (counter-clockwise) face out, standing on y = 0.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "ao/scene/mesh.h"
#include "ao/scene/procedural.h"

namespace ao::test {

/// A sheet bent through 180 degrees into an arch (half a cylinder of `radius` about the z axis,
/// `length` long, centred on the origin, its two edges on y = 0), with `holes` round holes of
/// radius `hole_radius` (world units, measured on the sheet) along its crown. Tessellated as a grid
/// of `around` x `along` quads; a hole drops the triangles whose centroid lies in it, so its rim
/// follows the triangles. Fronts face away from the axis. A mechanical part made of sheet metal.
inline Mesh make_holed_arch(float radius = 0.8f, float length = 2.4f, int holes = 3, float hole_radius = 0.22f, int around = 96,
                            int along = 96) {
  Mesh m;
  const float pi = 3.14159265358979323846f;
  for (int j = 0; j <= along; ++j)
    for (int i = 0; i <= around; ++i) {
      const float a = pi * static_cast<float>(i) / static_cast<float>(around);  // from +x over the top to -x
      const float z = length * (static_cast<float>(j) / static_cast<float>(along) - 0.5f);
      m.positions.push_back({radius * std::cos(a), i == 0 || i == around ? 0.0f : radius * std::sin(a), z});
    }
  const auto v = [&](int i, int j) { return static_cast<std::uint32_t>(j * (around + 1) + i); };
  const float arc = pi * radius;  // the crown is at arc length arc / 2
  const auto in_hole = [&](Vec3 c) {
    const float s = radius * std::atan2(c.y, c.x);  // arc length from +x
    for (int h = 0; h < holes; ++h) {
      const float hz = length * ((static_cast<float>(h) + 0.5f) / static_cast<float>(holes) - 0.5f);
      const float ds = s - 0.5f * arc, dz = c.z - hz;
      if (ds * ds + dz * dz < hole_radius * hole_radius) return true;
    }
    return false;
  };
  const auto add = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    const Vec3 centre = (m.positions[a] + m.positions[b] + m.positions[c]) * (1.0f / 3.0f);
    if (!in_hole(centre)) m.indices.insert(m.indices.end(), {a, b, c});
  };
  for (int j = 0; j < along; ++j)
    for (int i = 0; i < around; ++i) {
      // Counter-clockwise seen from outside (from away from the axis).
      add(v(i, j), v(i + 1, j + 1), v(i, j + 1));
      add(v(i, j), v(i + 1, j), v(i + 1, j + 1));
    }
  return m;
}

/// Half a sphere shell of `radius`, opening up, its lowest point on y = 0: a bowl.
inline Mesh make_bowl(float radius = 1.0f, int segments = 96, int rings = 48) {
  const Mesh sphere = make_sphere({0, radius, 0}, radius, segments, rings);  // rings even: a ring on the equator
  Mesh m;
  m.positions = sphere.positions;
  for (std::size_t t = 0; t < sphere.triangle_count(); ++t) {
    const std::uint32_t* i = sphere.indices.data() + 3 * t;
    if (sphere.positions[i[0]].y + sphere.positions[i[1]].y + sphere.positions[i[2]].y < 3.0f * radius) m.indices.insert(m.indices.end(), i, i + 3);
  }
  return m;
}

/// A box from `lo` to `hi` without its top face: an open container seen into through the gap.
inline Mesh make_open_box(Vec3 lo = {-0.9f, 0.0f, -0.7f}, Vec3 hi = {0.9f, 1.0f, 0.7f}) {
  const Mesh box = make_box(lo, hi);
  Mesh m;
  m.positions = box.positions;
  for (std::size_t t = 0; t < box.triangle_count(); ++t) {
    const std::uint32_t* i = box.indices.data() + 3 * t;
    if (box.positions[i[0]].y + box.positions[i[1]].y + box.positions[i[2]].y < 3.0f * hi.y) m.indices.insert(m.indices.end(), i, i + 3);
  }
  return m;
}

}  // namespace ao::test
