// SPDX-License-Identifier: Apache-2.0
#include "ao/scene/mesh.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include "ao/core/error.h"

namespace ao {

Bounds3 Mesh::bounds() const {
  Bounds3 b;
  for (const Vec3& p : positions) b.extend(p);
  return b;
}

namespace {

/// Per mesh: does some instance name it (then it is drawn only through its instances)?
std::vector<char> instanced_meshes(const Scene& s) {
  std::vector<char> used(s.meshes.size(), 0);
  for (const Instance& in : s.instances)
    if (in.mesh < used.size()) used[in.mesh] = 1;
  return used;
}

}  // namespace

Bounds3 Scene::bounds() const {
  Bounds3 b;
  const std::vector<char> instanced = instanced_meshes(*this);
  std::vector<Bounds3> mesh_bounds(meshes.size());
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    mesh_bounds[i] = meshes[i].bounds();
    if (!instanced[i]) b.extend(mesh_bounds[i]);
  }
  for (const Instance& in : instances)
    if (in.mesh < meshes.size()) b.extend(transform_bounds(in.object_to_world, mesh_bounds[in.mesh]));
  return b;
}

std::size_t Scene::triangle_count() const {
  std::size_t n = 0;
  for (const SceneObject& o : objects()) n += meshes[o.mesh].triangle_count();
  return n;
}

std::size_t Scene::stored_triangle_count() const {
  std::size_t n = 0;
  for (const Mesh& m : meshes) n += m.triangle_count();
  return n;
}

std::vector<SceneObject> Scene::objects() const {
  std::vector<SceneObject> out;
  const std::vector<char> instanced = instanced_meshes(*this);
  for (std::size_t i = 0; i < meshes.size(); ++i)
    if (!instanced[i]) out.push_back({static_cast<std::uint32_t>(i), SceneObject::kNoInstance});
  for (std::size_t k = 0; k < instances.size(); ++k)
    if (instances[k].mesh < meshes.size()) out.push_back({instances[k].mesh, static_cast<std::uint32_t>(k)});
  return out;
}

Scene flatten_instances(const Scene& scene) {
  Scene out;
  out.name = scene.name;
  out.preferred_view = scene.preferred_view;
  out.analytic = scene.analytic;
  out.warnings = scene.warnings;
  for (const SceneObject& o : scene.objects()) {
    Mesh m = scene.meshes[o.mesh];
    if (o.instance != SceneObject::kNoInstance) {
      const Affine3& t = scene.instances[o.instance].object_to_world;
      const Affine3 n = cofactor(t);
      for (Vec3& p : m.positions) p = t.point(p);
      for (Vec3& v : m.normals) v = normalize(n.vector(v));
    }
    m.positions.reserve(m.positions.size() + kVertexPadding);  // see kVertexPadding
    out.meshes.push_back(std::move(m));
  }
  return out;
}

std::size_t Scene::vertex_count() const {
  std::size_t n = 0;
  for (const Mesh& m : meshes) n += m.positions.size();
  return n;
}

namespace {

/// Triangles (or vertices) per parallel task: big enough that scheduling costs nothing, small
/// enough that two cores share a million-element pass evenly.
constexpr std::size_t kGrain = 1 << 15;

/// Smallest i in [0, n) with bad(i), or n when there is none: in parallel, the same answer at any
/// thread count, so the error a file gets does not depend on the machine.
template <class Bad>
std::size_t first_where(std::size_t n, const Bad& bad) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, kGrain), n,
      [&](const tbb::blocked_range<std::size_t>& r, std::size_t found) {
        if (found < r.begin()) return found;
        for (std::size_t i = r.begin(); i < r.end(); ++i)
          if (bad(i)) return std::min(found, i);
        return found;
      },
      [](std::size_t a, std::size_t b) { return std::min(a, b); });
}

/// A power of two that brings a tiny mesh to an extent between 1/2 and 1; 1 for a mesh of ordinary
/// size. The area test and the face normals square or multiply edge vectors, which underflows in
/// float for a mesh smaller than about 1e-10 (its triangles would all look degenerate, its normals
/// be noise). Edges multiplied by a power of two (exact: only the exponents change) give a tiny
/// mesh the area test and the normals of the same mesh at unit size: the threshold is relative to
/// the mesh's own scale. Meshes of 2^-20 (1e-6) and more are used as they are (a factor 1).
float tiny_mesh_scale(const Mesh& mesh) {
  const Bounds3 b = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, mesh.positions.size(), kGrain), Bounds3{},
      [&](const tbb::blocked_range<std::size_t>& r, Bounds3 acc) {
        for (std::size_t v = r.begin(); v < r.end(); ++v) acc.extend(mesh.positions[v]);
        return acc;
      },
      [](Bounds3 x, const Bounds3& y) {
        x.extend(y.lo);
        x.extend(y.hi);
        return x;
      });
  const float extent = std::max({b.hi.x - b.lo.x, b.hi.y - b.lo.y, b.hi.z - b.lo.z});
  if (!(extent > 0) || extent >= std::ldexp(1.0f, -20)) return 1.0f;
  return std::ldexp(1.0f, -std::ilogb(extent) - 1);
}

}  // namespace

