#include "ao/methods/volumetric.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>

#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/methods/characteristic.h"
#include "ao/methods/containment.h"
#include "ao/methods/samples.h"
#include "ao/methods/screen_space_internal.h"

namespace ao {

namespace {
constexpr int kTile = 64;
}

const ParamTable<VolumetricParams>& volumetric_param_table() {
  using P = Param<VolumetricParams>;
  static const ParamTable<VolumetricParams> table{
      "volumetric",
      {{P::integer("samples", &VolumetricParams::samples, Range::closed(1, kMaxScreenSpaceSamples), "", "n in eq. 6-7: pipes per pixel"),
        P::enumeration<VolumeNormalizer>("normalizer", &VolumetricParams::normalizer,
                                         {{"wis", VolumeNormalizer::WeightedImportance}, {"analytic", VolumeNormalizer::Analytic}},
                                         "F in eq. 7: the samples' own estimate of the sphere's volume (wis) or the exact one"),
        P::boolean("silhouette_elimination", &VolumetricParams::silhouette_elimination,
                   "AT 4.3 for pipes: a surface more than R in front of a pipe's entry does not occlude it"),
        P::real("bias", &VolumetricParams::bias, Range::at_least(0), "world units", "added to z* - z_entry; 0 = auto (as containment)")},
       interleave_params(&VolumetricParams::interleave)}};
  return table;
}

void VolumetricParams::validate() const { volumetric_param_table().validate(*this); }
void to_json(nlohmann::json& j, const VolumetricParams& p) { j = volumetric_param_table().to_json(p); }
void from_json(const nlohmann::json& j, VolumetricParams& p) { volumetric_param_table().from_json(j, p); }

template <class Characteristic>
Image<float> volumetric_ao(const GBuffer& g, const Characteristic& ch, float radius, const VolumetricParams& params, std::uint32_t seed) {
  Falloff{Membership::Cubic, radius}.validate();
  params.validate();
  const int w = g.width(), h = g.height();
  const DiskSamples s = make_disk_samples(params.samples);
  const std::array<Rotation, 16> rotations = interleave_rotations(seed, params.interleave.interleave);
  const float R = radius, half_r = 0.5f * radius;
  // Eq. 7: F = R sum h_i (weighted importance: the samples' own estimate of |S|, whose error is
  // correlated with that of the free volume) or the exact 2Rn/3.
  float sum_h = 0;
  for (float hi : s.h) sum_h += hi;
  const float F = params.normalizer == VolumeNormalizer::WeightedImportance ? R * sum_h : 2.0f * R * static_cast<float>(params.samples) / 3.0f;
  const float inv_f = 1.0f / F;
  // AT 4.3 for pipes: a surface more than R in front of the pipe's entry is a distant foreground
  // object and does not occlude (z_entry - z* > R).
  const float far_limit = params.silhouette_elimination ? -R : -kInfinity;
  Image<float> v(w, h, 1.0f);
  parallel_for_tiles(w, h, kTile, [&](const Tile& t) {
    // A local copy: its members are then known not to alias the accumulators, so the loop vectorises.
    // Locals, not the closure's references: loads through the closure may alias the accumulators,
    // which kept them in the loop and stopped if-conversion (GCC 12: "control flow in loop").
    const Characteristic local_ch = ch;
    const float hr = half_r, lim = far_limit;
    PixelRow row;
    std::vector<int> index;  // entry k of the row is pixel t.x0 + index[k] (covered pixels only)
    std::vector<float> cx, cy, cz, free_len;
    alignas(64) float fx0[kTile], fy0[kTile], cax[kTile], cbx[kTile], cay[kTile], cby[kTile];  // depth-buffer path
    for (int y = t.y0; y < t.y1; ++y) {
      load_pixel_row_simd(row, index, g, y, t.x0, t.x1, rotations, params.bias, false);  // no tangent frame: pipes run along the view axis
      const int count = row.count;
      cx.resize(static_cast<std::size_t>(count));
      cy.resize(static_cast<std::size_t>(count));
      cz.resize(static_cast<std::size_t>(count));
      free_len.assign(static_cast<std::size_t>(count), 0.0f);
      // Fig. 4: the tangent sphere's centre x + N R/2.
      for (int k = 0; k < count; ++k) {
        const auto i = static_cast<std::size_t>(k);
        cx[i] = row.px[i] + half_r * row.nx[i];
        cy[i] = row.py[i] + half_r * row.ny[i];
        cz[i] = row.pz[i] + half_r * row.nz[i];
      }
      float* __restrict acc = free_len.data();
      const float *pcx = cx.data(), *pcy = cy.data(), *pcz = cz.data(), *rc = row.rc.data(), *rs = row.rs.data(), *bias = row.bias.data();
      if constexpr (std::is_same_v<Characteristic, DepthBufferCharacteristic>) {
        // The depth-buffer lookup with the projection hoisted out of the sample loop: a pipe's point
        // (c_x + o_x, c_y + o_y, c_z) has the same depth c_z for every sample, so the divide by -c_z
        // and the rotation fold into per-pixel affine coefficients of the pixel position:
        //   f_x = f_x0 + x_i a_x - y_i b_x,  f_y = f_y0 - x_i a_y - y_i b_y.
        const ScreenProjection pr = local_ch.projection;
        const float* __restrict depth = local_ch.depth;
        const float max_x = static_cast<float>(pr.width - 1), max_y = static_cast<float>(pr.height - 1);
        for (int k = 0; k < count; ++k) {
          const float inv = -1.0f / pcz[k], kx = inv * pr.scale_x, ky = inv * pr.scale_y;
          fx0[k] = pcx[k] * kx + pr.centre_x, fy0[k] = pr.centre_y - pcy[k] * ky;
          cax[k] = rc[k] * kx, cbx[k] = rs[k] * kx, cay[k] = rs[k] * ky, cby[k] = rc[k] * ky;
        }
        for (int i = 0; i < s.size(); ++i) {
          const float xi = hr * s.x[static_cast<std::size_t>(i)], yi = hr * s.y[static_cast<std::size_t>(i)];
          const float half_chord = hr * s.h[static_cast<std::size_t>(i)];  // (R/2) h_i = z_c - z_entry
          const float chord = 2.0f * half_chord;                              // z_exit - z_entry
#pragma GCC ivdep
          for (int k = 0; k < count; ++k) {
            const float fx = fx0[k] + xi * cax[k] - yi * cbx[k], fy = fy0[k] - xi * cay[k] - yi * cby[k];
            const float z = pcz[k];
            // As ScreenProjection::locate: clamp-to-edge, free only behind the camera.
            const bool valid = z < 0.0f;
            const int ix = static_cast<int>(std::min(std::max(valid ? fx : 0.0f, 0.0f), max_x));
            const int iy = static_cast<int>(std::min(std::max(valid ? fy : 0.0f, 0.0f), max_y));
            const float zs = depth[iy * pr.width + ix];
            // As DepthBufferCharacteristic::distance, then z* - z_entry = (z* - z_c) + (R/2) h_i.
            const float to_surface = (valid ? zs + z : kInfinity) + half_chord + bias[k];
            const float dz = std::min(std::max(to_surface, 0.0f), chord);  // fig. 7 a-c
            const bool distant = (to_surface < lim) & (to_surface > -1e30f);
            acc[k] += distant ? chord : dz;
          }
        }
      } else {
        for (int i = 0; i < s.size(); ++i) {
          // Disk sample i scaled to the sphere, rotated per pixel below by (rc, rs) about the view axis.
          const float xi = hr * s.x[static_cast<std::size_t>(i)], yi = hr * s.y[static_cast<std::size_t>(i)];
          const float half_chord = hr * s.h[static_cast<std::size_t>(i)];  // (R/2) h_i = z_c - z_entry
          const float chord = 2.0f * half_chord;                              // z_exit - z_entry
// Lane k writes only its own accumulator; the gathers read the (read-only) G-buffer.
#pragma GCC ivdep
          for (int k = 0; k < count; ++k) {
            // Disk sample rotated by the pixel's interleaving angle about the view axis, at depth z_c.
            const float ox = rc[k] * xi - rs[k] * yi, oy = rs[k] * xi + rc[k] * yi;
            // distance = z* - z_c, so z* - z_entry = distance + (R/2) h_i.
            const float to_surface = local_ch.distance(pcx[k] + ox, pcy[k] + oy, pcz[k]) + half_chord + bias[k];
            // Fig. 7: dz = clamp(z* - z_entry, 0, chord): (a) surface inside: z* - z_entry; (b) behind:
            // the chord; (c) in front: 0. Branch-free (max/min, & not &&) so the loop if-converts.
            const float dz = std::min(std::max(to_surface, 0.0f), chord);
            const bool distant = (to_surface < lim) & (to_surface > -1e30f);  // -inf: inner all along, not distant
            acc[k] += distant ? chord : dz;
          }
        }
      }
      for (int k = 0; k < count; ++k) v(t.x0 + index[static_cast<std::size_t>(k)], y) = std::min(acc[k] * inv_f, 1.0f);  // eq. 7; analytic F can overshoot 1
    }
  });
  if (params.interleave.interleave && params.interleave.filter)
    v = depth_aware_box_filter(v, g, effective_depth_limit(params.interleave, radius), carried_depth_plane(ch));
  return v;
}

Image<float> volumetric_ao(const GBuffer& g, float radius, const VolumetricParams& params, std::uint32_t seed) {
  return volumetric_ao(g, DepthBufferCharacteristic(g), radius, params, seed);
}

template Image<float> volumetric_ao(const GBuffer&, const DepthBufferCharacteristic&, float, const VolumetricParams&, std::uint32_t);
template Image<float> volumetric_ao(const GBuffer&, const ImplicitCharacteristic&, float, const VolumetricParams&, std::uint32_t);
template Image<float> volumetric_ao(const GBuffer&, const HeightFieldCharacteristic&, float, const VolumetricParams&, std::uint32_t);
template Image<float> volumetric_ao(const GBuffer&, const DepthTimesHeightField&, float, const VolumetricParams&, std::uint32_t);
template Image<float> volumetric_ao(const GBuffer&, const EliminatedDepthTimesHeightField&, float, const VolumetricParams&, std::uint32_t);

}  // namespace ao
