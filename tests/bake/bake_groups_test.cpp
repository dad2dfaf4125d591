// SPDX-License-Identifier: Apache-2.0
// Bake groups and occluders: meshes of different groups do not darken each other, shared
// occluders darken every group, the floor is a ground plane, and group names are checked.
#include <gtest/gtest.h>

#include "ao/bake/bake_groups.h"
#include "ao/bake/raytraced_bake.h"
#include "ao/core/error.h"
#include "ao/reference/ray_scene.h"
#include "ao/scene/procedural.h"
#include "support/bake_maps.h"

namespace ao {
namespace {

// A floor quad with UVs over the whole map, facing up (y = 0, x and z in [-0.5, 0.5]).
Mesh floor_quad(const char* name) {
  Mesh m = make_quad({-0.5f, 0, 0.5f}, {0.5f, 0, 0.5f}, {0.5f, 0, -0.5f}, {-0.5f, 0, -0.5f});
  m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  m.name = name;
  return m;
}

Scene floor_and_box() {
  Scene s;
  s.name = "test";
  s.meshes.push_back(floor_quad("floor_low"));
  Mesh box = make_box({-0.3f, 0, -0.3f}, {0.3f, 0.6f, 0.3f});  // stands on the floor: darkens it
  box.name = "box";
  s.meshes.push_back(box);
  validate_and_prepare(s);
  return s;
}

using test::mean_covered;

BakeResult bake(const Scene& s, const std::vector<BakeGroup>& groups, const std::vector<Mesh>& occluders) {
  RaytracedBakeParams p;
  p.samples = 32;
  return bake_groups(s, groups, occluders, 16, 16, [&](const Scene& gs, const TexelCoverage& cov, const BakeGroup&) {
    const RayScene rays(gs);
    return bake_raytraced(rays, cov, p);
  });
}

TEST(BakeGroups, MeshesInDifferentGroupsDoNotDarkenEachOther) {
  const Scene s = floor_and_box();
  BakeGroup all{"", {0, 1}, {}};
  const BakeResult together = bake(s, {all}, {});
  const BakeResult apart = bake(s, groups_per_mesh(s), {});
  // Alone, an open quad is fully visible: every ray leaves into the upper hemisphere (exact).
  EXPECT_EQ(mean_covered(apart), 1.0);
  // With the box in its group, the texels under the box are black and those beside it darker.
  EXPECT_LT(mean_covered(together), 0.8);
  const BakeResult listed = bake(s, groups_from_lists(s, {{"floor_low"}, {"box"}}), {});
  EXPECT_EQ(mean_covered(listed), 1.0);
}

TEST(BakeGroups, SharedOccludersDarkenEveryGroup) {
  const Scene s = floor_and_box();
  std::vector<Mesh> occluders{s.meshes[1]};
  const BakeResult r = bake(s, {{"floor", {0}, {}}}, occluders);
  EXPECT_LT(mean_covered(r), 0.8);
}

TEST(BakeGroups, FloorIsAGroundPlaneUnderTheModel) {
  // A vertical quad standing on the floor (x in [-0.5, 0.5], y in [0, 1], facing +z): with an
  // infinite floor the lower half of its hemisphere is blocked, V = 1/2 exactly; the floor is 20
  // diagonals wide, which leaves atan(1/20) of the horizon open: V in [0.5, 0.52]. Without it, 1.
  Scene s;
  s.name = "wall";
  Mesh q = make_quad({-0.5f, 0, 0}, {0.5f, 0, 0}, {0.5f, 1, 0}, {-0.5f, 1, 0});
  q.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  s.meshes.push_back(q);
  validate_and_prepare(s);
  const Mesh floor = make_floor_occluder(s.bounds());
  EXPECT_EQ(floor.bounds().hi.y, 0.0f);
  const BakeResult with = bake(s, groups_per_mesh(s), {floor});
  const BakeResult without = bake(s, groups_per_mesh(s), {});
  EXPECT_EQ(mean_covered(without), 1.0);
  // Tolerance: 32 scrambled-Sobol rays per texel over 256 texels; half of each set goes down.
  EXPECT_NEAR(mean_covered(with), 0.51, 0.02);
}

TEST(BakeGroups, MatchByNamePairsLowAndHighSuffixes) {
  EXPECT_EQ(bake_group_key("bolt_low"), "bolt");
  EXPECT_EQ(bake_group_key("bolt_HIGH"), "bolt");
  EXPECT_EQ(bake_group_key("bolt"), "bolt");
  Scene low, high;
  low.name = "low.obj";
  for (const char* n : {"bolt_low", "nut_low"}) low.meshes.push_back(floor_quad(n));
  for (const char* n : {"nut_high", "bolt_high", "bolt", "washer_high"}) high.meshes.push_back(floor_quad(n));
  std::vector<std::string> unused;
  const auto groups = groups_by_name(low, high, &unused);
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_EQ(groups[0].meshes, std::vector<std::size_t>{0});
  EXPECT_EQ(groups[0].high, (std::vector<std::size_t>{1, 2}));
  EXPECT_EQ(groups[1].high, std::vector<std::size_t>{0});
  EXPECT_EQ(unused, std::vector<std::string>{"washer_high"});
  low.meshes.push_back(floor_quad("gear_low"));
  EXPECT_THROW(groups_by_name(low, high), InputError);
}

TEST(BakeGroups, UnknownOrRepeatedNamesInAGroupAreErrors) {
  const Scene s = floor_and_box();
  EXPECT_THROW(groups_from_lists(s, {{"nope"}}), InputError);
  EXPECT_THROW(groups_from_lists(s, {{"box"}, {"box"}}), InputError);
  const auto g = groups_from_lists(s, {{"box"}});
  ASSERT_EQ(g.size(), 2u);  // the box, and the meshes not named
  EXPECT_EQ(g[1].meshes, std::vector<std::size_t>{0});
}

}  // namespace
}  // namespace ao
