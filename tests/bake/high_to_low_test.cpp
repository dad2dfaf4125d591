// SPDX-License-Identifier: Apache-2.0
// High-to-low baking against a direct ray-traced reference on the high mesh, miss handling and
// cage checks. The meshes are spheres built here: a coarse low-poly sphere with lat-long UVs and a
// finely tessellated sphere with bumps (radius 1 + A sin(K phi) sin(K theta)).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "ao/bake/high_to_low.h"
#include "ao/bake/raytraced_bake.h"
#include "ao/bake/texel_coverage.h"
#include "ao/core/error.h"
#include "ao/reference/embree_scene_internal.h"
#include "ao/reference/ray_scene.h"
#include "ao/reference/raytraced.h"
#include "ao/scene/procedural.h"

namespace ao {
namespace {

constexpr float kPi = 3.14159265358979f;

Vec3 sphere_dir(float theta, float phi) { return {std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)}; }

// Lat-long sphere of radius r(theta, phi): (segments + 1) x (rings + 1) vertices (the seam is
// doubled for the UVs), u = phi / 2pi, v = 1 - theta / pi. Counter-clockwise seen from outside.
// `keep` may drop triangles (by their centre direction) to cut holes.
Mesh lat_long_sphere(int segments, int rings, const std::function<float(float, float)>& r, bool uvs,
                     const std::function<bool(Vec3)>& keep = {}) {
  Mesh m;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      const float theta = kPi * static_cast<float>(i) / static_cast<float>(rings);
      const float phi = 2 * kPi * static_cast<float>(j) / static_cast<float>(segments);
      // Exact copies at the seam and the poles, so shared edges are watertight for the ray tracer.
      if (i == 0 || i == rings) m.positions.push_back(Vec3{0, i == 0 ? 1.0f : -1.0f, 0} * r(theta, 0));
      else if (j == segments) m.positions.push_back(m.positions[m.positions.size() - static_cast<std::size_t>(segments)]);
      else m.positions.push_back(sphere_dir(theta, phi) * r(theta, phi));
      if (uvs) m.uvs.push_back({static_cast<float>(j) / static_cast<float>(segments), 1.0f - static_cast<float>(i) / static_cast<float>(rings)});
    }
  auto id = [&](int i, int j) { return static_cast<std::uint32_t>(i * (segments + 1) + j); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const std::uint32_t a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      for (const std::array<std::uint32_t, 3>& t : {std::array<std::uint32_t, 3>{a, b, c}, std::array<std::uint32_t, 3>{a, c, d}}) {
        const Vec3 centre = (m.positions[t[0]] + m.positions[t[1]] + m.positions[t[2]]) / 3.0f;
        if (keep && !keep(normalize(centre))) continue;
        m.indices.insert(m.indices.end(), t.begin(), t.end());
      }
    }
  return m;
}

constexpr float kBumpAmplitude = 0.1f;
constexpr float kBumpFrequency = 8.0f;
float bumpy(float theta, float phi) { return 1.0f + kBumpAmplitude * std::sin(kBumpFrequency * phi) * std::sin(kBumpFrequency * theta); }
float round_unit(float, float) { return 1.0f; }

Scene prepared(Mesh m, const char* name) {
  Scene s;
  s.name = name;
  s.meshes.push_back(std::move(m));
  validate_and_prepare(s);
  return s;
}

HighToLowParams params_for_bumps() {
  HighToLowParams p;
  p.ao.samples = 256;
  p.cage_extrusion = 0.2f;  // the bumps reach 0.1 outside the unit sphere; the low faces lie up to 1 - cos(pi/24) ~ 0.01 inside it
  return p;
}

