// SPDX-License-Identifier: Apache-2.0
#include "ao/methods/containment/containment.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>

#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/core/params_table.h"
#include "ao/methods/characteristic.h"
#include "ao/methods/containment/containment_kernel_internal.h"
#include "ao/methods/samples.h"
#include "ao/methods/screen_space_internal.h"
#include "ao/methods/screen_space_method_internal.h"
#include "ao/simd/depth_plane.h"

namespace ao {

namespace {
constexpr float kInfinityLike = 1e30f;  // below this a distance stands for -infinity (characteristic.h)
// Tiles of 128 x 16 pixels: a row segment of eight 16-lane vectors per sample loop, and few rows
// per tile; faster than 64 x 64 tiles in bench containment/0.
constexpr int kTileWidth = 128, kTileHeight = 16;
constexpr int kMaxRaySteps = 8;
}

const ParamTable<ContainmentParams>& containment_param_table() {
  using P = Param<ContainmentParams>;
  static const ParamTable<ContainmentParams> table{
      "containment",
      {{P::integer("samples", &ContainmentParams::samples, Range::closed(1, kMaxScreenSpaceSamples), "", "n in eq. 5: test points per pixel"),
        P::integer("ray_steps", &ContainmentParams::ray_steps, Range::closed(1, kMaxRaySteps), "",
                   "m: tests along each ray at (j/m) r, j = 1..m (AT sec. 4); 1 = eq. 5's end point only"),
        P::boolean("silhouette_elimination", &ContainmentParams::silhouette_elimination,
                   "AT 4.3: a point is occluded only if the surface in front of it is less than R in front"),
        P::real("bias", &ContainmentParams::bias, Range::at_least(0), "world units",
                "depth-test bias; 0 = auto (one pixel footprint x (1 + tan theta_v))")},
       interleave_params(&ContainmentParams::interleave), depth_layer_params(&ContainmentParams::layers),
       {thickness_param(&ContainmentParams::layers)},
       {characteristic_param(&ContainmentParams::characteristic)}}};
  return table;
}

void ContainmentParams::validate() const {
  containment_param_table().validate(*this);
  check_thickness(layers, "containment");
}
void to_json(nlohmann::json& j, const ContainmentParams& p) { j = containment_param_table().to_json(p); }
void from_json(const nlohmann::json& j, ContainmentParams& p) { containment_param_table().from_json(j, p); }

namespace {

// VAO eq. 5 and AT sec. 4 with an analytic characteristic function: the tests of
// simd::count_open_rays, one pixel at a time (the analytic scenes are small test scenes).
// open[k] = the number of entry k's rays whose m test points are all free.
template <class Characteristic>
void count_open_rays(const simd::CoveredPixels& row, const Characteristic& ch, const ContainmentSamples& s, int m, float far_limit,
                     float* open) {
  const float inv_m = 1.0f / static_cast<float>(m);
  for (int k = 0; k < row.count; ++k) {
    const auto e = static_cast<std::size_t>(k);
    const Vec3 x{row.px[e], row.py[e], row.pz[e]}, t{row.tx[e], row.ty[e], row.tz[e]}, b{row.bx[e], row.by[e], row.bz[e]},
        n{row.nx[e], row.ny[e], row.nz[e]};
    int free_rays = 0;
    for (int i = 0; i < s.size(); ++i) {
      const auto si = static_cast<std::size_t>(i);
      bool blocked = false;
      for (int j = 1; j <= m; ++j) {
        // AT sec. 4: I = prod_j I0(x + w r j/m); VAO eq. 5: p_i = x + X_i T + Y_i B + Z_i N.
        const float f = static_cast<float>(j) * inv_m;
        const Vec3 q = x + t * (f * s.x[si]) + b * (f * s.y[si]) + n * (f * s.z[si]);
        const float d = ch.distance(q.x, q.y, q.z);
        // AT 4.3: occluded only if the surface is less than R in front; an analytic surface's
        // -FLT_MAX ("inner along the whole line") is never a distant foreground object.
        const bool near = d > far_limit || d < -kInfinityLike;
        blocked = blocked || (d < -row.bias[e] && near);
      }
      free_rays += blocked ? 0 : 1;
    }
    open[k] = static_cast<float>(free_rays);
  }
}

}  // namespace

template <class Characteristic>
Image<float> containment_ao(const GBuffer& g, const Characteristic& ch, const Falloff& falloff, const ContainmentParams& params,
                            std::uint32_t seed) {
  falloff.validate();
  params.validate();
  const int w = g.width(), h = g.height();
  const ContainmentSamples s = make_containment_samples(params.samples, falloff);
  const std::array<Rotation, 16> rotations = interleave_rotations(seed, params.interleave.interleave);
  // AT 4.3: a test point is occluded only if R > z - z* > 0, i.e. distance in (-R, -bias).
  const float far_limit = params.silhouette_elimination ? -falloff.radius : -kInfinity;
  const float inv_n = 1.0f / static_cast<float>(params.samples);
  const int m = params.ray_steps;
  const simd::Rotations16 rot = simd_rotations(rotations);
  check_layers(ch, params.layers, falloff.radius, "containment");
  // V = 1 where nothing is covered: each tile fills its own rows, so the image's fresh pages are
  // first touched in parallel.
  Image<float> v;
  v.resize(w, h);
  parallel_for_tiles(w, h, kTileWidth, kTileHeight, [&](const Tile& t) {
    simd::CoveredPixels row;
    simd::AlignedVector<float> open(static_cast<std::size_t>(simd::padded(t.x1 - t.x0)));
    for (int y = t.y0; y < t.y1; ++y) {
      std::fill_n(&v(t.x0, y), t.x1 - t.x0, 1.0f);
      simd::load_covered_pixels(row, g, y, t.x0, t.x1, rot, params.bias, true);
      if constexpr (std::is_same_v<Characteristic, DepthBufferCharacteristic>)
        simd::count_open_rays(row, simd_depth_plane(ch, params.layers), simd_points(s), m, far_limit, open.data());
      else
        count_open_rays(row, ch, s, m, far_limit, open.data());
      // Eq. 5: V = the fraction of free test points (of free rays, with m > 1).
      for (int k = 0; k < row.count; ++k) v(t.x0 + row.index[static_cast<std::size_t>(k)], y) = open[static_cast<std::size_t>(k)] * inv_n;
    }
  });
  if (params.interleave.interleave && params.interleave.filter)
    v = depth_aware_box_filter(v, g, effective_depth_limit(params.interleave, falloff.radius), carried_depth_plane(ch));
  return v;
}

Image<float> containment_ao(const GBuffer& g, const Falloff& falloff, const ContainmentParams& params, std::uint32_t seed) {
  return containment_ao(g, depth_characteristic(g, params.layers, falloff.radius, "containment"), falloff, params, seed);
}

MethodOutput run(const MethodInput& in, const ContainmentParams& params) {
  MethodOutput out;
  // AT 4.3 tests the sample point itself: a surface more than R in front of it is distant.
  detail::with_characteristic(in, params.characteristic, params.layers, "containment", params.silhouette_elimination, in.falloff.radius,
                              [&](const auto& ch, bool kernel_elimination) {
                                ContainmentParams q = params;
                                q.silhouette_elimination = kernel_elimination;
                                out.visibility = containment_ao(in.gbuffer, ch, in.falloff, q, in.seed);
                              });
  detail::add_characteristic_stats(out, params.characteristic, params.silhouette_elimination);
  return out;
}

void check_gpu(const ContainmentParams& params) {
  detail::check_gpu_screen_space("containment", params.characteristic, params.layers);
}

template Image<float> containment_ao(const GBuffer&, const DepthBufferCharacteristic&, const Falloff&, const ContainmentParams&, std::uint32_t);
template Image<float> containment_ao(const GBuffer&, const ImplicitCharacteristic&, const Falloff&, const ContainmentParams&, std::uint32_t);
template Image<float> containment_ao(const GBuffer&, const HeightFieldCharacteristic&, const Falloff&, const ContainmentParams&, std::uint32_t);
template Image<float> containment_ao(const GBuffer&, const DepthTimesHeightField&, const Falloff&, const ContainmentParams&, std::uint32_t);
template Image<float> containment_ao(const GBuffer&, const EliminatedDepthTimesHeightField&, const Falloff&, const ContainmentParams&,
                                     std::uint32_t);

}  // namespace ao
