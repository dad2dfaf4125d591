#include "ao/methods/interleave.h"

#include <cmath>

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

template <class T>
Image<T> box_filter(const Image<T>& image, const GBuffer& g, float limit) {
  const int w = image.width(), h = image.height();
  Image<T> out = image;
  const float* depth = g.depth.data();
  parallel_for_tiles(w, h, 64, [&](const Tile& t) {
    std::vector<T> sum(static_cast<std::size_t>(w));
    std::vector<float> count(static_cast<std::size_t>(w));
    for (int y = t.y0; y < t.y1; ++y) {
      std::fill(sum.begin() + t.x0, sum.begin() + t.x1, T{});
      std::fill(count.begin() + t.x0, count.begin() + t.x1, 0.0f);
      const float* dc = depth + static_cast<std::size_t>(y) * w;
      for (int dy = -2; dy <= 1; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= h) continue;
        const float* dn = depth + static_cast<std::size_t>(yy) * w;
        const T* vn = image.data() + static_cast<std::size_t>(yy) * w;
        for (int dx = -2; dx <= 1; ++dx) {
          const int lo = std::max(t.x0, -dx), hi = std::min(t.x1, w - dx);
          // Background neighbours hold depth +infinity, so |difference| > limit drops them too.
          for (int x = lo; x < hi; ++x) {
            const bool use = std::abs(dn[x + dx] - dc[x]) <= limit;
            sum[static_cast<std::size_t>(x)] += use ? vn[x + dx] : T{};
            count[static_cast<std::size_t>(x)] += use ? 1.0f : 0.0f;
          }
        }
      }
      for (int x = t.x0; x < t.x1; ++x)
        if (g.covered(x, y) && count[static_cast<std::size_t>(x)] > 0) out(x, y) = sum[static_cast<std::size_t>(x)] / count[static_cast<std::size_t>(x)];
    }
  });
  return out;
}

}  // namespace

Image<float> depth_aware_box_filter(const Image<float>& image, const GBuffer& g, float depth_limit) { return box_filter(image, g, depth_limit); }
Image<Vec3> depth_aware_box_filter(const Image<Vec3>& image, const GBuffer& g, float depth_limit) { return box_filter(image, g, depth_limit); }

}  // namespace ao