TEST(HighToLow, BumpySphereMatchesARayTracedRenderOfTheHighMesh) {
  const Scene low = prepared(lat_long_sphere(24, 12, round_unit, true), "low");
  // 250 x 125, not a multiple of the map's 64: the reference rays below, through texel centres, would
  // otherwise pass exactly through vertices of the high mesh, where a ray tracer may slip between triangles.
  const Scene high = prepared(lat_long_sphere(250, 125, bumpy, false), "high");
  const RayScene high_rays(high);
  const int size = 64;
  const TexelCoverage cov = compute_texel_coverage(low, size);
  const HighToLowParams p = params_for_bumps();
  const BakeResult r = bake_high_to_low(low, cov, extrude_cage(low, *p.cage_extrusion), high_rays, high_rays, p);
  EXPECT_EQ(r.missed_texels, 0u);

  // Reference: at the texel centre's (theta, phi), the high surface found by a ray towards the sphere's
  // centre (independent of the cage), its interpolated normal, and 2048 rays of the ground truth.
  // The cage ray through the low point runs along the low mesh's interpolated normal, which is within
  // a few thousandths of a radian of that radial line here, far below the bumps' wavelength (0.8 rad).
  RaytracedParams rp;
  rp.samples = 2048;
  const Falloff unlimited{Membership::Step, 100.0f};  // 100 >> the sphere's diameter 2.2: unlimited distance
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  double se = 0, se_low = 0, ref_min = 1;
  int n = 0;
  for (int y = 2; y < size; y += 3)
    for (int x = 1; x < size; x += 3) {
      if (cov.uv_area(x, y) < 0.999f) continue;  // whole texels only: their patch is one smooth piece of surface
      const float u = (static_cast<float>(x) + 0.5f) / size, v = 1.0f - (static_cast<float>(y) + 0.5f) / size;
      const float theta = kPi * (1.0f - v), phi = 2 * kPi * u;
      if (theta < 0.3f || theta > kPi - 0.3f) continue;  // the poles, where the lat-long bumps crowd below a texel's size
      const Vec3 d = sphere_dir(theta, phi);
      RTCRayHit rh{};
      rh.ray = {2 * d.x, 2 * d.y, 2 * d.z, 0, -d.x, -d.y, -d.z, 0, 10, 0xffffffffu, 0, 0};  // from outside, towards the centre
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(embree_scene(high_rays), &ctx, &rh);
      ASSERT_NE(rh.hit.geomID, RTC_INVALID_GEOMETRY_ID) << d.x << " " << d.y << " " << d.z;
      const Mesh& hm = high.meshes[0];
      const std::uint32_t* i = &hm.indices[3 * rh.hit.primID];
      const float bu = rh.hit.u, bv = rh.hit.v;
      const Vec3 nrm = normalize(hm.normals[i[0]] * (1 - bu - bv) + hm.normals[i[1]] * bu + hm.normals[i[2]] * bv);
      const float ref = estimate_visibility(high_rays, d * (2 - rh.ray.tfar), nrm, unlimited, rp, static_cast<std::uint32_t>(y * size + x)).visibility;
      const float got = r.visibility(x, y);
      se += (got - ref) * (got - ref);
      se_low += (1.0 - ref) * (1.0 - ref);  // what a bake of the (convex) low mesh itself would give: V = 1
      ref_min = std::min<double>(ref_min, ref);
      ++n;
    }
  ASSERT_GT(n, 100);
  const double rmse = std::sqrt(se / n), rmse_low = std::sqrt(se_low / n);
  // Tolerance 0.025: about twice the RMSE measured here (0.0137 over 357 points with the default 4
  // cage points per texel; 0.0109 with a cage ray per sample, 0.0256 with one per texel), which is the
  // Monte Carlo noise of the bake (256 scrambled-Sobol samples per texel) and of the reference (2048
  // rays) plus the texel's average against the value at its centre (bumps 0.8 rad long, texels 0.1 x
  // 0.05 rad). A bake that used the wrong surface, e.g. the convex low mesh (V = 1), is off by 0.124.
  EXPECT_LT(rmse, 0.025) << "points " << n;
  // The test can tell: the bumps darken the valleys well below 1, so V = 1 everywhere is far off.
  EXPECT_LT(ref_min, 0.8);
  EXPECT_GT(rmse_low, 4 * 0.025);
}

TEST(HighToLow, MissesAreReportedMaskedAndFilledFromNeighbours) {
  const Scene low = prepared(lat_long_sphere(24, 12, round_unit, true), "low");
  // A hole in the high sphere: no triangle within 25 degrees of +x.
  const Scene high = prepared(lat_long_sphere(128, 64, round_unit, false, [](Vec3 d) { return d.x < std::cos(25.0f * kPi / 180.0f); }), "high");
  const RayScene high_rays(high);
  const TexelCoverage cov = compute_texel_coverage(low, 64);
  HighToLowParams p;
  p.ao.samples = 16;
  p.cage_extrusion = 0.05f;
  const BakeResult r = bake_high_to_low(low, cov, extrude_cage(low, *p.cage_extrusion), high_rays, high_rays, p);
  ASSERT_GT(r.missed_texels, 20u);
  std::size_t marked = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      if (!r.missed(x, y)) continue;
      ++marked;
      EXPECT_TRUE(r.mask(x, y));
      // Texel (x, y) looks towards +x: u near 0 or 1 (phi = 0) and v near 0.5.
      const float u = (static_cast<float>(x) + 0.5f) / 64, v = 1.0f - (static_cast<float>(y) + 0.5f) / 64;
      const Vec3 d = sphere_dir(kPi * (1 - v), 2 * kPi * u);
      EXPECT_GT(d.x, std::cos(40.0f * kPi / 180.0f)) << x << "," << y;
      // Filled from the neighbours: an open sphere (the inside of the hole's rim is seen through it,
      // but a sphere's outside is fully open), not black.
      EXPECT_GT(r.visibility(x, y), 0.9f) << x << "," << y;
    }
  EXPECT_EQ(marked, r.missed_texels);
}

TEST(HighToLow, ExplicitCageEqualsTheExtrudedOne) {
  const Scene low = prepared(lat_long_sphere(24, 12, round_unit, true), "low");
  const Scene high = prepared(lat_long_sphere(96, 48, bumpy, false), "high");
  const RayScene high_rays(high);
  const TexelCoverage cov = compute_texel_coverage(low, 32);
  HighToLowParams p = params_for_bumps();
  p.ao.samples = 32;
  const CagePositions extruded = extrude_cage(low, 0.2f);
  Scene cage_scene = low;
  cage_scene.name = "cage";
  cage_scene.meshes[0].positions = extruded[0];
  const BakeResult a = bake_high_to_low(low, cov, extruded, high_rays, high_rays, p);
  const BakeResult b = bake_high_to_low(low, cov, cage_from_mesh(low, cage_scene), high_rays, high_rays, p);
  for (std::size_t i = 0; i < a.visibility.size(); ++i) ASSERT_EQ(a.visibility[i], b.visibility[i]);
}

