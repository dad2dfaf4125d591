// SPDX-License-Identifier: Apache-2.0
#include "ao/scene/procedural.h"

#include <cmath>
#include <memory>
#include <optional>

#include "ao/core/closest_name.h"
#include "ao/core/error.h"

namespace ao {

namespace {

// Adds one vertex and returns its index.
std::uint32_t add_vertex(Mesh& m, Vec3 p, Vec3 n) {
  m.positions.push_back(p);
  m.normals.push_back(n);
  return static_cast<std::uint32_t>(m.positions.size() - 1);
}

void add_triangle(Mesh& m, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  m.indices.insert(m.indices.end(), {a, b, c});
}

void add_flat_quad(Mesh& m, Vec3 p0, Vec3 p1, Vec3 p2, Vec3 p3) {
  const Vec3 n = normalize(cross(p1 - p0, p3 - p0));
  const std::uint32_t a = add_vertex(m, p0, n), b = add_vertex(m, p1, n), c = add_vertex(m, p2, n), d = add_vertex(m, p3, n);
  add_triangle(m, a, b, c);
  add_triangle(m, a, c, d);
}

Vec3 rotate_y(Vec3 p, Vec3 pivot, float deg) {
  const float a = deg * kPi / 180.0f, c = std::cos(a), s = std::sin(a);
  const Vec3 d = p - pivot;
  return pivot + Vec3{c * d.x + s * d.z, d.y, -s * d.x + c * d.z};
}

Mesh named(Mesh m, std::string name) {
  m.name = std::move(name);
  return m;
}

// A scene's preferred view: from `eye` towards `target`, with the camera's default field of view
// unless one is given.
Camera look_at(Vec3 eye, Vec3 target, std::optional<float> vertical_fov_deg = std::nullopt) {
  Camera view;
  view.eye = eye;
  view.target = target;
  if (vertical_fov_deg) view.vertical_fov_deg = *vertical_fov_deg;
  return view;
}

// Axis-aligned rectangle on the ground (y = 0), facing up.
void add_ground_rect(Mesh& m, float x0, float z0, float x1, float z1, float y = 0.0f) {
  add_flat_quad(m, {x0, y, z1}, {x1, y, z1}, {x1, y, z0}, {x0, y, z0});
}

Scene default_scene() {
  Scene s;
  s.name = "default";
  const Vec3 ground_albedo{0.75f, 0.73f, 0.70f};

  // Ground: a 12 x 12 square with a 1 x 1 hole over a 1.5 deep pit.
  Mesh ground;
  ground.name = "ground";
  ground.albedo = ground_albedo;
  const float g = 6.0f;
  const float px0 = 1.6f, px1 = 2.6f, pz0 = 0.6f, pz1 = 1.6f, depth = 1.5f;
  add_ground_rect(ground, -g, -g, g, pz0);
  add_ground_rect(ground, -g, pz1, g, g);
  add_ground_rect(ground, -g, pz0, px0, pz1);
  add_ground_rect(ground, px1, pz0, g, pz1);
  // Pit walls face into the pit.
  add_flat_quad(ground, {px0, 0, pz0}, {px0, -depth, pz0}, {px1, -depth, pz0}, {px1, 0, pz0});
  add_flat_quad(ground, {px1, 0, pz1}, {px1, -depth, pz1}, {px0, -depth, pz1}, {px0, 0, pz1});
  add_flat_quad(ground, {px0, 0, pz1}, {px0, -depth, pz1}, {px0, -depth, pz0}, {px0, 0, pz0});
  add_flat_quad(ground, {px1, 0, pz0}, {px1, -depth, pz0}, {px1, -depth, pz1}, {px1, 0, pz1});
  add_ground_rect(ground, px0, pz0, px1, pz1, -depth);
  s.meshes.push_back(std::move(ground));

  // Sphere resting on the ground: contact shadow.
  s.meshes.push_back(named(make_sphere({-2.2f, 0.9f, 1.4f}, 0.9f, 64, 32, {0.80f, 0.35f, 0.30f}), "sphere"));
  // Rotated box: creases where it meets the ground.
  s.meshes.push_back(named(make_box({-0.3f, 0.0f, -1.8f}, {0.9f, 1.2f, -0.6f}, {0.35f, 0.55f, 0.80f}, 30.0f), "box"));
  // Stairs: five steps rising along +x, each a closed box, a staircase of inner corners.
  Mesh stairs;
  stairs.name = "stairs";
  stairs.albedo = {0.85f, 0.80f, 0.55f};
  for (int i = 0; i < 5; ++i) {
    const float x0 = -4.6f + 0.4f * static_cast<float>(i);
    append_mesh(stairs, make_box({x0, 0.0f, -2.8f}, {x0 + 0.4f, 0.25f * static_cast<float>(i + 1), -1.4f}));
  }
  s.meshes.push_back(std::move(stairs));
  // Thin pillars in a row: thin occluders, narrow gaps.
  Mesh pillars;
  pillars.name = "pillars";
  pillars.albedo = {0.9f, 0.9f, 0.9f};
  for (int i = 0; i < 6; ++i) append_mesh(pillars, make_cylinder({-1.5f + 0.45f * static_cast<float>(i), 0.0f, -3.6f}, 0.07f, 2.2f));
  s.meshes.push_back(std::move(pillars));
  // A wall behind, occlusion at the largest scale.
  s.meshes.push_back(named(make_box({-5.0f, 0.0f, -5.0f}, {5.0f, 2.0f, -4.6f}, {0.7f, 0.7f, 0.72f}), "wall"));
  // Torus lying on the ground: a ring-shaped crease and a hole.
  s.meshes.push_back(named(make_torus({3.2f, 0.25f, -1.8f}, 0.75f, 0.25f, 64, 24, {0.45f, 0.75f, 0.45f}), "torus"));
  // A field of small cubes: fine-scale occlusion.
  Mesh cubes;
  cubes.name = "cubes";
  cubes.albedo = {0.8f, 0.6f, 0.8f};
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) {
      const float x = -0.4f + 0.3f * static_cast<float>(i), z = 2.2f + 0.3f * static_cast<float>(j);
      const float h = 0.1f + 0.06f * static_cast<float>((i * 7 + j * 3) % 5);
      append_mesh(cubes, make_box({x, 0.0f, z}, {x + 0.16f, h, z + 0.16f}, {}, 15.0f * static_cast<float>((i + j) % 3)));
    }
  s.meshes.push_back(std::move(cubes));

