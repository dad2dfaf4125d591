// SPDX-License-Identifier: Apache-2.0
// glTF instances (docs/instancing.md): a mesh that the node tree uses several times is loaded once
// with one Scene::instances entry per node and traced through Embree instances. Known answer: the
// same scene with every instance copied into world space (flatten_instances, and the loader's
// pre-transformed path) must give the same G-buffer, AO and method images.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/bake/high_to_low.h"
#include "ao/bake/raytraced_bake.h"
#include "ao/bake/texel_coverage.h"
#include "ao/core/camera.h"
#include "ao/core/error.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/io/mesh_io.h"
#include "ao/registry/registry.h"
#include "ao/reference/ray_scene.h"
#include "ao/reference/raytraced.h"
#include "support/bytes.h"
#include "support/load_error.h"
#include "support/run.h"

namespace ao {
namespace {

using nlohmann::json;
using test::TempDir;
using test::base64;
using test::append;

struct FlatMesh {
  std::vector<float> positions, normals;  // xyz per vertex
  std::vector<std::uint16_t> indices;
};

// A cube of half-side 1 with its own 4 corners per face (24 vertices, face normals), counter-
// clockwise seen from outside.
FlatMesh cube() {
  FlatMesh m;
  for (int axis = 0; axis < 3; ++axis)
    for (float sign : {-1.0f, 1.0f}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const auto base = static_cast<std::uint16_t>(m.positions.size() / 3);
      for (int c = 0; c < 4; ++c) {
        float p[3], n[3] = {0, 0, 0};
        p[axis] = sign;
        p[u] = (c == 1 || c == 2) ? 1.0f : -1.0f;
        p[v] = (c >= 2) ? 1.0f : -1.0f;
        n[axis] = sign;
        m.positions.insert(m.positions.end(), p, p + 3);
        m.normals.insert(m.normals.end(), n, n + 3);
      }
      // (u, v) corners 0 (-,-) 1 (+,-) 2 (+,+) 3 (-,+): counter-clockwise about +axis, since u x v = axis.
      const std::uint16_t q[6] = {0, 1, 2, 0, 2, 3}, r[6] = {0, 2, 1, 0, 3, 2};
      for (int k = 0; k < 6; ++k) m.indices.push_back(static_cast<std::uint16_t>(base + (sign > 0 ? q[k] : r[k])));
    }
  return m;
}

// A floor quad, x in [-8, 8], z in [-5, 5], facing +y.
FlatMesh floor_quad() {
  return {{-8, 0, -5, 8, 0, -5, 8, 0, 5, -8, 0, 5}, {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0}, {0, 2, 1, 0, 3, 2}};
}

// A glTF with the given meshes (one primitive each, float positions and normals, uint16 indices,
// one base64 buffer) and nodes (JSON objects with "mesh"/"children"/transforms); `roots` are the
// scene's root nodes.
std::string gltf_text(const std::vector<FlatMesh>& meshes, const json& nodes, const json& roots) {
  std::string bytes;
  json views = json::array(), accessors = json::array(), gmeshes = json::array();
  for (const FlatMesh& m : meshes) {
    const auto view = [&](const std::string& data) {
      views.push_back({{"buffer", 0}, {"byteOffset", bytes.size()}, {"byteLength", data.size()}});
      bytes += data;
      while (bytes.size() % 4) bytes += '\0';
      return views.size() - 1;
    };
    std::string p, n, i;
    append(p, m.positions);
    append(n, m.normals);
    append(i, m.indices);
    const std::size_t count = m.positions.size() / 3;
    json lo = {1e30, 1e30, 1e30}, hi = {-1e30, -1e30, -1e30};
    for (std::size_t v = 0; v < count; ++v)
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k].get<double>(), static_cast<double>(m.positions[3 * v + k]));
        hi[k] = std::max(hi[k].get<double>(), static_cast<double>(m.positions[3 * v + k]));
      }
    accessors.push_back({{"bufferView", view(p)}, {"componentType", 5126}, {"count", count}, {"type", "VEC3"}, {"min", lo}, {"max", hi}});
    accessors.push_back({{"bufferView", view(n)}, {"componentType", 5126}, {"count", count}, {"type", "VEC3"}});
    accessors.push_back({{"bufferView", view(i)}, {"componentType", 5123}, {"count", m.indices.size()}, {"type", "SCALAR"}});
    const std::size_t a = accessors.size() - 3;
    gmeshes.push_back({{"primitives", json::array({{{"attributes", {{"POSITION", a}, {"NORMAL", a + 1}}}, {"indices", a + 2}}})}});
  }
  json j = {{"asset", {{"version", "2.0"}}},
            {"scene", 0},
            {"scenes", json::array({{{"nodes", roots}}})},
            {"nodes", nodes},
            {"meshes", gmeshes},
            {"buffers", json::array({{{"byteLength", bytes.size()}, {"uri", "data:application/octet-stream;base64," + base64(bytes)}}})},
            {"bufferViews", views},
            {"accessors", accessors}};
  return j.dump();
}

