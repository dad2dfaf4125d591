// SPDX-License-Identifier: Apache-2.0
// The AO family of maps (thickness, cavity, spread angle, relative distance, tangent-space bent
// normals) against configurations with known answers: a slab of known depth, a floor under a
// ceiling, planes and a cylinder whose UV parameterisation gives the tangent frame in closed form.
#include <gtest/gtest.h>

#include <cmath>

#include "ao/bake/raytraced_bake.h"
#include "ao/bake/tangents.h"
#include "ao/bake/texel_coverage.h"
#include "ao/core/error.h"
#include "ao/jobs/bake.h"
#include "ao/reference/ray_scene.h"
#include "ao/scene/procedural.h"
#include "support/bake_maps.h"
#include "support/scenes.h"

namespace ao {
namespace {

// Quad facing +y at height y, x in [-0.5, 0.5], z in [0, 1], UVs over the whole map.
Mesh uv_floor(float y) {
  Mesh m = make_quad({-0.5f, y, 1}, {0.5f, y, 1}, {0.5f, y, 0}, {-0.5f, y, 0});
  m.uvs = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  return m;
}

using test::mean_covered;
using test::scene_of;

BakeResult bake(const Scene& s, const RaytracedBakeParams& p, int size = 16) {
  const RayScene rays(s);
  return bake_raytraced(rays, compute_texel_coverage(s, size), p, {});
}

// The linear membership mu = min(d / R, 1) over the cosine-weighted cone of half-angle alpha
// about a plane's normal, with a parallel plane at distance h (a = h / R): a ray at cos(theta) = c
// meets it at d = h / c, and c has density 2c / sin^2(alpha) on [cos(alpha), 1]. For
// c >= a, mu = a / c; below, 1:
//   V = (1 / sin^2 alpha) * [ integral from cos(alpha) to max(a, cos(alpha)) of 2c dc
//                             + integral from max(a, cos(alpha)) to 1 of 2a dc ].
double linear_between_planes(double a, double alpha) {
  const double lo = std::cos(alpha), mid = std::clamp(a, lo, 1.0), s2 = std::sin(alpha) * std::sin(alpha);
  return ((mid * mid - lo * lo) + 2 * a * (1 - mid)) / s2;
}

RaytracedBakeParams linear(float r, float spread = 180.0f, Hemisphere side = Hemisphere::Outside) {
  RaytracedBakeParams p;
  p.samples = 256;
  p.membership = Membership::Linear;
  p.max_distance = r;
  p.spread_angle = spread;
  p.hemisphere = side;
  return p;
}

TEST(BakeFamily, ThicknessOfASlabIsTheClosedForm) {
  // The baked face is the top of a slab of depth h = 1, 40 wide: rays into it meet the bottom at
  // d = h / cos(theta); the side walls lie 20 away, beyond every R here.
  const Scene s = scene_of({uv_floor(1.0f), make_box({-20, 0, -20}, {20, 1, 20})});
  for (const float r : {0.5f, 2.0f, 4.0f}) {
    SCOPED_TRACE("R = " + std::to_string(r));
    const double want = linear_between_planes(1.0 / r, kPi / 2);
    EXPECT_NEAR(mean_covered(bake(s, linear(r, 180.0f, Hemisphere::Inside))), want, 0.01);
  }
  EXPECT_NEAR(linear_between_planes(0.5, kPi / 2), 0.75, 1e-12);  // 2a - a^2: the closed form itself
  // A 120-degree cone (alpha = 60 degrees), R = 2: the grazing half of the hemisphere is left out.
  EXPECT_NEAR(mean_covered(bake(s, linear(2.0f, 120.0f, Hemisphere::Inside))), linear_between_planes(0.5, kPi / 3), 0.01);
  // The outside of the slab's top is open sky: thickness looks the other way, AO sees nothing.
  EXPECT_EQ(mean_covered(bake(s, linear(2.0f))), 1.0);
}

TEST(BakeFamily, SpreadAngleNarrowsTheConeOfAO) {
  // A floor under a ceiling at height 1: the same closed form as the slab, for the outside.
  const Scene s = scene_of({uv_floor(0.0f), make_box({-20, 1, -20}, {20, 1.2f, 20})});
  for (const float spread : {180.0f, 120.0f, 60.0f}) {
    SCOPED_TRACE("spread " + std::to_string(spread));
    const double alpha = spread * kPi / 360.0;
    EXPECT_NEAR(mean_covered(bake(s, linear(2.0f, spread))), linear_between_planes(0.5, alpha), 0.01);
  }
  // Step membership, R = 1.5: a ray is unoccluded when d = 1 / c >= R, i.e. c <= 2/3; in a cone
  // of half-angle 60 degrees that is (4/9 - 1/4) / (3/4) of the cosine-weighted directions.
  RaytracedBakeParams step;
  step.samples = 256;
  step.max_distance = 1.5f;
  step.spread_angle = 120.0f;
  EXPECT_NEAR(mean_covered(bake(s, step)), (4.0 / 9 - 0.25) / 0.75, 0.01);
}

TEST(BakeFamily, RelativeDistanceIsAFractionOfTheBakedMeshesDiagonal) {
  // The baked floor is 1 x 1 (diagonal sqrt 2); the ceiling occludes but does not count.
  const Scene s = scene_of({uv_floor(0.0f), make_box({-20, 1, -20}, {20, 1.2f, 20})});
  RaytracedBakeParams relative = linear(1.0f);
  relative.relative_distance = true;
  const BakeResult a = bake(s, relative), b = bake(s, linear(std::sqrt(2.0f)));
  for (std::size_t i = 0; i < a.visibility.size(); ++i) ASSERT_EQ(a.visibility[i], b.visibility[i]) << "texel " << i;
  EXPECT_LT(mean_covered(a), 0.99);  // the ceiling is within reach
  // Per-vertex AO of meshes without UVs: a fraction of every mesh's diagonal (here the ceiling's box and a
  // floor quad: from (-20, 0, -20) to (20, 1.2, 20)).
  const Scene bare = scene_of({make_quad({-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}), make_box({-20, 1, -20}, {20, 1.2f, 20})});
  const RayScene bare_rays(bare);
  RaytracedBakeParams per_vertex = relative;
  per_vertex.max_distance = 0.05f;
  const std::vector<float> rel = bake_vertices_raytraced(bare_rays, per_vertex);
  const std::vector<float> abs = bake_vertices_raytraced(bare_rays, linear(0.05f * length(Vec3{40, 1.2f, 40})));
  ASSERT_EQ(rel, abs);
  EXPECT_LT(rel[0], 0.99f);  // the ceiling at 1 is within 0.05 x 56.6
  RaytracedBakeParams no_distance;
  no_distance.relative_distance = true;
  EXPECT_THROW(no_distance.validate(), InputError);
  RaytracedBakeParams inside_ignoring = linear(1.0f, 180.0f, Hemisphere::Inside);
  inside_ignoring.ignore_back_faces = true;
  EXPECT_THROW(inside_ignoring.validate(), InputError);
  RaytracedBakeParams zero_spread;
  zero_spread.spread_angle = 0.0f;
  EXPECT_THROW(zero_spread.validate(), InputError);
}

// A flat n x n grid in y = 0 (facing +y), x and z in [0, 1], UV = the linear map `uv` of (x, z).
template <class UvOf>
Mesh uv_grid(int n, UvOf uv) {
  Mesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float x = static_cast<float>(i) / n, z = static_cast<float>(j) / n;
      m.positions.push_back({x, 0, z});
      m.uvs.push_back(uv(x, z));
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const auto v = [&](int a, int b) { return static_cast<std::uint32_t>(b * (n + 1) + a); };
      // Counter-clockwise seen from +y.
      for (const std::uint32_t k : {v(i, j), v(i, j + 1), v(i + 1, j + 1), v(i, j), v(i + 1, j + 1), v(i + 1, j)}) m.indices.push_back(k);
    }
  return m;
}

TEST(Tangents, APlaneTakesItsParameterisationsDirections) {
  // UV = a rotation by phi of (x, z), scaled, mirrored or not: dP/du and dP/dv are the columns of
  // the inverse map; MikkTSpace's tangent is dP/du, and sign * cross(n, t) points along dP/dv.
  for (const bool mirror : {false, true})
    for (const float phi : {0.0f, 0.7f, 2.5f}) {
      SCOPED_TRACE(std::string(mirror ? "mirrored" : "kept") + ", phi " + std::to_string(phi));
      const float c = std::cos(phi), s = std::sin(phi), m = mirror ? -1.0f : 1.0f;
      const Scene scene = scene_of({uv_grid(4, [&](float x, float z) { return Vec2{m * (c * x - s * z) * 0.5f, (s * x + c * z) * 0.5f}; })});
      // (u, v) = 0.5 * [[m c, -m s], [s, c]] (x, z): its inverse's columns, normalised.
      const Vec3 du = normalize(Vec3{m * c, 0, -m * s}), dv = normalize(Vec3{s, 0, c});
      const Mesh& mesh = scene.meshes[0];
      const std::vector<CornerTangent> t = mikktspace_tangents(mesh);
      ASSERT_EQ(t.size(), mesh.indices.size());
      for (std::size_t k = 0; k < t.size(); ++k) {
        const Vec3 n = mesh.normals[mesh.indices[k]];
        EXPECT_NEAR(dot(t[k].t, du), 1.0f, 1e-5f) << "corner " << k;
        EXPECT_NEAR(dot(cross(n, t[k].t) * t[k].sign, dv), 1.0f, 1e-5f) << "corner " << k;
      }
    }
}

TEST(Tangents, ACylinderTakesTheDirectionAroundIt) {
  // u = the angle around the axis / 2 pi: the tangent is the circumferential direction.
  Mesh m;
  const int segments = 16, rows = 3;
  for (int j = 0; j <= rows; ++j)
    for (int i = 0; i <= segments; ++i) {  // the seam's column twice, with u = 0 and u = 1
      const float a = 2 * kPi * static_cast<float>(i) / segments;
      m.positions.push_back({std::cos(a), static_cast<float>(j) / rows, -std::sin(a)});
      m.normals.push_back({std::cos(a), 0, -std::sin(a)});  // radial, on the seam's two columns alike
      m.uvs.push_back({static_cast<float>(i) / segments, static_cast<float>(j) / rows});
    }
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < segments; ++i) {
      const auto v = [&](int a, int b) { return static_cast<std::uint32_t>(b * (segments + 1) + a); };
      for (const std::uint32_t k : {v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j), v(i + 1, j + 1), v(i, j + 1)}) m.indices.push_back(k);
    }
  const Scene s = scene_of({m});
  const Mesh& mesh = s.meshes[0];
  const std::vector<CornerTangent> t = mikktspace_tangents(mesh);
  for (std::size_t k = 0; k < t.size(); ++k) {
    const Vec3 p = mesh.positions[mesh.indices[k]];
    const Vec3 around = normalize(Vec3{p.z, 0, -p.x});  // d/da of (cos a, y, -sin a)
    EXPECT_NEAR(dot(t[k].t, around), 1.0f, 1e-4f) << "corner " << k;
    EXPECT_NEAR(dot(t[k].t, mesh.normals[mesh.indices[k]]), 0.0f, 1e-5f) << "corner " << k;
    EXPECT_EQ(t[k].sign, 1.0f);  // u around, v up, normal out: right-handed
  }
}

