// SPDX-License-Identifier: Apache-2.0
#include "ao/scene/procedural.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>
#include <vector>
#include <utility>

#include "ao/core/error.h"

namespace ao {
namespace {

// A closed, consistently oriented mesh uses every directed edge exactly once and its reverse once.
bool is_closed_and_oriented(const Mesh& m) {
  // Weld by position: builders duplicate vertices along creases for flat normals.
  std::map<std::tuple<float, float, float>, int> ids;
  auto id = [&](std::uint32_t v) {
    const Vec3 p = m.positions[v];
    return ids.emplace(std::make_tuple(p.x, p.y, p.z), static_cast<int>(ids.size())).first->second;
  };
  std::map<std::pair<int, int>, int> edges;
  for (std::size_t t = 0; t < m.indices.size(); t += 3)
    for (int k = 0; k < 3; ++k) ++edges[{id(m.indices[t + k]), id(m.indices[t + (k + 1) % 3])}];
  for (const auto& [e, count] : edges) {
    if (count != 1) return false;
    const auto it = edges.find({e.second, e.first});
    if (it == edges.end() || it->second != 1) return false;
  }
  return true;
}

// Signed volume by the divergence theorem: positive for outward-facing closed meshes.
double signed_volume(const Mesh& m) {
  double v = 0;
  for (std::size_t t = 0; t < m.indices.size(); t += 3) {
    const Vec3 a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]], c = m.positions[m.indices[t + 2]];
    v += dot(a, cross(b, c)) / 6.0;
  }
  return v;
}

TEST(Procedural, BoxIsClosedWithExactVolume) {
  const Mesh box = make_box({0, 0, 0}, {1, 2, 3}, {}, 30.0f);
  EXPECT_TRUE(is_closed_and_oriented(box));
  EXPECT_NEAR(signed_volume(box), 6.0, 1e-4);
  EXPECT_NEAR(signed_volume(make_box({0, 0, 0}, {1, 2, 3}, {}, 0.0f, true)), -6.0, 1e-4);
}

TEST(Procedural, ClosedShapesAreClosedAndFaceOutwards) {
  const Mesh sphere = make_sphere({0, 0, 0}, 1.0f, 64, 32);
  EXPECT_TRUE(is_closed_and_oriented(sphere));
  EXPECT_NEAR(signed_volume(sphere), 4.0 / 3.0 * M_PI, 0.02);
  const Mesh cylinder = make_cylinder({0, 0, 0}, 0.5f, 2.0f, 64);
  EXPECT_TRUE(is_closed_and_oriented(cylinder));
  EXPECT_NEAR(signed_volume(cylinder), M_PI * 0.25 * 2.0, 0.01);
  const Mesh torus = make_torus({0, 0, 0}, 1.0f, 0.25f, 96, 32);
  EXPECT_TRUE(is_closed_and_oriented(torus));
  EXPECT_NEAR(signed_volume(torus), 2 * M_PI * M_PI * 1.0 * 0.0625, 0.01);
}

TEST(Procedural, ShadingNormalsAgreeWithWinding) {
  for (const Mesh& m : {make_sphere({0, 0, 0}, 1.0f), make_torus({0, 0, 0}, 1.0f, 0.3f), make_cylinder({0, 0, 0}, 1, 1)})
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
      const Vec3 a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]], c = m.positions[m.indices[t + 2]];
      ASSERT_GT(dot(cross(b - a, c - a), m.normals[m.indices[t]]), 0.0f) << "triangle " << t / 3;
    }
}

TEST(Procedural, EveryBuiltinSceneBuildsAndValidates) {
  for (const std::string& name : builtin_scene_names()) {
    const Scene s = make_builtin_scene(name);
    EXPECT_GT(s.triangle_count(), 0u) << name;
    EXPECT_TRUE(s.preferred_view.has_value()) << name;
    EXPECT_TRUE(s.warnings.empty()) << name << ": " << (s.warnings.empty() ? "" : s.warnings[0]);
  }
  EXPECT_THROW(make_builtin_scene("teapot"), InputError);
}

TEST(Procedural, AnalyticDescriptionsAreWhereTheListsSay) {
  const std::vector<std::string> implicit = builtin_scenes_with_implicit_surface(), height_field = builtin_scenes_with_height_field();
  EXPECT_EQ(implicit, (std::vector<std::string>{"plane", "wedge", "sphere-on-plane"}));
  EXPECT_EQ(height_field, (std::vector<std::string>{"displaced"}));
  for (const std::string& name : builtin_scene_names()) {
    const Scene s = make_builtin_scene(name);
    EXPECT_EQ(s.analytic.implicit.has_value(), std::count(implicit.begin(), implicit.end(), name) == 1) << name;
    EXPECT_EQ(s.analytic.height_field.has_value(), std::count(height_field.begin(), height_field.end(), name) == 1) << name;
  }
}