// One cube used by three nodes under a translated group node (translated; rotated 40 degrees about
// (1,1,0)/sqrt(2); scaled non-uniformly), and a floor used once.
std::string three_cubes_gltf() {
  const float half = 0.5f * 40.0f * kPi / 180.0f, s = std::sin(half) / std::sqrt(2.0f);
  const json nodes = json::array({
      {{"name", "floor"}, {"mesh", 1}, {"translation", {0, -1.6, 0}}},
      {{"name", "group"}, {"translation", {0.5, 0, 0.25}}, {"children", {2, 3, 4}}},
      {{"name", "moved"}, {"mesh", 0}, {"translation", {-3.2, 0, 0}}},
      {{"name", "turned"}, {"mesh", 0}, {"rotation", {s, s, 0, std::cos(half)}}, {"translation", {0, 0.3, -0.5}}},
      {{"name", "stretched"}, {"mesh", 0}, {"scale", {1.6, 0.5, 0.8}}, {"translation", {3.4, -0.4, 0.5}}},
  });
  return gltf_text({cube(), floor_quad()}, nodes, {0, 1});
}

Camera view_of(const Scene& s) { return frame_bounds(s.bounds(), {0.6f, 0.7f, 1.0f}, 40.0f, 120, 80); }

TEST(GltfInstances, RepeatedMeshIsLoadedOnceWithOneInstancePerNode) {
  TempDir dir;
  const auto file = dir.write("cubes.gltf", three_cubes_gltf());
  const Scene s = load_scene_file(file);
  ASSERT_EQ(s.meshes.size(), 2u);  // the cube (object space) and the floor (world space)
  ASSERT_EQ(s.instances.size(), 3u);
  EXPECT_EQ(s.instances[0].name, "moved");
  EXPECT_EQ(s.instances[1].name, "turned");
  EXPECT_EQ(s.instances[2].name, "stretched");
  const std::uint32_t cube_mesh = s.instances[0].mesh;
  for (const Instance& in : s.instances) EXPECT_EQ(in.mesh, cube_mesh);
  EXPECT_EQ(s.meshes[cube_mesh].triangle_count(), 12u);
  EXPECT_FLOAT_EQ(s.meshes[cube_mesh].bounds().hi.x, 1.0f);  // object space
  // The group's translation (0.5, 0, 0.25) is part of every instance's transform.
  EXPECT_NEAR(s.instances[0].object_to_world.c3.x, -2.7f, 1e-6f);
  EXPECT_NEAR(s.instances[0].object_to_world.c3.z, 0.25f, 1e-6f);
  EXPECT_EQ(s.triangle_count(), 3u * 12u + 2u);
  EXPECT_EQ(s.stored_triangle_count(), 12u + 2u);
  const std::vector<SceneObject> objects = s.objects();
  ASSERT_EQ(objects.size(), 4u);
  EXPECT_EQ(objects[0].instance, SceneObject::kNoInstance);  // the floor first, then the instances
  EXPECT_EQ(objects[3].instance, 2u);

  // Flattened by the loader: no instances, the same triangles, the same world bounds.
  const Scene flat = load_scene_file(file, {.flatten_instances = true});
  EXPECT_TRUE(flat.instances.empty());
  EXPECT_EQ(flat.triangle_count(), s.triangle_count());
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(flat.bounds().lo[k], s.bounds().lo[k], 1e-5f);
    EXPECT_NEAR(flat.bounds().hi[k], s.bounds().hi[k], 1e-5f);
  }
}