TEST(Tangents, TangentSpaceIsWhatAShaderDecodes) {
  // For frames that are neither unit nor orthogonal (interpolated ones), the shader's decoding
  // normalize(x t + y b + z n) of the encoded direction gives the direction back.
  const Vec3 frames[][2] = {{{1, 0, 0}, {0, 0, 1}}, {{0.9f, 0.1f, 0.2f}, {0.1f, 0.2f, 1.1f}}, {{-0.5f, 0.8f, 0.1f}, {0.3f, 0.3f, 0.9f}}};
  const Vec3 dirs[] = {{0, 0, 1}, {0.3f, -0.2f, 0.9f}, {-0.7f, 0.1f, 0.2f}};
  for (const auto& f : frames)
    for (const float sign : {1.0f, -1.0f})
      for (const Vec3 w : dirs) {
        const Vec3 x = to_tangent_space(w, f[0], f[1], sign);
        const Vec3 b = cross(f[1], f[0]) * sign;
        const Vec3 back = normalize(f[0] * x.x + b * x.y + f[1] * x.z);
        const Vec3 want = normalize(w);
        EXPECT_NEAR(length(back - want), 0.0f, 1e-5f);
        EXPECT_NEAR(length(x), 1.0f, 1e-5f);
      }
}

TEST(BakeFamily, TangentSpaceBentNormalsAreTheWorldOnesInThePlanesFrame) {
  // A floor beside a wall, UVs rotated on it: the tangent-space map is the world-space map seen in
  // the frame (dP/du, dP/dv, n) of the parameterisation.
  const float phi = 0.7f, c = std::cos(phi), s = std::sin(phi);
  const Scene scene = scene_of({uv_grid(4, [&](float x, float z) { return Vec2{0.5f + 0.5f * (c * x - s * z), 0.05f + 0.5f * (s * x + c * z)}; }),
                                 make_box({-1, 0, -0.2f}, {2, 0.5f, 0})});
  BakeRequest r;
  r.scene = std::make_shared<const Scene>(scene);
  r.size = MapSize{32, 32};
  r.denoise = 0.0f;
  r.padding = 0;
  r.outputs.map = "map.png";
  r.outputs.bent_normals = "bent.png";  // names what to bake: nothing is written for a scene in memory
  const BakeBatchResult world = run_bake(r);
  r.bent_normal_space = BentNormalSpace::Tangent;
  const BakeBatchResult tangent = run_bake(r);
  const Image<Vec3>& w = world.meshes.at(0).map.bent_normal;
  const Image<Vec3>& t = tangent.meshes.at(0).map.bent_normal;
  ASSERT_FALSE(w.empty());
  const Vec3 du = normalize(Vec3{c, 0, -s}), dv = normalize(Vec3{s, 0, c}), n{0, 1, 0};
  std::size_t checked = 0;
  for (std::size_t i = 0; i < w.size(); ++i) {
    if (!world.meshes[0].map.mask[i]) continue;
    const Vec3 want = normalize(Vec3{dot(w[i], du), dot(w[i], dv), dot(w[i], n)});
    ASSERT_NEAR(length(t[i] - want), 0.0f, 1e-4f) << "texel " << i;
    ++checked;
  }
  EXPECT_GT(checked, 200u);
}

