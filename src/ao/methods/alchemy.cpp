#include "ao/methods/alchemy.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/core/sampling.h"
#include "ao/methods/alchemy_internal.h"

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

using alchemy_internal::kCoordOffset;
using alchemy_internal::kMaxPixelRadius;
using alchemy_internal::kMaxSamples;
using alchemy_internal::kRotations;
using alchemy_internal::RotationTable;
using alchemy_internal::rotations;
// Tiles of 128 x 8 pixels: rows long enough to vectorise over pixels, and a tile's sample footprint
// (the tile grown by the disk's pixel radius) small enough to stay in L2 for typical radii.
constexpr int kTileWidth = 128, kTileHeight = 8;

// Per-pixel data of one row segment, structure of arrays so the sample loop vectorises over pixels.
struct Row {
  alignas(64) std::array<float, kTileWidth> cx, cy, cz, nx, ny, nz, bias, radius_px, jitter, rot_c, rot_s, sum;
};

// sqrt(x) for x in [0, 1]: std::sqrt keeps a branch to set errno on negative input, which stops the
// sample loop from vectorising (this file is built without -fno-math-errno), so: the classic reciprocal square
// root bit trick and two Newton steps, relative error < 5e-6 (far below a pixel at any disk radius).
inline float sqrt_unit(float x) {
  float r = std::bit_cast<float>(0x5f3759dfu - (std::bit_cast<std::uint32_t>(x) >> 1));
  r = r * (1.5f - 0.5f * x * r * r);
  r = r * (1.5f - 0.5f * x * r * r);
  return x * r;
}

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
       bilateral_params<AlchemyParams>("filter_", [](AlchemyParams& p) -> BilateralParams& { return p.bilateral; })}};
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

Falloff alchemy_reference_falloff(const AlchemyParams& p, float default_radius) {
  return Falloff{Membership::Step, alchemy_constants(p, default_radius).radius};
}

