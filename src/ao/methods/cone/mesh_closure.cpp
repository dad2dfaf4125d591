// SPDX-License-Identifier: Apache-2.0
// What each mesh stands for (mesh_closure.h): its boundary edges and holes, and for an open mesh
// its enclosure by its generalized winding number (Jacobson, Kavan, Sorkine-Hornung, SIGGRAPH
// 2013; winding_number.h); and the closed meshes around the camera (rooms).
#include "ao/methods/cone/mesh_closure.h"

#include <algorithm>
#include <cmath>
#include <mutex>

#include "ao/scene/topology.h"

namespace ao {

namespace {

// Sheet or solid with holes, from the winding number of the mesh itself (voxelize.h, MeshKind).
// Just in front of and just behind a triangle's centroid c, w(c + n d) + w(c - n d) = 2 w_rest(c):
// the triangle's own solid angles cancel (mirror images), leaving twice the winding number of
// the rest of the mesh at c. A closed mesh has w_rest = 1/2 everywhere (the rest subtends the
// whole half-space behind the face), a flat sheet 0. `enclosure` is the magnitude of 2 w_rest
// averaged over the area (at every (n / kEnclosureSamples)-th triangle), `orientation` its sign.
void classify_open_mesh(const Mesh& m, MeshClosure& c) {
  c.winding = MeshWinding(m);
  const std::size_t nt = m.triangle_count();
  // Small holes (kSmallHoles): each hole's vector area from its boundary edges (about any point,
  // here its first vertex), the orientation from the sign of the enclosed volume (about the box's
  // centre; the holes change it little).
  {
    std::vector<Vec3> hole_area(c.holes, Vec3{0, 0, 0}), origin(c.holes, Vec3{0, 0, 0});
    std::vector<std::uint8_t> has(c.holes, 0);
    for (std::size_t e = 0; e < c.boundary.size(); ++e) {
      const std::uint32_t h = c.hole[e];
      if (!has[h]) origin[h] = m.positions[c.boundary[e][0]], has[h] = 1;
      hole_area[h] += cross(m.positions[c.boundary[e][0]] - origin[h], m.positions[c.boundary[e][1]] - origin[h]) * 0.5f;
    }
    double holes = 0, area = 0;
    for (const Vec3& a : hole_area) holes += length(a);
    for (std::size_t t = 0; t < nt; ++t) {
      const Vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]], d = m.positions[m.indices[3 * t + 2]];
      area += 0.5 * length(cross(b - a, d - a));
    }
    if (area > 0 && holes < kSmallHoles * area) {
      c.kind = MeshKind::SolidWithHoles;
      c.enclosure = static_cast<float>(1.0 - holes / area);
      c.orientation = signed_volume(m) < 0 ? -1 : 1;
      return;
    }
  }
  const std::size_t step = std::max<std::size_t>(1, nt / kEnclosureSamples);
  double sum = 0, area = 0;
  Vec3 vector_area{0, 0, 0};
  for (std::size_t t = 0; t < nt; ++t) {
    const Vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]], d = m.positions[m.indices[3 * t + 2]];
    vector_area += cross(b - a, d - a) * 0.5f;
  }
  for (std::size_t t = 0; t < nt; t += step) {
    const Vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]], d = m.positions[m.indices[3 * t + 2]];
    const Vec3 n2 = cross(b - a, d - a);
    const float len = length(n2);
    if (!(len > 0.0f)) continue;
    const float at = 0.5f * len;
    // 1% of the inradius (2 area / perimeter): far closer to c than any other triangle is.
    const float delta = 0.01f * 2.0f * at / (length(b - a) + length(d - b) + length(a - d));
    const Vec3 centre = (a + b + d) * (1.0f / 3.0f), n = n2 / len;
    sum += at * (c.winding.get()(centre + n * delta) + c.winding.get()(centre - n * delta));
    area += at;
  }
  const double mean = area > 0 ? sum / area : 0.0;
  c.enclosure = static_cast<float>(std::min(1.0, std::abs(mean)));
  c.orientation = mean < 0 ? -1 : 1;
  c.kind = c.enclosure >= kSolidEnclosure ? MeshKind::SolidWithHoles : MeshKind::Sheet;
  // A flat sheet (a ground, a wall): every vertex within 1e-5 of its extent of one plane. Its
  // winding number then has the sign of the side of that plane everywhere.
  const float len = length(vector_area);
  if (len > 0.0f) {
    const Vec3 n = vector_area / len;
    const Bounds3 box = m.bounds();
    const float tol = 1e-5f * box.diagonal();
    const float offset = dot(n, m.positions[m.indices[0]]);
    bool flat = true;
    for (std::uint32_t i : m.indices) flat = flat && std::abs(dot(n, m.positions[i]) - offset) <= tol;
    if (flat) c.plane = {n.x, n.y, n.z, -offset};
    c.flat = flat;
  }
}

