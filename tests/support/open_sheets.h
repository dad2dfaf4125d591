// SPDX-License-Identifier: Apache-2.0
// Open meshes (sheets and containers) for the cone method's open-surface voxelization, generated
// so that the tests and bench/tools/open_sheets.cpp (which writes them as OBJ for `ao compare`)
// need no files. Each is one mesh whose fronts (counter-clockwise) face out, standing on y = 0.
// And closed meshes opened as scans come (a base cut off, holes punched).
#pragma once

#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "ao/scene/mesh.h"
#include "ao/scene/procedural.h"

namespace ao::test {

// Open meshes made from closed ones, as scans come: `keep` decides per triangle from its centroid.
template <class Keep>
inline Mesh cut(const Mesh& closed, Keep keep) {
  Mesh m = closed;
  m.indices.clear();
  for (std::size_t t = 0; t < closed.triangle_count(); ++t) {
    const std::uint32_t* v = closed.indices.data() + 3 * t;
    const Vec3 c = (closed.positions[v[0]] + closed.positions[v[1]] + closed.positions[v[2]]) * (1.0f / 3.0f);
    if (keep(c)) m.indices.insert(m.indices.end(), v, v + 3);
  }
  return m;
}

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
  // rings even: a ring on the equator, so the rim is flat.
  return cut(make_sphere({0, radius, 0}, radius, segments, rings), [radius](Vec3 c) { return c.y < radius; });
}

/// A box from `lo` to `hi` without its top face: an open container seen into through the gap.
inline Mesh make_open_box(Vec3 lo = {-0.9f, 0.0f, -0.7f}, Vec3 hi = {0.9f, 1.0f, 0.7f}) {
  return cut(make_box(lo, hi), [hi](Vec3 c) { return c.y < hi.y; });
}

// The same mesh with every triangle turned over (fronts become backs).
inline Mesh turned_over(Mesh m) {
  for (std::size_t t = 0; t < m.triangle_count(); ++t) std::swap(m.indices[3 * t + 1], m.indices[3 * t + 2]);
  return m;
}
// Removes the cap below y = lo + fraction * height (a bust open at its base).
inline Mesh cut_base(const Mesh& closed, float fraction) {
  Bounds3 b;
  for (const Vec3& p : closed.positions) b.extend(p);
  const float y = b.lo.y + fraction * (b.hi.y - b.lo.y);
  return cut(closed, [&](Vec3 c) { return c.y > y; });
}
// Punches holes: drops the triangles within `radius` of three vertices on the upper half.
inline Mesh punch_holes(const Mesh& closed, float radius_fraction) {
  Bounds3 b;
  for (const Vec3& p : closed.positions) b.extend(p);
  std::vector<Vec3> centres;
  const float mid = 0.5f * (b.lo.y + b.hi.y);
  for (std::size_t v = 0; v < closed.positions.size() && centres.size() < 3; v += closed.positions.size() / 7 + 1)
    if (closed.positions[v].y > mid) centres.push_back(closed.positions[v]);
  const float r = radius_fraction * b.diagonal();
  return cut(closed, [&](Vec3 c) {
    for (const Vec3& q : centres)
      if (length(c - q) < r) return false;
    return true;
  });
}

}  // namespace ao::test