AlchemyImage render_alchemy(const GBuffer& g, const AlchemyParams& params, float default_radius, std::uint32_t seed, const ProgressFn& progress) {
  const AlchemyConstants k = alchemy_constants(params, default_radius);
  const int w = g.width(), h = g.height(), s = params.samples;
  AlchemyImage out{Image<float>(w, h, 1.0f)};
  const auto t0 = std::chrono::steady_clock::now();

  // Screen radius of the world disk: both image axes have 0.5 * height / tan(fov/2) pixels per unit
  // of x/(-z) (camera.h's projection), so the disk of radius r at depth z_C projects to a disk of
  // radius r * that / z_C, and uniform area on it is uniform area on the world disk (sec. 2.3).
  const float px_per_unit = 0.5f * static_cast<float>(h) / g.camera.tan_half_fov();
  const float r2 = k.radius * k.radius;
  // 2 sigma / s: eq. 9's 2 pi u / s (uniform directions, pdf 1/(2 pi)) times the paper's nominal
  // 1/pi (sec. 2.3), with u folded into sigma.
  const float scale = 2.0f * k.sigma / static_cast<float>(s);
  const float inv_s = 1.0f / static_cast<float>(s);
  const float eps = k.epsilon, beta = k.beta, contrast = params.contrast;
  // Sample points are read from the depth buffer, P = z(Q') * (camera ray through the pixel centre),
  // as sec. 2.3 allows ("read a depth or position buffer"): one 4-byte gather per sample instead of
  // three from the 12-byte positions, which keeps a tile's sample footprint in L2 (the gathers' cache
  // misses were most of the time; docs/methods/alchemy.md). C is reconstructed the same way, so C and
  // its samples agree exactly on a plane.
  const Image<float> depth_image = depth_plane(g);  // also the filter's
  const float* depth_buffer = depth_image.data();
  const float t = g.camera.tan_half_fov();
  // camera_direction(px, py) = (ax * px + bx, ay * py + by, -1) for continuous pixel coordinates.
  const float ax = 2.0f * t * g.camera.aspect() / static_cast<float>(w), bx = -t * g.camera.aspect();
  const float ay = -2.0f * t / static_cast<float>(h), by = t;
  const alchemy_internal::Directions directions = alchemy_internal::sample_directions(s);
  const std::array<float, kMaxSamples>&ux = directions.x, &uy = directions.y;
  const RotationTable& rot = rotations();
  ProgressCounter counter(progress, static_cast<std::size_t>(w) * h);

  // 32-bit gather indices (twice the lanes of 64-bit ones) whenever the position buffer allows.
  const bool small = static_cast<std::size_t>(w) * h < static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
  const auto run = [&]<class Index>() {
    tbb::parallel_for(
        tbb::blocked_range2d<int>(0, h, kTileHeight, 0, w, kTileWidth),
        [&](const tbb::blocked_range2d<int>& range) {
          const int x0 = range.cols().begin(), n = range.cols().end() - x0;
          Row row;
          for (int y = range.rows().begin(); y < range.rows().end(); ++y) {
            const std::size_t base = static_cast<std::size_t>(y) * w + x0;
            const float* nn = &g.normal[base].x;
            const float* depth = &depth_image[base];
            const std::uint32_t* cov = &g.object_id[base];
            // Per-pixel set-up in plain loops the compiler vectorises (component loads of the AoS
            // Vec3s, integer hashing, a table gather).
            for (int j = 0; j < n; ++j) {
              const float d = cov[j] ? depth[j] : 0.0f;  // background: C = 0, its result is overwritten
              row.cx[j] = d * (ax * (static_cast<float>(x0 + j) + 0.5f) + bx);
              row.cy[j] = d * (ay * (static_cast<float>(y) + 0.5f) + by);
              row.cz[j] = -d;
              row.nx[j] = nn[3 * j], row.ny[j] = nn[3 * j + 1], row.nz[j] = nn[3 * j + 2];
            }
            for (int j = 0; j < n; ++j) {
              // Eq. 10's z_C beta: z_C < 0, so this lowers v.n and drops samples nearly in the tangent
              // plane (self-occlusion from imprecise normals and positions), more so far away.
              row.bias[j] = row.cz[j] * beta;
              // Background has depth +inf, so radius 0; it is overwritten with V = 1 below.
              row.radius_px[j] = std::min(kMaxPixelRadius, k.radius * px_per_unit / depth[j]);
              row.sum[j] = 0.0f;
            }
            for (int j = 0; j < n; ++j) {
              const std::uint32_t hs = pixel_seed(seed, x0 + j, y);
              row.jitter[j] = to_unit_float(hs);
              const std::uint32_t ri = hash32(hs) & (kRotations - 1);
              row.rot_c[j] = rot.c[ri], row.rot_s[j] = rot.s[ri];
            }
            const float fy0 = static_cast<float>(y) + 0.5f + kCoordOffset;
            const float fx0 = static_cast<float>(x0) + 0.5f + kCoordOffset;
            for (int i = 0; i < s; ++i) {
              const float pux = ux[i], puy = uy[i], stratum = static_cast<float>(i);
              // Vectorised over the row's pixels: one sample each, a gather of P_i, eq. 10's term.
              // Branch-free (bitwise & on the conditions, selects) so it if-converts.
              for (int j = 0; j < n; ++j) {
                // Sample i lies in the i-th of s equal-area annuli (radius sqrt((i + jitter) / s)) at
                // angle i * golden angle + the pixel's rotation: stratified, and uniform on the disk.
                const float rho = row.radius_px[j] * sqrt_unit((stratum + row.jitter[j]) * inv_s);
                const float dx = rho * (row.rot_c[j] * pux - row.rot_s[j] * puy);
                const float dy = rho * (row.rot_s[j] * pux + row.rot_c[j] * puy);
                // +kCoordOffset keeps the coordinate positive, so truncation is floor.
                // Clamp-to-edge: a sample beyond the frame reads the nearest border pixel (the surfaces
                // at the edge go on beyond it) rather than counting as empty space.
                const int ix = std::clamp(static_cast<int>(fx0 + static_cast<float>(j) + dx) - static_cast<int>(kCoordOffset), 0, w - 1);
                const int iy = std::clamp(static_cast<int>(fy0 + dy) - static_cast<int>(kCoordOffset), 0, h - 1);
                const float dp = depth_buffer[static_cast<Index>(iy) * w + ix];
                const float px = dp * (ax * (static_cast<float>(ix) + 0.5f) + bx);
                const float py = dp * (ay * (static_cast<float>(iy) + 0.5f) + by);
                const float pz = -dp;
                const float vx = px - row.cx[j], vy = py - row.cy[j], vz = pz - row.cz[j];
                const float vv = vx * vx + vy * vy + vz * vz;
                const float vn = vx * row.nx[j] + vy * row.ny[j] + vz * row.nz[j] + row.bias[j];
                // Background samples (depth +inf, so vv is inf or NaN and fails vv < r^2) contribute
                // nothing: the paper's assumption that unseen space is empty. vv < r^2 is eq. 9's H.
                const bool use = (vv < r2) & (vn > 0.0f);
                const float term = vn / (vv + eps);
                row.sum[j] += use ? term : 0.0f;
              }
            }
            float* v = &out.visibility[base];
            for (int j = 0; j < n; ++j) {
              const float a = std::max(0.0f, 1.0f - scale * row.sum[j]);  // eq. 10 before ^k
              v[j] = cov[j] ? a : 1.0f;
            }
            if (contrast != 1.0f)
              for (int j = 0; j < n; ++j) v[j] = std::pow(v[j], contrast);  // eq. 10's ^k; 1 stays 1
          }
          counter.add(static_cast<std::size_t>(n) * (range.rows().end() - range.rows().begin()));
        },
        tbb::simple_partitioner());
  };
  if (small)
    run.template operator()<std::int32_t>();
  else
    run.template operator()<std::int64_t>();
  out.estimator_ms = ms_since(t0);
  if (params.filter) {
    const auto t1 = std::chrono::steady_clock::now();
    out.unfiltered = out.visibility;
    bilateral_filter(g, depth_image, out.visibility, params.bilateral);
    out.filter_ms = ms_since(t1);
  }
  return out;
}

}  // namespace ao
