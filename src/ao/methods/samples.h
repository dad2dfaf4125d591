// SPDX-License-Identifier: Apache-2.0
// Sample sets shared by the screen-space methods of volumetric-ambient-occlusion (VAO) and
// ambient-transfer (AT):
//  - Poisson-disk point sets obtained by Lloyd relaxation (AT sec. 4.1, citing Lloyd 1982), in the
//    unit square, the unit cube or the unit disk. They are computed once per (domain, n) and cached.
//  - Containment-test offsets (X_i, Y_i, Z_i) = w_i r_i (VAO eq. 5, AT eq. 8): w_i cosine
//    distributed by AT's polar map of (xi_x, xi_y), r_i = mu^-1(xi_z) for the chosen membership.
//  - Pipe positions (x_i, y_i) in the unit disk for volumetric AO (VAO eq. 6-7).
//  - The 16 rotations of the 4x4 interleaving pattern (VAO and AT sec. 4.2).
// Samples are stored structure-of-arrays so the kernels' inner loops vectorise.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "ao/core/math.h"
#include "ao/core/membership.h"

namespace ao {

/// Domains of the Poisson-disk sets.
enum class PoissonDomain {
  Square,  ///< [0,1)^2; points have z = 0.
  Cube,    ///< [0,1)^3.
  Disk,    ///< The unit disk centred at the origin; points have z = 0.
};

/// Largest n the sample generators accept (Lloyd relaxation is O(n) per density point).
inline constexpr int kMaxScreenSpaceSamples = 256;

/// n points of a Poisson-disk (centroidal Voronoi) distribution in `domain`, by 32 Lloyd iterations
/// from a fixed pseudo-random start over a fixed set of density points. Deterministic: the same n
/// and domain give the same points on every run and thread. Cached: the first call for a (domain, n)
/// computes the set (~1 ms for n = 16), later calls return the cached one. Thread-safe.
/// n in [1, kMaxScreenSpaceSamples]; InputError otherwise.
std::span<const Vec3> poisson_disk(PoissonDomain domain, int n);

/// Containment-test offsets in the tangent frame, world units, SoA (AT eq. 8).
struct ContainmentSamples {
  std::vector<float> x, y, z;  ///< X_i, Y_i (tangent plane) and Z_i (along N >= 0) of w_i r_i.
  std::vector<float> r;        ///< r_i = mu^-1(xi_z), the sample's distance from the shaded point.
  int size() const { return static_cast<int>(x.size()); }
};

/// n offsets (X_i, Y_i, Z_i) = w_i r_i from the Poisson-disk set in the unit cube (AT sec. 4.1):
/// w_i = T cos(2 pi xi_x) sqrt(xi_y) + B sin(2 pi xi_x) sqrt(xi_y) + N sqrt(1 - xi_y) (cosine
/// distributed) and r_i = mu^-1(xi_z), so the points have density mu'(r) cos(theta) / pi.
ContainmentSamples make_containment_samples(int n, const Falloff& falloff);

/// Pipe positions (x_i, y_i) in the unit disk (VAO eq. 6-7), SoA, with h_i = sqrt(1 - x_i^2 - y_i^2).
struct DiskSamples {
  std::vector<float> x, y, h;
  int size() const { return static_cast<int>(x.size()); }
};
/// The n-point Poisson-disk set of the unit disk.
DiskSamples make_disk_samples(int n);

/// (cos alpha, sin alpha) of a rotation about the surface normal.
struct Rotation {
  float c = 1, s = 0;
};

/// The 16 rotations of the 4x4 interleaving pattern, indexed by (y % 4) * 4 + x % 4. With
/// `interleave` the angles are stratified random, alpha_k = 2 pi (sigma(k) + u_k) / 16 with sigma a
/// seeded permutation and u_k seeded jitter, so the 16 sets are distinct and a 4x4 window holds one
/// of each; without, all 16 entries are the same seeded random angle (one sample set everywhere).
/// Depends only on `seed`, never on threads.
std::array<Rotation, 16> interleave_rotations(std::uint32_t seed, bool interleave);

}  // namespace ao
