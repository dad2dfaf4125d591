// SPDX-License-Identifier: Apache-2.0
// The ray-traced baker's choice of hemisphere (RaytracedBakeParams::normal, `ao bake --normal`):
// where the shading normals are the face normals (a flat-shaded cube) both choices bake the same
// map and the same vertex values; where they are not (a coarse smooth-shaded sphere, a convex
// solid) only the shading hemisphere reaches below the faces, so only it loses visibility.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "ao/bake/raytraced_bake.h"
#include "ao/bake/texel_coverage.h"
#include "ao/scene/procedural.h"

namespace ao {
namespace {

// A cube (flat: 4 vertices and one normal per face) with each face in its own cell of a 3 x 2
// UV grid, standing on a floor quad without UVs that only occludes.
Scene cube_on_floor() {
  Scene s;
  Mesh cube = make_box({-0.5f, 0, -0.5f}, {0.5f, 1, 0.5f});
  const float m = 0.02f;  // margin between cells
  for (std::size_t f = 0; f < 6; ++f) {
    const float u0 = static_cast<float>(f % 3) / 3 + m, v0 = static_cast<float>(f / 3) / 2 + m, u1 = u0 + 1.0f / 3 - 2 * m, v1 = v0 + 0.5f - 2 * m;
    for (const Vec2 uv : {Vec2{u0, v0}, Vec2{u1, v0}, Vec2{u1, v1}, Vec2{u0, v1}}) cube.uvs.push_back(uv);
  }
  s.meshes.push_back(std::move(cube));
  s.meshes.push_back(make_quad({-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, {-4, 0, -4}));
  s.name = "cube";
  validate_and_prepare(s);
  return s;
}

// A coarse UV sphere (12 x 6) with smooth vertex normals and latitude-longitude UVs, alone or
// touching a floor quad.
Scene coarse_sphere(bool floor = false) {
  constexpr int segments = 12, rings = 6;
  Scene s;
  Mesh sphere = make_sphere({0, 0, 0}, 1.0f, segments, rings);
  for (int r = 0; r <= rings; ++r)
    for (int k = 0; k <= segments; ++k) sphere.uvs.push_back({static_cast<float>(k) / segments, static_cast<float>(r) / rings});
  s.meshes.push_back(std::move(sphere));
  if (floor) s.meshes.push_back(make_quad({-4, -1, 4}, {4, -1, 4}, {4, -1, -4}, {-4, -1, -4}));
  s.name = "sphere";
  validate_and_prepare(s);
  return s;
}

RaytracedBakeParams with_normal(SurfaceNormal n) { return {.samples = 64, .normal = n, .seed = 3}; }

TEST(BakeNormal, FlatShadedCubeGivesTheSameMapAndVerticesWithEitherNormal) {
  const Scene s = cube_on_floor();
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  const TexelCoverage cov = compute_texel_coverage(s, 48);
  const BakeResult a = bake_raytraced(rs, cov, with_normal(SurfaceNormal::Shading));
  const BakeResult b = bake_raytraced(rs, cov, with_normal(SurfaceNormal::Geometric));
  double sum_v = 0, max_diff = 0;
  std::size_t covered = 0;
  for (std::size_t i = 0; i < a.visibility.size(); ++i) {
    if (!a.mask[i]) continue;
    ++covered;
    sum_v += a.visibility[i];
    max_diff = std::max(max_diff, static_cast<double>(std::abs(a.visibility[i] - b.visibility[i])));
  }
  EXPECT_GT(covered, 500u);
  EXPECT_LT(sum_v / static_cast<double>(covered), 0.99) << "the floor must occlude the cube's lower texels for the test to mean anything";
  // Same sample sets about the same normal vectors (axis-aligned faces: the interpolated normal
  // and the cross product are exact): identical maps.
  EXPECT_EQ(max_diff, 0.0);
  const std::vector<float> va = bake_vertices_raytraced(rs, with_normal(SurfaceNormal::Shading));
  const std::vector<float> vb = bake_vertices_raytraced(rs, with_normal(SurfaceNormal::Geometric));
  ASSERT_EQ(va.size(), vb.size());
  for (std::size_t i = 0; i < va.size(); ++i) EXPECT_EQ(va[i], vb[i]) << "vertex " << i;
}

TEST(BakeNormal, CoarseSmoothSphereDiffersBetweenNormals) {
  const Scene s = coarse_sphere();
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  const TexelCoverage cov = compute_texel_coverage(s, 64);
  const BakeResult shading = bake_raytraced(rs, cov, with_normal(SurfaceNormal::Shading));
  const BakeResult geometric = bake_raytraced(rs, cov, with_normal(SurfaceNormal::Geometric));
  // A convex solid: about each face's own normal nothing of it is in view, so V = 1 exactly;
  // the smooth normal tilts the hemisphere below the face away from the face centres, and those
  // rays count as occluded.
  double mean_shading = 0;
  std::size_t covered = 0;
  for (std::size_t i = 0; i < geometric.visibility.size(); ++i) {
    if (!geometric.mask[i]) continue;
    ++covered;
    EXPECT_EQ(geometric.visibility[i], 1.0f) << "texel " << i;
    mean_shading += shading.visibility[i];
  }
  ASSERT_GT(covered, 500u);
  mean_shading /= static_cast<double>(covered);
  EXPECT_LT(mean_shading, 0.995);
}

// Per vertex: a floor and a wall 2 wide and 1 deep/high meeting at a right angle along x, welded
// there, so the smooth normal on the crease is the mean of the two faces', (0, 1, 1) / sqrt 2.
// At the crease every direction below either plane is blocked at once and every other one is open
// (unlimited distance), so V is the cosine-weighted share of the quarter-space above the floor and
// in front of the wall: 1 - 2 (1 - cos 45 deg) / 2 = 0.7071 about the smooth normal (each plane
// cuts a cap of projected fraction (1 - cos 45 deg) / 2 off its hemisphere), 0.5 about either face
// normal (the other plane halves its hemisphere).
TEST(BakeNormal, SmoothCreaseVertexDiffersBetweenNormals) {
  Mesh m;
  for (const float x : {-1.0f, 0.0f, 1.0f}) {
    m.positions.push_back({x, 0, 1});  // floor, far edge
    m.positions.push_back({x, 0, 0});  // crease
    m.positions.push_back({x, 1, 0});  // wall, top edge
  }
  for (std::uint32_t c = 0; c < 2; ++c) {
    const std::uint32_t a = 3 * c, b = 3 * (c + 1);
    for (const std::uint32_t i : {a, b, b + 1, a, b + 1, a + 1}) m.indices.push_back(i);      // floor, facing +y
    for (const std::uint32_t i : {a + 1, b + 1, b + 2, a + 1, b + 2, a + 2}) m.indices.push_back(i);  // wall, facing +z
  }
  Scene s;
  s.meshes.push_back(std::move(m));
  s.name = "crease";
  validate_and_prepare(s);
  ASSERT_NEAR(s.meshes[0].normals[4].y, std::sqrt(0.5f), 1e-5f);
  const RayScene rs(s, bake_bvh_options(s.triangle_count()));
  RaytracedBakeParams p{.samples = 4096, .seed = 3};
  const float shading = bake_vertices_raytraced(rs, p)[4];
  p.normal = SurfaceNormal::Geometric;
  const float geometric = bake_vertices_raytraced(rs, p)[4];
  // Tolerance 0.005: a few times the sampling error of 4096 scrambled-Sobol rays (binomial
  // bound sqrt(0.25 / 4096) = 0.008, Sobol well under it).
  EXPECT_NEAR(geometric, 0.5, 0.005);
  EXPECT_NEAR(shading, 1.0 - (1.0 - std::sqrt(0.5)), 0.005);
}

}  // namespace
}  // namespace ao
