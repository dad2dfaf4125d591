// SPDX-License-Identifier: Apache-2.0
// A mesh's connectivity (scene/topology.h) on shapes whose answers are known: a box is closed
// once its faces' own copies of its corners are welded, a quad has four boundary edges, a box
// 2 x 3 x 4 encloses 24 (negative with its fronts facing in), and a ray from outside leaves a
// closed mesh through the side its fronts say, unless the eye is inside (a room) or the mesh is
// open; a mirroring instance turns the side. An open mesh faces out of what it encloses, whichever
// way it was wound.
#include "ao/scene/topology.h"

#include <gtest/gtest.h>

#include "ao/scene/procedural.h"
#include "support/open_sheets.h"
#include "support/scenes.h"

namespace ao {
namespace {

using test::scene_of;

// The exit sides as seen from `eye`, its rooms found as render_second_layer finds them.
std::vector<std::int8_t> exit_sides_from(const Scene& s, Vec3 eye) {
  const std::vector<std::int8_t> sides = closed_mesh_sides(s);
  return solid_exit_sides(s, sides, closed_objects_around(s, sides, eye));
}

TEST(Topology, WeldedEdgesOfABoxAndAQuad) {
  const Mesh box = make_box({0, 0, 0}, {2, 3, 4});
  ASSERT_EQ(box.positions.size(), 24u) << "make_box gives each face its own corners";
  const MeshEdges e = mesh_edges(box);
  EXPECT_EQ(e.welded, 8u);
  EXPECT_EQ(e.edges, 18u) << "12 box edges and 6 face diagonals";
  EXPECT_TRUE(e.boundary.empty());
  const MeshEdges q = mesh_edges(make_quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}));
  EXPECT_EQ(q.edges, 5u);
  EXPECT_EQ(q.boundary.size(), 4u);
}

TEST(Topology, SignedVolumeSaysWhichWayTheFrontsFace) {
  EXPECT_NEAR(signed_volume(make_box({0, 0, 0}, {2, 3, 4})), 24.0, 1e-9);
  EXPECT_NEAR(signed_volume(make_box({0, 0, 0}, {2, 3, 4}, {0.8f, 0.8f, 0.8f}, 0.0f, true)), -24.0, 1e-9);
  const double sphere = signed_volume(make_sphere({5, 0, 0}, 1.0f, 96, 48));
  EXPECT_LT(sphere, 4.18879) << "inscribed facets";
  EXPECT_GT(sphere, 4.18879 * 0.99) << "4/3 pi, less the facets' chords";
}

TEST(Topology, ARayLeavesAClosedSolidSeenFromOutside) {
  const Vec3 outside{0, 0, 10}, inside{0, 0, 0};
  const Mesh box = make_box({-1, -1, -1}, {1, 1, 1}), inward = make_box({-1, -1, -1}, {1, 1, 1}, {0.8f, 0.8f, 0.8f}, 0.0f, true);
  const Mesh quad = make_quad({-1, -1, -3}, {1, -1, -3}, {1, 1, -3}, {-1, 1, -3});
  const Scene s = scene_of({box, inward, quad});
  EXPECT_EQ(exit_sides_from(s, outside), (std::vector<std::int8_t>{1, -1, 0}));
  EXPECT_EQ(exit_sides_from(s, inside), (std::vector<std::int8_t>{0, 0, 0})) << "around the eye: rooms";
  EXPECT_TRUE(inside_closed_object(s, s.objects()[0], inside));
  EXPECT_FALSE(inside_closed_object(s, s.objects()[0], outside));
  EXPECT_EQ(closed_objects_around(s, closed_mesh_sides(s), inside), (std::vector<std::uint8_t>{1, 1, 0})) << "rooms, either way round";
  EXPECT_EQ(closed_objects_around(s, closed_mesh_sides(s), outside), (std::vector<std::uint8_t>{0, 0, 0}));
}

TEST(Topology, AMirroringInstanceTurnsTheSide) {
  Scene s;
  s.name = "instances";
  s.meshes = {make_box({-1, -1, -1}, {1, 1, 1})};
  Affine3 moved, mirrored;
  moved.c3 = {5, 0, 0};
  mirrored.c0 = {-1, 0, 0}, mirrored.c3 = {-5, 0, 0};
  s.instances = {{0, moved, "moved"}, {0, mirrored, "mirrored"}};
  validate_and_prepare(s);
  EXPECT_EQ(exit_sides_from(s, {0, 0, 10}), (std::vector<std::int8_t>{1, -1}));
  EXPECT_EQ(exit_sides_from(s, {5, 0, 0}), (std::vector<std::int8_t>{0, -1})) << "the eye inside the moved box";
}

// An open mesh is read in the orientation whose fronts face out of what it encloses, whichever way
// its file wound it; a flat one has no such side, and neither is asked of a closed one.
TEST(Topology, AnOpenMeshFacesOutOfWhatItEncloses) {
  const Mesh bowl = test::make_bowl(), quad = make_quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1});
  const Mesh box = make_box({-1, -1, -1}, {1, 1, 1});
  const Scene s = scene_of({bowl, test::turned_over(bowl), quad, test::turned_over(quad), box});
  EXPECT_EQ(open_mesh_facings(s, closed_mesh_sides(s)), (std::vector<std::int8_t>{1, -1, 0, 0, 0}));

  Scene mirrored;
  mirrored.name = "instances";
  mirrored.meshes = {bowl};
  Affine3 moved, mirror;
  moved.c3 = {5, 0, 0};
  mirror.c0 = {-1, 0, 0}, mirror.c3 = {-5, 0, 0};
  mirrored.instances = {{0, moved, "moved"}, {0, mirror, "mirrored"}};
  validate_and_prepare(mirrored);
  EXPECT_EQ(open_mesh_facings(mirrored, closed_mesh_sides(mirrored)), (std::vector<std::int8_t>{1, -1})) << "a mirror turns it over";
}

}  // namespace
}  // namespace ao
