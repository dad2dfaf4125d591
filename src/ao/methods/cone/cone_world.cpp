// SPDX-License-Identifier: Apache-2.0
// Voxel cone traced AO on the world grid (Dalla Favera & Celes 2012, sec. III-C): the quantities
// of the paper the kernel (simd::trace_cones, src/ao/methods/cone/cone_kernel.cpp) runs with for every pixel. See
// cone.h for the convention (V = 1 - the paper's blocked fraction), docs/methods/cone.md (Speed)
// for how the kernel is laid out.
#include <algorithm>
#include <cmath>

#include "ao/core/parallel.h"
#include "ao/methods/cone/cone_internal.h"
#include "ao/simd/aligned_internal.h"
#include "ao/methods/cone/cone_kernel_internal.h"

namespace ao::cone_internal {

namespace {

// Obstructed fraction of one sphere (sec. III-C1): prisms along the grid's z through the great
// disk's samples; each prism spans the sphere's chord [z_in, z_out] at its sample. Monte Carlo
// over the disk: volume ~ sum of chords, obstructed volume ~ sum of solid lengths, so the
// fraction is their ratio (as volumetric AO's pipes, the paper's [4]). The spheres of a chain
// differ only in radius, so per sphere: its radii in voxels along (i, j, k), each prism's half
// chord in voxels and the sum of its chords.
struct WorldSampler {
  const VoxelGrid& g;
  Vec3 inv;   // 1 / voxel size along (i, j, k)
  int np;     // prisms per sphere
  int lanes;  // np rounded up to whole vectors
  // The prisms stay within rho_max of the disk's centre and half_max of the equator (unit disk).
  float rho_max = 0, half_max = 0;
  // Structure of arrays, padded to `lanes` with zeros: disk points; per sphere its radii, chord sum
  // and its prisms' half chords ([k * lanes + s]).
  simd::AlignedVector<float> du, dv, rx, ry, rz, chord, half;

  WorldSampler(const VoxelGrid& grid, const ConeSetup& setup, float r_max)
      : g(grid), inv{1.0f / grid.voxel_size.x, 1.0f / grid.voxel_size.y, 1.0f / grid.voxel_size.z}, np(static_cast<int>(setup.disk.size())),
        lanes(simd::padded(np)), du(static_cast<std::size_t>(lanes), 0.0f), dv(du.size(), 0.0f) {
    for (int s = 0; s < np; ++s) {
      const ConeSetup::Disk& d = setup.disk[static_cast<std::size_t>(s)];
      du[static_cast<std::size_t>(s)] = d.u, dv[static_cast<std::size_t>(s)] = d.v;
      rho_max = std::max(rho_max, std::sqrt(d.u * d.u + d.v * d.v));
      half_max = std::max(half_max, d.half_chord);
    }
    half.assign(setup.sphere_radius.size() * static_cast<std::size_t>(lanes), 0.0f);
    for (std::size_t k = 0; k < setup.sphere_radius.size(); ++k) {
      const float r = setup.sphere_radius[k] * r_max;
      rx.push_back(r * inv.x), ry.push_back(r * inv.y), rz.push_back(r * inv.z);
      float sum = 0;
      for (int s = 0; s < np; ++s) {
        const float h = setup.disk[static_cast<std::size_t>(s)].half_chord * rz.back();
        half[k * static_cast<std::size_t>(lanes) + static_cast<std::size_t>(s)] = h;
        sum += 2.0f * h;
      }
      chord.push_back(sum);
    }
  }

