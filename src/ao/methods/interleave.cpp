#include "ao/methods/interleave.h"

#include <array>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/methods/screen_space_internal.h"

namespace ao {

float effective_depth_limit(const InterleaveOptions& o, float radius) { return o.filter_depth_limit > 0 ? o.filter_depth_limit : 0.25f * radius; }

void PixelRow::load(const GBuffer& g, int row, int first, int last, const std::array<Rotation, 16>& rotations, float bias_world) {
  y = row;
  x0 = first;
  count = last - first;
  for (std::vector<float>* v : {&px, &py, &pz, &nx, &ny, &nz, &tx, &ty, &tz, &bx, &by, &bz, &rc, &rs, &bias})
    v->resize(static_cast<std::size_t>(count));
  covered.resize(static_cast<std::size_t>(count));
  // One pixel's footprint at unit depth: the image plane spans 2 tan(fov/2) over `height` pixels.
  const float footprint = 2.0f * g.camera.tan_half_fov() / static_cast<float>(g.height());
  for (int k = 0; k < count; ++k) {
    const int x = first + k;
    const auto i = static_cast<std::size_t>(k);
    const Rotation r = rotations[static_cast<std::size_t>((y & 3) * 4 + (x & 3))];
    rc[i] = r.c;
    rs[i] = r.s;
    covered[i] = g.covered(x, y) ? 1 : 0;
    if (!covered[i]) {
      // Dummy point one unit in front of the camera facing it: finite arithmetic, result discarded.
      px[i] = py[i] = 0, pz[i] = -1;
      nx[i] = ny[i] = 0, nz[i] = 1;
      tx[i] = 1, ty[i] = tz[i] = 0;
      bx[i] = bz[i] = 0, by[i] = 1;
      bias[i] = 0;
      continue;
    }
    const Vec3 p = g.position(x, y), n = g.normal(x, y);
    const Frame f = Frame::from_normal(n);
    // Rotation by alpha about N (sec. 4.2): T' = cos a T + sin a B, B' = -sin a T + cos a B.
    const Vec3 t = f.t * r.c + f.b * r.s, b = f.b * r.c - f.t * r.s;
    px[i] = p.x, py[i] = p.y, pz[i] = p.z;
    nx[i] = n.x, ny[i] = n.y, nz[i] = n.z;
    tx[i] = t.x, ty[i] = t.y, tz[i] = t.z;
    bx[i] = b.x, by[i] = b.y, bz[i] = b.z;
    if (bias_world > 0) {
      bias[i] = bias_world;
    } else {
      const float cos_v = std::max(std::abs(dot(n, normalize(p))), 0.124f);  // tan <= 8
      const float tan_v = std::sqrt(1.0f - cos_v * cos_v) / cos_v;
      bias[i] = footprint * (-p.z) * (1.0f + tan_v);
    }
  }
}

namespace {

// The 4x4 window is not separable (neighbours are skipped by their depth difference to the CENTRE
// pixel), so it runs as one pass of 16 taps, SIMD across x. Sources are rows of S interleaved
// floats per pixel (S = 1: float planes; S = 3: a Vec3 RGB image, filtered in place of planes).
// Blocks of 16 pixels make each tap's depth test once per pixel (spread to the pixel's S lanes by a
// permute for RGB) and share it by the N sources filtered together (RGB + obscurance for transfer);
// the count and sums of all 16 taps stay in registers (no per-tap row traffic). Taps are summed in
// the same order (dy, then dx) for every channel count and layout, and a skipped tap adds +0 exactly
// as a missing one, so results match between the float, RGB and planar entry points (and the scalar
// border pixels), and never depend on threads.
using V8 = float __attribute__((vector_size(32)));
using V8i = std::int32_t __attribute__((vector_size(32)));

inline V8 load8(const float* p) {
  V8 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store8(float* p, V8 v) { std::memcpy(p, &v, sizeof v); }
inline V8 splat8(float f) { return V8{f, f, f, f, f, f, f, f}; }
inline V8i splat8i(std::int32_t i) { return V8i{i, i, i, i, i, i, i, i}; }

// A pixel mask (or value) of 8 pixels spread to their S lanes each: S vectors of 8 lanes.
template <int S, typename T>
inline std::array<T, S> spread(T m) {
  if constexpr (S == 1) {
    return {m};
  } else {
    static_assert(S == 3);
#if defined(__clang__)
    return {__builtin_shufflevector(m, m, 0, 0, 0, 1, 1, 1, 2, 2), __builtin_shufflevector(m, m, 2, 3, 3, 3, 4, 4, 4, 5),
            __builtin_shufflevector(m, m, 5, 5, 6, 6, 6, 7, 7, 7)};
#else
    return {__builtin_shuffle(m, V8i{0, 0, 0, 1, 1, 1, 2, 2}), __builtin_shuffle(m, V8i{2, 3, 3, 3, 4, 4, 4, 5}),
            __builtin_shuffle(m, V8i{5, 5, 6, 6, 6, 7, 7, 7})};
#endif
  }
}

template <int N, int S>
void box_filter_lanes(const std::array<const float*, N>& src, const std::array<float*, N>& dst, const GBuffer& g, float limit,
                      const Image<float>* depth_image) {
  const int w = g.width(), h = g.height(), lanes = S * w;
  Image<float> own;
  if (!depth_image) depth_plane(g, own);
  const float* depth = depth_image ? depth_image->data() : own.data();
  const std::uint32_t* cov = g.object_id.data();
  tbb::parallel_for(
      tbb::blocked_range<int>(0, h, 8),
      [&](const tbb::blocked_range<int>& r) {
        auto depth_row = [&](int yy) { return depth + static_cast<std::size_t>(yy) * w; };
        // Centre depths, NaN on uncovered pixels: no tap passes, count stays 0 and the value is kept.
        std::vector<float> centre(static_cast<std::size_t>(w));
        const V8 lim = splat8(limit), one = splat8(1.0f);
        const V8i abs_mask = splat8i(0x7fffffff);
        for (int y = r.begin(); y < r.end(); ++y) {
          const std::size_t row = static_cast<std::size_t>(y) * lanes;
          const float* dcy = depth_row(y);
          for (int x = 0; x < w; ++x) centre[static_cast<std::size_t>(x)] = cov[static_cast<std::size_t>(y) * w + x] ? dcy[x] : std::numeric_limits<float>::quiet_NaN();
          const int dy_lo = std::max(-2, -y), dy_hi = std::min(1, h - 1 - y);
          // Pixels whose taps dx = -2..+1 all lie inside the row run in blocks of 16 (16 x S lanes): the
          // depth test is made once per pixel; for RGB its mask is spread to the pixel's 3 lanes.
          int p = 2;
          for (; p + 16 <= w - 1; p += 16) {
            const V8 dc0 = load8(&centre[static_cast<std::size_t>(p)]), dc1 = load8(&centre[static_cast<std::size_t>(p) + 8]);
            V8 n0{}, n1{};
            std::array<V8, N * S> s0{}, s1{};
            for (int dy = dy_lo; dy <= dy_hi; ++dy) {
              const float* dn = depth_row(y + dy) + p;
              const std::size_t nrow = static_cast<std::size_t>(y + dy) * lanes + static_cast<std::size_t>(S) * p;
              for (int dx = -2; dx <= 1; ++dx) {
                const V8i m0 = (V8)((V8i)(load8(dn + dx) - dc0) & abs_mask) <= lim;
                const V8i m1 = (V8)((V8i)(load8(dn + dx + 8) - dc1) & abs_mask) <= lim;
                n0 += (V8)(m0 & (V8i)one);
                n1 += (V8)(m1 & (V8i)one);
                const std::array<V8i, S> e0 = spread<S>(m0), e1 = spread<S>(m1);
                for (int c = 0; c < N; ++c) {
                  const float* v = src[static_cast<std::size_t>(c)] + nrow + S * dx;
                  for (int k = 0; k < S; ++k) {
                    s0[static_cast<std::size_t>(c * S + k)] += (V8)(e0[static_cast<std::size_t>(k)] & (V8i)load8(v + 8 * k));
                    s1[static_cast<std::size_t>(c * S + k)] += (V8)(e1[static_cast<std::size_t>(k)] & (V8i)load8(v + 8 * S + 8 * k));
                  }
                }
              }
            }
            const std::array<V8, S> c0 = spread<S>(n0), c1 = spread<S>(n1);
            for (int k = 0; k < S; ++k) {
              const V8 q0 = c0[static_cast<std::size_t>(k)], q1 = c1[static_cast<std::size_t>(k)];
              const V8i k0 = q0 > V8{}, k1 = q1 > V8{};  // else keep the value (uncovered, or no tap)
              for (int c = 0; c < N; ++c) {
                const std::size_t at = row + static_cast<std::size_t>(S) * p + 8 * k;
                const float* in = src[static_cast<std::size_t>(c)] + at;
                float* out = dst[static_cast<std::size_t>(c)] + at;
                store8(out, (V8)((k0 & (V8i)(s0[static_cast<std::size_t>(c * S + k)] / q0)) | (~k0 & (V8i)load8(in))));
                store8(out + 8 * S, (V8)((k1 & (V8i)(s1[static_cast<std::size_t>(c * S + k)] / q1)) | (~k1 & (V8i)load8(in + 8 * S))));
              }
            }
          }
          const int l = S * p, vlo = 2 * S;
          // The rest one lane at a time, same tap order.
          auto scalar = [&](int l0, int l1) {
            for (int q = l0; q < l1; ++q) {
              const int x = q / S;
              const float dc = centre[static_cast<std::size_t>(x)];
              float n = 0;
              std::array<float, N> s{};
              for (int dy = dy_lo; dy <= dy_hi; ++dy) {
                const float* dn = depth_row(y + dy);
                const std::size_t nrow = static_cast<std::size_t>(y + dy) * lanes;
                for (int dx = std::max(-2, -x); dx <= std::min(1, w - 1 - x); ++dx) {
                  const int t = q + S * dx;
                  const bool use = std::abs(dn[x + dx] - dc) <= limit;
                  n += use ? 1.0f : 0.0f;
                  for (int c = 0; c < N; ++c) s[static_cast<std::size_t>(c)] += use ? src[static_cast<std::size_t>(c)][nrow + t] : 0.0f;
                }
              }
              for (int c = 0; c < N; ++c) {
                const float in = src[static_cast<std::size_t>(c)][row + q];
                dst[static_cast<std::size_t>(c)][row + q] = n > 0 ? s[static_cast<std::size_t>(c)] / n : in;
              }
            }
          };
          scalar(0, std::min(vlo, lanes));
          scalar(std::max(l, std::min(vlo, lanes)), lanes);
        }
      },
      tbb::simple_partitioner());
}

void check_size(const GBuffer& g, int w, int h) {
  if (w != g.width() || h != g.height()) throw InputError("depth_aware_box_filter: the image must have the G-buffer's size");
}

}  // namespace

Image<float> depth_aware_box_filter(const Image<float>& image, const GBuffer& g, float depth_limit, const Image<float>* depth) {
  check_size(g, image.width(), image.height());
  Image<float> out(image.width(), image.height());
  box_filter_lanes<1, 1>({image.data()}, {out.data()}, g, depth_limit, depth);
  return out;
}

Image<Vec3> depth_aware_box_filter(const Image<Vec3>& image, const GBuffer& g, float depth_limit, const Image<float>* depth) {
  check_size(g, image.width(), image.height());
  // Interleaved RGB lanes directly (3 lanes per pixel, one depth test per lane), no planar copies.
  static_assert(sizeof(Vec3) == 3 * sizeof(float));
  Image<Vec3> out(image.width(), image.height());
  box_filter_lanes<1, 3>({&image.data()->x}, {&out.data()->x}, g, depth_limit, depth);
  return out;
}

void depth_aware_box_filter_planes(std::span<const float* const> src, std::span<float* const> dst, const GBuffer& g, float depth_limit,
                                   const Image<float>* depth) {
  if (src.size() != dst.size() || src.size() > 4) throw InputError("depth_aware_box_filter_planes: 1 to 4 source planes, one destination each");
  auto in = [&](std::size_t c) { return src[c]; };
  auto out = [&](std::size_t c) { return dst[c]; };
  switch (src.size()) {  // up to 4 channels share one pass of depth tests
    case 1: box_filter_lanes<1, 1>({in(0)}, {out(0)}, g, depth_limit, depth); break;
    case 2: box_filter_lanes<2, 1>({in(0), in(1)}, {out(0), out(1)}, g, depth_limit, depth); break;
    case 3: box_filter_lanes<3, 1>({in(0), in(1), in(2)}, {out(0), out(1), out(2)}, g, depth_limit, depth); break;
    case 4: box_filter_lanes<4, 1>({in(0), in(1), in(2), in(3)}, {out(0), out(1), out(2), out(3)}, g, depth_limit, depth); break;
    default: break;
  }
}

void depth_aware_box_filter_planes(std::span<Image<float>* const> planes, const GBuffer& g, float depth_limit, const Image<float>* depth) {
  for (const Image<float>* p : planes) check_size(g, p->width(), p->height());
  Image<float> own;
  if (!depth && planes.size() > 4) depth = &(own = depth_plane(g));  // built once for every group of 4
  for (std::size_t done = 0; done < planes.size();) {
    const std::size_t k = std::min<std::size_t>(4, planes.size() - done);
    std::array<Image<float>, 4> out;
    std::array<const float*, 4> src{};
    std::array<float*, 4> dst{};
    for (std::size_t c = 0; c < k; ++c) {
      out[c] = Image<float>(g.width(), g.height());
      src[c] = planes[done + c]->data(), dst[c] = out[c].data();
    }
    depth_aware_box_filter_planes(std::span(src.data(), k), std::span(dst.data(), k), g, depth_limit, depth);
    for (std::size_t c = 0; c < k; ++c) *planes[done + c] = std::move(out[c]);
    done += k;
  }
}

}  // namespace ao
