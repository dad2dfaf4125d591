// SPDX-License-Identifier: Apache-2.0
// Open meshes (sheets and containers) for the cone method's open-surface voxelization, generated
// so that the tests and bench/tools/open_sheets.cpp (which writes them as OBJ for `ao compare`)
// need no files. Each is one mesh whose fronts (counter-clockwise) face out, standing on y = 0.
// And closed meshes opened as scans come (a base cut off, holes punched).
#pragma once

#include <algorithm>
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

/// A sheet over the unit square of parameters: `at(u, v)` places the grid's vertices (nu x nv
/// quads), and a triangle is kept where `keep(u, v)` holds at its centroid in parameters (an
/// outline, holes). Fronts face along d(at)/du x d(at)/dv.
template <class At, class Keep>
inline Mesh make_parametric_sheet(int nu, int nv, At at, Keep keep) {
  Mesh m;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) m.positions.push_back(at(static_cast<float>(i) / static_cast<float>(nu), static_cast<float>(j) / static_cast<float>(nv)));
  const auto v = [&](int i, int j) { return static_cast<std::uint32_t>(j * (nu + 1) + i); };
  const auto add = [&](int i0, int j0, int i1, int j1, int i2, int j2) {
    const float u = static_cast<float>(i0 + i1 + i2) / (3.0f * static_cast<float>(nu));
    const float w = static_cast<float>(j0 + j1 + j2) / (3.0f * static_cast<float>(nv));
    if (keep(u, w)) m.indices.insert(m.indices.end(), {v(i0, j0), v(i1, j1), v(i2, j2)});
  };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      add(i, j, i + 1, j, i + 1, j + 1);
      add(i, j, i + 1, j + 1, i, j + 1);
    }
  return m;
}

inline constexpr float kPi = 3.14159265358979323846f;

/// A face mask as a scan gives it: one curved sheet (a part of an ellipsoid, 1.2 wide, 1.6 tall,
/// 0.5 deep, facing +z), with a nose and brows standing out of it and two eye holes, its chin near
/// y = 0. The nose and the brows are thinner than the scene's radius: a slab that deep behind their
/// tops would come out through their undersides.
inline Mesh make_mask() {
  const auto outline = [](float u, float v) {
    const float x = 2 * u - 1, y = 2 * v - 1;
    const auto eye = [&](float ex) { return (x - ex) * (x - ex) / 0.045f + (y - 0.25f) * (y - 0.25f) / 0.012f < 1; };
    return x * x + y * y * (y < 0 ? 1.15f : 1.0f) < 1 && !eye(-0.38f) && !eye(0.38f);
  };
  return make_parametric_sheet(96, 128,
                               [](float u, float v) {
                                 const float x = 2 * u - 1, y = 2 * v - 1;
                                 const float theta = 1.1f * x, phi = 0.9f * y;
                                 Vec3 p{0.6f * std::sin(theta) / std::sin(1.1f), 0.8f + 0.8f * y, 0.5f * std::cos(theta) * std::cos(phi)};
                                 // Nose: a ridge down the middle, deepest at its tip; brows over the eyes.
                                 const float nose = 0.2f * std::exp(-x * x / 0.01f) * std::exp(-(y + 0.05f) * (y + 0.05f) / 0.05f);
                                 const float brows = 0.06f * std::exp(-(y - 0.42f) * (y - 0.42f) / 0.004f) * (1 - x * x);
                                 p.z += nose + brows;
                                 return p;
                               },
                               outline);
}

/// Half a sphere shell of `radius` standing on y = 0 (a dome), with one round window of angular
/// radius `window` (radians) facing (1, 0, 1.3) horizontally, raised by `elevation` radians: the
/// ground inside is seen through it from the suite's camera.
inline Mesh make_dome(float radius = 1.0f, float window = 0.4f, float elevation = 0.6f) {
  const Vec3 w = normalize(Vec3{std::cos(elevation) * 0.61f, std::sin(elevation), std::cos(elevation) * 0.79f});
  return make_parametric_sheet(128, 48,
                               [radius](float u, float v) {
                                 const float az = 2 * kPi * u, el = 0.5f * kPi * v;
                                 return Vec3{radius * std::cos(el) * std::cos(az), radius * std::sin(el), -radius * std::cos(el) * std::sin(az)};
                               },
                               [w, window](float u, float v) {
                                 const float az = 2 * kPi * u, el = 0.5f * kPi * v;
                                 const Vec3 d{std::cos(el) * std::cos(az), std::sin(el), -std::cos(el) * std::sin(az)};
                                 return dot(d, w) < std::cos(window);
                               });
}