// Whether the surface goes on across boundary edge a -> b of one of its triangles (its rim_frame
// `out` and `n`): a T-junction between the pieces of a ground, an edge where a ground meets the
// walls of a pit. Just beyond the edge, a hundredth of its length off the triangle's plane on
// either side, a free rim has nothing nearer than the edge itself (sqrt 2 hundredths away); a
// surface that goes on, in the plane or folding up to 90 degrees either way, passes a hundredth
// away or nearer.
bool goes_on(const WindingNumber& w, Vec3 a, Vec3 b, Vec3 out, Vec3 n) {
  const float delta = 0.01f * length(b - a);
  for (const float side : {1.0f, -1.0f})
    if (std::abs(w.signed_distance((a + b) * 0.5f + (out + n * side) * delta)) < 1.2 * delta) return true;
  return false;
}

// MeshClosure::free_rim of a sheet, in the mesh's own space (once per mesh, whatever instances it has).
void find_free_rims(const Mesh& m, MeshClosure& c) {
  const WindingNumber& w = c.winding.get();
  c.free_rim.assign(c.boundary.size(), 0);
  for (std::size_t e = 0; e < c.boundary.size(); ++e) {
    const Vec3 a = m.positions[c.boundary[e][0]], b = m.positions[c.boundary[e][1]];
    Vec3 out, n;
    c.free_rim[e] = rim_frame(a, b, m.positions[rim_apex(m, c, e)], out, n) && !goes_on(w, a, b, out, n) ? 1 : 0;
  }
}

}  // namespace

struct MeshWinding::State {
  const Mesh* mesh = nullptr;
  std::once_flag once;
  std::unique_ptr<WindingNumber> field;
};

MeshWinding::MeshWinding(const Mesh& mesh) : state_(std::make_shared<State>()) { state_->mesh = &mesh; }

const WindingNumber& MeshWinding::get() const {
  static const WindingNumber empty;
  if (!state_) return empty;
  std::call_once(state_->once, [&] { state_->field = std::make_unique<WindingNumber>(state_->mesh->positions, state_->mesh->indices); });
  return *state_->field;
}

std::vector<MeshClosure> analyze_closure(const Scene& scene) {
  std::vector<MeshClosure> out;
  out.reserve(scene.meshes.size());
  for (const Mesh& m : scene.meshes) {
    const MeshEdges edges = mesh_edges(m);
    MeshClosure c;
    c.boundary = edges.boundary;
    c.boundary_triangle = edges.boundary_triangle;
    c.edges = edges.edges;
    const std::vector<std::uint32_t>& id = edges.weld;
    const std::uint32_t next = edges.welded;
    c.boundary_edges = c.boundary.size();
    if (!c.boundary.empty()) {
      // Holes: connected components of the boundary edges over welded vertices (union-find).
      std::vector<std::uint32_t> parent(next);
      for (std::uint32_t v = 0; v < next; ++v) parent[v] = v;
      const auto find = [&](std::uint32_t v) {
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
      };
      for (const auto& [a, b] : c.boundary) parent[find(id[a])] = find(id[b]);
      std::vector<std::uint32_t> number(next, ~0u);
      for (const auto& [a, b] : c.boundary) {
        std::uint32_t& n = number[find(id[a])];
        if (n == ~0u) n = c.holes++;
        c.hole.push_back(n);
      }
      classify_open_mesh(m, c);
      if (c.open_surface()) find_free_rims(m, c);
    }
    out.push_back(std::move(c));
  }
  return out;
}

std::vector<std::uint8_t> closed_meshes_around(const Scene& scene, std::span<const MeshClosure> closure, Vec3 eye) {
  const std::vector<SceneObject> objects = scene.objects();
  std::vector<std::uint8_t> around(objects.size(), 0);
  bool any = false;
  for (std::size_t k = 0; k < objects.size(); ++k) {
    if (!closure[objects[k].mesh].closed()) continue;
    around[k] = inside_closed_object(scene, objects[k], eye) ? 1 : 0;
    any = any || around[k];
  }
  if (!any) around.clear();
  return around;
}

}  // namespace ao