TEST(HighToLow, CageOfAnotherTopologyIsAOneLineError) {
  const Scene low = prepared(lat_long_sphere(24, 12, round_unit, true), "low");
  const Scene other = prepared(lat_long_sphere(20, 10, round_unit, true), "cage.obj");
  try {
    cage_from_mesh(low, other);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("cage.obj"), std::string::npos) << msg;
    EXPECT_NE(msg.find("topology"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

// The cage ray's hit is interpolated with triangle barycentrics, so a quad BVH of the high mesh
// (the ray-traced bake's) is refused; as occluders it is fine.
TEST(HighToLow, QuadTargetsAreRejectedQuadOccludersAreNot) {
  const Scene low = prepared(lat_long_sphere(12, 6, round_unit, true), "low");
  const Scene high = prepared(lat_long_sphere(24, 12, round_unit, false), "high");
  const RayScene tris(high);
  const RayScene quads(high, bake_bvh_options(high.triangle_count()));
  ASSERT_TRUE(quads.quads());
  const TexelCoverage cov = compute_texel_coverage(low, 16);
  HighToLowParams p;
  p.ao.samples = 16;
  p.cage_extrusion = 0.05f;
  const CagePositions cage = extrude_cage(low, *p.cage_extrusion);
  EXPECT_THROW(bake_high_to_low(low, cov, cage, quads, quads, p), InputError);
  const BakeResult want = bake_high_to_low(low, cov, cage, tris, tris, p);
  const BakeResult got = bake_high_to_low(low, cov, cage, tris, quads, p);
  double diff = 0;
  for (std::size_t i = 0; i < want.visibility.size(); ++i) diff = std::max(diff, std::abs(static_cast<double>(got.visibility[i]) - want.visibility[i]));
  EXPECT_LE(diff, 2.0 / 16);  // the same rays; one grazing an edge two triangles share may differ
}

// The filter on a high-to-low map: a low floor (UVs over the map) bakes a high floor 0.01 above it
// under a ceiling at height d = 0.5 above the high floor, occluders within R = 1, where V = (d/R)^2
// = 1/4 at every high point (bake_test.cpp derives it). At 16 rays per texel the filter must more
// than halve the error and keep the mean (16 x 32 x 32 samples: standard error ~0.002).
TEST(HighToLow, DenoisingAveragesTheNoiseAndKeepsTheMean) {
  Mesh floor = make_quad({-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, {-2, 0, -2});
  floor.uvs = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  const Scene low = prepared(floor, "low");
  const Scene high = prepared(make_quad({-2, 0.01f, 2}, {2, 0.01f, 2}, {2, 0.01f, -2}, {-2, 0.01f, -2}), "high");
  Scene around = high;
  around.meshes.push_back(make_box({-8, 0.51f, -8}, {8, 0.71f, 8}));
  validate_and_prepare(around);
  const RayScene targets(high), occluders(around);
  const TexelCoverage cov = compute_texel_coverage(low, 32);
  HighToLowParams p;
  p.ao.samples = 16;
  p.ao.max_distance = 1.0f;
  p.cage_extrusion = 0.05f;
  const CagePositions cage = extrude_cage(low, *p.cage_extrusion);
  auto error = [&](float sigma) {
    HighToLowParams q = p;
    q.ao.denoise = sigma;
    const BakeResult r = bake_high_to_low(low, cov, cage, targets, occluders, q);
    EXPECT_EQ(r.missed_texels, 0u);
    double se = 0, sum = 0;
    int n = 0;
    for (std::size_t i = 0; i < r.visibility.size(); ++i)
      if (r.mask[i]) se += (r.visibility[i] - 0.25) * (r.visibility[i] - 0.25), sum += r.visibility[i], ++n;
    return std::pair{std::sqrt(se / n), sum / n};
  };
  const auto [rmse0, mean0] = error(0.0f);
  const auto [rmse1, mean1] = error(1.0f);
  EXPECT_GT(rmse0, 0.02);
  EXPECT_LT(rmse1, 0.5 * rmse0);
  EXPECT_NEAR(mean0, 0.25, 0.01);
  EXPECT_NEAR(mean1, 0.25, 0.01);
}

TEST(HighToLow, BadDistancesAreRejected) {
  HighToLowParams p;
  p.cage_extrusion = -1.0f;
  EXPECT_THROW(p.validate(), InputError);
  p.cage_extrusion.reset();
  p.max_back = std::nanf("");
  EXPECT_THROW(p.validate(), InputError);
  p.max_back.reset();
  p.max_front = kInfinity;
  EXPECT_THROW(p.validate(), InputError);
}

}  // namespace
}  // namespace ao