void generate_normals(Mesh& mesh) {
  // Each task owns a range of vertices and walks all triangles in order, adding only to its own
  // vertices: every vertex sums its triangles in triangle order, as a serial loop would, so the
  // normals do not depend on the thread count, and no two tasks write the same vertex. The walk
  // over the indices is repeated per task, but it is a sequential read; the angles, the costly
  // part, are computed once per corner.
  const std::size_t nv = mesh.positions.size(), nc = mesh.indices.size() - mesh.indices.size() % 3;
  const float scale = tiny_mesh_scale(mesh);  // exact; 1 but for meshes below 1e-6
  mesh.normals.resize(nv);
  const auto parts = static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, parts, 1), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t part = r.begin(); part < r.end(); ++part) {
      const std::size_t v0 = nv * part / parts, size = nv * (part + 1) / parts - v0;
      std::fill(mesh.normals.begin() + static_cast<std::ptrdiff_t>(v0), mesh.normals.begin() + static_cast<std::ptrdiff_t>(v0 + size), Vec3{});
      for (std::size_t t = 0; t < nc; t += 3) {
        const std::uint32_t i[3] = {mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]};
        // i - v0 < size, unsigned, tests v0 <= i < v0 + size.
        const bool own[3] = {i[0] - v0 < size, i[1] - v0 < size, i[2] - v0 < size};
        if (!(own[0] || own[1] || own[2])) continue;
        const Vec3 p[3] = {mesh.positions[i[0]] * scale, mesh.positions[i[1]] * scale, mesh.positions[i[2]] * scale};
        const Vec3 n = normalize(cross(p[1] - p[0], p[2] - p[0]));
        for (int k = 0; k < 3; ++k) {
          if (!own[k]) continue;
          // Angle weighting makes the result independent of how a flat region is triangulated.
          const Vec3 e0 = normalize(p[(k + 1) % 3] - p[k]);
          const Vec3 e1 = normalize(p[(k + 2) % 3] - p[k]);
          const float angle = std::acos(std::clamp(dot(e0, e1), -1.0f, 1.0f));
          mesh.normals[i[k]] += n * angle;
        }
      }
      for (std::size_t v = v0; v < v0 + size; ++v) {
        Vec3& n = mesh.normals[v];
        n = length(n) > 0 ? normalize(n) : Vec3{0, 0, 1};
      }
    }
  }, tbb::simple_partitioner());
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

/// A triangle has area when its edges' cross product is not zero (in float, at `scale`).
bool has_area(Vec3 a, Vec3 b, Vec3 c, float scale) {
  const Vec3 n = cross((b - a) * scale, (c - a) * scale);
  return dot(n, n) > 0.0f;
}

// Vertices and their attributes: finite, in range, one per vertex; the albedo clamped to [0, 1].
void validate_vertices(const std::string& w, Mesh& mesh) {
  const auto bad_position = [&](std::size_t v) {
    const Vec3 p = mesh.positions[v];
    return !is_finite(p) || std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}) > kMaxCoordinate;
  };
  if (const std::size_t v = first_where(mesh.positions.size(), bad_position); v < mesh.positions.size()) {
    const Vec3 p = mesh.positions[v];
    if (!is_finite(p)) throw InputError(w + ": vertex " + std::to_string(v) + " has a non-finite coordinate");
    const float m = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    throw InputError(w + ": vertex " + std::to_string(v) + " has coordinate " + format_magnitude(m) + ", beyond the +-" +
                     format_magnitude(kMaxCoordinate) + " ao traces correctly (scale the mesh down)");
  }
  if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size())
    throw InputError(w + ": " + std::to_string(mesh.normals.size()) + " normals for " + std::to_string(mesh.positions.size()) + " vertices");
  if (!mesh.uvs.empty() && mesh.uvs.size() != mesh.positions.size())
    throw InputError(w + ": " + std::to_string(mesh.uvs.size()) + " UVs for " + std::to_string(mesh.positions.size()) + " vertices");
  const auto bad_uv = [&](std::size_t v) { return !std::isfinite(mesh.uvs[v].x) || !std::isfinite(mesh.uvs[v].y); };
  if (const std::size_t v = first_where(mesh.uvs.size(), bad_uv); v < mesh.uvs.size())
    throw InputError(w + ": UV " + std::to_string(v) + " is not finite");
  for (float c : {mesh.albedo.x, mesh.albedo.y, mesh.albedo.z})
    if (!std::isfinite(c)) throw InputError(w + ": albedo is not finite");
  mesh.albedo = min(max(mesh.albedo, Vec3{0, 0, 0}), Vec3{1, 1, 1});
}