TEST(GltfInstances, FileWithoutRepeatedMeshesHasNoInstances) {
  TempDir dir;
  const json nodes = json::array({{{"mesh", 0}, {"translation", {0, 1, 0}}}, {{"mesh", 1}}});
  const Scene s = load_scene_file(dir.write("two.gltf", gltf_text({cube(), floor_quad()}, nodes, {0, 1})));
  EXPECT_TRUE(s.instances.empty());
  EXPECT_EQ(s.triangle_count(), 14u);
  EXPECT_NEAR(s.bounds().hi.y, 2.0f, 1e-6f);
}

struct Rendered {
  std::unique_ptr<RayScene> rays;
  GBuffer g;
};

Rendered render(const Scene& s, const Camera& cam) {
  Rendered r{std::make_unique<RayScene>(s), {}};
  r.g = render_gbuffer(*r.rays, cam, GBufferOptions{});
  return r;
}

// Pixels where the two G-buffers saw the same surface; the rest must be rare: a ray
// through an edge shared by two triangles (or passing a silhouette) may take either side when the
// instance is traced in its own coordinates, whose rounding differs from the world copy's.
struct Agreement {
  std::size_t same = 0, differ = 0;
  double max_depth_rel = 0, max_normal = 0, max_position_rel = 0;
};

Agreement compare_gbuffers(const GBuffer& a, const GBuffer& b, bool same_ids) {
  Agreement r;
  for (std::size_t i = 0; i < a.object_id.size(); ++i) {
    if (!a.covered(i) && !b.covered(i)) continue;
    // With the same objects, the same triangle; else (assimp's copies joined into one mesh
    // renumber the triangles) the same face, told by its normal.
    const bool match = a.covered(i) && b.covered(i) &&
                       (same_ids ? a.primitive_id[i] == b.primitive_id[i] && a.object_id[i] == b.object_id[i] : length(a.normal[i] - b.normal[i]) < 1e-2f);
    if (!match) {
      ++r.differ;
      continue;
    }
    ++r.same;
    r.max_depth_rel = std::max(r.max_depth_rel, std::abs(static_cast<double>(a.depth(i)) - b.depth(i)) / b.depth(i));
    r.max_normal = std::max(r.max_normal, static_cast<double>(length(a.normal[i] - b.normal[i])));
    r.max_position_rel = std::max(r.max_position_rel, static_cast<double>(length(a.position[i] - b.position[i]) / length(b.position[i])));
  }
  return r;
}

TEST(GltfInstances, GBufferMatchesTheFlattenedScene) {
  TempDir dir;
  const auto file = dir.write("cubes.gltf", three_cubes_gltf());
  const Scene inst = load_scene_file(file);
  const Scene copies = flatten_instances(inst);                           // object i = object i
  const Scene pretransformed = load_scene_file(file, {.flatten_instances = true});  // assimp's copies, one merged mesh
  ASSERT_TRUE(copies.instances.empty());
  const Camera cam = view_of(inst);
  const Rendered a = render(inst, cam), b = render(copies, cam), c = render(pretransformed, cam);

  for (const Rendered* other : {&b, &c}) {
    const Agreement r = compare_gbuffers(a.g, other->g, other == &b);
    SCOPED_TRACE(other == &b ? "flatten_instances" : "flatten_instances load option");
    EXPECT_GT(r.same, 1500u);  // of 120 x 80 pixels
    // At most 0.5% of the covered pixels on an edge (see Agreement); measured: none.
    EXPECT_LE(r.differ, r.same / 200);
    // Relative depth 1e-5 (doc's criterion): a few float ulps of the transform's rounding
    // (measured: depth 2.4e-7, position 2.8e-7, normal 1.4e-7).
    EXPECT_LT(r.max_depth_rel, 1e-5);
    EXPECT_LT(r.max_position_rel, 1e-5);
    EXPECT_LT(r.max_normal, 1e-5);
  }

  // Every instance is an object of its own, ids 1 (floor) to 4, and primitive ids are triangles of
  // the cube (0..11) or of the floor (0..1).
  std::set<std::uint32_t> ids;
  for (std::size_t i = 0; i < a.g.object_id.size(); ++i) {
    if (!a.g.covered(i)) continue;
    ids.insert(a.g.object_id[i]);
    EXPECT_LT(a.g.primitive_id[i], a.g.object_id[i] == 1 ? 2u : 12u) << "pixel " << i;
  }
  EXPECT_EQ(ids, (std::set<std::uint32_t>{1, 2, 3, 4}));
}

