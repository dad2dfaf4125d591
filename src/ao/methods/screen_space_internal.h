// Internals of the screen-space methods (containment, volumetric, transfer), not installed: the
// per-pixel setup their kernels share, a row of pixels as structure-of-arrays (position, rotated
// tangent frame, depth bias) so that the loops over samples run across pixels in SIMD lanes, and
// the parameter objects' key check.
#pragma once

#include <array>
#include <initializer_list>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/gbuffer.h"
#include "ao/methods/samples.h"

namespace ao {

/// InputError naming `method` and the key when `j` is not an object or has a key not in `keys`.
void require_known_keys(const nlohmann::json& j, std::initializer_list<const char*> keys, const char* method);

/// A run of pixels [x0, x0 + count) of one row, structure-of-arrays. Uncovered pixels get a
/// harmless dummy point far in front of the camera and covered = 0.
struct PixelRow {
  int y = 0, x0 = 0, count = 0;
  std::vector<float> px, py, pz;  ///< Camera-space position of the shaded point x.
  std::vector<float> nx, ny, nz;  ///< Unit normal N.
  std::vector<float> tx, ty, tz;  ///< Tangent T, rotated by the pixel's interleaving angle about N.
  std::vector<float> bx, by, bz;  ///< Binormal B = N x T, rotated likewise.
  std::vector<float> rc, rs;      ///< The pixel's rotation (cos, sin), for samples in the view plane.
  std::vector<float> bias;        ///< Depth-test bias, world units (see load()).
  std::vector<unsigned char> covered;

  /// Fills the row from the G-buffer. The depth bias of a pixel is `bias_world` when > 0, else
  /// auto: one pixel footprint at its depth times (1 + tan theta_v) with theta_v the angle between
  /// the normal and the view ray (clamped to tan 83 deg = 8): the most a nearest-pixel depth lookup
  /// on the same surface can be off by, so planes do not shadow themselves.
  void load(const GBuffer& g, int y, int x0, int x1, const std::array<Rotation, 16>& rotations, float bias_world);
};

/// PixelRow::load for the covered pixels of [x0, x1) only, compacted: entry k of `row` (k <
/// row.count) is pixel x0 + index[k], and every entry is covered. Background pixels (30% of the
/// default scene) then cost the sample loops nothing. The values are PixelRow::load's, computed in
/// passes GCC vectorises (AVX-512: 16 entries per vector). With `frame` false the rotated tangent
/// frame (tx..bz) is left unset: volumetric AO needs only the position, normal, rotation and bias.
/// Shared by containment.cpp and volumetric.cpp. containment.cpp is compiled with -fno-math-errno
/// (src/CMakeLists.txt) so that the square roots of the auto bias vectorise.
void load_pixel_row_simd(PixelRow& row, std::vector<int>& index, const GBuffer& g, int y, int x0, int x1,
                         const std::array<Rotation, 16>& rotations, float bias_world, bool frame);

}  // namespace ao