// Each implicit description bounds what its meshes show: every vertex is on the boundary of the
// outer region (min f = 0) and no triangle's centroid is outside it (min f <= 0; the sphere's flat
// triangles are inside the round sphere by up to their sagitta).
TEST(Procedural, ImplicitDescriptionsPassThroughTheirMeshes) {
  for (const std::string& name : builtin_scenes_with_implicit_surface()) {
    const Scene s = make_builtin_scene(name);
    const ImplicitSurface& surface = *s.analytic.implicit;
    for (const Mesh& m : s.meshes) {
      for (const Vec3& p : m.positions) ASSERT_NEAR(surface.value(p), 0.0f, 1e-5f) << name << ", " << m.name;
      for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        const Vec3 c = (m.positions[m.indices[t]] + m.positions[m.indices[t + 1]] + m.positions[m.indices[t + 2]]) / 3.0f;
        ASSERT_LE(surface.value(c), 1e-5f) << name << ", " << m.name << ", triangle " << t / 3;
        ASSERT_GT(surface.value(c), -1e-3f) << name << ", " << m.name << ", triangle " << t / 3;
      }
    }
  }
}

TEST(Procedural, DisplacedSceneIsAFloorOfDomesWithObjectsOnIt) {
  const Scene s = make_builtin_scene("displaced");
  ASSERT_EQ(s.meshes.size(), 3u);
  EXPECT_EQ(s.meshes[0].name, "floor");
  const HeightFieldSurface& hf = *s.analytic.height_field;
  ASSERT_TRUE(hf.map);
  float lo = kInfinity, hi = -kInfinity;
  for (const Vec3& p : s.meshes[0].positions) lo = std::min(lo, p.y), hi = std::max(hi, p.y);
  EXPECT_NEAR(lo, 0.0f, 1e-6f);
  // The domes' tops fall between texel centres, half a texel diagonal off: cos^2(pi/2 x 0.088) = 0.98.
  EXPECT_NEAR(hi, 0.98f * hf.amplitude, 0.005f * hf.amplitude);
  // Normals face up, and the winding agrees with them.
  const Mesh& floor = s.meshes[0];
  for (std::size_t t = 0; t < floor.indices.size(); t += 3) {
    const Vec3 a = floor.positions[floor.indices[t]], b = floor.positions[floor.indices[t + 1]], c = floor.positions[floor.indices[t + 2]];
    ASSERT_GT(dot(cross(b - a, c - a), floor.normals[floor.indices[t]]), 0.0f) << "triangle " << t / 3;
    ASSERT_GT(floor.normals[floor.indices[t]].y, 0.3f) << "triangle " << t / 3;
  }
}

TEST(Procedural, DefaultSceneShowsEveryFeature) {
  const Scene s = make_builtin_scene("default");
  std::set<std::string> names;
  for (const Mesh& m : s.meshes) names.insert(m.name);
  for (const char* n : {"ground", "sphere", "box", "stairs", "pillars", "torus", "cubes", "wall"}) EXPECT_TRUE(names.count(n)) << n;
}

TEST(SceneValidation, DropsDegenerateTrianglesWithAWarning) {
  Scene s;
  s.name = "test";
  Mesh m = make_quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0});
  m.positions.push_back({2, 2, 2});
  m.normals.push_back({0, 0, 1});
  m.indices.insert(m.indices.end(), {0, 0, 1, 0, 1, 4});  // repeated index; 0,1,4 is fine
  m.positions[4] = {2, 0, 0};                               // now collinear with 0 and 1: zero area
  s.meshes.push_back(m);
  validate_and_prepare(s);
  EXPECT_EQ(s.triangle_count(), 2u);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("2 degenerate"), std::string::npos) << s.warnings[0];
}

TEST(SceneValidation, RejectsBadMeshes) {
  auto attempt = [](auto mutate) {
    Scene s;
    s.name = "bad.obj";
    s.meshes.push_back(make_quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}));
    mutate(s.meshes[0]);
    try {
      validate_and_prepare(s);
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("bad.obj", 0), 0u) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      return true;
    }
    return false;
  };
  EXPECT_TRUE(attempt([](Mesh& m) { m.positions[1].y = std::nanf(""); }));
  EXPECT_TRUE(attempt([](Mesh& m) { m.positions[2].x = kInfinity; }));
  EXPECT_TRUE(attempt([](Mesh& m) { m.indices[4] = 99; }));
  EXPECT_TRUE(attempt([](Mesh& m) { m.indices.pop_back(); }));
  EXPECT_TRUE(attempt([](Mesh& m) { m.normals.pop_back(); }));
  EXPECT_TRUE(attempt([](Mesh& m) { m.normals[0].z = std::nanf(""); }));
  EXPECT_TRUE(attempt([](Mesh& m) { m.uvs.assign(3, Vec2{}); }));
  EXPECT_TRUE(attempt([](Mesh& m) { m.indices.clear(); }));
  EXPECT_TRUE(attempt([](Mesh& m) { m.positions.assign(m.positions.size(), Vec3{1, 1, 1}); }));
  Scene empty;
  empty.name = "empty.ply";
  EXPECT_THROW(validate_and_prepare(empty), InputError);
}

}  // namespace
}  // namespace ao
