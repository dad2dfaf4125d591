// SPDX-License-Identifier: Apache-2.0
#include "ao/methods/alchemy/alchemy.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/core/params_table.h"
#include "ao/core/sampling.h"
#include "ao/methods/alchemy/alchemy_internal.h"
#include "ao/methods/alchemy/alchemy_kernel_internal.h"
#include "ao/methods/screen_space_method_internal.h"
#include "ao/simd/depth_plane.h"

namespace ao {

namespace alchemy_internal {

const RotationTable& rotations() {
  static const RotationTable t = [] {
    RotationTable r;
    for (int i = 0; i < kRotations; ++i) {
      const double a = 2.0 * M_PI * (i + 0.5) / kRotations;
      r.c[i] = static_cast<float>(std::cos(a));
      r.s[i] = static_cast<float>(std::sin(a));
    }
    return r;
  }();
  return t;
}

Directions sample_directions(int s) {
  // Golden angle: successive samples of the pattern are spread evenly in angle.
  constexpr float kGoldenAngle = 2.39996322972865332f;
  Directions d;
  for (int i = 0; i < s; ++i) d.x[i] = std::cos(kGoldenAngle * i), d.y[i] = std::sin(kGoldenAngle * i);
  return d;
}

}  // namespace alchemy_internal

namespace {

using alchemy_internal::kMaxPixelRadius;
using alchemy_internal::kMaxSamples;
using alchemy_internal::RotationTable;
using alchemy_internal::rotations;
// Tiles of 128 x 8 pixels: rows long enough to vectorise over pixels, and a tile's sample footprint
// (the tile grown by the disk's pixel radius) small enough to stay in L2 for typical radii.
constexpr int kTileWidth = 128, kTileHeight = 8;
static_assert(kTileWidth <= simd::kMaxAlchemySegment);
// The kernel's coordinate offset and rotation mask are the pattern's (ao/methods/alchemy/alchemy_kernel.cpp).
static_assert(alchemy_internal::kCoordOffset == 65536.0f && alchemy_internal::kRotations == 1024);

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

const ParamTable<AlchemyParams>& alchemy_param_table() {
  using P = Param<AlchemyParams>;
  static const ParamTable<AlchemyParams> table{
      "alchemy",
      {{P::real("radius", &AlchemyParams::radius, Range::at_least(0), "world units", "r of eq. 9-10; 0 = the falloff radius R"),
        P::integer("samples", &AlchemyParams::samples, Range::closed(1, kMaxSamples), "", "s of eq. 10: samples per pixel"),
        P::enumeration<AlchemyPreset>("preset", &AlchemyParams::preset, {{"fitted", AlchemyPreset::Fitted}, {"paper", AlchemyPreset::Paper}},
                                      "sigma when intensity is null: fitted 0.4 (least RMSE against the reference), paper 1"),
        P::optional_real("intensity", &AlchemyParams::intensity, Range::at_least(0), "paper metres", "sigma of eq. 10; null = the preset's"),
        P::real("contrast", &AlchemyParams::contrast, Range::above(0), "", "k of eq. 10"),
        P::real("bias", &AlchemyParams::bias, Range::at_least(0), "", "beta of eq. 10, multiplies z_C"),
        P::real("epsilon", &AlchemyParams::epsilon, Range::above(0), "paper square metres", "epsilon of eq. 10"),
        P::real("meter", &AlchemyParams::meter, Range::at_least(0), "world units", "world units per paper metre; 0 = r / 0.5"),
        P::boolean("filter", &AlchemyParams::filter, "apply the cross-bilateral filter (sec. 2, pass 5)")},
       bilateral_params<AlchemyParams>("filter_", [](AlchemyParams& p) -> BilateralParams& { return p.bilateral; }),
       depth_layer_params(&AlchemyParams::layers)}};
  return table;
}

void AlchemyParams::validate() const {
  alchemy_param_table().validate(*this);
  bilateral.validate();
}
void to_json(nlohmann::json& j, const AlchemyParams& p) { j = alchemy_param_table().to_json(p); }
void from_json(const nlohmann::json& j, AlchemyParams& p) { alchemy_param_table().from_json(j, p); }

AlchemyConstants alchemy_constants(const AlchemyParams& p, float default_radius) {
  p.validate();
  const float r = p.radius > 0 ? p.radius : default_radius;
  if (!(r > 0.0f) || !std::isfinite(r)) throw InputError("alchemy: radius r must be a positive number of world units");
  // The paper's constants are metric and its images use r = 0.5 m: by default one paper metre is 2r.
  const float m = p.meter > 0 ? p.meter : r / 0.5f;
  // sigma is a length and epsilon an area in eq. 10 (v.n / v.v is 1/length); beta multiplies z_C and
  // is compared with v.n, both lengths, so it is a pure number and is not scaled.
  return {r, m, p.effective_intensity() * m, p.epsilon * m * m, p.bias};
}

AlchemyImage render_alchemy(const GBuffer& g, const AlchemyParams& params, float default_radius, std::uint32_t seed, const ProgressFn& progress) {
  if (params.layers.layers < 2) return render_alchemy(g, nullptr, params, default_radius, seed, progress);
  const float separation = effective_separation(params.layers, alchemy_constants(params, default_radius).radius);
  if (!has_second_layer(g, separation)) throw_missing_second_layer("alchemy", separation);
  return render_alchemy(g, &g.second_depth, params, default_radius, seed, progress);
}

AlchemyImage render_alchemy(const GBuffer& g, const Image<float>* second_layer, const AlchemyParams& params, float default_radius,
                            std::uint32_t seed, const ProgressFn& progress) {
  const AlchemyConstants k = alchemy_constants(params, default_radius);
  if (params.layers.layers == 2 && !second_layer) throw_missing_second_layer("alchemy", effective_separation(params.layers, k.radius));
  const int w = g.width(), h = g.height(), s = params.samples;
  AlchemyImage out;
  out.visibility.resize(w, h);  // every pixel written by alchemy_row (1 where not covered), in parallel
  const auto t0 = std::chrono::steady_clock::now();

  // Screen radius of the world disk: both image axes have 0.5 * height / tan(fov/2) pixels per unit
  // of x/(-z) (camera.h's projection), so the disk of radius r at depth z_C projects to a disk of
  // radius r * that / z_C, and uniform area on it is uniform area on the world disk (sec. 2.3):
  // DepthView::px_per_unit.
  // 2 sigma / s: eq. 9's 2 pi u / s (uniform directions, pdf 1/(2 pi)) times the paper's nominal
  // 1/pi (sec. 2.3), with u folded into sigma.
  const float scale = 2.0f * k.sigma / static_cast<float>(s);
  // Sample points are read from the depth buffer, P = z(Q') * (camera ray through the pixel centre),
  // as sec. 2.3 allows ("read a depth or position buffer"): one 4-byte gather per sample instead of
  // three from the 12-byte positions, which keeps a tile's sample footprint in L2 (the gathers' cache
  // misses were most of the time; docs/methods/alchemy.md). C is reconstructed the same way, so C and
  // its samples agree exactly on a plane.
  const Image<float> depth_image = depth_plane(g);  // also the filter's
  const float t = g.camera.tan_half_fov();
  const alchemy_internal::Directions directions = alchemy_internal::sample_directions(s);
  const std::array<float, kMaxSamples>&ux = directions.x, &uy = directions.y;
  const RotationTable& rot = rotations();
  simd::AlchemyInputs in;
  static_cast<simd::DepthView&>(in) = simd::depth_view(depth_image.data(), &g.normal.data()->x, g.object_id.data(), w, h, t, g.camera.aspect());
  in.radius = k.radius, in.max_pixel_radius = kMaxPixelRadius;
  in.epsilon = k.epsilon, in.beta = k.beta, in.scale = scale, in.samples = s;
  in.ux = ux.data(), in.uy = uy.data(), in.rot_c = rot.c.data(), in.rot_s = rot.s.data(), in.seed = seed;
  if (params.layers.layers == 2) {
    if (second_layer->width() != w || second_layer->height() != h) throw InputError("alchemy: the second depth layer must have the G-buffer's size");
    in.second = second_layer->data();
  }
  const float contrast = params.contrast;
  ProgressCounter counter(progress, static_cast<std::size_t>(w) * h);
  tbb::parallel_for(
      tbb::blocked_range2d<int>(0, h, kTileHeight, 0, w, kTileWidth),
      [&](const tbb::blocked_range2d<int>& range) {
        const int x0 = range.cols().begin(), x1 = range.cols().end();
        for (int y = range.rows().begin(); y < range.rows().end(); ++y) {
          float* v = &out.visibility(x0, y);
          simd::alchemy_row(in, y, x0, x1, v);
          if (contrast != 1.0f)
            for (int j = 0; j < x1 - x0; ++j) v[j] = std::pow(v[j], contrast);  // eq. 10's ^k; 1 stays 1
        }
        counter.add(static_cast<std::size_t>(x1 - x0) * (range.rows().end() - range.rows().begin()));
      },
      tbb::simple_partitioner());
  out.estimator_ms = ms_since(t0);
  if (params.filter) {
    const auto t1 = std::chrono::steady_clock::now();
    out.unfiltered = out.visibility;
    bilateral_filter(g, depth_image, out.visibility, params.bilateral);
    out.filter_ms = ms_since(t1);
  }
  return out;
}

MethodOutput run(const MethodInput& in, const AlchemyParams& params) {
  params.validate();
  // Two layers: the G-buffer's second layer, or one traced for this run (the separation scales with r).
  std::shared_ptr<const Image<float>> second;
  if (params.layers.layers == 2)
    second = detail::second_layer_for(in, effective_separation(params.layers, alchemy_constants(params, in.falloff.radius).radius), "alchemy");
  AlchemyImage img = render_alchemy(in.gbuffer, second.get(), params, in.falloff.radius, in.seed, in.progress);
  MethodOutput out;
  out.visibility = std::move(img.visibility);
  if (!img.unfiltered.empty()) out.extras["unfiltered"] = std::move(img.unfiltered);
  out.stats = nlohmann::json{{"estimator_ms", img.estimator_ms}, {"filter_ms", img.filter_ms}};
  return out;
}

void check_gpu(const AlchemyParams& params) {
  if (params.layers.layers != 1)
    throw InputError("alchemy: layers=2 (a second depth layer) runs on the CPU backend only; the GPU shaders read one layer");
}

}  // namespace ao
