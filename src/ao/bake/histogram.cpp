// SPDX-License-Identifier: Apache-2.0
// Based on McGraw & Sowers, "Hardware Accelerated Per-Texel Ambient Occlusion Mapping" (2008).
//
// The paper's pipeline, stage by stage, and where it lives here:
//  - Directions w_d uniform on the sphere (sec. 3, after eq. 6): sphere_directions.cpp.
//  - Stage 1, "render from light direction w": an orthographic z-buffered rasterisation with back-face
//    culling (ortho_raster.cpp, simd::rasterize_front_faces). For each visible pixel the fragment
//    program outputs (u, v) and (w . n)|J|, with n the interpolated normal and |J| =
//    |det d(u,v)/d(x_w,y_w)| (eq. 9). We recompute (u, v) and (w . n) from the pixel's barycentrics
//    in the scatter (simd::scatter_histogram, src/ao/bake/histogram_kernel.cpp); |J| of an
//    affine map is the ratio of the triangle's UV area to its image area, exactly what the paper's
//    dFdx/dFdy estimate (they are exact for linear interpolation).
//  - Stage 2, "sum over pixels": the histogram scatter of eq. 7-8, each pixel adding (w . n)|J| to
//    the texel holding its (u, v).
//  - Stage 3, normalisation and seams (sec. 3.3): below, and padding.cpp.
//
// Normalisation. Eq. 8 leaves the constant C open and the paper fixes it by scaling the largest
// value to 1 (BakeNormalization::Max). The default computes it. With D directions uniform on the
// sphere, (1/pi) * integral over the hemisphere ~= (1/pi)(4 pi / D) sum_d = (4/D) sum_d, and each
// pixel of world area p^2 covers p^2 / (w . n_g) of surface, so
//     V(T) = (4/D) * sum_d sum_pixels in T  (w . n) * p^2 / (w . n_g)  /  A(T)                 (eq. 2)
// with A(T) the world area of the texel's patch (texel_coverage.cpp). The per-pixel weight is the
// paper's (w . n)|J| times the triangle's stretch s = world area / UV area: |J| s = 1 / (w . n_g),
// i.e. |J| converts image area to UV area (sec. 3.1) and s converts UV area to surface area, so
// no constant-stretch-per-texel assumption (eq. 4) is needed. On flat geometry (n = n_g) the weight
// is 1: the estimate is the count of visible pixels, i.e. the texel's visible projected area.
//
// Deviations: the splat (sec. 3.2) is applied as a box convolution of the accumulated histogram,
// which is what additive blending of points of that size computes, once instead of per fragment.
// Accumulation is in 64-bit fixed point (weights quantised to 2^-20), so per-thread buffers sum
// to the same bits in any order: the map is identical at any thread count.
#include "ao/bake/histogram.h"

#include <cmath>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "ao/bake/ortho_raster.h"
#include "ao/bake/padding.h"
#include "ao/core/error.h"
#include "ao/core/params_table.h"
#include "ao/core/sampling.h"
#include "ao/bake/histogram_kernel_internal.h"

