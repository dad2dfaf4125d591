// SPDX-License-Identifier: Apache-2.0
// Internals of the cone method, not installed: its sampling pattern (the tabulated per-pixel
// jitter and the prisms' points on the great disk), built once per call or per prism count.
#pragma once

#include <cstdint>
#include <vector>

#include "ao/methods/cone/cone.h"

namespace ao {

// The per-pixel jitter of deviation 5 (docs/methods/cone.md), tabulated once per call: pixel
// (x, y) takes slot (x mod P, y mod P) of a P x P table whose entries come from
// pixel_seed(seed, slot), so the image does not depend on the thread count and each pixel's cones
// are as random as with a hash per pixel; only pixels P apart repeat a pattern. Per slot: the
// prism pattern turns by beta, and each cone takes one random direction in its own cell of the
// hemisphere (stratified sampling of the cell's measure: theta uniform in the band's sin^2 theta
// or 1 - cos theta, phi uniform in its azimuth range) and one random scale of its sphere chain.
// Fixed directions and distances make the error a fixed function of the distance to each
// occluder, which shows as rings that no averaging over seeds removes. What is left per pixel and
// cone is turning the tabulated axis into the normal's frame.
struct ConePattern {
  // 32: a multiple of the tile size, far beyond the 5-tap filter's reach, and 32 x 32 slots x 6
  // cones of 16 bytes stay in the L2 cache (98 KB).
  static constexpr int kPeriod = 32;
  struct Cone {
    float x, y, z;  ///< Axis in the normal's frame (z along the normal).
    float scale;    ///< Chain scale s = q^-xi in (1/q, 1].
  };
  int period = 1;
  int cones = 0;
  std::vector<float> rot;  // per slot: cos and sin of the prism pattern's turn
  std::vector<Cone> cone;  // per slot, `cones` in order
  int slot(int x, int y) const { return (y & (period - 1)) * period + (x & (period - 1)); }
};

/// The table of ConePattern for `setup`'s cones (period 1 and no jitter when `jitter` is false).
ConePattern make_cone_pattern(const ConeSetup& setup, bool jitter, std::uint32_t seed);

/// n Poisson-disk points on the unit disk with their half chords (ConeSetup::disk).
std::vector<ConeSetup::Disk> cone_disk_points(int n);

}  // namespace ao