// Triangles, in blocks of kGrain: each block checks its indices and moves the triangles it keeps
// to its own front (in place: a kept triangle never moves up); the blocks are then joined in
// order, which keeps the file's triangle order.
void compact_triangles(const std::string& w, Mesh& mesh) {
  const std::size_t vertex_count = mesh.positions.size(), triangle_count = mesh.indices.size() / 3;
  const std::size_t blocks = (triangle_count + kGrain - 1) / kGrain;
  struct Block {
    std::size_t kept = 0;
    std::size_t bad_triangle = SIZE_MAX;  ///< First triangle with an index out of range.
    std::uint32_t bad_index = 0;
  };
  std::vector<Block> block(blocks);
  std::uint32_t* const idx = mesh.indices.data();
  const float area_scale = tiny_mesh_scale(mesh);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
    const std::size_t t0 = b * kGrain, t1 = std::min(triangle_count, t0 + kGrain);
    std::size_t kept = t0;
    for (std::size_t t = t0; t < t1; ++t) {
      const std::uint32_t a = idx[3 * t], bb = idx[3 * t + 1], c = idx[3 * t + 2];
      for (std::uint32_t i : {a, bb, c})
        if (i >= vertex_count) {
          block[b] = {0, t, i};
          return;
        }
      if (a == bb || bb == c || a == c || !has_area(mesh.positions[a], mesh.positions[bb], mesh.positions[c], area_scale)) continue;
      idx[3 * kept] = a;
      idx[3 * kept + 1] = bb;
      idx[3 * kept + 2] = c;
      ++kept;
    }
    block[b].kept = kept - t0;
  });
  std::size_t kept = 0;
  for (std::size_t b = 0; b < blocks; ++b) {
    if (block[b].bad_triangle != SIZE_MAX)
      throw InputError(w + ": triangle " + std::to_string(block[b].bad_triangle) + " uses vertex " + std::to_string(block[b].bad_index) +
                       ", the mesh has " + std::to_string(vertex_count));
    if (kept != b * kGrain) std::memmove(idx + 3 * kept, idx + 3 * b * kGrain, 3 * block[b].kept * sizeof(std::uint32_t));
    kept += block[b].kept;
  }
  // Degenerate triangles have no area, so they can neither occlude nor be seen: dropping them
  // changes no result but spares the ray tracer and the bakers a division by zero. The caller
  // reports how many went.
  mesh.indices.resize(3 * kept);
}

// Given normals: finite, made unit length (a zero one becomes +z).
void normalize_given_normals(const std::string& w, Mesh& mesh) {
  const auto bad_normal = [&](std::size_t v) { return !is_finite(mesh.normals[v]); };
  if (const std::size_t v = first_where(mesh.normals.size(), bad_normal); v < mesh.normals.size())
    throw InputError(w + ": normal " + std::to_string(v) + " is not finite");
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.normals.size(), kGrain), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t v = r.begin(); v < r.end(); ++v) {
      const float len = length(mesh.normals[v]);
      mesh.normals[v] = len > 0 ? mesh.normals[v] / len : Vec3{0, 0, 1};
    }
  });
}

void validate_mesh(const Scene& scene, Mesh& mesh) {
  const std::string w = where(scene, mesh);
  if (mesh.indices.size() % 3 != 0) throw InputError(w + ": index count " + std::to_string(mesh.indices.size()) + " is not a multiple of 3");
  // Every check below runs in parallel and reports the first offender in file order.
  validate_vertices(w, mesh);
  compact_triangles(w, mesh);
  if (!mesh.normals.empty()) normalize_given_normals(w, mesh);
  else generate_normals(mesh);
  // Loaders reserve this up front; a reallocation here only happens for meshes built in code.
  if (mesh.positions.capacity() < mesh.positions.size() + kVertexPadding) mesh.positions.reserve(mesh.positions.size() + kVertexPadding);
}

}  // namespace