namespace ao {

namespace {

constexpr double kFixedScale = 1048576.0;  // 2^20
// Upper bound of a pixel's weight (w . n)/(w . n_g) in units of 1: reached only on nearly edge-on
// triangles whose interpolated normal leans far from the face normal; those pixels are rare and
// their expected contribution is bounded, so the clamp only removes spikes of noise.
constexpr float kMaxWeight = 64.0f;
// How far (texel rings) a texel with too few expected samples looks for a reliable one.
constexpr int kUnreliableRings = 8;

struct ThreadAccum {
  std::vector<std::uint64_t> sum;
  std::vector<std::int64_t> bent;  // 3 per texel
  std::vector<float> cos_v;        // per vertex, w . n
  std::uint64_t fragments = 0;
  RasterTarget target;
};

// 1-D weights of a box of width `size` texels centred on a texel: the overlap of [k-0.5, k+0.5]
// with [-size/2, size/2], i.e. an antialiased point of that size (sec. 3.2).
std::vector<double> box_weights(float size) {
  const int r = static_cast<int>(std::ceil(size / 2 - 0.5f));
  std::vector<double> w(static_cast<std::size_t>(2 * r + 1));
  for (int k = -r; k <= r; ++k)
    w[static_cast<std::size_t>(k + r)] = std::max(0.0, std::min<double>(k + 0.5, size / 2.0) - std::max<double>(k - 0.5, -size / 2.0));
  return w;
}

void box_filter(std::vector<double>& img, int width, int height, const std::vector<double>& kw) {
  const int r = static_cast<int>(kw.size() / 2);
  std::vector<double> tmp(img.size(), 0.0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      double s = 0;
      for (int k = -r; k <= r; ++k)
        if (x + k >= 0 && x + k < width) s += kw[static_cast<std::size_t>(k + r)] * img[static_cast<std::size_t>(y) * width + x + k];
      tmp[static_cast<std::size_t>(y) * width + x] = s;
    }
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      double s = 0;
      for (int k = -r; k <= r; ++k)
        if (y + k >= 0 && y + k < height) s += kw[static_cast<std::size_t>(k + r)] * tmp[static_cast<std::size_t>(y + k) * width + x];
      img[static_cast<std::size_t>(y) * width + x] = s;
    }
}

}  // namespace

std::string_view to_string(BakeNormalization n) { return n == BakeNormalization::Area ? "area" : "max"; }

std::optional<BakeNormalization> parse_normalization(std::string_view name) {
  if (name == "area") return BakeNormalization::Area;
  if (name == "max") return BakeNormalization::Max;
  return std::nullopt;
}

const ParamTable<HistogramParams>& histogram_param_table() {
  using P = Param<HistogramParams>;
  using H = HistogramParams;
  static const ParamTable<H> table{
      "bake histogram",
      {P::integer("directions", &H::directions, Range::closed(1, 65536), "", "D: directions on the whole sphere (about half light a texel)"),
       P::enumeration<DirectionSet>("direction_set", &H::direction_set, {{"fibonacci", DirectionSet::Fibonacci}, {"gaussian", DirectionSet::Gaussian}},
                                    "fibonacci (stratified; lower error) or the paper's gaussian"),
       P::real("pixels_per_texel", &H::pixels_per_texel, Range::open_closed(0, 8), "", "view resolution: pixels along an average texel's edge seen face-on"),
       P::real("point_size", &H::point_size, Range::closed(1, 16), "texels", "sec. 3.2 splat size: 1 = one texel (no smoothing); > 1 blurs"),
       P::enumeration<BakeNormalization>("normalization", &H::normalization, {{"area", BakeNormalization::Area}, {"max", BakeNormalization::Max}},
                                         "area (exact, absolute V) or max (the paper's: the most open texel is 1)"),
       P::boolean("seam_fix", &H::seam_fix, "sec. 3.3: refill chart-border texels less than half covered from the nearest well-covered texel"),
       P::real("min_samples", &H::min_samples, Range::closed(0, 1e6), "",
               "texels expected to get fewer pixel samples than this (chart slivers) copy the nearest texel that gets enough; 0 = off"),
       P::boolean("bent_normals", &H::bent_normals, "also accumulate the average unoccluded direction (sec. 3)"),
       P::seed("seed", &H::seed, "keys the directions and the per-direction pixel-grid offsets")}};
  return table;
}

void HistogramParams::validate() const { histogram_param_table().validate(*this); }
void to_json(nlohmann::json& j, const HistogramParams& p) { j = histogram_param_table().to_json(p); }
void from_json(const nlohmann::json& j, HistogramParams& p) { histogram_param_table().from_json(j, p); }

float histogram_pixel_size(const TexelCoverage& coverage, float pixels_per_texel) {
  double area = 0;
  for (float a : coverage.world_area.pixels()) area += a;
  const double per_texel = area / static_cast<double>(std::max<std::size_t>(coverage.covered_texels, 1));
  return static_cast<float>(std::sqrt(per_texel) / pixels_per_texel);
}

