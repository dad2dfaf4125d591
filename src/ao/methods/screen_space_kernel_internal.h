// SPDX-License-Identifier: Apache-2.0
// What the kernels of the depth-buffer screen-space methods share (containment and volumetric AO:
// Szirmay-Kalos et al., "Volumetric Ambient Occlusion for Real-Time Rendering and Games", eq. 5-7;
// ambient transfer: Szirmay-Kalos et al., "Ambient Transfer", eq. 8-9 and sec. 4; each kernel in its
// method's folder): a row's covered pixels in the lanes of vectors (the row loader,
// screen_space_kernel.cpp), the depth plane and the test points. Each kernel runs all samples of a
// vector of pixels with its per-pixel values and sums in registers, one depth gather per test
// point. The methods derive the samples and constants from the papers and hand them over; what the
// kernels compute is stated in their headers in the papers' terms.
#pragma once

#include <cstdint>

#include "ao/core/gbuffer.h"
#include "ao/simd/aligned_internal.h"

namespace ao::simd {

/// The 16 rotations of the 4x4 interleaving pattern (VAO and AT sec. 4.2): entry (y % 4) * 4 + x % 4.
struct Rotations16 {
  float c[16], s[16];  ///< cos and sin of the angle.
};

/// The covered pixels of a row segment [x0, x0 + ...), compacted, structure of arrays: entry k < count
/// is pixel x0 + index[k]. Every array holds padded(count) entries; those past `count` are a
/// harmless point (one unit in front of the camera, facing it) whose results are never read.
struct CoveredPixels {
  int y = 0, x0 = 0, count = 0;
  AlignedVector<int> index;
  AlignedVector<float> px, py, pz;  ///< Camera-space position of the shaded point x.
  AlignedVector<float> nx, ny, nz;  ///< Unit normal N.
  AlignedVector<float> tx, ty, tz;  ///< Tangent T rotated by the pixel's interleaving angle about N (with `frame`).
  AlignedVector<float> bx, by, bz;  ///< Binormal B = N x T, rotated likewise (with `frame`).
  AlignedVector<float> rc, rs;      ///< The pixel's rotation (cos, sin).
  AlignedVector<float> bias;        ///< Depth-test bias, world units.
};

/// Fills `row` with the covered pixels of [x0, x1) of row y of `g`. The depth bias is `bias_world`
/// when > 0, else one pixel footprint at the pixel's depth times (1 + tan theta_v), theta_v the
/// angle between N and the view ray (tan clamped to 8): the most a nearest-pixel depth lookup on the
/// same surface can be off by. With `frame` false the rotated frame (tx..bz) is left unset.
void load_covered_pixels(CoveredPixels& row, const GBuffer& g, int y, int x0, int x1, const Rotations16& rotations, float bias_world,
                         bool frame);

/// The depth plane (VAO fig. 2c) and the projection onto it (ScreenProjection's constants):
/// pixel (ix, iy) of camera-space p = (scale_x x / -z + centre_x, centre_y - scale_y y / -z),
/// clamped to the image; +infinity on background.
struct DepthPlane {
  const float* depth = nullptr;  ///< width * height linear depths.
  float scale_x = 1, scale_y = 1, centre_x = 0, centre_y = 0;
  int width = 0, height = 0;
  /// A deep G-buffer's second layer (GBuffer::second_depth), or null: one layer, the solid along
  /// a pixel's ray is [z*, infinity). With it (methods/depth_layers.h): [z*, infinity) where the
  /// layer holds a back face (z2 > 0, finite: a closed solid), [z*, z2] of it whatever AT 4.3 says
  /// where that is a closed mesh's exit; where it holds a front face (z2 < 0) or nothing
  /// (+infinity) the visible surface is a sheet: [z*, z* + separation], [-z2, infinity), and in
  /// between solid for a receiver the sheet hides the point from (`normals`).
  const float* second = nullptr;
  float separation = 0;
  /// With `second`: the visible surface's camera-space unit normal per pixel, facing the camera
  /// (GBuffer::normal: 3 floats a pixel).
  const float* normals = nullptr;
};

/// The sheet test's tolerance as a fraction of the separation: the segment from a receiver to a
/// point behind a sheet meets the sheet's tangent plane on the sheet when the surface seen at that
/// point's pixel is no more than this behind it (docs/methods/depth-layers.md measures it).
inline constexpr float kCrossingTolerance = 0.25f;

/// Test points in the tangent frame, world units (VAO eq. 5, AT eq. 8): (x[i], y[i], z[i]), n of them.
struct TestPoints {
  const float* x = nullptr;
  const float* y = nullptr;
  const float* z = nullptr;
  int n = 0;
};

}  // namespace ao::simd
