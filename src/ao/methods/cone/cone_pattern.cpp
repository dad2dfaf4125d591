// SPDX-License-Identifier: Apache-2.0
// The cone method's sampling pattern: see cone_pattern_internal.h.
#include "ao/methods/cone/cone_pattern_internal.h"

#include <algorithm>
#include <cmath>

#include "ao/core/sampling.h"
#include "ao/methods/samples.h"

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

// The prisms' points on the sphere's great disk: the methods' one Poisson-disk set of the unit disk
// (samples.h, Lloyd-relaxed, so evenly spread and inside: a point on the rim would have a zero
// chord and be wasted), each with its half chord h = sqrt(1 - x^2 - y^2).
std::vector<ConeSetup::Disk> cone_disk_points(int n) {
  std::vector<ConeSetup::Disk> out;
  for (const Vec3& q : poisson_disk(PoissonDomain::Disk, n)) out.push_back({q.x, q.y, std::sqrt(std::max(0.0f, 1.0f - q.x * q.x - q.y * q.y))});
  return out;
}

}  // namespace ao