TEST(GltfInstances, RaytracedAoMatchesTheFlattenedScene) {
  TempDir dir;
  const Scene inst = load_scene_file(dir.write("cubes.gltf", three_cubes_gltf()));
  const Scene copies = flatten_instances(inst);
  const Camera cam = view_of(inst);
  const Rendered a = render(inst, cam), b = render(copies, cam);
  RaytracedParams params;
  params.samples = params.min_samples = 64;
  const Falloff falloff{Membership::Step, 0.3f * inst.bounds().diagonal()};
  const RaytracedImage va = render_raytraced(*a.rays, a.g, falloff, params, 7);
  const RaytracedImage vb = render_raytraced(*b.rays, b.g, falloff, params, 7);
  // Same seed, same pixels, same directions. The instanced G-buffer places its hit points through
  // the instance transform, the flattened one from transformed vertices, so the points (and the
  // rays' origins) differ by a few float roundings: a ray's fate can only change where it grazes an
  // edge or a face, 1/64 of the pixel per ray. Near the cubes' corners on the floor a few rays of
  // one pixel graze at once. Measured: 2 pixels differ, by 3/64.
  std::size_t differ = 0, covered = 0;
  double sum = 0;
  for (std::size_t i = 0; i < va.visibility.size(); ++i) {
    if (!a.g.covered(i) || !b.g.covered(i)) continue;
    ++covered;
    const double d = std::abs(static_cast<double>(va.visibility[i]) - vb.visibility[i]);
    sum += d;
    if (d > 1e-6) ++differ;
    EXPECT_LE(d, 4.0 / 64 + 1e-6) << "pixel " << i;
  }
  EXPECT_LE(differ, covered / 200);
  EXPECT_LT(sum / static_cast<double>(covered), 1e-4);
}

TEST(GltfInstances, EveryScreenSpaceMethodAndConeMatchTheFlattenedScene) {
  TempDir dir;
  const Scene inst = load_scene_file(dir.write("cubes.gltf", three_cubes_gltf()));
  const Scene copies = flatten_instances(inst);
  const Camera cam = view_of(inst);
  const Rendered a = render(inst, cam), b = render(copies, cam);
  const Falloff falloff{Membership::Step, 0.1f * inst.bounds().diagonal()};
  for (const MethodInfo& m : all_methods()) {
    if (m.needs_scene && m.name != "cone") continue;  // raytraced: the test above
    SCOPED_TRACE(std::string(m.name));
    const MethodOutput oa = run_method(MethodInput{a.g, a.rays.get(), falloff, 5, {}, &inst.analytic}, m.decode(m.default_params()));
    const MethodOutput ob = run_method(MethodInput{b.g, b.rays.get(), falloff, 5, {}, &copies.analytic}, m.decode(m.default_params()));
    // The inputs differ by float rounding (positions 1e-5 relative at most, above) and at the
    // rare edge pixels; the methods are continuous in them but for thresholds (a sample just in
    // front of or behind a depth), so: a small mean difference, and few pixels that differ at all.
    // Measured: no pixel differs by 1e-3, mean differences 0 to 7e-9.
    std::size_t differ = 0;
    double sum = 0;
    for (std::size_t i = 0; i < oa.visibility.size(); ++i) {
      const double d = std::abs(static_cast<double>(oa.visibility[i]) - ob.visibility[i]);
      sum += d;
      if (d > 1e-3) ++differ;
    }
    EXPECT_LE(differ, oa.visibility.size() / 500);
    EXPECT_LT(sum / static_cast<double>(oa.visibility.size()), 1e-5);
  }
}

