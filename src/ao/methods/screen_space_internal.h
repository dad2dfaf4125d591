// Internals of the screen-space methods (containment, volumetric, transfer), not installed: their
// inputs in the form of the SIMD kernel layer (src/ao/simd/screen_space_internal.h), which takes a
// row's covered pixels as structure-of-arrays and runs the loops over samples across pixels.
#pragma once

#include <array>

#include "ao/methods/characteristic.h"
#include "ao/methods/samples.h"
#include "ao/simd/screen_space_internal.h"

namespace ao {

/// The interleaving pattern's rotations as the kernels take them.
inline simd::Rotations16 simd_rotations(const std::array<Rotation, 16>& r) {
  simd::Rotations16 out;
  for (std::size_t k = 0; k < 16; ++k) out.c[k] = r[k].c, out.s[k] = r[k].s;
  return out;
}

/// The depth plane a depth-buffer characteristic reads, with its projection.
inline simd::DepthPlane simd_depth_plane(const DepthBufferCharacteristic& ch) {
  const ScreenProjection& p = ch.projection;
  return {ch.depth, p.scale_x, p.scale_y, p.centre_x, p.centre_y, p.width, p.height};
}

/// Test-point offsets (X_i, Y_i, Z_i) as the kernels take them.
inline simd::TestPoints simd_points(const ContainmentSamples& s) { return {s.x.data(), s.y.data(), s.z.data(), s.size()}; }
/// Disk samples (x_i, y_i, h_i) as the kernels take them (h_i in z).
inline simd::TestPoints simd_points(const DiskSamples& s) { return {s.x.data(), s.y.data(), s.h.data(), s.size()}; }

}  // namespace ao