  s.preferred_view = look_at({4.4f, 4.6f, 7.0f}, {-0.2f, 0.1f, -0.9f}, 45.0f);
  return s;
}

// A 40 x 40 ground square at y = 0, named "plane": the open ground of the analytic scenes.
Mesh open_ground() {
  Mesh m;
  m.name = "plane";
  add_ground_rect(m, -20, -20, 20, 20);
  return m;
}

Scene plane_scene() {
  Scene s;
  s.name = "plane";
  s.meshes.push_back(open_ground());
  s.analytic.implicit = ImplicitSurface{{ImplicitSurfacePrimitive::half_space({0, 0, 0}, {0, 1, 0})}};
  s.preferred_view = look_at({0, 6, 10}, {0, 0, 0});
  return s;
}

Scene wedge_scene() {
  Scene s;
  s.name = "wedge";
  Mesh m;
  m.name = "wedge";
  const float L = 100.0f;
  add_flat_quad(m, {-L, 0, L}, {L, 0, L}, {L, 0, 0}, {-L, 0, 0});  // floor, facing +y
  add_flat_quad(m, {-L, 0, 0}, {L, 0, 0}, {L, L, 0}, {-L, L, 0});  // wall, facing +z
  s.meshes.push_back(std::move(m));
  // Outer region y >= 0 and z >= 0 (the quads end at 100 units; R is far smaller).
  s.analytic.implicit = ImplicitSurface{{ImplicitSurfacePrimitive::half_space({0, 0, 0}, {0, 1, 0}),
                                         ImplicitSurfacePrimitive::half_space({0, 0, 0}, {0, 0, 1})}};
  s.preferred_view = look_at({3, 3, 6}, {0, 0.5f, 0.5f});
  return s;
}

Scene sphere_on_plane_scene() {
  Scene s;
  s.name = "sphere-on-plane";
  s.meshes.push_back(open_ground());
  s.meshes.push_back(named(make_sphere({0, 1, 0}, 1.0f, 96, 48), "sphere"));
  // The tessellated sphere lies inside the analytic one by at most its sagitta, 1 - cos(pi/96) ~ 5e-4
  // units, far below the depth-test bias at any distance the view shows.
  s.analytic.implicit = ImplicitSurface{{ImplicitSurfacePrimitive::half_space({0, 0, 0}, {0, 1, 0}),
                                         ImplicitSurfacePrimitive::sphere_exterior({0, 1, 0}, 1.0f)}};
  s.preferred_view = look_at({0, 3, 6}, {0, 0.6f, 0});
  return s;
}

Scene box_room_scene() {
  Scene s;
  s.name = "box-room";
  s.meshes.push_back(named(make_box({-2, 0, -2.5f}, {2, 3, 2.5f}, {0.8f, 0.8f, 0.8f}, 0.0f, true), "room"));
  s.meshes.push_back(named(make_box({-1.2f, 0, -1.6f}, {-0.2f, 1.0f, -0.6f}, {0.8f, 0.5f, 0.3f}, 20.0f), "box"));
  s.meshes.push_back(named(make_sphere({0.9f, 0.6f, -0.8f}, 0.6f), "sphere"));
  s.preferred_view = look_at({1.7f, 2.4f, 2.2f}, {-0.6f, 0.4f, -1.5f}, 70.0f);
  return s;
}

// The height field as a mesh: one vertex per texel centre, where HeightFieldSurface's bilinear
// lookup is exactly the texel's value, so the mesh interpolates the analytic surface (within a
// triangle the two differ by the bilinear patch's twist, at most a quarter of the texel's second
// difference). `count_u` x `count_v` vertices from texel (0, 0); smooth normals from central
// differences of the map, the slope of the surface through the neighbouring vertices.
Mesh make_height_field_mesh(const HeightFieldSurface& hf, int count_u, int count_v) {
  Mesh m;
  const Image<float>& map = *hf.map;
  const int w = map.width(), h = map.height();
  const float du = hf.period / static_cast<float>(w), dv = hf.period / static_cast<float>(h);
  auto at = [&](int i, int j) { return hf.amplitude * map(((i % w) + w) % w, ((j % h) + h) % h); };
  for (int j = 0; j < count_v; ++j)
    for (int i = 0; i < count_u; ++i) {
      const float u = (static_cast<float>(i) + 0.5f) * du, v = (static_cast<float>(j) + 0.5f) * dv;
      const float hu = (at(i + 1, j) - at(i - 1, j)) / (2 * du), hv = (at(i, j + 1) - at(i, j - 1)) / (2 * dv);
      add_vertex(m, hf.origin + hf.frame.to_world({u, v, at(i, j)}), normalize(hf.frame.to_world({-hu, -hv, 1.0f})));
    }
  // Counter-clockwise seen from the normal's side when (t, b, n) is right-handed; flipped otherwise.
  const bool right_handed = dot(cross(hf.frame.t, hf.frame.b), hf.frame.n) > 0;
  const auto idx = [&](int i, int j) { return static_cast<std::uint32_t>(j * count_u + i); };
  for (int j = 0; j + 1 < count_v; ++j)
    for (int i = 0; i + 1 < count_u; ++i) {
      const std::uint32_t a = idx(i, j), b = idx(i + 1, j), c = idx(i + 1, j + 1), d = idx(i, j + 1);
      if (right_handed) {
        add_triangle(m, a, b, c);
        add_triangle(m, a, c, d);
      } else {
        add_triangle(m, a, c, b);
        add_triangle(m, a, d, c);
      }
    }
  return m;
}

Scene displaced_scene() {
  Scene s;
  s.name = "displaced";
  // An 8 x 8 floor displaced by a 64 x 64 map of 4 x 4 domes repeating every 2 units (domes 0.5
  // apart, 0.2 high), so the default R (0.1 x diagonal, ~1.1) spans a few of them.
  constexpr int kMapSize = 64, kBumps = 4, kTiles = 4;
  constexpr float kPeriod = 2.0f, kAmplitude = 0.2f, kHalf = 0.5f * kPeriod * kTiles;
  HeightFieldSurface hf;
  const float texel = kPeriod / kMapSize;
  // u along +x, v along -z, normal +y (right-handed); the first vertex (a texel centre) at (-4, ., 4).
  hf.frame = {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}};
  hf.origin = {-kHalf - 0.5f * texel, 0.0f, kHalf + 0.5f * texel};
  hf.map = std::make_shared<const Image<float>>(make_bump_map(kMapSize, kBumps));
  hf.period = kPeriod;
  hf.amplitude = kAmplitude;
  const int count = kMapSize * kTiles + 1;  // vertices per side: the floor spans [-4, 4] exactly
  Mesh floor = make_height_field_mesh(hf, count, count);
  floor.name = "floor";
  floor.albedo = {0.76f, 0.70f, 0.60f};
  s.meshes.push_back(std::move(floor));
  s.analytic.height_field = std::move(hf);
  // Objects standing on the bumps, which pierce their undersides: occlusion the height field alone
  // does not know about (VAO fig. 12: "the z-buffer-based classification handles other objects' occlusions").
  s.meshes.push_back(named(make_sphere({-1.3f, 0.8f, 0.3f}, 0.8f, 64, 32, {0.35f, 0.55f, 0.80f}), "sphere"));
  s.meshes.push_back(named(make_box({0.5f, 0.0f, -1.7f}, {1.9f, 1.1f, -0.5f}, {0.80f, 0.45f, 0.30f}, 25.0f), "box"));
  // The eye low enough that the domes hide parts of each other.
  s.preferred_view = look_at({3.0f, 3.0f, 5.2f}, {0.0f, 0.2f, -0.6f}, 45.0f);
  return s;
}