/// A terrain: a height field 3 x 3 (hills, a ridge, a valley cut by a ravine narrower than the
/// scene's radius), about 0.05 above y = 0 at its lowest. An open sheet seen from above, its edges
/// cliffs.
inline Mesh make_terrain() {
  return make_parametric_sheet(128, 128,
                               [](float u, float v) {
                                 const float x = 3 * u - 1.5f, z = 1.5f - 3 * v;
                                 const float hills = 0.25f * std::sin(2.1f * x) * std::cos(1.7f * z) + 0.18f * std::exp(-((x - 0.6f) * (x - 0.6f) + (z + 0.5f) * (z + 0.5f)) / 0.15f);
                                 const float ravine = -0.3f * std::exp(-(x + 0.3f * z + 0.2f) * (x + 0.3f * z + 0.2f) / 0.01f);
                                 return Vec3{x, 0.6f + hills + ravine, z};
                               },
                               [](float, float) { return true; });
}

/// A cloth thrown over a round table that is not there: flat on a disk of radius 0.7 at y = 1,
/// then hanging down in eight folds to a hem at y = 0.25. Open below: a tent over the ground.
inline Mesh make_tablecloth() {
  return make_parametric_sheet(128, 64,
                               [](float u, float v) {
                                 const float az = 2 * kPi * u, s = 1.4f * v;  // s: distance from the centre along the cloth
                                 const float top = 0.7f, over = std::max(0.0f, s - top);
                                 const float r = std::min(s, top) + 0.15f * over + 0.1f * (over / 0.7f) * std::sin(8 * az);
                                 return Vec3{r * std::cos(az), 1.0f - 1.07f * over, -r * std::sin(az)};
                               },
                               [](float, float) { return true; });
}

/// A leaf lying on the ground: an outline 1.6 long and 0.7 wide, folded along its midrib into a V
/// (its halves rise 25 degrees) and curled up towards its tip, its midrib 0.02 above y = 0.
inline Mesh make_leaf() {
  return make_parametric_sheet(64, 128,
                               [](float u, float v) {
                                 const float x = 0.35f * (2 * u - 1), t = 1.6f * v;
                                 const float fold = 0.47f * std::abs(x);
                                 const float curl = 0.35f * v * v * v;
                                 return Vec3{x, 0.02f + fold + curl, 0.8f - t};
                               },
                               [](float u, float v) {
                                 const float half = std::sin(kPi * std::pow(v, 0.8f));  // the outline's half width, 0 at both ends
                                 return std::abs(2 * u - 1) < half;
                               });
}

/// A gutter: half a pipe of radius 0.2 and length 2, open upwards, lying on y = 0. Its inside is
/// curved tighter than the scene's radius.
inline Mesh make_gutter(float radius = 0.2f, float length = 2.0f) {
  return make_parametric_sheet(48, 96,
                               [=](float u, float v) {
                                 const float a = kPi * (1 + u);  // from -x under the axis to +x
                                 return Vec3{radius * std::cos(a), radius + radius * std::sin(a), length * (v - 0.5f)};
                               },
                               [](float, float) { return true; });
}

/// A closed ellipsoid 1.2 wide, 1.6 tall and 1 deep (the mask's width and height), standing on
/// y = 0: the closed mesh the mask is compared with.
inline Mesh make_head() {
  Mesh m = make_sphere({0, 0, 0}, 1.0f, 96, 48);
  for (Vec3& p : m.positions) p = {0.6f * p.x, 0.8f + 0.8f * p.y, 0.5f * p.z};
  return m;
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

/// The ground every mesh of the suite stands on: a square quad at the object's lowest height,
/// centred under it, twice its diagonal on a side.
inline Mesh ground_under(const Mesh& object, Vec3 albedo = {0.8f, 0.8f, 0.8f}) {
  const Bounds3 b = object.bounds();
  const Vec3 c = b.center();
  const float e = b.diagonal();
  return make_quad({c.x - e, b.lo.y, c.z + e}, {c.x + e, b.lo.y, c.z + e}, {c.x + e, b.lo.y, c.z - e}, {c.x - e, b.lo.y, c.z - e}, albedo);
}

}  // namespace ao::test
