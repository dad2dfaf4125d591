// SPDX-License-Identifier: Apache-2.0
// Affine maps of 3D space (3x4 matrices), as glTF nodes place instanced meshes in the world.
#pragma once

#include <cmath>

#include "ao/core/math.h"

namespace ao {

/// x' = c0 x + c1 y + c2 z + c3: a 3x3 linear part (columns c0, c1, c2) and a translation c3.
/// The memory layout (12 floats, column by column) is Embree's RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR.
/// The default is the identity.
struct Affine3 {
  Vec3 c0{1, 0, 0}, c1{0, 1, 0}, c2{0, 0, 1}, c3{0, 0, 0};

  /// The linear part applied to a direction (no translation).
  Vec3 vector(Vec3 v) const { return c0 * v.x + c1 * v.y + c2 * v.z; }
  /// The whole map applied to a point.
  Vec3 point(Vec3 p) const { return vector(p) + c3; }
  /// Determinant of the linear part, in double: its sign says whether the map mirrors, and a
  /// zero means the map flattens space (no inverse).
  double determinant() const {
    const auto d = [](float v) { return static_cast<double>(v); };
    return d(c0.x) * (d(c1.y) * d(c2.z) - d(c2.y) * d(c1.z)) - d(c1.x) * (d(c0.y) * d(c2.z) - d(c2.y) * d(c0.z)) +
           d(c2.x) * (d(c0.y) * d(c1.z) - d(c1.y) * d(c0.z));
  }
  bool is_finite() const { return ao::is_finite(c0) && ao::is_finite(c1) && ao::is_finite(c2) && ao::is_finite(c3); }
};

static_assert(sizeof(Affine3) == 12 * sizeof(float), "Affine3 is passed to Embree as 12 packed floats");

/// a after b: (a * b)(p) = a(b(p)).
inline Affine3 operator*(const Affine3& a, const Affine3& b) { return {a.vector(b.c0), a.vector(b.c1), a.vector(b.c2), a.point(b.c3)}; }

/// The cofactor matrix of m's linear part (det(L) times its inverse transpose), as the linear part
/// of the result (translation zero). It maps the cross product of two vectors to the cross product
/// of their images, L a x L b = cof(L) (a x b), so a face normal transformed by it points where
/// the normal of the transformed triangle points, mirrors included; unlike the inverse transpose it
/// exists for every matrix. Normalise after applying it.
inline Affine3 cofactor(const Affine3& m) { return {cross(m.c1, m.c2), cross(m.c2, m.c0), cross(m.c0, m.c1), {0, 0, 0}}; }

/// The inverse map of m, whose determinant must not be 0 (validate_and_prepare refuses such
/// instances): L^-1 = cof(L)^T / det(L), computed in double, and the translation -L^-1 c3.
inline Affine3 inverse(const Affine3& m) {
  const Affine3 c = cofactor(m);
  const double inv = 1.0 / m.determinant();
  const auto f = [inv](double v) { return static_cast<float>(v * inv); };
  // Row k of L^-1 is column k of cof(L) over det(L).
  Affine3 r{{f(c.c0.x), f(c.c1.x), f(c.c2.x)}, {f(c.c0.y), f(c.c1.y), f(c.c2.y)}, {f(c.c0.z), f(c.c1.z), f(c.c2.z)}, {0, 0, 0}};
  r.c3 = -r.vector(m.c3);
  return r;
}

/// How much more m's linear part L stretches space along one direction than along another: the
/// condition number ||L||_F ||L^-1||_F (Frobenius norms, in double; ||L^-1||_F = ||cof(L)||_F /
/// |det L|), which is at least the ratio of L's largest to its smallest singular value and at most
/// 3 times it. 1 for a rotation or a uniform scale, about 1.4e20 for a scale of (1e-20, 1, 1);
/// +infinity when L is singular or not finite.
inline double squash_ratio(const Affine3& m) {
  const auto norm2 = [](const Affine3& a) {
    double s = 0;
    for (const Vec3& c : {a.c0, a.c1, a.c2})
      for (const float v : {c.x, c.y, c.z}) s += static_cast<double>(v) * static_cast<double>(v);
    return s;
  };
  // The cofactors in double: in float the products of tiny entries underflow.
  const auto d = [](float v) { return static_cast<double>(v); };
  const Vec3 &a = m.c0, &b = m.c1, &c = m.c2;
  const double cof[9] = {d(b.y) * d(c.z) - d(b.z) * d(c.y), d(b.z) * d(c.x) - d(b.x) * d(c.z), d(b.x) * d(c.y) - d(b.y) * d(c.x),
                         d(c.y) * d(a.z) - d(c.z) * d(a.y), d(c.z) * d(a.x) - d(c.x) * d(a.z), d(c.x) * d(a.y) - d(c.y) * d(a.x),
                         d(a.y) * d(b.z) - d(a.z) * d(b.y), d(a.z) * d(b.x) - d(a.x) * d(b.z), d(a.x) * d(b.y) - d(a.y) * d(b.x)};
  double cof2 = 0;
  for (const double v : cof) cof2 += v * v;
  const double det = std::abs(m.determinant());
  const double ratio = std::sqrt(norm2(m)) * std::sqrt(cof2) / det;
  return std::isfinite(ratio) && det > 0 ? ratio : HUGE_VAL;
}

/// The axis-aligned box of m applied to the corners of b (an empty box stays empty).
inline Bounds3 transform_bounds(const Affine3& m, const Bounds3& b) {
  Bounds3 out;
  if (b.empty()) return out;
  for (int k = 0; k < 8; ++k) out.extend(m.point({k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y, k & 4 ? b.hi.z : b.lo.z}));
  return out;
}

}  // namespace ao