// The built-in scenes, in the order the help lists them, with the analytic descriptions they carry.
struct BuiltinScene {
  const char* name;
  Scene (*make)();
  bool implicit;      ///< Scene::analytic.implicit is set.
  bool height_field;  ///< Scene::analytic.height_field is set.
};
const BuiltinScene kBuiltinScenes[] = {
    {"default", default_scene, false, false},       {"plane", plane_scene, true, false},
    {"wedge", wedge_scene, true, false},            {"sphere-on-plane", sphere_on_plane_scene, true, false},
    {"box-room", box_room_scene, false, false},     {"displaced", displaced_scene, false, true},
};

}  // namespace

std::vector<std::string> builtin_scene_names() {
  std::vector<std::string> names;
  for (const BuiltinScene& b : kBuiltinScenes) names.emplace_back(b.name);
  return names;
}

std::vector<std::string> builtin_scenes_with_implicit_surface() {
  std::vector<std::string> names;
  for (const BuiltinScene& b : kBuiltinScenes)
    if (b.implicit) names.emplace_back(b.name);
  return names;
}

std::vector<std::string> builtin_scenes_with_height_field() {
  std::vector<std::string> names;
  for (const BuiltinScene& b : kBuiltinScenes)
    if (b.height_field) names.emplace_back(b.name);
  return names;
}

