// SPDX-License-Identifier: Apache-2.0
#include "ao/methods/samples.h"

#include <cmath>
#include <map>
#include <mutex>
#include <string>
#include <utility>

#include "ao/core/error.h"
#include "ao/core/sampling.h"

namespace ao {

namespace {

constexpr int kLloydIterations = 32;
constexpr std::uint32_t kPoissonSeed = 0x5eed1a7du;  // fixed: the sets are constants of the method

// Uniform pseudo-random point of the domain number `i` (fixed sequence; disk by rejection).
Vec3 domain_point(PoissonDomain domain, std::uint32_t& counter) {
  for (;;) {
    const std::uint32_t k = counter++;
    const float a = to_unit_float(hash_combine(kPoissonSeed, 3 * k));
    const float b = to_unit_float(hash_combine(kPoissonSeed, 3 * k + 1));
    const float c = to_unit_float(hash_combine(kPoissonSeed, 3 * k + 2));
    switch (domain) {
      case PoissonDomain::Square: return {a, b, 0};
      case PoissonDomain::Cube: return {a, b, c};
      case PoissonDomain::Disk: {
        const Vec3 p{2 * a - 1, 2 * b - 1, 0};
        if (p.x * p.x + p.y * p.y < 1.0f) return p;
        break;
      }
    }
  }
}

// Lloyd relaxation (Lloyd 1982) over a discrete density: each iteration assigns every density
// point to its nearest site and moves each site to the centroid of its points. The fixed point is
// a centroidal Voronoi tessellation, whose sites are evenly spread (a Poisson-disk-like, blue-noise
// set, AT sec. 4.1). Centroids of convex cells of a convex domain stay inside the domain.
std::vector<Vec3> lloyd(PoissonDomain domain, int n) {
  std::uint32_t counter = 0;
  std::vector<Vec3> sites(static_cast<std::size_t>(n));
  for (Vec3& s : sites) s = domain_point(domain, counter);
  const int m = std::max(4096, 128 * n);
  std::vector<Vec3> density(static_cast<std::size_t>(m));
  for (Vec3& d : density) d = domain_point(domain, counter);
  std::vector<Vec3> sum(sites.size());
  std::vector<int> count(sites.size());
  for (int it = 0; it < kLloydIterations; ++it) {
    std::fill(sum.begin(), sum.end(), Vec3{});
    std::fill(count.begin(), count.end(), 0);
    for (const Vec3& d : density) {
      int best = 0;
      float best_d2 = kInfinity;
      for (int s = 0; s < n; ++s) {
        const Vec3 e = d - sites[static_cast<std::size_t>(s)];
        const float d2 = dot(e, e);
        if (d2 < best_d2) best_d2 = d2, best = s;
      }
      sum[static_cast<std::size_t>(best)] += d;
      ++count[static_cast<std::size_t>(best)];
    }
    for (std::size_t s = 0; s < sites.size(); ++s)
      if (count[s] > 0) sites[s] = sum[s] / static_cast<float>(count[s]);
  }
  return sites;
}

}  // namespace

std::span<const Vec3> poisson_disk(PoissonDomain domain, int n) {
  if (n < 1 || n > kMaxScreenSpaceSamples)
    throw InputError("samples must be in [1, " + std::to_string(kMaxScreenSpaceSamples) + "], got " + std::to_string(n));
  static std::mutex mutex;
  static std::map<std::pair<int, int>, std::vector<Vec3>> cache;  // node-based: spans stay valid
  const std::lock_guard lock(mutex);
  auto [it, inserted] = cache.try_emplace({static_cast<int>(domain), n});
  if (inserted) it->second = lloyd(domain, n);
  return it->second;
}

ContainmentSamples make_containment_samples(int n, const Falloff& falloff) {
  const std::span<const Vec3> xi = poisson_disk(PoissonDomain::Cube, n);
  ContainmentSamples s;
  for (const Vec3& u : xi) {
    // AT sec. 4.1: cosine-distributed direction from (xi_x, xi_y), distance r = mu^-1(xi_z).
    const float phi = 2.0f * kPi * u.x;
    const float sin_theta = std::sqrt(u.y);
    const float cos_theta = std::sqrt(std::max(0.0f, 1.0f - u.y));
    const float r = falloff.inverse(std::min(u.z, 0.99999f));  // xi < 1 keeps Exp's inverse finite
    s.x.push_back(std::cos(phi) * sin_theta * r);  // AT eq. 8: (X, Y, Z) = w r
    s.y.push_back(std::sin(phi) * sin_theta * r);
    s.z.push_back(cos_theta * r);
    s.r.push_back(r);
  }
  return s;
}

DiskSamples make_disk_samples(int n) {
  const std::span<const Vec3> p = poisson_disk(PoissonDomain::Disk, n);
  DiskSamples s;
  for (const Vec3& u : p) {
    s.x.push_back(u.x);
    s.y.push_back(u.y);
    s.h.push_back(std::sqrt(std::max(0.0f, 1.0f - u.x * u.x - u.y * u.y)));
  }
  return s;
}

std::array<Rotation, 16> interleave_rotations(std::uint32_t seed, bool interleave) {
  std::array<Rotation, 16> rot;
  const std::uint32_t key = hash_combine(hash32(seed), 0x1e7e5eedu);
  if (!interleave) {
    const float a = 2.0f * kPi * to_unit_float(key);
    rot.fill({std::cos(a), std::sin(a)});
    return rot;
  }
  // Seeded Fisher-Yates permutation of the 16 strata.
  std::array<int, 16> perm;
  for (int k = 0; k < 16; ++k) perm[static_cast<std::size_t>(k)] = k;
  for (int k = 15; k > 0; --k) {
    const int j = static_cast<int>(hash_combine(key, static_cast<std::uint32_t>(k)) % static_cast<std::uint32_t>(k + 1));
    std::swap(perm[static_cast<std::size_t>(k)], perm[static_cast<std::size_t>(j)]);
  }
  for (int k = 0; k < 16; ++k) {
    const float u = to_unit_float(hash_combine(key, 100u + static_cast<std::uint32_t>(k)));
    const float a = 2.0f * kPi * (static_cast<float>(perm[static_cast<std::size_t>(k)]) + u) / 16.0f;
    rot[static_cast<std::size_t>(k)] = {std::cos(a), std::sin(a)};
  }
  return rot;
}

}  // namespace ao
