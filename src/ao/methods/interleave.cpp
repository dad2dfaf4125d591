#include "ao/methods/interleave.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "ao/core/error.h"
#include "ao/core/parallel.h"

namespace ao {

void add_interleave_options(nlohmann::json& j, const InterleaveOptions& o) {
  j["interleave"] = o.interleave;
  j["filter"] = o.filter;
  j["filter_depth_limit"] = o.filter_depth_limit;
}

void read_interleave_options(const nlohmann::json& j, InterleaveOptions& o, const char* method) {
  try {
    if (j.contains("interleave")) o.interleave = j.at("interleave").get<bool>();
    if (j.contains("filter")) o.filter = j.at("filter").get<bool>();
    if (j.contains("filter_depth_limit")) o.filter_depth_limit = j.at("filter_depth_limit").get<float>();
  } catch (const nlohmann::json::exception& e) {
    throw InputError(std::string(method) + ": bad parameter type: " + e.what());
  }
}

void require_known_keys(const nlohmann::json& j, std::initializer_list<const char*> keys, const char* method) {
  if (!j.is_object()) throw InputError(std::string(method) + ": parameters must be a JSON object");
  for (const auto& [key, value] : j.items()) {
    bool known = false;
    for (const char* k : keys) known = known || key == k;
    if (!known) throw InputError(std::string(method) + ": unknown parameter '" + key + "'");
  }
}

void validate_interleave_options(const InterleaveOptions& o, const char* method) {
  if (!(o.filter_depth_limit >= 0.0f) || !std::isfinite(o.filter_depth_limit))
    throw InputError(std::string(method) + ": filter_depth_limit must be a finite number >= 0 of world units (0 = R/4)");
}

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
// pixel), so it runs as one pass of 16 taps over whole rows, SIMD across x. Each tap's depth test
// is made once per pixel and shared by the N planar channels filtered together (RGB + obscurance
// for transfer). Taps are summed in the same order (dy, then dx) for every channel count, so
// results match between the float, RGB and planar entry points, and never depend on threads.
template <int N>
void box_filter_planes(const std::array<const float*, N>& src, const std::array<float*, N>& dst, const GBuffer& g, float limit) {
  const int w = g.width(), h = g.height();
  const float* depth = g.depth.data();
  const std::uint8_t* cov = g.coverage.data();
  tbb::parallel_for(
      tbb::blocked_range<int>(0, h, 4),
      [&](const tbb::blocked_range<int>& r) {
        std::vector<float> buffer(static_cast<std::size_t>(w) * (N + 1));
        float* __restrict count = buffer.data();
        std::array<float*, N> sum;
        for (int c = 0; c < N; ++c) sum[static_cast<std::size_t>(c)] = buffer.data() + static_cast<std::size_t>(c + 1) * w;
        for (int y = r.begin(); y < r.end(); ++y) {
          std::fill(buffer.begin(), buffer.end(), 0.0f);
          const std::size_t row = static_cast<std::size_t>(y) * w;
          const float* __restrict dc = depth + row;
          for (int dy = -2; dy <= 1; ++dy) {
            const int yy = y + dy;
            if (yy < 0 || yy >= h) continue;
            const std::size_t nrow = static_cast<std::size_t>(yy) * w;
            for (int dx = -2; dx <= 1; ++dx) {
              const int lo = std::max(0, -dx), hi = std::min(w, w - dx);
              const float* __restrict dn = depth + nrow + dx;
              std::array<const float*, N> vn;
              for (int c = 0; c < N; ++c) vn[static_cast<std::size_t>(c)] = src[static_cast<std::size_t>(c)] + nrow + dx;
// Accumulators are private to the task; sources are read-only.
#pragma GCC ivdep
              for (int x = lo; x < hi; ++x) {
                // Background neighbours hold depth +infinity, so |difference| > limit drops them too.
                const bool use = std::abs(dn[x] - dc[x]) <= limit;
                count[x] += use ? 1.0f : 0.0f;
                for (int c = 0; c < N; ++c) sum[static_cast<std::size_t>(c)][x] += use ? vn[static_cast<std::size_t>(c)][x] : 0.0f;
              }
            }
          }
#pragma GCC ivdep
          for (int x = 0; x < w; ++x) {
            const bool keep = (cov[row + x] == 0) | !(count[x] > 0);  // uncovered pixels keep their value (&: no branch)
            const float n = keep ? 1.0f : count[x];
            for (int c = 0; c < N; ++c) {
              const float in = src[static_cast<std::size_t>(c)][row + x];
              dst[static_cast<std::size_t>(c)][row + x] = keep ? in : sum[static_cast<std::size_t>(c)][x] / n;  // divide: as before, exact means
            }
          }
        }
      },
      tbb::simple_partitioner());
}

void check_size(const GBuffer& g, int w, int h) {
  if (w != g.width() || h != g.height()) throw InputError("depth_aware_box_filter: the image must have the G-buffer's size");
}

}  // namespace

Image<float> depth_aware_box_filter(const Image<float>& image, const GBuffer& g, float depth_limit) {
  check_size(g, image.width(), image.height());
  Image<float> out(image.width(), image.height());
  box_filter_planes<1>({image.data()}, {out.data()}, g, depth_limit);
  return out;
}

Image<Vec3> depth_aware_box_filter(const Image<Vec3>& image, const GBuffer& g, float depth_limit) {
  check_size(g, image.width(), image.height());
  // Planar channels: the AoS Vec3 layout would need strided loads in the tap loop.
  const std::size_t n = image.size();
  std::vector<float> planes(6 * n);
  float *r = planes.data(), *gr = r + n, *b = gr + n;
  for (std::size_t i = 0; i < n; ++i) r[i] = image[i].x, gr[i] = image[i].y, b[i] = image[i].z;
  box_filter_planes<3>({r, gr, b}, {b + n, b + 2 * n, b + 3 * n}, g, depth_limit);
  Image<Vec3> out(image.width(), image.height());
  for (std::size_t i = 0; i < n; ++i) out[i] = Vec3{b[n + i], b[2 * n + i], b[3 * n + i]};
  return out;
}

void depth_aware_box_filter_planes(std::span<Image<float>* const> planes, const GBuffer& g, float depth_limit) {
  if (planes.empty()) return;
  for (const Image<float>* p : planes) check_size(g, p->width(), p->height());
  std::size_t done = 0;
  while (done < planes.size()) {  // up to 4 channels share one pass of depth tests
    const std::size_t k = std::min<std::size_t>(4, planes.size() - done);
    std::vector<Image<float>> out;
    for (std::size_t c = 0; c < k; ++c) out.emplace_back(g.width(), g.height());
    auto in = [&](std::size_t c) { return static_cast<const float*>(planes[done + c]->data()); };
    if (k == 1) box_filter_planes<1>({in(0)}, {out[0].data()}, g, depth_limit);
    if (k == 2) box_filter_planes<2>({in(0), in(1)}, {out[0].data(), out[1].data()}, g, depth_limit);
    if (k == 3) box_filter_planes<3>({in(0), in(1), in(2)}, {out[0].data(), out[1].data(), out[2].data()}, g, depth_limit);
    if (k == 4) box_filter_planes<4>({in(0), in(1), in(2), in(3)}, {out[0].data(), out[1].data(), out[2].data(), out[3].data()}, g, depth_limit);
    for (std::size_t c = 0; c < k; ++c) *planes[done + c] = std::move(out[c]);
    done += k;
  }
}

}  // namespace ao