  // Spheres that start nearer the apex than this (world units) are skipped: 1.5 voxels, within
  // which the voxelized surface itself (its staircase on curved and slanted faces, and the surface
  // voxel whose centre is inside) fills them.
  float near_limit() const { return 1.5f * std::max({g.voxel_size.x, g.voxel_size.y, g.voxel_size.z}); }
};

// The spheres of one cone, j < ns being sphere j of its chain and j = ns its filler. The chain of a
// cone with scale s has sphere j at s d_j with radius s r_j, starting at s (d_j - r_j); a scaled
// chain ends at s R_max, and the filler sphere, inscribed in [s R_max, R_max] along the axis,
// samples the rest: its radius (1 - s) R_max / 2 is at most the last sphere's (equal at s = 1/q),
// and it fits in the cone for s >= 1/q. So each sphere's distance along the axis, radius scale and
// "is sampled" test are affine in s:
//   distance = dist_a s + dist_b, radius scale = min(rad_a s + rad_b, 1), sampled: use_a s + use_b >= 0,
// sampled meaning: the sphere starts at least near_limit from the apex (the chain), the filler's
// radius is more than 1e-3 of the last sphere's. The half extents of its prisms' box at radius
// scale 1 (x, y in window cells, z in voxels, a relative margin of 1e-3 for rounding) are what the
// empty-space test reads: the prisms read columns within rho_max (rx, ry) of the centre and voxels
// within half_max rz along them.
struct ConeChain {
  int per_cone = 0;
  std::vector<float> dist_a, dist_b, rad_a, rad_b, use_a, use_b, ex, ey, ez;
  std::vector<int> k;  // sphere of the chain whose prisms it uses

  ConeChain(const ConeSetup& setup, const WorldSampler& sample, float r_max) {
    const int ns = static_cast<int>(setup.sphere_distance.size());
    per_cone = ns + 1;
    const float near = sample.near_limit();
    const float inv_last_radius = 1.0f / setup.sphere_radius.back();  // relative to R_max
    constexpr float kInvC = 1.0f / VoxelGrid::kCellXY;
    for (int j = 0; j <= ns; ++j) {
      const int kj = std::min(j, ns - 1);
      const auto sj = static_cast<std::size_t>(j);
      if (j < ns) {
        dist_a.push_back(setup.sphere_distance[sj] * r_max), dist_b.push_back(0.0f);
        rad_a.push_back(1.0f), rad_b.push_back(0.0f);
        use_a.push_back((setup.sphere_distance[sj] - setup.sphere_radius[sj]) * r_max), use_b.push_back(-near);
      } else {
        dist_a.push_back(0.5f * r_max), dist_b.push_back(0.5f * r_max);
        rad_a.push_back(-0.5f * inv_last_radius), rad_b.push_back(0.5f * inv_last_radius);
        use_a.push_back(-0.5f * inv_last_radius), use_b.push_back(0.5f * inv_last_radius - 1e-3f);
      }
      const auto sk = static_cast<std::size_t>(kj);
      ex.push_back(sample.rho_max * sample.rx[sk] * 1.001f * kInvC), ey.push_back(sample.rho_max * sample.ry[sk] * 1.001f * kInvC);
      ez.push_back(sample.half_max * sample.rz[sk] * 1.001f);
      k.push_back(kj);
    }
  }
};

// The spheres of all of a pixel's cones in one flat run of slots, i = c * per_cone + j (cone c,
// sphere j of its chain), padded to a multiple of 8 with slots that are never sampled (the kernel
// places them in vectors of 8 at most, beside 64-bit mask loads): with 6 cones of 6 spheres, 5
// vectors of 8 instead of 6 half-empty ones per cone. Per slot: its cone and the constants of its
// sphere in the chain.
struct FlatSlots {
  int n = 0, padded = 0;
  simd::AlignedVector<std::int32_t> cone, sphere;
  simd::AlignedVector<float> dist_a, dist_b, rad_a, rad_b, use_a, use_b, ex, ey, ez;

