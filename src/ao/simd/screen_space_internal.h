// Kernels of the depth-buffer screen-space methods (containment and volumetric AO: Szirmay-Kalos et
// al., "Volumetric Ambient Occlusion for Real-Time Rendering and Games", eq. 5-7; ambient transfer:
// Szirmay-Kalos et al., "Ambient Transfer", eq. 8-9 and sec. 4), written once for every SIMD target
// (screen_space.cpp). A row's covered pixels sit in the lanes of vectors; each kernel runs all
// samples of a vector of pixels with its per-pixel values and sums in registers, one depth gather
// per test point. The methods (src/ao/methods/) derive the samples and constants from the papers
// and hand them over; what the kernels compute is stated here in the papers' terms.
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
  /// A deep G-buffer's second layer (GBuffer::second_depth), or null. With it the solid along a
  /// pixel's ray is [z*, z2] where the layer holds a back face z2 > 0, [z*, z* + separation] and
  /// [-z2, infinity) where it holds a front face (z2 < 0), and [z*, infinity) where it holds
  /// +infinity; without it [z*, infinity) (methods/depth_layers.h).
  const float* second = nullptr;
  float separation = 0;
};

/// Test points in the tangent frame, world units (VAO eq. 5, AT eq. 8): (x[i], y[i], z[i]), n of them.
struct TestPoints {
  const float* x = nullptr;
  const float* y = nullptr;
  const float* z = nullptr;
  int n = 0;
};

/// Containment AO (VAO eq. 5; AT sec. 4 with m tests per ray): open[k] = the number of the n rays
/// of entry k all of whose m test points x + (j/m)(X T + Y B + Z N), j = 1..m, are free: depth
/// distance z* - depth(p) >= -bias, or (AT sec. 4.3) at most `far_limit` (< 0; -infinity: no
/// elimination), or p behind the camera. `open` holds padded(row.count) floats.
void count_open_rays(const CoveredPixels& row, const DepthPlane& plane, const TestPoints& samples, int m, float far_limit, float* open);

/// Volumetric AO's pipes (VAO eq. 6-7, fig. 4 and 7): free[k] = sum over the n disk samples
/// (R/2)(x_i, y_i) rotated by the pixel's angle of the pipe's free length clamp(z* - z_entry, 0,
/// chord) inside the tangent sphere of radius R/2 centred at x + N R/2, chord = R h_i; a pipe whose
/// surface lies more than -far_limit in front of its entry is free (AT 4.3 for pipes). `free`
/// holds padded(row.count) floats.
void sum_free_pipes(const CoveredPixels& row, const DepthPlane& plane, float half_radius, const TestPoints& disk, float far_limit,
                    float* free);

/// Ambient transfer (AT eq. 6, 9) on the depth buffer. Its inputs besides the tests of
/// count_open_rays: the reflectance a blocked ray brings back (a~ of eq. 9), either from a palette
/// of at most 32 RGB values whose index sits in the low 5 bits of each pixel's packed depth word, or
/// read at the occluder's pixel of an RGB image; in the radiance mode also the occluder's direct
/// radiance Ld~ (never with a palette).
struct TransferInputs {
  const std::uint32_t* packed = nullptr;  ///< Depth words with a palette index in the low 5 bits; null: no palette.
  const float* palette = nullptr;         ///< 96 floats: the palette's R, G, B planes of 32 entries.
  const float* albedo = nullptr;          ///< RGB triples per pixel: a~ without a palette.
  const float* direct = nullptr;          ///< RGB triples per pixel: Ld~ (radiance mode), else null.
  float albedo_scale = 1;                 ///< Multiplies a~ and Ld~.
};

/// Where ambient transfer's results go, per pixel of the G-buffer (index y * width + x).
struct TransferOutputs {
  float* r = nullptr;  ///< W's R, or (with `rgb`) its Rec. 709 luminance.
  float* g = nullptr;  ///< W's G (unused with `rgb`).
  float* b = nullptr;  ///< W's B (unused with `rgb`).
  float* o = nullptr;  ///< O = sum I / n (eq. 5 from the same tests).
  Vec3* rgb = nullptr; ///< W interleaved, or null.
};

/// AT sec. 4 and eq. 9 for the entries of `row` (pixel offset of entry k from `out`'s row start
/// `row_base`: row.index[k]): per ray, the nearest of its m test points x + (j/m) w r that is
/// occluded (as count_open_rays) names the occluder pixel whose a~ (and Ld~) the ray brings back;
/// W = sum I / (n - scale sum (1 - I) a~) clamped to 1 (0 when no ray is open), or in the radiance
/// mode (sum I + scale sum (1 - I) Ld~) / (n - scale sum (1 - I) a~) (0 unless both are > 0).
void transfer_rays(const CoveredPixels& row, const DepthPlane& plane, const TestPoints& samples, int m, float far_limit,
                   const TransferInputs& in, std::size_t row_base, const TransferOutputs& out);

/// Transfer's last pass over filtered planes: rgb[k] = (r[k], g[k], b[k]) (W interleaved) and lum[k]
/// its Rec. 709 luminance for k < n. `lum` may be `r` (each value is read before it is written).
void interleave_transfer(const float* r, const float* g, const float* b, std::size_t n, Vec3* rgb, float* lum);

}  // namespace ao::simd