TEST(BakeFamily, CavityIsTheMapWithinItsRelativeDistance) {
  const Scene scene = scene_of({uv_floor(0.0f), make_box({-0.2f, 0, 0.3f}, {0.2f, 0.05f, 0.6f})});
  BakeRequest r;
  r.scene = std::make_shared<const Scene>(scene);
  r.size = MapSize{32, 32};
  r.outputs.map = "map.png";
  r.outputs.cavity = "cavity.png";
  r.outputs.thickness = "thickness.png";
  r.cavity_distance = 0.05f;
  const BakeBatchResult family = run_bake(r);
  BakeRequest plain = r;
  plain.outputs.cavity.clear();
  plain.outputs.thickness.clear();
  plain.raytraced.max_distance = 0.05f;
  plain.raytraced.relative_distance = true;
  const BakeBatchResult near = run_bake(plain);
  const Image<float>& cavity = family.meshes.at(0).cavity;
  ASSERT_EQ(cavity.size(), near.meshes.at(0).map.visibility.size());
  for (std::size_t i = 0; i < cavity.size(); ++i) ASSERT_EQ(cavity[i], near.meshes[0].map.visibility[i]) << "texel " << i;
  // A single-sided floor has nothing behind it: its thickness is 1 everywhere (nothing within R).
  const Image<float>& thickness = family.meshes[0].thickness;
  ASSERT_FALSE(thickness.empty());
  for (std::size_t i = 0; i < thickness.size(); ++i) {
    if (family.meshes[0].map.mask[i]) {
      ASSERT_NEAR(thickness[i], 1.0f, 1e-6f) << "texel " << i;
    }
  }
}