namespace {

// Node names come from the file: kept printable, one line and short in messages.
std::string instance_label(const Scene& scene, std::size_t k) {
  const Instance& in = scene.instances[k];
  if (in.name.empty()) return "instance " + std::to_string(k);
  std::string name;
  for (char c : in.name.substr(0, 64)) name += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  return "node '" + name + (in.name.size() > 64 ? "...'" : "'");
}

// Transforms: finite, invertible, not squashed beyond kMaxSquashRatio, and keeping their mesh inside +-kMaxCoordinate. The box test
// first (8 corners); only a transform whose box leaves the range has its vertices checked one by
// one, since a rotated box can stick out where no vertex does.
void validate_instances(const Scene& scene) {
  std::vector<Bounds3> mesh_bounds(scene.meshes.size());
  std::vector<char> have(scene.meshes.size(), 0);
  for (std::size_t k = 0; k < scene.instances.size(); ++k) {
    const Instance& in = scene.instances[k];
    const std::string w = scene.name + ": " + instance_label(scene, k);
    const Affine3& t = in.object_to_world;
    if (const std::string problem = transform_problem(t); !problem.empty()) throw InputError(w + " " + problem);
    if (!have[in.mesh]) mesh_bounds[in.mesh] = scene.meshes[in.mesh].bounds(), have[in.mesh] = 1;
    const Bounds3 b = transform_bounds(t, mesh_bounds[in.mesh]);
    const auto too_far = [](Vec3 p) { return !is_finite(p) || std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}) > kMaxCoordinate; };
    if (!too_far(b.lo) && !too_far(b.hi)) continue;
    for (const Vec3& p : scene.meshes[in.mesh].positions) {
      const Vec3 q = t.point(p);
      if (!too_far(q)) continue;
      const float m = is_finite(q) ? std::max({std::abs(q.x), std::abs(q.y), std::abs(q.z)}) : kInfinity;
      throw InputError(w + " moves its mesh to coordinate " + format_magnitude(m) + ", beyond the +-" + format_magnitude(kMaxCoordinate) +
                       " ao traces correctly (scale the scene down)");
    }
  }
}

}  // namespace

std::string transform_problem(const Affine3& t) {
  if (!t.is_finite()) return "has a non-finite transform";
  // A zero determinant flattens the mesh onto a plane or a line: every triangle would be
  // degenerate, and the ray tracer needs the inverse.
  const double det = t.determinant();
  if (!(std::abs(det) > 0) || !std::isfinite(1.0 / det)) return "has a transform with determinant 0 (it flattens the mesh)";
  // Nearly flat is flat in float, and rays in the mesh's own space become too long for Embree.
  const double ratio = squash_ratio(t);
  if (ratio > kMaxSquashRatio) {
    char text[160];
    std::snprintf(text, sizeof text, "has a transform that squashes the mesh: it scales one direction %.2g times more than another, ao traces at most %.0e",
                  ratio, kMaxSquashRatio);
    return text;
  }
  return {};
}

void check_traceable_size(const Scene& scene) {
  const Bounds3 b = scene.bounds();
  if (b.empty()) return;
  const Vec3 size = b.hi - b.lo;
  const float extent = std::max({size.x, size.y, size.z});
  if (extent < kMinSceneExtent)
    throw InputError(scene.name + ": the scene is " + format_magnitude(extent) + " units across, less than the " + format_magnitude(kMinSceneExtent) +
                     " ao traces correctly (scale it up)");
}

void validate_and_prepare(Scene& scene) {
  if (scene.meshes.empty()) throw InputError(scene.name + ": the scene has no meshes");
  for (std::size_t k = 0; k < scene.instances.size(); ++k)
    if (scene.instances[k].mesh >= scene.meshes.size())
      throw InputError(scene.name + ": " + instance_label(scene, k) + " uses mesh " + std::to_string(scene.instances[k].mesh) + ", the scene has " +
                       std::to_string(scene.meshes.size()));
  for (Mesh& mesh : scene.meshes) {
    const std::size_t before = mesh.triangle_count();
    validate_mesh(scene, mesh);
    const std::size_t dropped = before - mesh.triangle_count();
    if (dropped > 0)
      scene.warnings.push_back(where(scene, mesh) + ": dropped " + std::to_string(dropped) + " degenerate (zero-area) triangle" +
                               (dropped == 1 ? "" : "s"));
  }
  // Meshes left without triangles go, and instances follow their mesh's new index.
  std::vector<std::uint32_t> new_index(scene.meshes.size(), SceneObject::kNoInstance);
  std::uint32_t next = 0;
  for (std::size_t i = 0; i < scene.meshes.size(); ++i)
    if (scene.meshes[i].triangle_count() > 0) new_index[i] = next++;
  std::erase_if(scene.meshes, [](const Mesh& m) { return m.triangle_count() == 0; });
  if (!scene.instances.empty()) {
    for (Instance& in : scene.instances) in.mesh = new_index[in.mesh];
    std::erase_if(scene.instances, [](const Instance& in) { return in.mesh == SceneObject::kNoInstance; });
    validate_instances(scene);
  }
  if (scene.triangle_count() == 0) throw InputError(scene.name + ": the scene has no triangles with nonzero area");
}

}  // namespace ao
