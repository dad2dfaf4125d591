// SPDX-License-Identifier: Apache-2.0
#include "ao/methods/volumetric/volumetric.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>

#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/core/params_table.h"
#include "ao/methods/characteristic.h"
#include "ao/methods/containment/containment.h"
#include "ao/methods/samples.h"
#include "ao/methods/screen_space_internal.h"
#include "ao/methods/screen_space_method_internal.h"
#include "ao/methods/volumetric/volumetric_kernel_internal.h"
#include "ao/simd/depth_plane.h"

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
       interleave_params(&VolumetricParams::interleave), depth_layer_params(&VolumetricParams::layers),
       {thickness_param(&VolumetricParams::layers)},
       {characteristic_param(&VolumetricParams::characteristic)}}};
  return table;
}

void VolumetricParams::validate() const {
  volumetric_param_table().validate(*this);
  check_thickness(layers, "volumetric");
}
void to_json(nlohmann::json& j, const VolumetricParams& p) { j = volumetric_param_table().to_json(p); }
void from_json(const nlohmann::json& j, VolumetricParams& p) { volumetric_param_table().from_json(j, p); }

namespace {

// VAO eq. 6-7 with an analytic characteristic function: simd::sum_free_pipes one pixel at a time
// (the analytic scenes are small test scenes). free[k] = sum over the pipes of entry k of their
// free length inside the tangent sphere.
template <class Characteristic>
void sum_free_pipes(const simd::CoveredPixels& row, const Characteristic& ch, float half_r, const DiskSamples& s, float far_limit, float* free) {
  for (int k = 0; k < row.count; ++k) {
    const auto e = static_cast<std::size_t>(k);
    // Fig. 4: the tangent sphere's centre x + N R/2.
    const float cx = row.px[e] + half_r * row.nx[e], cy = row.py[e] + half_r * row.ny[e], cz = row.pz[e] + half_r * row.nz[e];
    float acc = 0.0f;
    for (int i = 0; i < s.size(); ++i) {
      const auto si = static_cast<std::size_t>(i);
      // Disk sample i scaled to the sphere, rotated by the pixel's interleaving angle about the view axis, at depth z_c.
      const float xi = half_r * s.x[si], yi = half_r * s.y[si];
      const float half_chord = half_r * s.h[si];  // (R/2) h_i = z_c - z_entry
      const float chord = 2.0f * half_chord;       // z_exit - z_entry
      const float ox = row.rc[e] * xi - row.rs[e] * yi, oy = row.rs[e] * xi + row.rc[e] * yi;
      // distance = z* - z_c, so z* - z_entry = distance + (R/2) h_i.
      const float to_surface = ch.distance(cx + ox, cy + oy, cz) + half_chord + row.bias[e];
      // Fig. 7: dz = clamp(z* - z_entry, 0, chord): (a) surface inside: z* - z_entry; (b) behind:
      // the chord; (c) in front: 0. AT 4.3 for pipes: a distant foreground surface leaves it free.
      const float dz = std::min(std::max(to_surface, 0.0f), chord);
      const bool distant = to_surface < far_limit && to_surface > -1e30f;  // -inf: inner all along, not distant
      acc += distant ? chord : dz;
    }
    free[k] = acc;
  }
}

}  // namespace

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
  const simd::Rotations16 rot = simd_rotations(rotations);
  check_layers(ch, params.layers, radius, "volumetric");
  // V = 1 where nothing is covered: each tile fills its own rows, so the image's fresh pages are
  // first touched in parallel.
  Image<float> v;
  v.resize(w, h);
  parallel_for_tiles(w, h, kTile, [&](const Tile& t) {
    simd::CoveredPixels row;
    simd::AlignedVector<float> free_len(static_cast<std::size_t>(simd::padded(t.x1 - t.x0)));
    for (int y = t.y0; y < t.y1; ++y) {
      std::fill_n(&v(t.x0, y), t.x1 - t.x0, 1.0f);
      simd::load_covered_pixels(row, g, y, t.x0, t.x1, rot, params.bias, false);  // no tangent frame: pipes run along the view axis
      if constexpr (std::is_same_v<Characteristic, DepthBufferCharacteristic>)
        simd::sum_free_pipes(row, simd_depth_plane(ch, params.layers), half_r, simd_points(s), far_limit, free_len.data());
      else
        sum_free_pipes(row, ch, half_r, s, far_limit, free_len.data());
      for (int k = 0; k < row.count; ++k)
        v(t.x0 + row.index[static_cast<std::size_t>(k)], y) = std::min(free_len[static_cast<std::size_t>(k)] * inv_f, 1.0f);  // eq. 7; analytic F can overshoot 1
    }
  });
  if (params.interleave.interleave && params.interleave.filter)
    v = depth_aware_box_filter(v, g, effective_depth_limit(params.interleave, radius), carried_depth_plane(ch));
  return v;
}

Image<float> volumetric_ao(const GBuffer& g, float radius, const VolumetricParams& params, std::uint32_t seed) {
  return volumetric_ao(g, depth_characteristic(g, params.layers, radius, "volumetric"), radius, params, seed);
}

MethodOutput run(const MethodInput& in, const VolumetricParams& params) {
  MethodOutput out;
  // The kernel eliminates a surface more than R in front of a pipe's entry, which lies up to R/2 in
  // front of the sphere's centre, where the characteristic is read: a depth-buffer surface more than
  // 1.5 R in front of the centre is distant for every pipe, so the wrapped factor never drops a
  // surface the kernel's per-pipe test would keep.
  detail::with_characteristic(in, params.characteristic, params.layers, "volumetric", params.silhouette_elimination, 1.5f * in.falloff.radius,
                              [&](const auto& ch, bool kernel_elimination) {
                                VolumetricParams q = params;
                                q.silhouette_elimination = kernel_elimination;
                                out.visibility = volumetric_ao(in.gbuffer, ch, in.falloff.radius, q, in.seed);
                              });
  detail::add_characteristic_stats(out, params.characteristic, params.silhouette_elimination);
  return out;
}

void check_gpu(const VolumetricParams& params) { detail::check_gpu_screen_space("volumetric", params.characteristic, params.layers); }

template Image<float> volumetric_ao(const GBuffer&, const DepthBufferCharacteristic&, float, const VolumetricParams&, std::uint32_t);
template Image<float> volumetric_ao(const GBuffer&, const ImplicitCharacteristic&, float, const VolumetricParams&, std::uint32_t);
template Image<float> volumetric_ao(const GBuffer&, const HeightFieldCharacteristic&, float, const VolumetricParams&, std::uint32_t);
template Image<float> volumetric_ao(const GBuffer&, const DepthTimesHeightField&, float, const VolumetricParams&, std::uint32_t);
template Image<float> volumetric_ao(const GBuffer&, const EliminatedDepthTimesHeightField&, float, const VolumetricParams&, std::uint32_t);

}  // namespace ao
