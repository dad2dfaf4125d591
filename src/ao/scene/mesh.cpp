#include "ao/scene/mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "ao/core/error.h"

namespace ao {

Bounds3 Mesh::bounds() const {
  Bounds3 b;
  for (const Vec3& p : positions) b.extend(p);
  return b;
}

Bounds3 Scene::bounds() const {
  Bounds3 b;
  for (const Mesh& m : meshes) b.extend(m.bounds());
  return b;
}

std::size_t Scene::triangle_count() const {
  std::size_t n = 0;
  for (const Mesh& m : meshes) n += m.triangle_count();
  return n;
}

std::size_t Scene::vertex_count() const {
  std::size_t n = 0;
  for (const Mesh& m : meshes) n += m.positions.size();
  return n;
}

void generate_normals(Mesh& mesh) {
  mesh.normals.assign(mesh.positions.size(), Vec3{});
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const std::uint32_t i[3] = {mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]};
    const Vec3 p[3] = {mesh.positions[i[0]], mesh.positions[i[1]], mesh.positions[i[2]]};
    const Vec3 n = normalize(cross(p[1] - p[0], p[2] - p[0]));
    for (int k = 0; k < 3; ++k) {
      // Angle weighting makes the result independent of how a flat region is triangulated.
      const Vec3 e0 = normalize(p[(k + 1) % 3] - p[k]);
      const Vec3 e1 = normalize(p[(k + 2) % 3] - p[k]);
      const float angle = std::acos(std::clamp(dot(e0, e1), -1.0f, 1.0f));
      mesh.normals[i[k]] += n * angle;
    }
  }
  for (Vec3& n : mesh.normals) n = length(n) > 0 ? normalize(n) : Vec3{0, 0, 1};
}

namespace {

std::string format_magnitude(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", static_cast<double>(v));
  return buf;
}

std::string where(const Scene& scene, const Mesh& mesh) {
  return mesh.name.empty() || scene.meshes.size() == 1 ? scene.name : scene.name + " (mesh '" + mesh.name + "')";
}

void validate_mesh(const Scene& scene, Mesh& mesh) {
  const std::string w = where(scene, mesh);
  if (mesh.indices.size() % 3 != 0) throw InputError(w + ": index count " + std::to_string(mesh.indices.size()) + " is not a multiple of 3");
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const Vec3 p = mesh.positions[v];
    if (!is_finite(p)) throw InputError(w + ": vertex " + std::to_string(v) + " has a non-finite coordinate");
    const float m = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    if (m > kMaxCoordinate)
      throw InputError(w + ": vertex " + std::to_string(v) + " has coordinate " + format_magnitude(m) + ", beyond the +-" +
                       format_magnitude(kMaxCoordinate) + " ao traces correctly (scale the mesh down)");
  }
  if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size())
    throw InputError(w + ": " + std::to_string(mesh.normals.size()) + " normals for " + std::to_string(mesh.positions.size()) + " vertices");
  if (!mesh.uvs.empty() && mesh.uvs.size() != mesh.positions.size())
    throw InputError(w + ": " + std::to_string(mesh.uvs.size()) + " UVs for " + std::to_string(mesh.positions.size()) + " vertices");
  for (std::size_t v = 0; v < mesh.uvs.size(); ++v)
    if (!std::isfinite(mesh.uvs[v].x) || !std::isfinite(mesh.uvs[v].y)) throw InputError(w + ": UV " + std::to_string(v) + " is not finite");
  for (float c : {mesh.albedo.x, mesh.albedo.y, mesh.albedo.z})
    if (!std::isfinite(c)) throw InputError(w + ": albedo is not finite");
  mesh.albedo = min(max(mesh.albedo, Vec3{0, 0, 0}), Vec3{1, 1, 1});

  const std::size_t vertex_count = mesh.positions.size();
  std::size_t kept = 0;
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    const std::uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
    for (std::uint32_t i : {a, b, c})
      if (i >= vertex_count)
        throw InputError(w + ": triangle " + std::to_string(t / 3) + " uses vertex " + std::to_string(i) + ", the mesh has " +
                         std::to_string(vertex_count));
    const Vec3 n = cross(mesh.positions[b] - mesh.positions[a], mesh.positions[c] - mesh.positions[a]);
    if (a == b || b == c || a == c || !(dot(n, n) > 0.0f)) continue;
    mesh.indices[kept++] = a;
    mesh.indices[kept++] = b;
    mesh.indices[kept++] = c;
  }
  // Degenerate triangles have no area, so they can neither occlude nor be seen: dropping them
  // changes no result but spares the ray tracer and the bakers a division by zero. The caller
  // reports how many went.
  mesh.indices.resize(kept);
  if (!mesh.normals.empty()) {
    for (std::size_t v = 0; v < mesh.normals.size(); ++v) {
      if (!is_finite(mesh.normals[v])) throw InputError(w + ": normal " + std::to_string(v) + " is not finite");
      const float len = length(mesh.normals[v]);
      mesh.normals[v] = len > 0 ? mesh.normals[v] / len : Vec3{0, 0, 1};
    }
  } else {
    generate_normals(mesh);
  }
}

}  // namespace

void validate_and_prepare(Scene& scene) {
  if (scene.meshes.empty()) throw InputError(scene.name + ": the scene has no meshes");
  for (Mesh& mesh : scene.meshes) {
    const std::size_t before = mesh.triangle_count();
    validate_mesh(scene, mesh);
    const std::size_t dropped = before - mesh.triangle_count();
    if (dropped > 0)
      scene.warnings.push_back(where(scene, mesh) + ": dropped " + std::to_string(dropped) + " degenerate (zero-area) triangle" +
                               (dropped == 1 ? "" : "s"));
  }
  std::erase_if(scene.meshes, [](const Mesh& m) { return m.triangle_count() == 0; });
  if (scene.triangle_count() == 0) throw InputError(scene.name + ": the scene has no triangles with nonzero area");
}

}  // namespace ao