bool is_builtin_scene(std::string_view name) {
  for (const auto& n : builtin_scene_names())
    if (n == name) return true;
  return false;
}

Scene make_builtin_scene(std::string_view name) {
  for (const BuiltinScene& b : kBuiltinScenes)
    if (name == b.name) {
      Scene s = b.make();
      validate_and_prepare(s);
      return s;
    }
  std::string names;
  for (const auto& n : builtin_scene_names()) names += (names.empty() ? "" : ", ") + n;
  throw InputError(std::string(name) + ": not a file and not a built-in scene (" + names + ")" + did_you_mean(name, names));
}

Mesh make_quad(Vec3 p0, Vec3 p1, Vec3 p2, Vec3 p3, Vec3 albedo) {
  Mesh m;
  m.albedo = albedo;
  add_flat_quad(m, p0, p1, p2, p3);
  return m;
}

Mesh make_box(Vec3 lo, Vec3 hi, Vec3 albedo, float yaw_deg, bool inward) {
  Mesh m;
  m.albedo = albedo;
  const Vec3 c = (lo + hi) * 0.5f;
  auto P = [&](float x, float y, float z) { return rotate_y({x, y, z}, c, yaw_deg); };
  const float x0 = lo.x, y0 = lo.y, z0 = lo.z, x1 = hi.x, y1 = hi.y, z1 = hi.z;
  // Each face counter-clockwise seen from outside.
  const Vec3 faces[6][4] = {
      {P(x0, y0, z1), P(x1, y0, z1), P(x1, y1, z1), P(x0, y1, z1)},  // +z
      {P(x1, y0, z0), P(x0, y0, z0), P(x0, y1, z0), P(x1, y1, z0)},  // -z
      {P(x1, y0, z1), P(x1, y0, z0), P(x1, y1, z0), P(x1, y1, z1)},  // +x
      {P(x0, y0, z0), P(x0, y0, z1), P(x0, y1, z1), P(x0, y1, z0)},  // -x
      {P(x0, y1, z1), P(x1, y1, z1), P(x1, y1, z0), P(x0, y1, z0)},  // +y
      {P(x0, y0, z0), P(x1, y0, z0), P(x1, y0, z1), P(x0, y0, z1)},  // -y
  };
  for (const auto& f : faces) {
    if (inward) add_flat_quad(m, f[3], f[2], f[1], f[0]);
    else add_flat_quad(m, f[0], f[1], f[2], f[3]);
  }
  return m;
}

