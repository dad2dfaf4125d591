// SPDX-License-Identifier: Apache-2.0
// Voxel cone traced AO: configurations with known answers, the depth-resolution limitation the
// paper names (sec. IV-A) and its fix, the ray-traced reference, properties, bad parameters.
#include "ao/methods/cone/cone.h"

#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string_view>

#include "ao/eval/metrics.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/io/mesh_io.h"
#include "ao/reference/raytraced.h"
#include "ao/scene/procedural.h"

#include "support/open_sheets.h"
#include "support/scenes.h"

namespace ao {
namespace {

using test::scene_of;

// A one-pixel G-buffer seeing world point p with world normal n from a camera 3 units along n, on
// object `id` (1 = the scene's first mesh).
GBuffer one_pixel(Vec3 p, Vec3 n, std::uint32_t id = 1) {
  Camera cam;
  cam.eye = p + normalize(n + Vec3{0.1f, 0.2f, 0.3f}) * 3.0f;
  cam.target = p;
  cam.width = cam.height = 1;
  GBuffer g(cam);
  g.position(0, 0) = cam.world_to_camera_point(p);
  g.normal(0, 0) = normalize(cam.world_to_camera_vector(n));
  g.albedo(0, 0) = {0.8f, 0.8f, 0.8f};
  g.object_id(0, 0) = id;
  return g;
}

float cone_at(const Scene& s, Vec3 p, Vec3 n, float R, ConeParams params, std::uint32_t id = 1) {
  const GBuffer g = one_pixel(p, n, id);
  return render_cone(s, analyze_closure(s), g, R, params, 1).visibility(0, 0);
}

GBuffer small_gbuffer(const Scene& s, int w, int h) {
  const RayScene rs(s);
  Camera cam = *s.preferred_view;
  cam.width = w;
  cam.height = h;
  return render_gbuffer(rs, cam);
}

TEST(Cone, OpenPlaneIsFullyVisible) {
  const Scene s = make_builtin_scene("plane");
  const GBuffer g = small_gbuffer(s, 48, 32);
  for (ConeQuality q : {ConeQuality::Low, ConeQuality::Medium, ConeQuality::High}) {
    ConeParams p = cone_preset(q);
    p.columns = 128;
    const ConeResult r = render_cone(s, analyze_closure(s), g, 2.0f, p, 1);
    // 0.995: a jittered cone may sit at the horizon (theta = 90 deg - alpha); its spheres touch the
    // tangent plane and cut the top of the surface voxels, which reach up to half a voxel above
    // the plane (measured 0.9990 at worst).
    for (std::size_t i = 0; i < r.visibility.size(); ++i) ASSERT_GT(r.visibility[i], 0.995f) << "pixel " << i;
  }
}

// Floor y = 0 and wall z = 0 (the built-in wedge). At distance a from the wall on the floor,
// classical AO with R = 1 is 1 - (acos a - a sqrt(1 - a^2)) / pi (tests/reference).
TEST(Cone, WedgeFloorNearWallFollowsDiskSegmentFormula) {
  // The built-in wedge is 200 units wide; a 6-unit copy keeps voxels small against R = 1.
  Mesh m = make_quad({-3, 0, 3}, {3, 0, 3}, {3, 0, 0}, {-3, 0, 0});
  append_mesh(m, make_quad({-3, 0, 0}, {3, 0, 0}, {3, 3, 0}, {-3, 3, 0}));
  const Scene s = scene_of({m});
  ConeParams p = cone_preset(ConeQuality::High);
  p.cones = 24;  // more cones: the formula is about the integral, not about 6 cones' quantisation
  p.columns = 256;
  p.jitter = false;
  for (float a : {0.15f, 0.4f, 0.8f}) {
    const float expected = 1.0f - (std::acos(a) - a * std::sqrt(1.0f - a * a)) / kPi;
    // 0.08: each of 24 cones is 1/24 = 0.042 of the measure and straddles the wall's horizon
    // partially; sphere volumes, not rays, decide a straddling cone, which errs by up to about
    // two cones' worth at this resolution (measured 0.01-0.05).
    EXPECT_NEAR(cone_at(s, {0.3f, 0, a}, {0, 1, 0}, 1.0f, p), expected, 0.08f) << "a = " << a;
  }
  // Far from the wall the floor is open.
  EXPECT_EQ(cone_at(s, {0.3f, 0, 2.5f}, {0, 1, 0}, 1.0f, p), 1.0f);
}

// The paper's limitation (sec. IV-A: small cavities come out too bright at 128 bits): a point on a
// floor under a thin roof 0.11 above it. A tall pillar elsewhere stretches the grid to 8 units, so
// at 128 bits a voxel is 0.064 deep and, with the floor's top on a voxel boundary (the grid puts
// the largest area facing up there: the floor's top; the roof's is smaller), no voxel centre falls
// inside the 0.03-thick roof (centres at 0.097 and 0.161): the roof vanishes and the cavity looks
// open. At 512 bits (0.016 deep) two centres do.
TEST(Cone, ThinRoofMissedAt128BitsIsResolvedAt512) {
  const Scene s = scene_of({make_box({-2, -0.5f, -2}, {2, 0, 2}), make_box({-1.8f, 0.11f, -1.8f}, {1.8f, 0.14f, 1.8f}),
                            make_box({3, -0.5f, 3}, {3.2f, 7.5f, 3.2f})});
  const float R = 0.5f;
  // Reference: rays with theta > acos(0.11 / 0.5) travel R under the roof: V = (0.11 / R)^2... of
  // the cosine measure, V = 1 - sin^2(acos 0.22) = 0.0484.
  const RayScene rs(s);
  const float rt = estimate_visibility(rs, {0, 0, 0}, {0, 1, 0}, {Membership::Step, R}, {.samples = 4096}, 3).visibility;
  ASSERT_NEAR(rt, 0.0484f, 0.02f) << "the configuration's reference";
  ConeParams p = cone_preset(ConeQuality::Medium);
  p.depth_bits = 128;
  const float v128 = cone_at(s, {0, 0, 0}, {0, 1, 0}, R, p);
  p.depth_bits = 512;
  const float v512 = cone_at(s, {0, 0, 0}, {0, 1, 0}, R, p);
  EXPECT_GT(v128, 0.95f) << "at 128 bits the roof is lost and the point looks open";
  // At 512 bits the roof is there, but a 0.03-thick roof fills only part of the spheres that cut
  // it, and the spheres beyond it are empty: volume sampling, the paper's and ours, sees a thin
  // occluder as a partial one (measured 0.63 with the per-pixel jitter: error 0.58 against 0.95 at
  // 128 bits). The bound asks for the error to drop by over 30%.
  EXPECT_LT(std::abs(v512 - rt), 0.7f * std::abs(v128 - rt)) << "v128 " << v128 << ", v512 " << v512;
}

// Against the ray-traced reference (step, R = R_max) on built-in scenes at a small resolution.
// Bounds: the measured RMSE (sphere-on-plane 0.05, default 0.09 at this commit, see
// docs/methods/cone.md) plus a margin of 0.03 for the reference's own noise (256 rays, standard
// error ~0.03 per pixel) and platform differences.
TEST(Cone, CloseToRayTracedReferenceOnBuiltInScenes) {
  // box-room: a closed box facing in, seen from inside: its solid is outside (parity alone would
  // fill the room, V = 0: RMSE 0.90).
  for (const auto& [name, bound] : {std::pair{"sphere-on-plane", 0.08}, std::pair{"default", 0.12}, std::pair{"box-room", 0.08}}) {
    const Scene s = make_builtin_scene(name);
    const RayScene rs(s);
    Camera cam = *s.preferred_view;
    cam.width = 96;
    cam.height = 64;
    const GBuffer g = render_gbuffer(rs, cam);
    const float R = 0.1f * s.bounds().diagonal();
    const auto ref = render_raytraced(rs, g, {Membership::Step, R}, {.samples = 256}, 9);
    const ConeResult r = render_cone(s, analyze_closure(s), g, R, cone_preset(ConeQuality::Medium), 1);
    const ErrorMetrics m = compare_images(r.visibility, ref.visibility, coverage_mask(g));
    EXPECT_LT(m.rmse, bound) << name << ": mean signed error " << m.mean_signed;
  }
}

// A room: a closed box around the camera with a box inside. Its inside is air but for the box, and
// its walls are solid on their far side, a slab of R_max deep. Which way its faces turn does not
// matter: seen from outside, the same closed box (faces turned in or out) is a solid.
TEST(Cone, AClosedMeshAroundTheCameraIsARoom) {
  for (const bool inward : {true, false}) {
    const Scene s = scene_of({make_box({-2, 0, -2}, {2, 2, 2}, {0.8f, 0.8f, 0.8f}, 0.0f, inward), make_box({-0.5f, 0, -0.5f}, {0.5f, 1, 0.5f})});
    const std::vector<MeshClosure> closure = analyze_closure(s);
    EXPECT_EQ(closed_meshes_around(s, closure, {1.5f, 1.5f, 1.5f}), (std::vector<std::uint8_t>{1, 0})) << "inside the room";
    EXPECT_TRUE(closed_meshes_around(s, closure, {0, 1, 5}).empty()) << "outside it";
    EXPECT_EQ(closed_meshes_around(s, closure, {0, 0.5f, 0}), (std::vector<std::uint8_t>{1, 1})) << "inside the box in it";
    VoxelizeOptions o;
    o.columns = 64, o.depth_bits = 64, o.slab_thickness = 0.5f;
    const auto solid_at = [](const VoxelGrid& g, Vec3 p) {
      const int i = static_cast<int>((p.x - g.origin.x) / g.voxel_size.x), j = static_cast<int>((p.z - g.origin.z) / g.voxel_size.y),
                k = static_cast<int>((p.y - g.origin.y) / g.voxel_size.z);
      return g.voxel(i, j, k);
    };
    o.rooms = closed_meshes_around(s, closure, {1.5f, 1.5f, 1.5f});
    const VoxelGrid room = voxelize_world(s, closure, o);
    EXPECT_FALSE(solid_at(room, {1.5f, 1.5f, 1.5f})) << "the room's air";
    EXPECT_TRUE(solid_at(room, {0, 0.5f, 0})) << "the box in it";
    EXPECT_TRUE(solid_at(room, {2.3f, 1.0f, 0})) << "beyond a wall";
    EXPECT_TRUE(solid_at(room, {0, -0.3f, 0})) << "under the floor";
    EXPECT_LE(room.origin.y, -0.5f + 1e-3f) << "a slab's thickness of solid below the floor";
    o.rooms.clear();  // the camera outside: the closed box is a solid, its faces turned in or not
    const VoxelGrid solid = voxelize_world(s, closure, o);
    EXPECT_TRUE(solid_at(solid, {1.5f, 1.5f, 1.5f}));
    o.rooms = closed_meshes_around(s, closure, {1.5f, 1.5f, 1.5f});
    o.open_meshes = OpenMeshes::Parity;  // the paper's parity of everything fills the room
    EXPECT_TRUE(solid_at(voxelize_world(s, closure, o), {1.5f, 1.5f, 1.5f}));
  }
}

using test::cut_base;
using test::punch_holes;

struct OpenError {
  double rmse, mean_signed;
  nlohmann::json stats;
};
// Cone (medium preset) against the ray-traced step reference on `object` standing on a ground
// quad, seen from the front right and above, R = 0.1 x the scene's diagonal (or, with
// `object_fraction`, that fraction of the object's own diagonal: the CLI's default R, which leaves
// the flat ground out).
OpenError cone_error(const Mesh& object, int columns = 256, float object_fraction = 0) {
  const Bounds3 b = object.bounds();
  const float e = b.diagonal();
  const Scene s = scene_of({object, test::ground_under(object)});
  const RayScene rs(s);
  const Camera cam = frame_bounds(b, {1.0f, 0.8f, 1.3f}, 40.0f, 96, 72);
  const GBuffer g = render_gbuffer(rs, cam);
  const float R = object_fraction > 0 ? object_fraction * e : 0.1f * s.bounds().diagonal();
  const auto ref = render_raytraced(rs, g, {Membership::Step, R}, {.samples = 256}, 9);
  ConeParams p;
  p.columns = columns;
  const ConeResult r = render_cone(s, analyze_closure(s), g, R, p, 1);
  const ErrorMetrics m = compare_images(r.visibility, ref.visibility, coverage_mask(g));
  return {m.rmse, m.mean_signed, cone_stats(r)};
}

// The requirement: on open meshes made by cutting closed ones (a base removed, holes
// punched), cone's error against the reference of the open mesh stays within 2x its error on the
// closed mesh. Parity voxelization (the paper's) puts solid pillars above every column through a
// hole. Torus: generated, so the test runs without ../shared.
TEST(Cone, OpenMeshesCostAtMostTwiceTheClosedMeshError) {
  const Mesh torus = make_torus({0, 0.35f, 0}, 1.0f, 0.35f, 64, 24);
  const OpenError closed = cone_error(torus);
  for (const auto& [what, open] : {std::pair{"base cut", cut_base(torus, 0.15f)}, std::pair{"holes", punch_holes(torus, 0.06f)}}) {
    ASSERT_LT(open.triangle_count(), torus.triangle_count()) << what;
    const OpenError e = cone_error(open);
    EXPECT_LE(e.rmse, 2.0 * closed.rmse) << what << ": closed " << closed.rmse << ", mean signed " << e.mean_signed;
    EXPECT_EQ(e.stats["holed_meshes"], 1) << what;
    EXPECT_EQ(e.stats["odd_columns"], 0) << what << ": the holes are closed for the voxelization";
    EXPECT_GE(e.stats["warnings"].size(), 1u) << what;
  }
}

// The same on two real scanned meshes (carried in tests/data/meshes).
TEST(Cone, OpenScannedMeshesCostAtMostTwiceTheClosedMeshError) {
  const std::filesystem::path dir = AO_TEST_MESHES;
  for (const char* name : {"ChineseDragon-10kv.off", "elephant.off"}) {
    const Scene loaded = load_scene_file(dir / name);
    Mesh closed = loaded.meshes.at(0);
    const OpenError ce = cone_error(closed);
    for (const auto& [what, open] : {std::pair{"base cut", cut_base(closed, 0.1f)}, std::pair{"holes", punch_holes(closed, 0.03f)}}) {
      const OpenError e = cone_error(open);
      EXPECT_LE(e.rmse, 2.0 * ce.rmse) << name << ", " << what << ": closed " << ce.rmse << ", mean signed " << e.mean_signed;
    }
  }
}

// The open-mesh suite (tests/support/open_sheets.h; docs/methods/cone.md, "Open meshes"): cone on
// nine open meshes (a bent sheet with holes, half a sphere shell, a box without its top, a face
// mask, a dome with a window, a terrain, a tablecloth, a leaf, a gutter), each on a ground quad, seen
// from the front right and above, against its error on closed meshes in the same setting (the
// median of a box, a sphere, a torus and an ellipsoid the mask's size), at the CLI's R (0.1 x the
// object's diagonal). Before the slabs stopped where a sheet comes back (sheet_depth) and the
// side of a solid with holes was what a point sees of it (seen_side), the mask scored 0.080 and the
// dome 0.208 at 640 x 360 (5.1x and 13x that median). Before points beyond a sheet's rim saw past
// it (beyond_rim, cone_sides.cpp), the leaf scored 1.68x here. Measured here (96 x 72): 0.74-1.48x
// (the leaf 1.48x, the terrain 1.41x).
TEST(Cone, OpenMeshSuiteStaysNearTheClosedMeshError) {
  std::vector<double> closed_errors;
  for (const Mesh& m : {make_box({-0.9f, 0.0f, -0.7f}, {0.9f, 1.0f, 0.7f}), make_sphere({0, 1, 0}, 1.0f, 96, 48), make_torus({0, 0.35f, 0}, 1.0f, 0.35f, 64, 24),
                        test::make_head()})
    closed_errors.push_back(cone_error(m, 256, 0.1f).rmse);
  std::sort(closed_errors.begin(), closed_errors.end());
  const double closed = 0.5 * (closed_errors[1] + closed_errors[2]);
  const std::pair<const char*, Mesh> suite[] = {
      {"bent sheet with holes", test::make_holed_arch()}, {"half sphere shell", test::make_bowl()}, {"box without its top", test::make_open_box()},
      {"mask", test::make_mask()}, {"dome with a window", test::make_dome()}, {"terrain", test::make_terrain()},
      {"tablecloth", test::make_tablecloth()}, {"leaf", test::make_leaf()}, {"gutter", test::make_gutter()}};
  for (const auto& [what, open] : suite) {
    const OpenError e = cone_error(open, 256, 0.1f);
    EXPECT_LE(e.rmse, 1.5 * closed) << what << ": closed meshes " << closed << ", mean signed " << e.mean_signed;
    EXPECT_EQ(e.stats["odd_columns"], 0) << what;
    // The tablecloth is seen from above only; every other mesh shows its inside or its underside.
    if (std::string_view(what) != "tablecloth") {
      EXPECT_GE(e.stats["side_grids"], 2) << what << ": the inside or the underside is seen";
    }
  }
}

// A sheet stands for what it hides from the point, on the point's far side of it: under a roof (a
// quad at height h < R, facing up or turned down) a point on the floor sees what it would see
// under a closed roof as thick as R (cone's own answer for a solid roof, 0.41 here against the
// reference's (h / R)^2 = 0.25: sphere volumes at the horizon). On top of the roof the point is
// open. Before the two-sided voxelization the slab hung below a roof facing up whatever side the
// point was on: V = 0 under it.
TEST(Cone, ASheetOccludesFromBothSidesAsTheSolidItHides) {
  const float h = 0.5f, R = 1.0f;
  const Mesh floor = make_box({-4, -0.5f, -4}, {4, 0, 4});
  ConeParams p = cone_preset(ConeQuality::High);
  p.cones = 24;
  p.columns = 256;
  p.jitter = false;
  const Vec3 under{0.3f, 0, 0.2f}, up{0, 1, 0};
  const float solid = cone_at(scene_of({floor, make_box({-4, h, -4}, {4, h + R, 4})}), under, up, R, p);
  for (bool turned : {false, true}) {
    Mesh roof = make_quad({-4, h, 4}, {4, h, 4}, {4, h, -4}, {-4, h, -4});
    if (turned) std::swap(roof.indices[1], roof.indices[2]), std::swap(roof.indices[4], roof.indices[5]);
    const Scene s = scene_of({floor, roof});
    // 0.02: the slab is R thick on the grid's voxels, the solid roof's faces fall elsewhere on them
    // (measured 0.0025 facing up, 0.014 facing down).
    EXPECT_NEAR(cone_at(s, under, up, R, p), solid, 0.02) << (turned ? "roof facing down" : "roof facing up");
    EXPECT_GT(cone_at(s, {0.3f, h, 0.2f}, up, R, p, 2), 0.97f) << (turned ? "roof facing down" : "roof facing up") << ", on top";
  }
}

// A point beyond a sheet's free rim sees past the sheet: a shelf (a flat quad at height h = R / 2)
// over a floor; points on the floor out beyond its edge by 0.6 h, 0.8 h and h see its underside
// at a grazing angle and the sky over its edge, where the slab R deep on the shelf (the floor is
// behind it) stood as a wall: at 0.6 h, V = 0.66 against the reference's 0.87. Traced without the
// slab, the shelf is a film two voxels thick, which the cones see a little less of than the
// reference does (measured +0.05 to +0.07). Under the shelf the slab stays. Facing up or turned
// down.
TEST(Cone, APointBeyondASheetsRimSeesPastIt) {
  const float h = 0.25f, R = 0.5f;
  const Mesh floor = make_quad({-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, {-4, 0, -4});
  ConeParams p;
  p.columns = 256;
  p.filter_taps = 1;
  for (bool turned : {false, true}) {
    Mesh shelf = make_quad({-1, h, 1}, {1, h, 1}, {1, h, -1}, {-1, h, -1});
    if (turned) std::swap(shelf.indices[1], shelf.indices[2]), std::swap(shelf.indices[4], shelf.indices[5]);
    const Scene s = scene_of({floor, shelf});
    const RayScene rs(s);
    const char* what = turned ? "shelf turned down, out by " : "shelf facing up, out by ";
    for (const float out : {0.6f * h, 0.8f * h, h}) {
      const GBuffer g = one_pixel({1.0f + out, 0, 0.1f}, {0, 1, 0});
      const float reference = render_raytraced(rs, g, {Membership::Step, R}, {.samples = 4096}, 3).visibility(0, 0);
      const ConeResult r = render_cone(s, analyze_closure(s), g, R, p, 1);
      EXPECT_NEAR(r.visibility(0, 0), reference, 0.08f) << what << out;
      EXPECT_EQ(r.rim_pixels, 1u) << what << out;
    }
    const ConeResult under = render_cone(s, analyze_closure(s), one_pixel({0.5f, 0, 0.1f}, {0, 1, 0}), R, p, 1);
    EXPECT_EQ(under.rim_pixels, 0u) << (turned ? "shelf turned down" : "shelf facing up");
  }
}

// A side beyond a rim that gets no grid of its own (over kMaxSideGrids) is traced with the grid of
// its sides alone, not the all-front one: nine shelves over a floor, the whole floor behind each of
// them (one side), and the floor beyond each shelf's rim nine more sides; eight grids.
TEST(Cone, ASideBeyondARimWithoutAGridKeepsItsSidesGrid) {
  std::vector<Mesh> meshes{make_quad({-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, {-4, 0, -4})};
  for (int i = 0; i < 9; ++i) {
    const float x = 1.2f * static_cast<float>(i % 3 - 1), z = 1.2f * static_cast<float>(i / 3 - 1);
    const float a = 0.25f, h = 0.1f;
    meshes.push_back(make_quad({x - a, h, z + a}, {x + a, h, z + a}, {x + a, h, z - a}, {x - a, h, z - a}));
  }
  const Scene s = scene_of(meshes);
  const GBuffer g = render_gbuffer(RayScene(s), frame_bounds(Bounds3{{-2, 0, -2}, {2, 0.1f, 2}}, {0.2f, 1.0f, 0.3f}, 40.0f, 128, 96));
  ConeParams p;
  p.columns = 128;
  const ConeResult r = render_cone(s, analyze_closure(s), g, 0.2f, p, 1);
  EXPECT_EQ(r.side_grids, 8);
  EXPECT_EQ(r.unresolved_pixels, 0u);
  EXPECT_GT(r.rim_pixels, 0u);
}

// Where a surface goes on across its boundary edges it has no rim there: the default scene's
// ground is four quads around a pit (T-junctions between them) and the pit's walls and floor
// (edges where the ground folds down). Taken for rims, 37,047 of its pixels at 640 x 360 lost the
// ground's slab and its RMSE went from 0.042 to 0.055.
TEST(Cone, AGroundInPiecesHasNoRimAtItsSeams) {
  const Scene s = make_builtin_scene("default");
  const GBuffer g = small_gbuffer(s, 96, 54);
  ConeParams p;
  p.columns = 128;
  const std::vector<MeshClosure> closure = analyze_closure(s);
  ASSERT_GT(closure[0].boundary_edges, 4u) << "the ground's pieces meet at T-junctions";
  const ConeResult r = render_cone(s, closure, g, 0.1f * s.bounds().diagonal(), p, 1);
  EXPECT_EQ(r.rim_pixels, 0u);
  EXPECT_EQ(r.side_grids, 1);
}

// Two-sided: turning every triangle of an open sheet over changes nothing but the grid's height
// (a grid is taller by a slab when a slab rises above a face, which moves the voxel boundaries:
// 0.0065 at worst, measured unfiltered), on the same G-buffer.
TEST(Cone, SheetsLookTheSameTurnedOver) {
  const Mesh arch = test::make_holed_arch(), turned = test::turned_over(arch);
  const Mesh ground = make_quad({-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3});
  const Scene original = scene_of({arch, ground});
  const GBuffer g = render_gbuffer(RayScene(original), frame_bounds(arch.bounds(), {1.0f, 0.8f, 1.3f}, 40.0f, 64, 48));
  ConeParams p;
  p.columns = 128;
  p.filter_taps = 1;
  const ConeResult a = render_cone(original, analyze_closure(original), g, 0.3f, p, 1);
  const Scene other = scene_of({turned, ground});
  const ConeResult b = render_cone(other, analyze_closure(other), g, 0.3f, p, 1);
  // Three grids: the front, the underside, beyond the rims (the ground past the arch's ends).
  EXPECT_EQ(a.side_grids, 3);
  EXPECT_EQ(b.side_grids, 3);
  EXPECT_GT(a.back_pixels, 0u);
  EXPECT_GT(b.back_pixels, 0u);
  EXPECT_GT(a.rim_pixels, 0u);
  EXPECT_EQ(a.rim_pixels, b.rim_pixels);
  for (std::size_t i = 0; i < a.visibility.size(); ++i) ASSERT_NEAR(a.visibility[i], b.visibility[i], 0.01f) << "pixel " << i;
}

// A sphere that starts inside the surface voxel sees the surface's own voxels: with 10 spheres the
// first ones start 0.005 R from the apex. Spheres that start within 1.5 voxels are skipped, so an
// open plane stays open at any sphere count.
TEST(Cone, ManySpheresDoNotSeeTheSurfaceItself) {
  const Scene s = scene_of({make_box({-3, -0.3f, -3}, {3, 0, 3}), make_sphere({1.5f, 1.0f, 1.5f}, 0.9f, 48, 24)});
  ConeParams p = cone_preset(ConeQuality::Medium);
  p.columns = 128;
  for (int spheres : {5, 10, 16}) {
    p.spheres = spheres;
    // On the sphere's top (a curved surface: its voxels form a staircase) and on the open box top.
    EXPECT_GT(cone_at(s, {1.5f, 1.9f, 1.5f}, {0, 1, 0}, 1.0f, p), 0.97f) << spheres << " spheres, sphere top";
    EXPECT_GT(cone_at(s, {-2.0f, 0.0f, -2.0f}, {0, 1, 0}, 1.0f, p), 0.97f) << spheres << " spheres, box top";
  }
}

TEST(Cone, VisibilityInUnitIntervalAndSameAtOneAndTwoThreads) {
  const Scene s = make_builtin_scene("default");
  const GBuffer g = small_gbuffer(s, 64, 40);
  const auto closure = analyze_closure(s);
  for (GridSpace grid : {GridSpace::World, GridSpace::Eye}) {
    ConeParams p;
    p.grid = grid;
    p.columns = 128;
    Image<float> a, b;
    {
      tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
      a = render_cone(s, closure, g, 1.5f, p, 4).visibility;
    }
    {
      tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
      b = render_cone(s, closure, g, 1.5f, p, 4).visibility;
    }
    double sum = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(a[i], b[i]) << "pixel " << i;
      ASSERT_GE(a[i], 0.0f);
      ASSERT_LE(a[i], 1.0f);
      sum += a[i];
    }
    EXPECT_LT(sum / static_cast<double>(a.size()), 0.99) << "the demo scene has occlusion";
  }
}

// ConeContext keeps the grid between calls: the same pixels as render_cone for every parameter
// change, a new grid exactly when a voxelization input changes (world grid: the options; eye grid:
// also the G-buffer, whose camera lays out the columns).
// Empty-space skipping is exact: with every window mask full (every sphere passes the coarse test
// and is sampled by its prisms) the pixels are the same, bit for bit. Also with the largest
// window too small for the spheres (R large against the voxels), where the blocks decide.
TEST(Cone, EmptySpaceSkippingDoesNotChangeThePixels) {
  const Scene s = make_builtin_scene("default");
  const GBuffer g = small_gbuffer(s, 64, 40);
  for (const float fraction : {0.1f, 0.4f}) {
    const float R = fraction * s.bounds().diagonal();
    const ConeParams p = cone_preset(ConeQuality::Medium).resolved();
    const VoxelGrid grid = voxelize_world(s, analyze_closure(s), p.voxelize_options(R));
    VoxelGrid full = grid;
    std::fill(full.window.begin(), full.window.end(), ~std::uint64_t{0});
    Image<float> a(g.width(), g.height()), b(g.width(), g.height());
    compute_cone(g, grid, R, p, 1, a.view());
    compute_cone(g, full, R, p, 1, b.view());
    double sum = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(a[i], b[i]) << "R = " << fraction << " x diagonal, pixel " << i;
      sum += a[i];
    }
    EXPECT_LT(sum / static_cast<double>(a.size()), 0.99) << "the scene has occlusion";
  }
}

TEST(ConeContext, CachedGridGivesTheSamePixelsAndRebuildsOnlyWhenItsInputsChange) {
  const Scene s = make_builtin_scene("default");
  const auto closure = analyze_closure(s);
  const GBuffer g = small_gbuffer(s, 64, 40);
  const auto same_as_uncached = [&](ConeContext& ctx, const GBuffer& gb, float r, const ConeParams& p, std::uint32_t seed, bool reused) {
    const ConeResult cached = ctx.render(gb, r, p, seed);
    EXPECT_EQ(cached.grid_reused, reused);
    const Image<float> plain = render_cone(s, closure, gb, r, p, seed).visibility;
    ASSERT_EQ(cached.visibility.size(), plain.size());
    for (std::size_t i = 0; i < plain.size(); ++i) ASSERT_EQ(cached.visibility[i], plain[i]) << "pixel " << i;
  };
  ConeContext ctx(s);
  ConeParams p;
  p.columns = 128;
  same_as_uncached(ctx, g, 1.5f, p, 4, false);
  EXPECT_EQ(ctx.grid_builds(), 1);
  // Trace-only parameters and the seed: the same grid.
  same_as_uncached(ctx, g, 1.5f, p, 4, true);
  p.spheres = 3, p.prisms = 12, p.jitter = false, p.filter_taps = 1, p.aperture_deg = 40;
  same_as_uncached(ctx, g, 1.5f, p, 9, true);
  EXPECT_EQ(ctx.grid_builds(), 1);
  // Another view of the same scene: a world grid does not depend on the camera.
  Camera moved = g.camera;
  moved.eye = moved.eye + Vec3{0.3f, 0.2f, 0.0f};
  const GBuffer g2 = render_gbuffer(RayScene(s), moved);
  same_as_uncached(ctx, g2, 1.5f, p, 9, true);
  // Each voxelization input: a new grid.
  p.columns = 96;
  same_as_uncached(ctx, g2, 1.5f, p, 9, false);
  p.depth_bits = 256;
  same_as_uncached(ctx, g2, 1.5f, p, 9, false);
  p.open_meshes = OpenMeshes::Slab;
  same_as_uncached(ctx, g2, 1.5f, p, 9, false);
  p.slab_fraction = 0.5f;
  same_as_uncached(ctx, g2, 1.5f, p, 9, false);
  same_as_uncached(ctx, g2, 1.2f, p, 9, false);  // R_max sets the slab thickness
  EXPECT_EQ(ctx.grid_builds(), 6);
  // Eye grid: rebuilt for another grid space and for another camera, reused for the same one.
  p.grid = GridSpace::Eye;
  same_as_uncached(ctx, g2, 1.2f, p, 9, false);
  same_as_uncached(ctx, g2, 1.2f, p, 3, true);
  same_as_uncached(ctx, g, 1.2f, p, 3, false);
  EXPECT_EQ(ctx.grid_builds(), 8);
}

// Pixels on the back of a sheet get a grid of their own, kept by the context per combination of
// sides: the same pixels as render_cone, and no new grid for the same view.
TEST(ConeContext, KeepsOneGridPerSide) {
  const Scene s = scene_of({test::make_open_box(), make_quad({-3, 0, 3}, {3, 0, 3}, {3, 0, -3}, {-3, 0, -3})});
  const GBuffer g = render_gbuffer(RayScene(s), frame_bounds(test::make_open_box().bounds(), {1.0f, 0.8f, 1.3f}, 40.0f, 64, 48));
  ConeParams p;
  p.columns = 128;
  ConeContext ctx(s);
  const ConeResult first = ctx.render(g, 0.25f, p, 1);
  EXPECT_EQ(first.side_grids, 2) << "the box's inside is seen through its top";
  EXPECT_GT(first.back_pixels, 0u);
  EXPECT_EQ(ctx.grid_builds(), 2);
  const ConeResult again = ctx.render(g, 0.25f, p, 2);
  EXPECT_TRUE(again.grid_reused);
  EXPECT_EQ(ctx.grid_builds(), 2);
  const Image<float> plain = render_cone(s, analyze_closure(s), g, 0.25f, p, 2).visibility;
  for (std::size_t i = 0; i < plain.size(); ++i) ASSERT_EQ(again.visibility[i], plain[i]) << "pixel " << i;
}

TEST(Cone, PresetsFollowTableOneAndExplicitCountsOverride) {
  const ConeParams low = cone_preset(ConeQuality::Low).resolved(), high = cone_preset(ConeQuality::High).resolved();
  EXPECT_EQ(*low.cones, 6);
  EXPECT_EQ(*low.spheres, 3);
  EXPECT_EQ(*low.prisms, 3);
  EXPECT_EQ(*high.spheres, 7);
  EXPECT_EQ(*high.prisms, 12);
  const ConeParams p = nlohmann::json{{"preset", "high"}, {"prisms", 4}}.get<ConeParams>().resolved();
  EXPECT_EQ(*p.spheres, 7);
  EXPECT_EQ(*p.prisms, 4);
  // The sphere chain: tangent neighbours, inscribed in the cone, the last one ending at R_max.
  const ConeSetup setup = derive_cone_setup(p);
  const float sa = std::sin(15.0f * kPi / 180.0f);
  for (std::size_t k = 0; k + 1 < setup.sphere_distance.size(); ++k)
    EXPECT_NEAR(setup.sphere_distance[k + 1] - setup.sphere_radius[k + 1], setup.sphere_distance[k] + setup.sphere_radius[k], 1e-5f);
  EXPECT_NEAR(setup.sphere_distance.back() + setup.sphere_radius.back(), 1.0f, 1e-6f);
  EXPECT_NEAR(setup.sphere_radius[0], setup.sphere_distance[0] * sa, 1e-6f);
}

TEST(Cone, JsonRoundTripAndRejectsBadParameters) {
  ConeParams p = cone_preset(ConeQuality::Low);
  p.grid = GridSpace::Eye;
  p.depth_bits = 512;
  const ConeParams q = nlohmann::json(p).get<ConeParams>();
  EXPECT_EQ(nlohmann::json(q), nlohmann::json(p));
  for (const nlohmann::json& bad : {nlohmann::json{{"depth_bits", 33}}, nlohmann::json{{"depth_bits", 2000}}, nlohmann::json{{"cones", 0}},
                                    nlohmann::json{{"aperture_deg", -30}}, nlohmann::json{{"spheres", 17}}, nlohmann::json{{"columns", 2}}}) {
    EXPECT_THROW(bad.get<ConeParams>().resolved().validate(), InputError) << bad.dump();
  }
  EXPECT_THROW((nlohmann::json{{"preset", "ultra"}}.get<ConeParams>()), InputError);
  EXPECT_THROW((nlohmann::json{{"cone_count", 6}}.get<ConeParams>()), InputError);
  EXPECT_THROW((nlohmann::json{{"cones", "six"}}.get<ConeParams>()), InputError);
}

}  // namespace
}  // namespace ao
