// The cone method's sampling pattern: see cone_pattern_internal.h.
#include "ao/methods/cone_pattern_internal.h"

#include <algorithm>
#include <cmath>

#include "ao/core/sampling.h"

namespace ao {

ConePattern make_cone_pattern(const ConeSetup& setup, bool jitter, std::uint32_t seed) {
  ConePattern pat;
  pat.period = jitter ? ConePattern::kPeriod : 1;
  pat.cones = static_cast<int>(setup.cones.size());
  const int slots = pat.period * pat.period;
  pat.rot.resize(2 * static_cast<std::size_t>(slots));
  pat.cone.resize(static_cast<std::size_t>(slots) * pat.cones);
  const float log_q = std::log(setup.chain_ratio);
  for (int sy = 0; sy < pat.period; ++sy)
    for (int sx = 0; sx < pat.period; ++sx) {
      const int slot = pat.slot(sx, sy);
      const std::uint32_t ps = pixel_seed(seed, sx, sy);
      float rot_c = 1, rot_s = 0;
      if (jitter) {
        const float beta = 2.0f * kPi * to_unit_float(hash32(ps));
        rot_c = std::cos(beta), rot_s = std::sin(beta);
      }
      pat.rot[2 * slot] = rot_c, pat.rot[2 * slot + 1] = rot_s;
      for (int c = 0; c < pat.cones; ++c) {
        const ConeSetup::Cone& cone = setup.cones[c];
        float st = cone.sin_theta, ct = cone.cos_theta, cp = cone.cos_phi, sp = cone.sin_phi, scale = 1.0f;
        if (jitter) {
          const std::uint32_t hc = hash_combine(ps, 1u + static_cast<std::uint32_t>(c));
          const float u = cone.band0 + to_unit_float(hc) * (cone.band1 - cone.band0);
          st = setup.cosine ? std::sqrt(u) : std::sqrt(std::max(0.0f, u * (2.0f - u)));  // 1 - cos = u
          st = std::min(st, setup.sin_theta_max);
          ct = std::sqrt(1.0f - st * st);
          // phi = the cell's centre + delta, delta uniform in +-dphi / 2.
          const float delta = (to_unit_float(hash_combine(hc, 1u)) - 0.5f) * cone.dphi;
          const float cd = std::cos(delta), sd = std::sin(delta);
          cp = cone.cos_phi * cd - cone.sin_phi * sd, sp = cone.sin_phi * cd + cone.cos_phi * sd;
          // Chain scale s = q^-xi in (1/q, 1]: one ratio step of random phase, the geometric
          // analogue of jittering a uniform step.
          scale = std::exp(-to_unit_float(hash_combine(hc, 2u)) * log_q);
        }
        pat.cone[static_cast<std::size_t>(slot) * pat.cones + c] = {st * cp, st * sp, ct, scale};
      }
    }
  return pat;
}

// Poisson-disk points on the unit disk: best-candidate dart throwing (Mitchell 1991) from a fixed
// hash sequence, relaxed by Lloyd iterations on a fine grid over the disk so that the points are
// evenly spread and well inside (a sample on the rim has a zero chord and would be wasted).
std::vector<ConeSetup::Disk> cone_disk_points(int n) {
  std::vector<Vec2> pts;
  auto disk_point = [](std::uint32_t i) {
    const float r = std::sqrt(to_unit_float(hash32(2 * i + 17))), a = 2.0f * kPi * to_unit_float(hash32(2 * i + 18));
    return Vec2{r * std::cos(a), r * std::sin(a)};
  };
  std::uint32_t next = 0;
  for (int k = 0; k < n; ++k) {
    Vec2 best{};
    float best_d = -1;
    for (int c = 0; c < 16 * (k + 1); ++c) {
      const Vec2 q = disk_point(next++);
      float d = kInfinity;
      for (const Vec2& o : pts) d = std::min(d, (q.x - o.x) * (q.x - o.x) + (q.y - o.y) * (q.y - o.y));
      if (d > best_d) best_d = d, best = q;
    }
    pts.push_back(best);
  }
  constexpr int kGrid = 48, kIterations = 30;
  for (int it = 0; it < kIterations; ++it) {
    std::vector<Vec2> sum(n);
    std::vector<int> count(n, 0);
    for (int gy = 0; gy < kGrid; ++gy)
      for (int gx = 0; gx < kGrid; ++gx) {
        const float x = -1.0f + (gx + 0.5f) * 2.0f / kGrid, y = -1.0f + (gy + 0.5f) * 2.0f / kGrid;
        if (x * x + y * y > 1.0f) continue;
        int best = 0;
        float best_d = kInfinity;
        for (int k = 0; k < n; ++k) {
          const float d = (x - pts[k].x) * (x - pts[k].x) + (y - pts[k].y) * (y - pts[k].y);
          if (d < best_d) best_d = d, best = k;
        }
        sum[best].x += x, sum[best].y += y, ++count[best];
      }
    for (int k = 0; k < n; ++k)
      if (count[k] > 0) pts[k] = {sum[k].x / count[k], sum[k].y / count[k]};
  }
  std::vector<ConeSetup::Disk> out;
  for (const Vec2& q : pts) out.push_back({q.x, q.y, std::sqrt(std::max(0.0f, 1.0f - q.x * q.x - q.y * q.y))});
  return out;
}

}  // namespace ao