namespace {

// The histogram's sums over every direction (stages 1 and 2), merged over threads.
struct HistogramSums {
  std::vector<double> num;          // per texel: sum_d sum_pixels of the weights (eq. 8), pixel units
  std::vector<std::int64_t> bent;   // 3 per texel, fixed point: the bent normal's unnormalised sum
  std::uint64_t fragments = 0;
};

// Stage 1 (rasterise from w_d) and stage 2 (scatter into the texels) for every direction, each
// thread into its own integer buffers; the merge adds integers, so the order of threads does not
// matter.
HistogramSums scatter_directions(const RasterMesh& mesh, const TexelCoverage& cov, const std::vector<Vec3>& dirs, float pixel_size,
                                 const HistogramParams& params, const ProgressFn& progress) {
  const std::size_t texels = cov.texel_count();
  const bool bent = params.bent_normals;
  tbb::enumerable_thread_specific<ThreadAccum> accum;
  ProgressCounter counter(progress, dirs.size());
  tbb::parallel_for(tbb::blocked_range<int>(0, static_cast<int>(dirs.size()), 1), [&](const tbb::blocked_range<int>& range) {
    ThreadAccum& acc = accum.local();
    if (acc.sum.empty()) {
      acc.sum.assign(texels, 0);
      if (bent) acc.bent.assign(3 * texels, 0);
      acc.cos_v.resize(mesh.positions.size());
    }
    for (int d = range.begin(); d < range.end(); ++d) {
      const Vec3 w = dirs[static_cast<std::size_t>(d)];
      const std::uint32_t key = hash_combine(hash32(params.seed), static_cast<std::uint32_t>(d));
      const Vec2 jitter{to_unit_float(hash_combine(key, 1)), to_unit_float(hash_combine(key, 2))};
      const OrthoView view = make_ortho_view(mesh, w, pixel_size, jitter);
      rasterize(mesh, view, acc.target);  // stage 1
      for (std::size_t i = 0; i < mesh.normals.size(); ++i) acc.cos_v[i] = dot(w, mesh.normals[i]);
      // Stage 2: the histogram scatter, eq. 8, in its SIMD kernel (histogram_kernel.cpp, compiled for every x86-64 target).
      simd::ScatterInput in;
      in.ids = acc.target.id.data(), in.px = acc.target.px.data(), in.py = acc.target.py.data();
      in.view_width = view.width, in.view_height = view.height;
      in.indices = mesh.indices.data(), in.has_uv = mesh.has_uv.data(), in.stretch = mesh.stretch.data(), in.uvs = mesh.uvs.data();
      in.cos_v = acc.cos_v.data(), in.map_width = cov.width, in.map_height = cov.height, in.pixel_size = pixel_size;
      in.area_norm = params.normalization == BakeNormalization::Area;
      in.max_weight = kMaxWeight, in.fixed_scale = kFixedScale, in.bent = bent;
      in.bx = std::llround(w.x * 1024.0), in.by = std::llround(w.y * 1024.0), in.bz = std::llround(w.z * 1024.0);
      acc.fragments += simd::scatter_histogram(in, acc.sum.data(), bent ? acc.bent.data() : nullptr);
      counter.add(1);
    }
  });

  HistogramSums sums;
  sums.num.assign(texels, 0.0);
  sums.bent.assign(bent ? 3 * texels : 0, 0);
  std::vector<std::uint64_t> total(texels, 0);
  for (ThreadAccum& acc : accum) {
    if (acc.sum.empty()) continue;
    for (std::size_t i = 0; i < texels; ++i) total[i] += acc.sum[i];
    for (std::size_t i = 0; i < sums.bent.size(); ++i) sums.bent[i] += acc.bent[i];
    sums.fragments += acc.fragments;
  }
  for (std::size_t i = 0; i < texels; ++i) sums.num[i] = static_cast<double>(total[i]) / kFixedScale;
  return sums;
}

// Stage 3's normalisation: V per covered texel from the sums and A(T) in pixel units (`den`), by
// eq. 2 or the paper's max; the bent normals normalised. Returns how many texels the clamp to 1 cut.
std::size_t normalize_visibility(const HistogramSums& sums, const std::vector<double>& den, const TexelCoverage& cov,
                                 const HistogramParams& params, BakeResult& out) {
  const std::size_t texels = cov.texel_count();
  const bool area_norm = params.normalization == BakeNormalization::Area;
  out.visibility = Image<float>(cov.width, cov.height, 0.0f);
  double max_num = 0;
  for (std::size_t i = 0; i < texels; ++i)
    if (cov.mask[i]) max_num = std::max(max_num, sums.num[i]);
  std::size_t clamped = 0;
  for (std::size_t i = 0; i < texels; ++i) {
    if (!cov.mask[i]) continue;
    double v = 0;
    if (area_norm) v = den[i] > 0 ? 4.0 / params.directions * sums.num[i] / den[i] : 0.0;  // eq. 2 with (4/D) sum_d
    else v = max_num > 0 ? sums.num[i] / max_num : 0.0;                                   // the paper: max(1 - AO) = 1
    // Monte Carlo noise can exceed 1 on open texels; V is a fraction, so clamp (and count it).
    if (v > 1.0) ++clamped;
    out.visibility[i] = static_cast<float>(std::clamp(v, 0.0, 1.0));
  }
  if (params.bent_normals) {
    out.bent_normal = Image<Vec3>(cov.width, cov.height, Vec3{0, 0, 0});
    for (std::size_t i = 0; i < texels; ++i)
      if (cov.mask[i])
        out.bent_normal[i] = normalize(Vec3{static_cast<float>(sums.bent[3 * i]), static_cast<float>(sums.bent[3 * i + 1]),
                                            static_cast<float>(sums.bent[3 * i + 2])});
  }
  return clamped;
}

struct RefillCounts {
  std::size_t unreliable = 0, unfilled = 0;
};

// Texels that too few pixel samples can reach. A texel's expected number of samples over all
// directions is (D/4) A(T)/p^2 (a quarter of its area faces a random direction, in pixels). A
// chart that grazes a texel with a sliver of surface (the dragon at 512^2 has thousands with
// A(T) < 1e-3 of an average texel's) expects far less than one: no pixel lands in it and the
// ratio says V = 0, a black texel on the chart border that is not occlusion at all (and with
// a handful of samples the estimate is mostly noise). Such texels are not estimated: they take
// the value of the nearest texel that is. With the seam fix, chart-border texels too (sec. 3.3).
RefillCounts refill_unestimated_texels(const std::vector<double>& num, const std::vector<double>& den, const TexelCoverage& cov,
                                       const HistogramParams& params, BakeResult& out) {
  const std::size_t texels = cov.texel_count();
  const double samples_per_pixel_area = static_cast<double>(params.directions) / 4.0;
  Image<std::uint8_t> reliable(cov.width, cov.height, 0);
  RefillCounts counts;
  for (std::size_t i = 0; i < texels; ++i) {
    if (!cov.mask[i]) continue;
    const double expected = samples_per_pixel_area * den[i];  // den: A(T)/p^2, box-filtered with the splats
    reliable[i] = expected >= params.min_samples ? 1 : 0;
    counts.unreliable += reliable[i] ? 0 : 1;
  }
  std::vector<std::uint8_t> refilled(texels, 0);
  auto refill = [&](const Image<std::uint8_t>& keep, int rings, bool only_unreliable) {
    const Image<std::int32_t> nearest = nearest_valid_texel(keep, rings);
    for (std::size_t i = 0; i < texels; ++i) {
      if (!cov.mask[i] || keep[i] || refilled[i] || nearest[i] < 0 || (only_unreliable && reliable[i])) continue;
      out.visibility[i] = out.visibility[static_cast<std::size_t>(nearest[i])];
      if (params.bent_normals) out.bent_normal[i] = out.bent_normal[static_cast<std::size_t>(nearest[i])];
      refilled[i] = 1;
    }
  };
  if (params.seam_fix) {
    // Sec. 3.3: discard chart-boundary texels (erosion) and refill them from the nearest kept texel
    // (dilation). Deviation: we discard only boundary texels less than half covered by the
    // charts, and texels with too few samples. Their estimate rests on few pixels, so it is noisy;
    // fully covered border texels are as exact as interior ones under the area normalisation.
    // Texels with no kept texel within two rings (thin charts) keep their own values, if reliable.
    Image<std::uint8_t> keep = erode(cov.mask);
    for (std::size_t i = 0; i < texels; ++i) {
      if (cov.mask[i] && cov.uv_area[i] >= 0.5f) keep[i] = 1;
      if (!reliable[i]) keep[i] = 0;
    }
    refill(keep, 2, false);
  }
  // Unreliable texels not refilled yet (seam fix off, or no kept texel within two rings) take the
  // nearest reliable texel within kUnreliableRings; beyond that (a chart too small to hold one
  // reliable texel) they keep their own estimate.
  refill(reliable, kUnreliableRings, true);
  // Last resort for texels that no pixel reached at all (V = 0/den says nothing): the nearest
  // texel that some pixel reached, if any within kUnreliableRings.
  Image<std::uint8_t> sampled(cov.width, cov.height, 0);
  for (std::size_t i = 0; i < texels; ++i) sampled[i] = cov.mask[i] && (num[i] > 0 || refilled[i]) ? 1 : 0;
  for (std::size_t i = 0; i < texels; ++i)
    if (cov.mask[i] && !sampled[i] && reliable[i]) sampled[i] = 1;  // reached by no pixel but expected to be: truly occluded
  refill(sampled, kUnreliableRings, true);
  for (std::size_t i = 0; i < texels; ++i) counts.unfilled += cov.mask[i] && !reliable[i] && !refilled[i] ? 1 : 0;
  return counts;
}

}  // namespace