// Two nodes using the cube; the second with the given transform.
std::string two_cubes_gltf(const json& second) {
  json bad = second;
  bad["mesh"] = 0;
  return gltf_text({cube()}, json::array({{{"name", "fine"}, {"mesh", 0}}, bad}), {0, 1});
}

TEST(GltfInstances, BadTransformsAreRefusedNamingTheNode) {
  TempDir dir;
  EXPECT_LOAD_ERROR(dir.write("flat.gltf", two_cubes_gltf({{"name", "flat"}, {"scale", {1, 0, 1}}})),
                    "node 'flat' has a transform with determinant 0");
  EXPECT_LOAD_ERROR(dir.write("far.gltf", two_cubes_gltf({{"name", "far"}, {"translation", {3e9, 0, 0}}})),
                    "node 'far' moves its mesh to coordinate 3e+09, beyond the +-1e+09");
  // A node name from the file stays one printable line in the message.
  EXPECT_LOAD_ERROR(dir.write("name.gltf", two_cubes_gltf({{"name", "two\nlines"}, {"scale", {1, 1, 0}}})), "node 'two?lines' has a transform");
  // A parent's scale of 0 flattens its child: the child is named.
  const json nodes = json::array({{{"name", "fine"}, {"mesh", 0}}, {{"name", "squash"}, {"scale", {0, 1, 1}}, {"children", {2}}},
                                  {{"name", "child"}, {"mesh", 0}}});
  EXPECT_LOAD_ERROR(dir.write("parent.gltf", gltf_text({cube()}, nodes, {0, 1})), "node 'child' has a transform with determinant 0");
  // An instanced mesh whose only triangle is degenerate goes with its instances: nothing is left.
  const FlatMesh line{{0, 0, 0, 1, 0, 0, 2, 0, 0}, {0, 0, 1, 0, 0, 1, 0, 0, 1}, {0, 1, 2}};
  EXPECT_LOAD_ERROR(dir.write("line.gltf", gltf_text({line}, json::array({{{"mesh", 0}}, {{"mesh", 0}, {"translation", {0, 1, 0}}}}), {0, 1})),
                    "no triangles with nonzero area");
  // JSON has no NaN, so a non-finite transform is checked on a scene built in code.
  Scene s;
  s.name = "built";
  const FlatMesh c = cube();
  Mesh m;
  for (std::size_t v = 0; v < c.positions.size(); v += 3) m.positions.push_back({c.positions[v], c.positions[v + 1], c.positions[v + 2]});
  m.indices.assign(c.indices.begin(), c.indices.end());
  s.meshes.push_back(m);
  s.instances.push_back({0, Affine3{}, "a"});
  Affine3 nan_transform;
  nan_transform.c3.y = std::nanf("");
  s.instances.push_back({0, nan_transform, "b"});
  try {
    validate_and_prepare(s);
    ADD_FAILURE() << "a NaN transform was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "built: node 'b' has a non-finite transform");
  }
  s.instances[1] = {7, Affine3{}, "c"};
  try {
    validate_and_prepare(s);
    ADD_FAILURE() << "an instance of a missing mesh was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "built: node 'c' uses mesh 7, the scene has 1");
  }
}

// A unit sphere (lat-long, 48 x 24), counter-clockwise seen from outside.
Mesh unit_sphere() {
  Mesh m;
  const int seg = 48, rings = 24;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j < seg; ++j) {
      const float th = kPi * static_cast<float>(i) / rings, ph = 2 * kPi * static_cast<float>(j) / seg;
      m.positions.push_back({std::sin(th) * std::cos(ph), std::cos(th), -std::sin(th) * std::sin(ph)});
    }
  const auto id = [&](int i, int j) { return static_cast<std::uint32_t>(i * seg + j % seg); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < seg; ++j) m.indices.insert(m.indices.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1)});
  return m;
}