Mesh make_sphere(Vec3 center, float radius, int segments, int rings, Vec3 albedo) {
  Mesh m;
  m.albedo = albedo;
  for (int r = 0; r <= rings; ++r) {
    const float theta = kPi * static_cast<float>(r) / static_cast<float>(rings);
    for (int s = 0; s <= segments; ++s) {
      // s == segments repeats s == 0 exactly (not 2 pi, whose sine is not 0 in float), so the seam is closed.
      const float phi = 2.0f * kPi * static_cast<float>(s % segments) / static_cast<float>(segments);
      // Poles exactly on the axis (sin(pi) is not 0 in float), so all their copies coincide.
      const float sin_theta = (r == 0 || r == rings) ? 0.0f : std::sin(theta);
      const float cos_theta = r == 0 ? 1.0f : (r == rings ? -1.0f : std::cos(theta));
      const Vec3 n{sin_theta * std::cos(phi), cos_theta, -sin_theta * std::sin(phi)};
      add_vertex(m, center + n * radius, n);
    }
  }
  const auto idx = [&](int r, int s) { return static_cast<std::uint32_t>(r * (segments + 1) + s); };
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      // Skip the zero-area triangles at the poles.
      if (r != 0) add_triangle(m, idx(r, s), idx(r + 1, s), idx(r, s + 1));
      if (r != rings - 1) add_triangle(m, idx(r, s + 1), idx(r + 1, s), idx(r + 1, s + 1));
    }
  return m;
}

Mesh make_cylinder(Vec3 base, float radius, float height, int segments, Vec3 albedo) {
  Mesh m;
  m.albedo = albedo;
  const Vec3 top = base + Vec3{0, height, 0};
  for (int s = 0; s < segments; ++s) {
    const float a0 = 2.0f * kPi * static_cast<float>(s) / static_cast<float>(segments);
    const float a1 = 2.0f * kPi * static_cast<float>((s + 1) % segments) / static_cast<float>(segments);
    const Vec3 n0{std::cos(a0), 0, -std::sin(a0)}, n1{std::cos(a1), 0, -std::sin(a1)};
    const std::uint32_t b0 = add_vertex(m, base + n0 * radius, n0), b1 = add_vertex(m, base + n1 * radius, n1);
    const std::uint32_t t0 = add_vertex(m, top + n0 * radius, n0), t1 = add_vertex(m, top + n1 * radius, n1);
    add_triangle(m, b0, b1, t1);
    add_triangle(m, b0, t1, t0);
    // Caps as fans around their centres.
    const std::uint32_t ct = add_vertex(m, top, {0, 1, 0});
    add_triangle(m, ct, add_vertex(m, top + n0 * radius, {0, 1, 0}), add_vertex(m, top + n1 * radius, {0, 1, 0}));
    const std::uint32_t cb = add_vertex(m, base, {0, -1, 0});
    add_triangle(m, cb, add_vertex(m, base + n1 * radius, {0, -1, 0}), add_vertex(m, base + n0 * radius, {0, -1, 0}));
  }
  return m;
}

Mesh make_torus(Vec3 center, float major, float minor, int segments, int sides, Vec3 albedo) {
  Mesh m;
  m.albedo = albedo;
  for (int i = 0; i <= segments; ++i) {
    const float u = 2.0f * kPi * static_cast<float>(i % segments) / static_cast<float>(segments);
    const Vec3 ring{std::cos(u), 0, -std::sin(u)};
    for (int j = 0; j <= sides; ++j) {
      const float v = 2.0f * kPi * static_cast<float>(j % sides) / static_cast<float>(sides);
      const Vec3 n = ring * std::cos(v) + Vec3{0, std::sin(v), 0};
      add_vertex(m, center + ring * major + n * minor, n);
    }
  }
  const auto idx = [&](int i, int j) { return static_cast<std::uint32_t>(i * (sides + 1) + j); };
  for (int i = 0; i < segments; ++i)
    for (int j = 0; j < sides; ++j) {
      add_triangle(m, idx(i, j), idx(i + 1, j), idx(i + 1, j + 1));
      add_triangle(m, idx(i, j), idx(i + 1, j + 1), idx(i, j + 1));
    }
  return m;
}

void append_mesh(Mesh& dst, const Mesh& src) {
  const auto base = static_cast<std::uint32_t>(dst.positions.size());
  dst.positions.insert(dst.positions.end(), src.positions.begin(), src.positions.end());
  dst.normals.insert(dst.normals.end(), src.normals.begin(), src.normals.end());
  dst.uvs.insert(dst.uvs.end(), src.uvs.begin(), src.uvs.end());
  for (std::uint32_t i : src.indices) dst.indices.push_back(base + i);
}

}  // namespace ao