BakeResult bake_histogram(const Scene& scene, const TexelCoverage& cov, const HistogramParams& params, const ProgressFn& progress) {
  params.validate();
  const RasterMesh mesh = make_raster_mesh(scene, cov.width, cov.height);
  const std::vector<Vec3> dirs = sphere_directions(params.direction_set, params.directions, params.seed);

  // The view resolution matches the texel density: an average texel seen face-on spans
  // pixels_per_texel pixels. Views larger than 8192^2 are coarsened (a tiny UV region on a huge mesh).
  float pixel_size = histogram_pixel_size(cov, params.pixels_per_texel);
  pixel_size = std::max(pixel_size, 2.0f * mesh.radius / 8192.0f);

  HistogramSums sums = scatter_directions(mesh, cov, dirs, pixel_size, params, progress);

  // Denominator of the area normalisation: A(T) in pixel units (the weights' unit).
  std::vector<double> den(cov.texel_count(), 0.0);
  const double pix2 = static_cast<double>(pixel_size) * pixel_size;
  for (std::size_t i = 0; i < den.size(); ++i) den[i] = cov.world_area[i] / pix2;
  if (params.point_size > 1.0f) {
    // Sec. 3.2: splats of point_size texels = a box convolution of the histogram. The area
    // normalisation convolves its denominator too, so the result stays a weighted mean of V.
    const std::vector<double> kw = box_weights(params.point_size);
    box_filter(sums.num, cov.width, cov.height, kw);
    box_filter(den, cov.width, cov.height, kw);
  }

  BakeResult out;
  out.fragments = sums.fragments;
  out.mask = cov.mask;
  out.covered_texels = cov.covered_texels;
  out.directions = params.directions;
  out.warnings = cov.warnings();
  const std::size_t clamped = normalize_visibility(sums, den, cov, params, out);
  const RefillCounts refills = refill_unestimated_texels(sums.num, den, cov, params, out);
  out.stats = {{"view_size", make_ortho_view(mesh, {0, 0, 1}, pixel_size, {0, 0}).width},
               {"pixel_size", pixel_size},
               {"fragments", out.fragments},
               {"clamped_texels", clamped},
               {"unreliable_texels", refills.unreliable},
               {"unreliable_texels_unfilled", refills.unfilled}};
  return out;
}

}  // namespace ao
