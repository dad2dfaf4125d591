// SPDX-License-Identifier: Apache-2.0
#include "ao/scene/topology.h"

#include <cstring>
#include <utility>

#include <tbb/parallel_sort.h>

#include "ao/core/affine.h"

namespace ao {

namespace {

// Per object of Scene::objects(): its mesh's side (+1, -1 or 0), turned by an instance's transform
// that mirrors, and 0 where `skip` (empty: nowhere) is non-zero.
std::vector<std::int8_t> per_object_sides(const Scene& scene, std::span<const std::int8_t> per_mesh, std::span<const std::uint8_t> skip) {
  const std::vector<SceneObject> objects = scene.objects();
  std::vector<std::int8_t> out(objects.size(), 0);
  for (std::size_t k = 0; k < objects.size(); ++k) {
    int side = per_mesh[objects[k].mesh];
    if (side == 0 || (!skip.empty() && skip[k] != 0)) continue;
    if (objects[k].instance != SceneObject::kNoInstance && scene.instances[objects[k].instance].object_to_world.determinant() < 0) side = -side;
    out[k] = static_cast<std::int8_t>(side);
  }
  return out;
}

}  // namespace

MeshEdges mesh_edges(const Mesh& m) {
  MeshEdges out;
  const std::size_t nv = m.positions.size();
  std::vector<std::pair<std::array<std::uint32_t, 3>, std::uint32_t>> keyed(nv);
  for (std::size_t v = 0; v < nv; ++v) {
    std::array<std::uint32_t, 3> k;
    const float c[3] = {m.positions[v].x + 0.0f, m.positions[v].y + 0.0f, m.positions[v].z + 0.0f};  // + 0 turns -0 into +0
    std::memcpy(k.data(), c, sizeof c);
    keyed[v] = {k, static_cast<std::uint32_t>(v)};
  }
  tbb::parallel_sort(keyed.begin(), keyed.end());  // distinct elements: the order is unique
  out.weld.resize(nv);
  for (std::size_t v = 0; v < nv; ++v) {
    if (v > 0 && keyed[v].first != keyed[v - 1].first) ++out.welded;
    out.weld[keyed[v].second] = out.welded;
  }
  if (nv > 0) ++out.welded;
  // (undirected key, directed edge index 3 t + e) so that a boundary edge keeps its direction.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> edges;
  edges.reserve(m.indices.size());
  for (std::size_t t = 0; t < m.triangle_count(); ++t)
    for (int e = 0; e < 3; ++e) {
      std::uint64_t a = out.weld[m.indices[3 * t + e]], b = out.weld[m.indices[3 * t + (e + 1) % 3]];
      if (a > b) std::swap(a, b);
      edges.push_back({a << 32 | b, static_cast<std::uint32_t>(3 * t + e)});
    }
  tbb::parallel_sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    if ((j - i) % 2) {
      const std::uint32_t de = edges[i].second, t = de / 3, e = de % 3;
      out.boundary.push_back({m.indices[3 * t + e], m.indices[3 * t + (e + 1) % 3]});
      out.boundary_triangle.push_back(t);
    }
    ++out.edges;
    i = j;
  }
  return out;
}

double signed_volume(const Mesh& m) {
  // The divergence theorem about the box's centre (which keeps the sums small).
  const Vec3 o = m.bounds().center();
  double volume = 0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const Vec3 a = m.positions[m.indices[3 * t]] - o, b = m.positions[m.indices[3 * t + 1]] - o, d = m.positions[m.indices[3 * t + 2]] - o;
    volume += dot(a, cross(b, d)) / 6.0;
  }
  return volume;
}

bool inside_closed_object(const Scene& scene, const SceneObject& o, Vec3 p) {
  const Mesh& m = scene.meshes[o.mesh];
  // A direction no axis-aligned or diagonal face contains, so the ray meets no edge of a modelled
  // room exactly.
  Vec3 d = normalize(Vec3{0.5734f, 0.6321f, 0.5213f});
  if (o.instance != SceneObject::kNoInstance) {  // the point and the ray in the mesh's own space
    const Affine3 to_object = inverse(scene.instances[o.instance].object_to_world);
    p = to_object.point(p), d = to_object.vector(d);
  }
  const Bounds3 b = m.bounds();
  if (p.x < b.lo.x || p.y < b.lo.y || p.z < b.lo.z || p.x > b.hi.x || p.y > b.hi.y || p.z > b.hi.z) return false;
  std::size_t crossings = 0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    // Moller-Trumbore: the ray p + s d, s > 0, through the triangle.
    const Vec3 a = m.positions[m.indices[3 * t]], e1 = m.positions[m.indices[3 * t + 1]] - a, e2 = m.positions[m.indices[3 * t + 2]] - a;
    const Vec3 h = cross(d, e2);
    const float det = dot(e1, h);
    if (det == 0.0f) continue;
    const float inv = 1.0f / det;
    const Vec3 q = p - a;
    const float u = dot(q, h) * inv;
    if (u < 0.0f || u > 1.0f) continue;
    const Vec3 r = cross(q, e1);
    const float v = dot(d, r) * inv;
    if (v < 0.0f || u + v > 1.0f) continue;
    crossings += dot(e2, r) * inv > 0.0f ? 1 : 0;
  }
  return crossings % 2 == 1;
}

std::vector<std::int8_t> closed_mesh_sides(const Scene& scene) {
  std::vector<std::int8_t> out(scene.meshes.size(), 0);
  for (std::size_t i = 0; i < scene.meshes.size(); ++i)
    if (mesh_edges(scene.meshes[i]).boundary.empty()) {
      const double v = signed_volume(scene.meshes[i]);
      out[i] = static_cast<std::int8_t>(v > 0 ? 1 : v < 0 ? -1 : 0);
    }
  return out;
}

std::vector<std::int8_t> open_mesh_facings(const Scene& scene, std::span<const std::int8_t> mesh_sides) {
  std::vector<std::int8_t> per_mesh(scene.meshes.size(), 0);
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    const Mesh& m = scene.meshes[i];
    if (mesh_sides[i] != 0 || m.triangle_count() == 0) continue;
    // A flat mesh's volume about a centre in its plane is rounding: below this it has none.
    const double size = m.bounds().diagonal(), flat = 1e-7 * size * size * size;
    const double v = signed_volume(m);
    per_mesh[i] = static_cast<std::int8_t>(v > flat ? 1 : v < -flat ? -1 : 0);
  }
  return per_object_sides(scene, per_mesh, {});
}

std::vector<std::uint8_t> closed_objects_around(const Scene& scene, std::span<const std::int8_t> mesh_sides, Vec3 eye) {
  const std::vector<SceneObject> objects = scene.objects();
  std::vector<std::uint8_t> out(objects.size(), 0);
  for (std::size_t k = 0; k < objects.size(); ++k) out[k] = mesh_sides[objects[k].mesh] != 0 && inside_closed_object(scene, objects[k], eye) ? 1 : 0;
  return out;
}

std::vector<std::int8_t> solid_exit_sides(const Scene& scene, std::span<const std::int8_t> mesh_sides, std::span<const std::uint8_t> rooms) {
  return per_object_sides(scene, mesh_sides, rooms);
}

}  // namespace ao
