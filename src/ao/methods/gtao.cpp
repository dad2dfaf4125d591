#include "ao/methods/gtao.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/core/sampling.h"
#include "ao/methods/gtao_internal.h"
#include "ao/methods/screen_space_internal.h"

namespace ao {

namespace {

using gtao_internal::kMaxSlices;
using gtao_internal::kMaxSteps;
// Tiles of 128 x 16 pixels, as the other screen-space kernels: long row segments for the SIMD
// loops over pixels, few rows per tile.
constexpr int kTileWidth = 128, kTileHeight = 16;
constexpr float kHalfPi = 0.5f * kPi;

// acos on [-1, 1] by Abramowitz & Stegun 4.4.46 (|error| <= 2.2e-8 rad, below float resolution
// near pi/2), branch-free so the loops over pixels vectorise.
inline float fast_acos(float x) {
  const float a = std::min(std::abs(x), 1.0f);
  float p = -0.0012624911f;
  for (float c : {0.0066700901f, -0.0170881256f, 0.0308918810f, -0.0501743046f, 0.0889789874f, -0.2145988016f, 1.5707963050f}) p = p * a + c;
  const float r = p * std::sqrt(1.0f - a);
  return x < 0.0f ? kPi - r : r;
}

// The 4x4 pattern (the paper's spatial noise, undone by its 4x4 denoiser): per pattern entry p, the
// rotation of the slice set (a fraction of pi / slices) and the offset of the samples along a slice
// (a fraction of one step). Both stratified over the 16 entries with independent seeded
// permutations and jitter, so a 4x4 block holds 16 distinct rotations and offsets; without
// interleaving every entry is the same seeded value.
struct Pattern {
  std::array<float, 16> rotation, offset;
};

Pattern make_pattern(std::uint32_t seed, bool interleave) {
  Pattern p;
  auto permutation = [&](std::uint32_t salt) {
    std::array<int, 16> perm;
    for (int k = 0; k < 16; ++k) perm[static_cast<std::size_t>(k)] = k;
    // Fisher-Yates with hashed choices: depends only on the seed.
    for (int k = 15; k > 0; --k) {
      const int j = static_cast<int>(hash_combine(hash_combine(seed, salt), static_cast<std::uint32_t>(k)) % static_cast<std::uint32_t>(k + 1));
      std::swap(perm[static_cast<std::size_t>(k)], perm[static_cast<std::size_t>(j)]);
    }
    return perm;
  };
  const std::array<int, 16> pr = permutation(0x51u), po = permutation(0xA7u);
  for (int k = 0; k < 16; ++k) {
    const auto i = static_cast<std::size_t>(k);
    const float jr = to_unit_float(hash_combine(hash_combine(seed, 0x1Du), static_cast<std::uint32_t>(k)));
    const float jo = to_unit_float(hash_combine(hash_combine(seed, 0x2Eu), static_cast<std::uint32_t>(k)));
    p.rotation[i] = interleave ? (static_cast<float>(pr[i]) + jr) / 16.0f : to_unit_float(hash_combine(seed, 0x3Fu));
    p.offset[i] = interleave ? (static_cast<float>(po[i]) + jo) / 16.0f : to_unit_float(hash_combine(seed, 0x40u));
  }
  return p;
}

// Per-pixel values of one row segment (covered pixels only, compacted), structure of arrays so
// the loops over pixels vectorise.
struct Row {
  alignas(64) std::array<float, kTileWidth> fx, fy;          // pixel centre, pixel coordinates
  alignas(64) std::array<float, kTileWidth> px, py, pz;      // x, camera space
  alignas(64) std::array<float, kTileWidth> wx, wy, wz;      // w_o: unit vector from x to the eye
  alignas(64) std::array<float, kTileWidth> nx, ny, nz;      // unit normal
  alignas(64) std::array<float, kTileWidth> radius_px;       // R projected at x's depth, pixels
  alignas(64) std::array<int, kTileWidth> pattern, index;    // 4x4 pattern entry; offset from the segment start
  alignas(64) std::array<int, kTileWidth> pixel;             // y * width + x
  // Per slice:
  alignas(64) std::array<float, kTileWidth> dir_x, dir_y;    // screen direction (x right, y down)
  alignas(64) std::array<float, kTileWidth> cos_g, sin_g, gamma, np_len, inv_np;  // gamma and |n_p|
  alignas(64) std::array<float, kTileWidth> tpx, tpy, tpz, tnx, tny, tnz;  // tangent directions of sides + and -
  alignas(64) std::array<float, kTileWidth> best_pos, best_neg;  // cos of the horizons' elevations
  alignas(64) std::array<float, kTileWidth> run_pos, run_neg;    // pixels to the image edge along each side
  alignas(64) std::array<float, kTileWidth> sum_v, sum_open;
};

}  // namespace

const ParamTable<GtaoParams>& gtao_param_table() {
  using P = Param<GtaoParams>;
  static const ParamTable<GtaoParams> table{
      "gtao",
      {{P::integer("slices", &GtaoParams::slices, Range::closed(1, kMaxSlices), "", "slice directions per pixel (the outer integral over phi)"),
        P::integer("steps", &GtaoParams::steps, Range::closed(1, kMaxSteps), "", "depth-buffer samples on each side of a slice (the horizon search)"),
        P::real("step_power", &GtaoParams::step_power, Range::closed(1, 4), "", "samples at ((j + u) / steps)^step_power of the screen radius"),
        P::boolean("multi_bounce", &GtaoParams::multi_bounce, "the multi-bounce fit with the G-buffer albedo")},
       interleave_params(&GtaoParams::interleave)}};
  return table;
}

namespace gtao_internal {

Tables make_tables(const GtaoParams& params, std::uint32_t seed) {
  const int slices = params.slices, steps = params.steps;
  const Pattern pattern = make_pattern(seed, params.interleave.interleave);
  Tables t;
  // Slice k of pattern entry p has screen angle phi = pi (k + rotation_p) / slices: the slices
  // split the half circle evenly (a slice covers both of its sides), rotated per pixel.
  for (int k = 0; k < slices; ++k)
    for (int p = 0; p < 16; ++p) {
      const double phi = kPi * (k + pattern.rotation[static_cast<std::size_t>(p)]) / slices;
      t.dir_c[static_cast<std::size_t>(k)][static_cast<std::size_t>(p)] = static_cast<float>(std::cos(phi));
      t.dir_s[static_cast<std::size_t>(k)][static_cast<std::size_t>(p)] = static_cast<float>(std::sin(phi));
    }
  // Step j of pattern entry p lies at t = ((j + offset_p) / steps)^step_power of the screen radius.
  for (int j = 0; j < steps; ++j)
    for (int p = 0; p < 16; ++p)
      t.step_t[static_cast<std::size_t>(j)][static_cast<std::size_t>(p)] =
          std::pow((static_cast<float>(j) + pattern.offset[static_cast<std::size_t>(p)]) / static_cast<float>(steps), params.step_power);
  return t;
}

}  // namespace gtao_internal

void GtaoParams::validate() const { gtao_param_table().validate(*this); }
void to_json(nlohmann::json& j, const GtaoParams& p) { j = gtao_param_table().to_json(p); }
void from_json(const nlohmann::json& j, GtaoParams& p) { gtao_param_table().from_json(j, p); }

float gtao_multi_bounce(float v, float rho) {
  // The paper's cubic fit of path-traced multi-bounce AO against single-bounce V, per albedo rho.
  const float a = 2.0404f * rho - 0.3324f, b = -4.7951f * rho + 0.6417f, c = 2.7552f * rho + 0.6903f;
  return std::max(v, ((a * v + b) * v + c) * v);
}

GtaoImage gtao_ao(const GBuffer& g, float radius, const GtaoParams& params, std::uint32_t seed) {
  params.validate();
  if (!(radius > 0.0f) || !std::isfinite(radius)) throw InputError("gtao: radius R must be a positive number of world units");
  const int w = g.width(), h = g.height();
  const int slices = params.slices, steps = params.steps;
  const gtao_internal::Tables tables = gtao_internal::make_tables(params, seed);
  const auto &dir_c = tables.dir_c, &dir_s = tables.dir_s;
  const auto& step_t = tables.step_t;

  // Camera rays through pixel centres: ray(x, y) = (ax (x + 0.5) + bx, ay (y + 0.5) + by, -1), so a
  // sample's camera-space point is depth * ray (one 4-byte gather per sample; x is rebuilt the same
  // way, so x and its samples agree exactly on a plane).
  const float t = g.camera.tan_half_fov();
  const float ax = 2.0f * t * g.camera.aspect() / static_cast<float>(w), bx = -t * g.camera.aspect();
  const float ay = -2.0f * t / static_cast<float>(h), by = t;
  // Both image axes have 0.5 h / tan(fov/2) pixels per unit of x/(-z): R at depth z spans R * that / z pixels.
  const float px_per_unit = 0.5f * static_cast<float>(h) / t;
  const float r2 = radius * radius;
  // Continuous pixel coordinates stay below these (just inside the last pixel) along a slice.
  const float width_in = static_cast<float>(w) - 1e-3f, height_in = static_cast<float>(h) - 1e-3f;
  const Image<float> depth_image = depth_plane(g);  // also the filter's
  const float* depth = depth_image.data();

  Image<float> v(w, h, 1.0f);
  parallel_for_tiles(w, h, kTileWidth, kTileHeight, [&](const Tile& tile) {
    Row row;
    for (int y = tile.y0; y < tile.y1; ++y) {
      // Compaction to the covered pixels (background costs the sample loops nothing).
      int n = 0;
      for (int x = tile.x0; x < tile.x1; ++x) {
        row.index[static_cast<std::size_t>(n)] = x - tile.x0;
        n += g.covered(x, y) ? 1 : 0;
      }
      for (int k = 0; k < n; ++k) {
        const int x = tile.x0 + row.index[static_cast<std::size_t>(k)];
        const float d = depth[static_cast<std::size_t>(y) * w + x];
        const float fx = static_cast<float>(x) + 0.5f, fy = static_cast<float>(y) + 0.5f;
        row.fx[k] = fx, row.fy[k] = fy;
        row.px[k] = d * (ax * fx + bx), row.py[k] = d * (ay * fy + by), row.pz[k] = -d;
        const Vec3 nn = g.normal(x, y);
        row.nx[k] = nn.x, row.ny[k] = nn.y, row.nz[k] = nn.z;
        row.pattern[k] = (y & 3) * 4 + (x & 3);
        row.pixel[k] = y * w + x;
        row.sum_v[k] = 0.0f, row.sum_open[k] = 0.0f;
      }
      for (int k = 0; k < n; ++k) {
        const float inv = 1.0f / std::sqrt(row.px[k] * row.px[k] + row.py[k] * row.py[k] + row.pz[k] * row.pz[k]);
        row.wx[k] = -row.px[k] * inv, row.wy[k] = -row.py[k] * inv, row.wz[k] = -row.pz[k] * inv;
        row.radius_px[k] = radius * px_per_unit / -row.pz[k];
      }
      for (int s = 0; s < slices; ++s) {
        const auto& cs = dir_c[static_cast<std::size_t>(s)];
        const auto& sn = dir_s[static_cast<std::size_t>(s)];
        // The slice plane, the projected normal, gamma, and the tangent directions of both sides.
        for (int k = 0; k < n; ++k) {
          const float c = cs[static_cast<std::size_t>(row.pattern[k])], si = sn[static_cast<std::size_t>(row.pattern[k])];
          row.dir_x[k] = c, row.dir_y[k] = si;
          const float wx = row.wx[k], wy = row.wy[k], wz = row.wz[k];
          // The screen direction (c, si) (pixel y down) is the camera-space direction (c, -si, 0) of
          // the image plane; with w_o it spans the slice plane. Its part orthogonal to w_o, o, is the
          // slice's theta = +pi/2 axis.
          const float dw = c * wx - si * wy;
          float ox = c - dw * wx, oy = -si - dw * wy, oz = -dw * wz;
          const float oinv = 1.0f / std::sqrt(ox * ox + oy * oy + oz * oz);
          ox *= oinv, oy *= oinv, oz *= oinv;
          // Axis of the slice plane (unit: o and w_o are orthonormal), and n_p = n minus its axis part.
          const float qx = oy * wz - oz * wy, qy = oz * wx - ox * wz, qz = ox * wy - oy * wx;
          const float na = row.nx[k] * qx + row.ny[k] * qy + row.nz[k] * qz;
          const float npx = row.nx[k] - na * qx, npy = row.ny[k] - na * qy, npz = row.nz[k] - na * qz;
          const float len = std::sqrt(npx * npx + npy * npy + npz * npz);
          // gamma = angle of n_p from w_o, towards o when positive. cos gamma is clamped at 0: a
          // normal facing away from the eye (interpolated normals at silhouettes) is taken as
          // perpendicular to the view, so the hemisphere stays on the visible side.
          const float cos_g = len > 0.0f ? std::clamp((npx * wx + npy * wy + npz * wz) / len, 0.0f, 1.0f) : 1.0f;
          const float sign = npx * ox + npy * oy + npz * oz >= 0.0f ? 1.0f : -1.0f;
          const float sin_g = sign * std::sqrt(1.0f - cos_g * cos_g);
          row.cos_g[k] = cos_g, row.sin_g[k] = sin_g, row.gamma[k] = sign * fast_acos(cos_g), row.np_len[k] = len;
          row.inv_np[k] = len > 0.0f ? 1.0f / len : 0.0f;
          // The slice's tangent directions at theta = gamma + pi/2 (side +) and gamma - pi/2 (side -):
          // cos(theta) w_o + sin(theta) o.
          row.tpx[k] = -sin_g * wx + cos_g * ox, row.tpy[k] = -sin_g * wy + cos_g * oy, row.tpz[k] = -sin_g * wz + cos_g * oz;
          row.tnx[k] = sin_g * wx - cos_g * ox, row.tny[k] = sin_g * wy - cos_g * oy, row.tnz[k] = sin_g * wz - cos_g * oz;
          row.best_pos[k] = 1.0f, row.best_neg[k] = 1.0f;  // cos e of the tangent plane itself
          // Clamp-to-edge along the slice: how far (pixels) each side runs before leaving the image.
          // Samples beyond read the slice's last pixel inside it, a real surface point in the slice
          // plane, rather than counting the space beyond the frame as empty.
          const float fx = row.fx[k], fy = row.fy[k];
          const float to_right = (width_in - fx) / c, to_left = fx / -c, to_bottom = (height_in - fy) / si, to_top = fy / -si;
          const float run_x_pos = c > 0.0f ? to_right : c < 0.0f ? to_left : kInfinity;
          const float run_x_neg = c > 0.0f ? fx / c : c < 0.0f ? (width_in - fx) / -c : kInfinity;
          const float run_y_pos = si > 0.0f ? to_bottom : si < 0.0f ? to_top : kInfinity;
          const float run_y_neg = si > 0.0f ? fy / si : si < 0.0f ? (height_in - fy) / -si : kInfinity;
          row.run_pos[k] = std::min(run_x_pos, run_y_pos), row.run_neg[k] = std::min(run_x_neg, run_y_neg);
        }
        // The horizon search on both sides. A horizon is stored as its elevation e above the tangent
        // line of its side (theta = gamma +- pi/2 -+ e), kept as cos e, which falls as e rises
        // through [0, pi]: the lowest cos e of the samples within R above the tangent plane. A
        // sample's elevation is atan2(its height over x's tangent plane / |n_p|, its component along
        // the side's tangent direction): for a sample in the slice plane exactly the angle the
        // paper's horizon measures. A pixel centre lies up to half a pixel off the slice's screen
        // line; measured this way such a sample still never raises the horizon when it lies in x's
        // tangent plane, where the angle of its own direction from w_o would (by tens of degrees one
        // pixel from x, which made open planes grey).
        for (int side = 0; side < 2; ++side) {
          const float sgn = side == 0 ? 1.0f : -1.0f;
          float* __restrict best = side == 0 ? row.best_pos.data() : row.best_neg.data();
          const float* tx = side == 0 ? row.tpx.data() : row.tnx.data();
          const float* ty = side == 0 ? row.tpy.data() : row.tny.data();
          const float* tz = side == 0 ? row.tpz.data() : row.tnz.data();
          const float* run = side == 0 ? row.run_pos.data() : row.run_neg.data();
          for (int j = 0; j < steps; ++j) {
            const auto& tj = step_t[static_cast<std::size_t>(j)];
#pragma GCC ivdep
            for (int k = 0; k < n; ++k) {
              // At least one pixel from x, so the first sample is not x itself (unless x is on the
              // border and the slice leaves the image at once).
              const float dist = std::min(1.0f + tj[static_cast<std::size_t>(row.pattern[k])] * std::max(row.radius_px[k] - 1.0f, 0.0f), run[k]);
              const float off = sgn * dist;
              // The integer clamp only guards the reads against rounding at the border.
              const int ix = std::clamp(static_cast<int>(row.fx[k] + off * row.dir_x[k]), 0, w - 1);
              const int iy = std::clamp(static_cast<int>(row.fy[k] + off * row.dir_y[k]), 0, h - 1);
              const int at = iy * w + ix;
              const float ds = depth[at];
              const float vx = ds * (ax * (static_cast<float>(ix) + 0.5f) + bx) - row.px[k];
              const float vy = ds * (ay * (static_cast<float>(iy) + 0.5f) + by) - row.py[k];
              const float vz = -ds - row.pz[k];
              const float vv = vx * vx + vy * vy + vz * vz;
              const float up = (vx * row.nx[k] + vy * row.ny[k] + vz * row.nz[k]) * row.inv_np[k];
              const float along = vx * tx[k] + vy * ty[k] + vz * tz[k];
              // The radius cut (step membership); background (depth +inf: vv inf or NaN) fails it.
              // Only samples above the tangent plane can raise a horizon. A sample whose (along, up)
              // covers less than half of |v|^2 lies far off the slice (a pixel centre one pixel from
              // x can) and says little about it, and x's own pixel (read when x is on the border and
              // the slice leaves the image at once) has v = 0 up to rounding, no direction at all:
              // both are skipped. For a sample in the slice plane along^2 + up^2 = |v|^2.
              const float in_frame = along * along + up * up;
              const bool use = (vv < r2) & (up > 0.0f) & (2.0f * in_frame > vv) & (at != row.pixel[k]);
              const float cos_e = along / std::sqrt(use ? in_frame : 1.0f);
              best[k] = use ? std::min(best[k], cos_e) : best[k];
            }
          }
        }
        // The inner integral between the horizons, and the same for the open hemisphere.
        for (int k = 0; k < n; ++k) {
          const float gamma = row.gamma[k], cos_g = row.cos_g[k], sin_g = row.sin_g[k];
          const float c2 = std::clamp(row.best_pos[k], -1.0f, 1.0f), c1 = std::clamp(row.best_neg[k], -1.0f, 1.0f);
          const float e2 = fast_acos(c2), e1 = fast_acos(c1);
          // h2 = gamma + pi/2 - e2 and h1 = gamma - pi/2 + e1: inside [gamma - pi/2, gamma + pi/2]
          // (the paper's clamp to the hemisphere) by construction. A horizon past the view vector
          // (possible only for samples off the slice plane) is held at theta = 0: x is seen from the
          // eye, so the view direction is free.
          const bool past2 = gamma + kHalfPi - e2 < 0.0f, past1 = gamma - kHalfPi + e1 > 0.0f;
          const float h2 = past2 ? 0.0f : gamma + kHalfPi - e2, h1 = past1 ? 0.0f : gamma - kHalfPi + e1;
          // cos(2 h2 - gamma) = cos(gamma + pi - 2 e2) = -(cos gamma cos 2e2 + sin gamma sin 2e2) and
          // cos(2 h1 - gamma) = -(cos gamma cos 2e1 - sin gamma sin 2e1), with cos 2e = 2c^2 - 1 and
          // sin 2e = 2c sqrt(1 - c^2) (e in [0, pi]); at theta = 0, cos(-gamma) = cos gamma.
          const float s2 = std::sqrt(std::max(1.0f - c2 * c2, 0.0f)), s1 = std::sqrt(std::max(1.0f - c1 * c1, 0.0f));
          const float cos2 = past2 ? cos_g : -((2.0f * c2 * c2 - 1.0f) * cos_g + 2.0f * c2 * s2 * sin_g);
          const float cos1 = past1 ? cos_g : -((2.0f * c1 * c1 - 1.0f) * cos_g - 2.0f * c1 * s1 * sin_g);
          // The inner integral (both halves), times |n_p| (the outer integrand).
          const float a = 0.25f * (-cos1 + cos_g + 2.0f * h1 * sin_g) + 0.25f * (-cos2 + cos_g + 2.0f * h2 * sin_g);
          // Its value for the open hemisphere, h = gamma -+ pi/2: cos gamma + gamma sin gamma.
          const float open = cos_g + gamma * sin_g;
          row.sum_v[k] += row.np_len[k] * a;
          row.sum_open[k] += row.np_len[k] * open;
        }
      }
      for (int k = 0; k < n; ++k) {
        // V = sum |n_p| a / sum |n_p| a_open: the slices' own estimate of the open integral as the
        // normaliser (its limit is 1), so an open plane is exactly 1 at any slice count.
        const float so = row.sum_open[k];
        v(tile.x0 + row.index[static_cast<std::size_t>(k)], y) = so > 0.0f ? std::clamp(row.sum_v[k] / so, 0.0f, 1.0f) : 1.0f;
      }
    }
  });
  if (params.interleave.interleave && params.interleave.filter) v = depth_aware_box_filter(v, g, effective_depth_limit(params.interleave, radius), &depth_image);
  GtaoImage out;
  if (params.multi_bounce) {
    out.color = Image<Vec3>(w, h, Vec3{1, 1, 1});
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (!g.covered(x, y)) continue;
        const Vec3 a = g.albedo(x, y);
        const float vis = v(x, y);
        out.color(x, y) = {gtao_multi_bounce(vis, a.x), gtao_multi_bounce(vis, a.y), gtao_multi_bounce(vis, a.z)};
        v(x, y) = gtao_multi_bounce(vis, 0.2126f * a.x + 0.7152f * a.y + 0.0722f * a.z);  // Rec. 709 luminance
      }
  }
  out.visibility = std::move(v);
  return out;
}

}  // namespace ao