TEST(BakeFamily, HighToLowThicknessIsTheHighMeshsDepth) {
  // The low mesh is a quad on the top of a slab of depth 1 that is the high mesh: rays into the
  // high surface meet its bottom, as in ThicknessOfASlabIsTheClosedForm. R = 2 (a fraction
  // 2 / sqrt 2 of the low quad's diagonal): 2a - a^2 at a = 1/2.
  const Scene low = scene_of({uv_floor(1.0f)});
  const Scene high = scene_of({make_box({-20, 0, -20}, {20, 1, 20})});
  BakeRequest r;
  r.scene = std::make_shared<const Scene>(low);
  r.high_scene = std::make_shared<const Scene>(high);
  r.size = MapSize{16, 16};
  r.raytraced.samples = 256;
  r.outputs.map = "map.png";
  r.outputs.thickness = "thickness.png";
  r.thickness_distance = 2.0f / std::sqrt(2.0f);
  const BakeBatchResult out = run_bake(r);
  const MeshBake& m = out.meshes.at(0);
  ASSERT_FALSE(m.thickness.empty());
  ASSERT_GT(m.map.covered_texels, 100u);
  EXPECT_NEAR(mean_covered(m.map, m.thickness), 0.75, 0.01);
  EXPECT_NEAR(m.summary.at("thickness").at("max_distance").get<double>(), 2.0, 1e-5);
  EXPECT_EQ(m.summary.at("parameters").at("hemisphere"), "outside");  // the summary's settings are the AO map's
}

TEST(BakeFamily, BadFamilyRequestsAreRefused) {
  BakeRequest r;
  r.inputs = {"mesh.obj"};
  r.outputs.thickness = "t.png";
  r.method = Baker::Histogram;
  EXPECT_THROW(resolve_bake_request(r), InputError);
  r.method = Baker::Raytraced;
  r.thickness_distance = 0.0f;
  EXPECT_THROW(resolve_bake_request(r), InputError);
  r.thickness_distance = 0.25f;
  r.raytraced.ignore_back_faces = true;
  EXPECT_THROW(resolve_bake_request(r), InputError);
  BakeRequest space;
  space.inputs = {"mesh.obj"};
  space.bent_normal_space = BentNormalSpace::Tangent;  // without the bent normals output
  EXPECT_THROW(resolve_bake_request(space), InputError);
  EXPECT_THROW(bent_normal_space_from_name("tangnet"), InputError);
}

}  // namespace
}  // namespace ao