  FlatSlots(const ConeChain& q, int cones) {
    n = cones * q.per_cone;
    padded = (n + simd::kConeSlotGroup - 1) / simd::kConeSlotGroup * simd::kConeSlotGroup;
    for (int i = 0; i < padded; ++i) {
      const bool real = i < n;
      const auto j = static_cast<std::size_t>(real ? i % q.per_cone : 0);  // padding: never sampled
      cone.push_back(real ? i / q.per_cone : 0), sphere.push_back(q.k[j]);
      dist_a.push_back(q.dist_a[j]), dist_b.push_back(q.dist_b[j]), rad_a.push_back(q.rad_a[j]), rad_b.push_back(q.rad_b[j]);
      use_a.push_back(real ? q.use_a[j] : 0.0f), use_b.push_back(real ? q.use_b[j] : -1.0f);  // padding: 0 s - 1 < 0
      ex.push_back(q.ex[j]), ey.push_back(q.ey[j]), ez.push_back(q.ez[j]);
    }
  }
};

// The pattern's cone axes (in the normal's frame) and chain scales per pattern slot, cones padded
// to whole vectors with zeros.
struct PatternAxes {
  int cones_padded = 0;
  simd::AlignedVector<float> x, y, z, s;

  explicit PatternAxes(const ConePattern& pat) : cones_padded(simd::padded(pat.cones)) {
    const std::size_t slots = pat.cone.size() / static_cast<std::size_t>(pat.cones);
    for (auto* a : {&x, &y, &z, &s}) a->assign(slots * static_cast<std::size_t>(cones_padded), 0.0f);
    for (std::size_t slot = 0; slot < slots; ++slot)
      for (int c = 0; c < pat.cones; ++c) {
        const ConePattern::Cone& k = pat.cone[slot * static_cast<std::size_t>(pat.cones) + static_cast<std::size_t>(c)];
        const std::size_t o = slot * static_cast<std::size_t>(cones_padded) + static_cast<std::size_t>(c);
        x[o] = k.x, y[o] = k.y, z[o] = k.z, s[o] = k.scale;
      }
  }
};

}  // namespace

void trace_world(const GBuffer& gb, const VoxelGrid& g, float r_max, const ConeSetup& setup, const ConePattern& pat, ImageView<float> out,
                 const ProgressFn& progress) {
  const WorldSampler sample(g, setup, r_max);
  const ConeChain chain(setup, sample, r_max);
  const FlatSlots flat(chain, pat.cones);
  const PatternAxes axes(pat);
  simd::ConeTables tb;
  tb.prisms = sample.np, tb.prism_lanes = sample.lanes, tb.disk_u = sample.du.data(), tb.disk_v = sample.dv.data();
  tb.sphere_rx = sample.rx.data(), tb.sphere_ry = sample.ry.data(), tb.sphere_rz = sample.rz.data(), tb.sphere_chord = sample.chord.data();
  tb.half_chord = sample.half.data();
  tb.cones = pat.cones, tb.per_cone = chain.per_cone, tb.slots = flat.padded;
  tb.slot_cone = flat.cone.data(), tb.slot_sphere = flat.sphere.data();
  tb.dist_a = flat.dist_a.data(), tb.dist_b = flat.dist_b.data(), tb.rad_a = flat.rad_a.data(), tb.rad_b = flat.rad_b.data();
  tb.use_a = flat.use_a.data(), tb.use_b = flat.use_b.data(), tb.box_x = flat.ex.data(), tb.box_y = flat.ey.data(), tb.box_z = flat.ez.data();
  tb.cones_padded = axes.cones_padded, tb.turn = pat.rot.data();
  tb.axis_x = axes.x.data(), tb.axis_y = axes.y.data(), tb.axis_z = axes.z.data(), tb.axis_scale = axes.s.data();
  tb.inv_voxel = sample.inv;

  const simd::ConeView view{gb.camera.basis(), gb.camera.eye, g.origin, pat.period};
  ProgressCounter counter(progress, static_cast<std::size_t>(gb.width()) * gb.height());
  parallel_for_tiles(gb.width(), gb.height(), kTile, [&](const Tile& t) {
    simd::trace_cones(gb, g, tb, view, t.x0, t.x1, t.y0, t.y1, out);
    counter.add(static_cast<std::size_t>(t.x1 - t.x0) * (t.y1 - t.y0));
  });
}

}  // namespace ao::cone_internal