TEST(GltfInstances, HighToLowBakeOnInstancedTargetsMatchesCopies) {
  // Low: the cube with each face in its own cell of a 3 x 2 UV atlas. High: a sphere stored at half
  // size and turned 90 degrees about y, placed by one instance that undoes both (radius 1.2 around
  // the cube's centre) and a second one beside it (an occluder). Targets and occluders with
  // instances must bake what their flattened copies bake: the cage rays (trace_cage_ray) and the AO
  // rays (Tracer, passing back faces) resolve hits through the instance.
  const FlatMesh c = cube();
  Scene low;
  low.name = "low";
  Mesh lm;
  for (std::size_t v = 0; v < c.positions.size() / 3; ++v) {
    lm.positions.push_back({c.positions[3 * v], c.positions[3 * v + 1], c.positions[3 * v + 2]});
    const std::size_t face = v / 4, corner = v % 4;
    const float u = (corner == 1 || corner == 2) ? 1.0f : 0.0f, w = corner >= 2 ? 1.0f : 0.0f;
    lm.uvs.push_back({(static_cast<float>(face % 3) + 0.05f + 0.9f * u) / 3.0f, (static_cast<float>(face / 3) + 0.05f + 0.9f * w) / 2.0f});
  }
  lm.indices.assign(c.indices.begin(), c.indices.end());
  low.meshes.push_back(lm);
  validate_and_prepare(low);

  Scene high;
  high.name = "high";
  Mesh sm = unit_sphere();
  for (Vec3& p : sm.positions) p = Vec3{p.z, p.y, -p.x} * 0.5f;  // turned +90 degrees about y, half size
  high.meshes.push_back(sm);
  Affine3 undo;  // scale 2.4, turned -90 degrees about y: radius 1.2
  undo.c0 = {0, 0, 2.4f}, undo.c1 = {0, 2.4f, 0}, undo.c2 = {-2.4f, 0, 0};
  Affine3 beside = undo;
  beside.c3 = {3.0f, 0, 0};
  high.instances = {{0, undo, "target"}, {0, beside, "neighbour"}};
  validate_and_prepare(high);
  const Scene copies = flatten_instances(high);
  const RayScene hi(high), hc(copies);

  HighToLowParams p;
  p.ao.samples = 32;
  p.cage_extrusion = 0.5f;
  const TexelCoverage cov = compute_texel_coverage(low, 32);
  const BakeResult a = bake_high_to_low(low, cov, extrude_cage(low, 0.5f), hi, hi, p);
  const BakeResult b = bake_high_to_low(low, cov, extrude_cage(low, 0.5f), hc, hc, p);
  ASSERT_GT(a.covered_texels, 100u);
  EXPECT_EQ(a.missed_texels, b.missed_texels);
  // Same rays; a ray's fate differs only where it grazes an edge (1/32 of a texel's value).
  // The neighbour occludes: some texels are darker than open.
  std::size_t differ = 0;
  float darkest = 1;
  for (std::size_t i = 0; i < a.visibility.size(); ++i) {
    if (!a.mask[i]) continue;
    if (std::abs(a.visibility[i] - b.visibility[i]) > 1e-5f) ++differ;
    darkest = std::min(darkest, a.visibility[i]);
  }
  EXPECT_LE(differ, a.covered_texels / 100);
  EXPECT_LT(darkest, 0.9f);
}

TEST(GltfInstances, BakersRefuseInstancesAndTheLoaderFlattensForThem) {
  TempDir dir;
  const auto file = dir.write("cubes.gltf", three_cubes_gltf());
  // The loader option gives bakers copies; a scene with instances is refused with its name.
  EXPECT_TRUE(load_scene_file(file, {.flatten_instances = true}).instances.empty());
  const Scene inst = load_scene_file(file);
  const RayScene rays(inst);
  RaytracedBakeParams params;
  params.samples = 4;
  try {
    bake_vertices_raytraced(rays, params);
    ADD_FAILURE() << "baking instances was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cubes.gltf: has 3 mesh instances"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ao
