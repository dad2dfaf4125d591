// SPDX-License-Identifier: Apache-2.0
// Solid parity voxelization (Eisemann & Decoret 2008; Dalla Favera & Celes 2012, sec. III-B).
// See voxelize.h for the grid layout. The CPU pipeline:
//  1. every triangle is mapped to the
//     grid: column coordinates (x, y) and a depth attribute that is affine in (x, y) (voxel units
//     for the orthographic world grid, 1/depth for the perspective eye grid);
//  2. the rows of columns are split into bands; triangles are bucketed by band (counting sort per
//     chunk); each band rasterises the triangles that overlap it at the column centres and toggles
//     one bit per fragment (no atomics: bands are disjoint);
//  3. one prefix-XOR scan per column turns toggles into "XOR from the fragment to the far end"
//     (voxel_grid.cpp), and next to holes that are not flat the winding-number solid
//     (winding_solid.cpp);
//  4. slabs of open meshes, then coarse occupancy (blocks and windowed cell masks, voxelize.h) for
//     empty-space skipping (voxel_grid.cpp).
// What each mesh stands for (closed, a solid with holes, a sheet) is decided in mesh_closure.cpp.
#include "ao/methods/cone/voxelize.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <tuple>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "ao/core/error.h"
#include "ao/methods/cone/raster_kernel_internal.h"
#include "ao/methods/cone/voxel_grid_internal.h"
#include "ao/methods/cone/voxel_raster_internal.h"
#include "ao/methods/cone/winding_solid_internal.h"

namespace ao {

using voxel_internal::build_coarse;
using voxel_internal::ColumnHit;
using voxel_internal::fan_winding;
using voxel_internal::GridTri;
using voxel_internal::hole_centroids;
using voxel_internal::Holes;
using voxel_internal::object_space;
using voxel_internal::PrismCounts;
using voxel_internal::scan_columns;
using voxel_internal::SlotWinding;
using voxel_internal::WalkCount;
using voxel_internal::winding_solid;

namespace {

constexpr std::size_t kChunk = 4096;  // triangles per projection task
constexpr int kBands = 48;            // row bands of the raster stage: enough to balance 2-16 threads

struct Tri3 {
  Vec3 v[3];
  int kind;      // 0: parity; 1: open-mesh face, filled behind `normal`; 2: side of an open face's prism
  Vec3 normal;   // kind 1: the side the slab is away from (the front's normal, or its opposite for
                 // a grid traced from the back side, voxelize.h)
  int fan = -1;  // kind 0: slot of the solid with holes whose non-flat hole this fan triangle closes,
                 // or near which this triangle of it lies (Holes::near)
  float depth = 0;  // kind 1: how far behind `normal` the slab reaches (world units; 0: the grid's slab
                    // thickness); less where the sheet itself comes back within it (sheet_depth)
};

Tri3 source_triangle(const Mesh& m, std::size_t t, bool open) {
  const Vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]], c = m.positions[m.indices[3 * t + 2]];
  return {{a, b, c}, open ? 1 : 0, open ? normalize(cross(b - a, c - a)) : Vec3{}};
}

// An open face steep to the columns (a wall, for the world grid) has few or no fragments: a span
// along the column cannot stand for it. It becomes the closed prism between it and its copy
// moved `thickness` behind `normal` (kind 2), whose triangles face out of it; their union is
// ORed into the grid (voxelize_into, step 4). Calls emit for the prism's 8 triangles.
template <class Emit>
void emit_prism(const Tri3& t, float thickness, Emit&& emit) {
  const Vec3 o = t.normal * -(t.depth > 0.0f ? t.depth : thickness);
  // The top (the face itself) faces out when its counter-clockwise normal is `normal`; otherwise
  // (a slab in front of a face) its vertices are taken in the other order.
  const bool out = dot(cross(t.v[1] - t.v[0], t.v[2] - t.v[0]), t.normal) >= 0;
  const Vec3 a = t.v[0], b = out ? t.v[1] : t.v[2], c = out ? t.v[2] : t.v[1];
  const Vec3 top[3] = {a, b, c}, bottom[3] = {a + o, b + o, c + o};
  emit(Tri3{{top[0], top[1], top[2]}, 2, {}});
  emit(Tri3{{bottom[0], bottom[2], bottom[1]}, 2, {}});
  for (int e = 0; e < 3; ++e) {
    const int f = (e + 1) % 3;
    emit(Tri3{{top[e], bottom[e], bottom[f]}, 2, {}});
    emit(Tri3{{top[e], bottom[f], top[f]}, 2, {}});
  }
}

// |cos| of the angle between an open face and the column direction below which it is a wall.
constexpr float kSteep = 0.5f;

// Grid-space mapping of the two grids. map() returns false for a vertex that needs clipping.
struct WorldMap {
  Vec3 origin, inv_size;
  float slab;
  void operator()(Vec3 p, float& x, float& y, float& a) const {
    x = (p.x - origin.x) * inv_size.x;
    y = (p.z - origin.z) * inv_size.y;
    a = (p.y - origin.y) * inv_size.z;
  }
};

struct EyeMap {
  Frame basis;
  Vec3 eye;
  float sx, sy, ox, oy;  // column = (x / depth) * sx + ox, (y / depth) * sy + oy
  float z_clip;
  float slab;
};

// Sets the rows of a mapped triangle; false when no column centre of the grid can be inside.
bool finish_visible(GridTri& t, int nx, int ny) {
  const float xmin = std::min({t.x[0], t.x[1], t.x[2]}), xmax = std::max({t.x[0], t.x[1], t.x[2]});
  const float ymin = std::min({t.y[0], t.y[1], t.y[2]}), ymax = std::max({t.y[0], t.y[1], t.y[2]});
  // Column i's centre is i + 0.5: the box covers i in [ceil(min - 0.5), floor(max - 0.5)].
  if (!(xmax >= 0.5f && xmin <= static_cast<float>(nx) - 0.5f)) return false;  // also rejects NaN
  if (!(ymax >= ymin)) return false;                                           // NaN
  // Rows: the rounding of the ends clamped to [-2, ny + 1] first, where truncation does it (a
  // baseline x86-64 build has no rounding instruction, and this runs once per triangle); ends
  // beyond that range are rejected or clamped to the grid alike.
  const float lo = std::clamp(ymin - 0.5f, -2.0f, static_cast<float>(ny + 1)), hi = std::clamp(ymax - 0.5f, -2.0f, static_cast<float>(ny + 1));
  const int tl = static_cast<int>(lo), th = static_cast<int>(hi);
  const int j0 = tl + (static_cast<float>(tl) < lo ? 1 : 0), j1 = th - (static_cast<float>(th) > hi ? 1 : 0);  // ceil, floor
  if (j1 < 0 || j0 > ny - 1 || j0 > j1) return false;
  t.j0 = std::max(j0, 0);
  t.j1 = std::min(j1, ny - 1);
  return true;
}

void push_if_visible(std::vector<GridTri>& out, const GridTri& g, int nx, int ny) {
  GridTri t = g;
  if (finish_visible(t, nx, ny)) out.push_back(t);
}

void emit_world(std::vector<GridTri>& out, const Tri3& t, const WorldMap& m, int nx, int ny) {
  if (t.kind == 1 && std::abs(t.normal.y) < kSteep)
    return emit_prism(t, m.slab, [&](const Tri3& side) { emit_world(out, side, m, nx, ny); });
  // Built in place: a copy of a struct just written field by field stalls on store forwarding.
  GridTri& g = out.emplace_back();
  for (int k = 0; k < 3; ++k) m(t.v[k], g.x[k], g.y[k], g.a[k]);
  // Behind the front face: below a face looking up (+y is +k), above a face looking down.
  g.fill = t.kind == 1 ? (t.normal.y > 0 ? -1 : 1) : t.kind == 2 ? 2 : t.fan >= 0 ? 3 + t.fan : 0;
  if (t.kind == 1) g.slab = t.depth > 0.0f ? t.depth : m.slab;
  if (!finish_visible(g, nx, ny)) out.pop_back();
}

// Perspective: clip against depth >= z_clip (Sutherland-Hodgman on one plane), project, and
// keep 1/depth as the attribute, which is affine in screen space.
void emit_eye(std::vector<GridTri>& out, const Tri3& t, const EyeMap& m, int nx, int ny) {
  std::array<Vec3, 4> poly;
  int n = 0;
  Vec3 c[3];
  for (int k = 0; k < 3; ++k) c[k] = m.basis.to_local(t.v[k] - m.eye);
  const float facing = t.kind == 1 ? dot(m.basis.to_local(t.normal), normalize(c[0] + c[1] + c[2])) : 0.0f;
  if (t.kind == 1 && std::abs(facing) < kSteep)
    return emit_prism(t, m.slab, [&](const Tri3& side) { emit_eye(out, side, m, nx, ny); });
  for (int k = 0; k < 3; ++k) {
    const Vec3 p = c[k], q = c[(k + 1) % 3];
    const float dp = -p.z - m.z_clip, dq = -q.z - m.z_clip;
    if (dp >= 0) poly[n++] = p;
    if ((dp >= 0) != (dq >= 0)) poly[n++] = p + (q - p) * (dp / (dp - dq));
  }
  if (n < 3) return;
  // Behind the front face: deeper for a face turned to the eye, nearer for one turned away.
  const float slab = t.kind == 1 && t.depth > 0.0f ? t.depth : m.slab;
  const int fill = t.kind == 1 ? (facing < 0 ? 1 : -1) : t.kind == 2 ? 2 : t.fan >= 0 ? 3 + t.fan : 0;
  float x[4], y[4], a[4];
  for (int k = 0; k < n; ++k) {
    const float inv = 1.0f / -poly[k].z;
    x[k] = poly[k].x * inv * m.sx + m.ox;
    y[k] = poly[k].y * inv * m.sy + m.oy;
    a[k] = inv;
  }
  for (int k = 1; k + 1 < n; ++k) {
    GridTri g{{x[0], x[k], x[k + 1]}, {y[0], y[k], y[k + 1]}, {a[0], a[k], a[k + 1]}, 0, 0, fill, slab};
    push_if_visible(out, g, nx, ny);
  }
}

// How one object is voxelized (voxelize.h: OpenMeshes, and the `back` side of a grid).
enum class Treat : std::uint8_t {
  Parity,       // as it is
  Fans,         // a solid with holes: parity with its holes closed by fans, w evaluated near non-flat ones
  Slab,         // a slab behind its fronts
  SlabFlipped,  // a slab in front of its fronts
};

// Per object, and the number of open objects voxelized for their back side.
struct Treatments {
  std::vector<Treat> of;
  std::size_t back = 0;
  std::vector<std::uint8_t> thin;  // per object: a sheet of its own two voxels, no slab (kBeyondRim)
};
Treatments treatments(const Scene& scene, std::span<const MeshClosure> closure, OpenMeshes mode, std::span<const std::uint8_t> back) {
  if (closure.size() != scene.meshes.size()) throw InputError("voxelize: closure has " + std::to_string(closure.size()) +
                                                              " meshes, the scene " + std::to_string(scene.meshes.size()));
  const std::vector<SceneObject> objects = scene.objects();
  if (!back.empty() && back.size() != objects.size())
    throw InputError("voxelize: " + std::to_string(back.size()) + " back-side flags for " + std::to_string(objects.size()) + " objects");
  Treatments r{std::vector<Treat>(objects.size(), Treat::Parity), 0, std::vector<std::uint8_t>(objects.size(), 0)};
  std::vector<Treat>& t = r.of;
  for (std::size_t o = 0; o < objects.size(); ++o) {
    const MeshClosure& c = closure[objects[o].mesh];
    const std::uint8_t flags = mode == OpenMeshes::Winding && !c.closed() && !back.empty() ? back[o] : 0;
    const bool from_back = flags & kBackSide;
    r.back += from_back ? 1 : 0;
    r.thin[o] = c.open_surface() && (flags & kBeyondRim) ? 1 : 0;
    if (mode == OpenMeshes::Slab && c.open_surface()) {
      t[o] = Treat::Slab;
    } else if (mode == OpenMeshes::Winding && c.open_surface()) {
      t[o] = from_back ? Treat::SlabFlipped : Treat::Slab;
    } else if (mode == OpenMeshes::Winding && c.holed()) {
      // Seen from inside (through a hole), the shell's outside is what occludes: a slab on the
      // side its fronts face when they face out.
      const Affine3* tf = objects[o].instance == SceneObject::kNoInstance ? nullptr : &scene.instances[objects[o].instance].object_to_world;
      const int out = c.orientation * (tf && tf->determinant() < 0 ? -1 : 1);
      t[o] = !from_back ? Treat::Fans : out > 0 ? Treat::SlabFlipped : Treat::Slab;
    }
  }
  return r;
}

bool any_slab(std::span<const Treat> t) {
  return std::any_of(t.begin(), t.end(), [](Treat x) { return x == Treat::Slab || x == Treat::SlabFlipped; });
}

// Whether a slab rises above any face (world +y): a face turned down with a slab behind it, or
// turned up with one in front.
bool slab_rises(const Scene& scene, std::span<const Treat> t) {
  const std::vector<SceneObject> objects = scene.objects();
  for (std::size_t o = 0; o < objects.size(); ++o) {
    if (t[o] != Treat::Slab && t[o] != Treat::SlabFlipped) continue;
    const Mesh& m = scene.meshes[objects[o].mesh];
    const Affine3* tf = objects[o].instance == SceneObject::kNoInstance ? nullptr : &scene.instances[objects[o].instance].object_to_world;
    const float side = t[o] == Treat::Slab ? 1.0f : -1.0f;
    for (std::size_t k = 0; k < m.triangle_count(); ++k) {
      Vec3 v[3] = {m.positions[m.indices[3 * k]], m.positions[m.indices[3 * k + 1]], m.positions[m.indices[3 * k + 2]]};
      if (tf)
        for (Vec3& p : v) p = tf->point(p);
      if (side * cross(v[1] - v[0], v[2] - v[0]).y < 0) return true;
    }
  }
  return false;
}

// Row bands of the raster stage (kBands, fewer for a short grid) and the band of each row.
struct Bands {
  int ny = 0, count = 0;
  std::vector<int> of;  // per row
  int first_row(int b) const { return static_cast<int>(static_cast<long long>(ny) * b / count); }
};
Bands make_bands(int ny) {
  Bands b{ny, std::min(ny, kBands), std::vector<int>(ny)};
  for (int k = 0; k < b.count; ++k)
    for (int j = b.first_row(k); j < b.first_row(k + 1); ++j) b.of[j] = k;
  return b;
}

// A chunk's triangles bucketed by (fill kind, row band), a counting sort: bucket
// kind * bands + band is index[start[k], start[k + 1]); a triangle spanning bands is in each.
struct Buckets {
  std::vector<std::uint32_t> start, index;
};
// Fill kinds: 0 parity (fans included), 1 slab spans, 2 prisms (GridTri::fill).
int kind_of(const GridTri& t) { return t.fill == 0 || t.fill >= 3 ? 0 : t.fill == 2 ? 2 : 1; }
Buckets bucket(const std::vector<GridTri>& tris, const Bands& bands) {
  Buckets bk;
  bk.start.assign(3 * static_cast<std::size_t>(bands.count) + 1, 0);
  for (const GridTri& t : tris)
    for (int b = bands.of[t.j0]; b <= bands.of[t.j1]; ++b) ++bk.start[kind_of(t) * bands.count + b + 1];
  for (std::size_t k = 1; k < bk.start.size(); ++k) bk.start[k] += bk.start[k - 1];
  bk.index.resize(bk.start.back());
  std::vector<std::uint32_t> pos(bk.start.begin(), bk.start.end() - 1);
  for (std::size_t i = 0; i < tris.size(); ++i)
    for (int b = bands.of[tris[i].j0]; b <= bands.of[tris[i].j1]; ++b) bk.index[pos[kind_of(tris[i]) * bands.count + b]++] = static_cast<std::uint32_t>(i);
  return bk;
}

// The triangles voxelize_into maps: those of every object (Scene::objects(): a world-space mesh,
// or an instance whose mesh's triangles go through its transform), and for a solid with holes
// (Treat::Fans) one fan triangle per boundary edge after its own triangles: (b, a, centroid) for
// the boundary edge a -> b, so that every edge of the mesh and its fans is used twice and the
// parity pass sees a closed surface. Closure and hole centroids are per mesh, as an affine map
// keeps both (it maps centroids to centroids).
struct ObjectPlan {
  std::vector<SceneObject> objects;
  std::vector<Holes> holes;              // per mesh of a solid with holes
  std::vector<int> slot_of;              // per object with a hole that is not flat: its slot, else -1
  std::vector<std::size_t> slot_object;  // per slot: the object
  std::vector<std::size_t> first{0};     // object o's triangles are [first[o], first[o + 1])
  std::size_t fanned = 0;                // objects voxelized as solids with holes
};
ObjectPlan plan_objects(const Scene& scene, std::span<const MeshClosure> closure, std::span<const Treat> treat, float voxel) {
  ObjectPlan p;
  p.objects = scene.objects();
  p.holes.resize(scene.meshes.size());
  p.slot_of.assign(p.objects.size(), -1);
  std::vector<std::uint8_t> hole_info(scene.meshes.size(), 0);
  for (std::size_t oi = 0; oi < p.objects.size(); ++oi) {
    const std::size_t mi = p.objects[oi].mesh;
    const bool fans = treat[oi] == Treat::Fans;
    if (fans && !hole_info[mi]) {
      // Two voxels, in the mesh's own units (an instance's scale divides them).
      const float scale = p.objects[oi].instance == SceneObject::kNoInstance
                              ? 1.0f
                              : static_cast<float>(std::cbrt(std::abs(scene.instances[p.objects[oi].instance].object_to_world.determinant())));
      p.holes[mi] = hole_centroids(scene.meshes[mi], closure[mi], 2.0f * voxel / scale), hole_info[mi] = 1;
    }
    if (fans && std::find(p.holes[mi].flat.begin(), p.holes[mi].flat.end(), 0) != p.holes[mi].flat.end()) {
      p.slot_of[oi] = static_cast<int>(p.slot_object.size());
      p.slot_object.push_back(oi);
    }
    p.fanned += fans ? 1 : 0;
    p.first.push_back(p.first.back() + scene.meshes[mi].triangle_count() + (fans ? closure[mi].boundary.size() : 0));
  }
  return p;
}

// Where the columns of a grid run: world +y (eye null), or the view rays from `eye` (linear depth
// along `forward`).
struct ColumnAxis {
  const Vec3* eye = nullptr;
  Vec3 forward;
};

// How far the slab behind face `tri` (world space, its slab away from tri.normal) of an open mesh
// reaches: the grid's `slab`, or less where the mesh itself comes back within it (a nose, a brow,
// a fold of cloth: the slab behind the top of a brow would hang below it, in front of the eyes,
// where the reference sees air), but at least `min_depth` (two voxels: the surface's own). Measured
// the way the slab is filled (emit_world, emit_eye): along the column for a span (its length along
// the column; for the eye grid in linear depth), along the normal for a steep face's prism; from
// the face's centroid and from halfway to each corner (the nearest of the four), against the mesh's
// own triangles only: whatever else the slab enters is solid or behind that mesh's own slab.
// 0: the grid's slab.
float sheet_depth(const MeshClosure& c, const Affine3* tf, const Tri3& tri, float slab, float min_depth, const ColumnAxis& axis) {
  if (c.flat || !(slab > min_depth)) return 0.0f;  // a plane never comes back
  const WindingNumber& w = c.winding.get();
  if (w.size() == 0) return 0.0f;
  const Vec3 centre = (tri.v[0] + tri.v[1] + tri.v[2]) * (1.0f / 3.0f);
  Vec3 d = -tri.normal;
  float to_column = 1.0f;  // column length per unit of distance along d
  if (!axis.eye) {
    if (std::abs(tri.normal.y) >= kSteep) d = {0.0f, tri.normal.y > 0 ? -1.0f : 1.0f, 0.0f};
  } else {
    const Vec3 view = normalize(centre - *axis.eye);
    const float facing = dot(tri.normal, view);
    if (std::abs(facing) >= kSteep) d = facing < 0 ? view : -view, to_column = std::abs(dot(view, axis.forward));
  }
  const Affine3 to_mesh = tf ? inverse(*tf) : Affine3{};
  const Vec3 dm = tf ? to_mesh.vector(d) : d;  // world lengths along it (affine)
  float nearest = slab / to_column;
  for (int k = -1; k < 3; ++k) {
    const Vec3 p = k < 0 ? centre : (centre + tri.v[k]) * 0.5f;
    nearest = std::min(nearest, w.first_hit(tf ? to_mesh.point(p) : p, dm, 1e-3f * slab, nearest).t);
  }
  const float depth = nearest * to_column;
  return depth >= slab ? 0.0f : std::max(depth, min_depth);
}

// Triangle `local` of object `oi` (ObjectPlan) in world space, its slab's side for
// Treat::SlabFlipped and its depth (Treatments::thin: `min_depth`); false for a face given a slab
// that cannot reach `region` (VoxelizeOptions).
bool object_triangle(const Scene& scene, std::span<const MeshClosure> closure, const ObjectPlan& plan, const Treatments& treatment, std::size_t oi,
                     std::size_t local, const Bounds3& region, float slab_thickness, float min_depth, const ColumnAxis& axis, Tri3& tri) {
  const std::span<const Treat> treat = treatment.of;
  const std::size_t mi = plan.objects[oi].mesh;
  const Affine3* tf = plan.objects[oi].instance == SceneObject::kNoInstance ? nullptr : &scene.instances[plan.objects[oi].instance].object_to_world;
  const bool open = treat[oi] == Treat::Slab || treat[oi] == Treat::SlabFlipped;
  const Mesh& m = scene.meshes[mi];
  if (local < m.triangle_count()) {
    tri = source_triangle(m, local, open);
    if (open && !region.empty()) {
      Bounds3 reach;  // the triangle and its slab
      for (const Vec3& v : tri.v) reach.extend(tf ? tf->point(v) : v);
      reach.lo -= Vec3{slab_thickness, slab_thickness, slab_thickness};
      reach.hi += Vec3{slab_thickness, slab_thickness, slab_thickness};
      if (reach.hi.x < region.lo.x || reach.lo.x > region.hi.x || reach.hi.y < region.lo.y || reach.lo.y > region.hi.y || reach.hi.z < region.lo.z ||
          reach.lo.z > region.hi.z)
        return false;
    }
    if (plan.slot_of[oi] >= 0 && plan.holes[mi].near[local]) tri.fan = plan.slot_of[oi];
  } else {
    const std::size_t e = local - m.triangle_count();
    const auto [a, b] = closure[mi].boundary[e];
    const std::uint32_t h = closure[mi].hole[e];
    tri = Tri3{{m.positions[b], m.positions[a], plan.holes[mi].centre[h]}, 0, {}, plan.holes[mi].flat[h] ? -1 : plan.slot_of[oi]};
  }
  if (tf) {
    for (Vec3& v : tri.v) v = tf->point(v);
    if (tri.kind == 1) tri.normal = normalize(cross(tri.v[1] - tri.v[0], tri.v[2] - tri.v[0]));
  }
  if (treat[oi] == Treat::SlabFlipped) tri.normal = -tri.normal;
  if (tri.kind == 1)
    tri.depth = treatment.thin[oi] && slab_thickness > min_depth ? min_depth : sheet_depth(closure[mi], tf, tri, slab_thickness, min_depth, axis);
  return true;
}

// The union of one band's prisms (PrismCounts): the voxels where the running count is not 0.
void unite_prisms(VoxelGrid& g, const PrismCounts& counts) {
  for (std::size_t c = 0; c < counts.touched.size(); ++c) {
    if (!counts.touched[c]) continue;
    const std::int16_t* d = counts.delta.get() + c * g.depth_bits;
    std::uint64_t* col = g.bits.data() + (static_cast<std::size_t>(counts.r0) * g.nx + c) * g.words;
    int count = 0;
    for (int v = 0; v < g.depth_bits; ++v) {
      count += d[v];
      if (count != 0) col[v >> 6] |= std::uint64_t{1} << (v & 63);
    }
  }
}

// Rasterises band b's triangles of one fill kind (Buckets; 0: parity, 1: spans, 2: prisms, counted
// and then turned into voxels), listing the fans' fragments in `hits`. Returns fragments.
template <bool kPerspective>
std::size_t raster_band(VoxelGrid& g, const Bands& bands, int b, int fill_kind, const std::vector<std::vector<GridTri>>& tris,
                        const std::vector<Buckets>& buckets, float slab_thickness, std::vector<ColumnHit>& hits) {
  const int r0 = bands.first_row(b), r1 = bands.first_row(b + 1) - 1;
  const std::size_t k = static_cast<std::size_t>(fill_kind) * bands.count + b;
  bool any = false;
  for (std::size_t c = 0; c < buckets.size() && !any; ++c) any = buckets[c].start[k] < buckets[c].start[k + 1];
  if (!any) return 0;
  PrismCounts counts;
  if (fill_kind == 2) {
    const std::size_t columns = static_cast<std::size_t>(r1 - r0 + 1) * g.nx;
    counts = {r0, g.nx, g.depth_bits, std::unique_ptr<std::int16_t[]>(new std::int16_t[columns * g.depth_bits]), std::vector<std::uint8_t>(columns, 0)};
  }
  std::size_t f = 0;
  for (std::size_t c = 0; c < buckets.size(); ++c) {
    const std::uint32_t q0 = buckets[c].start[k], q1 = buckets[c].start[k + 1];
    if (q0 < q1)
      f += simd::rasterise_triangles(tris[c].data(), buckets[c].index.data() + q0, q1 - q0, kPerspective, r0, r1, g, slab_thickness, hits,
                                     fill_kind == 2 ? &counts : nullptr);
  }
  unite_prisms(g, counts);
  return f;
}

// The winding numbers of the slots of solids with holes (SlotWinding) of a plan.
SlotWinding slot_winding(const Scene& scene, std::span<const MeshClosure> closure, const ObjectPlan& plan) {
  SlotWinding s;
  for (std::size_t oi : plan.slot_object) {
    const std::size_t mi = plan.objects[oi].mesh;
    s.space.push_back(object_space(scene, plan.objects[oi]));
    s.sign.push_back(closure[mi].orientation * s.space.back().sign);
    s.fans.push_back(fan_winding(scene.meshes[mi], closure[mi], plan.holes[mi]));
  }
  return s;
}

VoxelStats grid_stats(const std::vector<std::vector<GridTri>>& tris, std::span<const std::size_t> fragments, std::span<const MeshClosure> closure) {
  VoxelStats s;
  for (const auto& chunk : tris) s.triangles += chunk.size();
  for (std::size_t f : fragments) s.fragments += f;
  for (const MeshClosure& c : closure) {
    s.open_meshes += c.open_surface() ? 1 : 0;
    s.holed_meshes += c.holed() ? 1 : 0;
    s.holes += c.holed() ? c.holes : 0;
    s.boundary_edges += c.boundary_edges;
  }
  return s;
}

// The rooms among the objects voxelized by parity (VoxelizeOptions::rooms).
std::size_t rooms_by_parity(const VoxelizeOptions& o, std::span<const Treat> treat) {
  if (o.open_meshes == OpenMeshes::Parity) return 0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < std::min(o.rooms.size(), treat.size()); ++k) n += o.rooms[k] && treat[k] == Treat::Parity ? 1 : 0;
  return n;
}

// Complements every column's depth_bits voxels (the bits past them stay clear).
void complement_columns(VoxelGrid& g) {
  const std::size_t columns = static_cast<std::size_t>(g.nx) * g.ny;
  const int tail = g.depth_bits % 64;
  const std::uint64_t last = tail ? (std::uint64_t{1} << tail) - 1 : ~std::uint64_t{0};
  tbb::parallel_for(std::size_t{0}, columns, [&](std::size_t c) {
    std::uint64_t* col = &g.bits[c * static_cast<std::size_t>(g.words)];
    for (int w = 0; w < g.words; ++w) col[w] = ~col[w] & (w == g.words - 1 ? last : ~std::uint64_t{0});
  });
}

// Stages 1-4 for any grid whose geometry fields are set; `voxel` is the largest extent of a voxel
// (world units), `emit` maps one Tri3 into a vector, `voxel_centre(i, j, k)` gives the world point
// of a voxel's centre.
template <bool kPerspective, class Emit, class Centre>
void voxelize_into(VoxelGrid& g, const Scene& scene, std::span<const MeshClosure> closure, const VoxelizeOptions& o, const Treatments& treatment,
                   float slab_thickness, float voxel, Emit&& emit, Centre&& voxel_centre, VoxelStats* stats) {
  const std::span<const Treat> treat = treatment.of;
  g.depth_bits = o.depth_bits;
  g.words = (o.depth_bits + 63) / 64;
  g.bits.assign(static_cast<std::size_t>(g.nx) * g.ny * g.words, 0);

  // 1. Map triangles to the grid, chunk by chunk (chunk boundaries are fixed: deterministic),
  // and bucket each chunk's triangles by (fill kind, row band) so that a band visits only the
  // triangles overlapping it.
  const Bands bands = make_bands(g.ny);
  const ObjectPlan plan = plan_objects(scene, closure, treat, voxel);
  ColumnAxis axis;
  if constexpr (kPerspective) axis = {&g.camera.eye, g.camera.basis().to_world({0.0f, 0.0f, -1.0f})};
  const std::size_t total = plan.first.back();
  const std::size_t chunks = (total + kChunk - 1) / kChunk;
  std::vector<std::vector<GridTri>> tris(chunks);
  std::vector<Buckets> buckets(chunks);
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
    const std::size_t t0 = c * kChunk, t1 = std::min(total, t0 + kChunk);
    std::size_t oi = static_cast<std::size_t>(std::upper_bound(plan.first.begin(), plan.first.end(), t0) - plan.first.begin()) - 1;
    auto& out = tris[c];
    out.reserve(t1 - t0);
    for (std::size_t t = t0; t < t1; ++t) {
      while (t >= plan.first[oi + 1]) ++oi;
      Tri3 tri;
      if (object_triangle(scene, closure, plan, treatment, oi, t - plan.first[oi], o.slab_region, slab_thickness, 2.0f * voxel, axis, tri))
        emit(out, tri);
    }
    buckets[c] = bucket(out, bands);
  });

  // 2. Raster bands of rows; parity fragments first, then (after the scan) open-mesh slabs,
  // which are ORed: a union, so overlapping slabs of neighbouring open triangles do not cancel.
  std::vector<std::size_t> fragments(bands.count, 0);
  std::vector<std::vector<ColumnHit>> hits(bands.count);  // fans' fragments (pass 0)
  const auto raster_pass = [&](int fill_kind) {
    tbb::parallel_for(0, bands.count, [&](int b) { fragments[b] += raster_band<kPerspective>(g, bands, b, fill_kind, tris, buckets, slab_thickness, hits[b]); });
  };
  raster_pass(0);

  // 3. Toggles -> solid, then the winding-number solid near holes that are not flat.
  const std::size_t odd = scan_columns(g);
  const WalkCount walked = plan.slot_object.empty() ? WalkCount{} : winding_solid(g, hits, slot_winding(scene, closure, plan), voxel_centre);

  // A closed mesh around the camera (a room) encloses air: its solid is the complement of its
  // parity (but for open_meshes=parity, the paper's voxelization of everything as it is). The
  // world grid's columns start outside every mesh, so with an odd number of rooms the whole grid
  // is complemented (objects inside the room stay solid: they toggle back). An eye grid's columns
  // start at the camera, inside the room, where parity is already right.
  if constexpr (!kPerspective) {
    if (rooms_by_parity(o, treat) % 2) complement_columns(g);
  }

  // 4. Slabs of open meshes, ORed after the parity; walls' prisms as the union of the prisms: per
  // column, the voxels where the count of prisms entered minus left is not 0 (prisms overlap
  // where walls meet, and parity would cancel them there).
  if (any_slab(treat)) {
    raster_pass(1);
    raster_pass(2);
  }
  const std::size_t set_voxels = build_coarse(g);  // also counts the solid voxels
  if (stats) {
    *stats = grid_stats(tris, fragments, closure);
    stats->odd_columns = odd;
    stats->set_voxels = set_voxels;
    stats->capped_meshes = plan.fanned;
    stats->back_objects = treatment.back;
    stats->winding_evaluations = walked.evaluated;
    stats->winding_voxels_changed = walked.changed;
  }
}

}  // namespace


void VoxelizeOptions::validate() const {
  if (columns < 8 || columns > 4096) throw InputError("cone: columns must be in [8, 4096], got " + std::to_string(columns));
  if (depth_bits < 32 || depth_bits > 1024 || depth_bits % 32 != 0)
    throw InputError("cone: depth_bits must be a multiple of 32 in [32, 1024], got " + std::to_string(depth_bits));
  if (!(slab_thickness >= 0.0f) || !std::isfinite(slab_thickness))
    throw InputError("cone: slab thickness must be a finite number >= 0, got " + std::to_string(slab_thickness));
}

// How far above a boundary between voxels world_grid_layout puts the ground, in voxels: far above
// the rounding of a point's voxel coordinate (1e-5 of a voxel for grids of a few hundred voxels),
// far below what a cone resolves.
constexpr float kGroundLift = 0.01f;

// The height of the scene's ground: the y shared by the three corners of the most area of triangles
// facing up (world space; of equal areas the highest), `lowest` when no such triangle faces up.
float ground_height(const Scene& scene, float lowest) {
  std::map<float, double> area;
  for (const SceneObject& ob : scene.objects()) {
    const Mesh& m = scene.meshes[ob.mesh];
    const Affine3* tf = ob.instance == SceneObject::kNoInstance ? nullptr : &scene.instances[ob.instance].object_to_world;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      Vec3 v[3] = {m.positions[m.indices[3 * t]], m.positions[m.indices[3 * t + 1]], m.positions[m.indices[3 * t + 2]]};
      if (tf)
        for (Vec3& p : v) p = tf->point(p);
      const Vec3 n = cross(v[1] - v[0], v[2] - v[0]);
      if (v[0].y == v[1].y && v[1].y == v[2].y && n.y > 0) area[v[0].y] += 0.5 * static_cast<double>(n.y);
    }
  }
  float best = lowest;
  double most = 0;
  for (const auto& [y, a] : area)  // ascending y
    if (a >= most) most = a, best = y;
  return best;
}

VoxelGrid world_grid_layout(const Scene& scene, const VoxelizeOptions& o, bool slab_beside, bool slab_above, float* slab_out) {
  VoxelGrid g;
  g.space = GridSpace::World;
  g.nx = g.ny = o.columns;
  g.depth_bits = o.depth_bits;
  g.words = (o.depth_bits + 63) / 64;
  const Bounds3 b = scene.bounds();
  if (b.empty()) throw InputError(scene.name + ": cannot voxelize an empty scene");
  // A flat scene has no height: give every axis at least 1e-4 of the diagonal so voxels have size.
  const float floor_extent = std::max(1e-4f * b.diagonal(), 1e-6f);
  const Vec3 e = max(b.extent(), Vec3{floor_extent, floor_extent, floor_extent});
  const float v0 = std::max({e.x / o.columns, e.z / o.columns, e.y / o.depth_bits});
  const float slab = o.slab_thickness > 0 ? o.slab_thickness : 2.0f * v0;
  if (slab_out) *slab_out = slab;
  // One voxel of margin on every side, and room for the slabs of open meshes below and beside
  // (a ground plane's slab hangs below it, a wall's prism stands behind it), and above when a
  // slab rises from a face (a roof seen from below, a ceiling seen from the room). A room (a
  // closed mesh around the camera) is solid outside: a slab's thickness of it all around, so that
  // a cone near its walls meets as much solid as behind an open wall.
  const float side = (slab_beside ? slab : 0.0f) + v0;
  const float top = (slab_above ? slab : 0.0f) + v0;
  // The scene's ground (the height of its largest horizontal area, else its lowest point) on a
  // boundary between voxels: a voxel is solid when its centre is, so a horizontal surface there is
  // resolved exactly rather than standing up to half a voxel into the air or sinking as far into
  // its solid (the grazing cones of every point on it saw that: a ground 4% too dark where its
  // voxels are 8% of R_max tall, or as much too bright). On a boundary between the coarse
  // occupancy's cells too (cell_bits voxels, build_coarse), so that the cells over the ground stay
  // empty, and a hundredth of a voxel below it (kGroundLift), so that a sphere that touches the
  // ground from above (the lowest cones' last spheres) reaches into no cell of it and is skipped: on
  // the boundary itself every such sphere was traced (16% more trace time on the default scene, for
  // nothing: its prisms meet no solid). One cell more height pays for the shift, so the top keeps
  // its margin.
  int cell = 1;
  while (cell * 64 < o.depth_bits) cell *= 2;
  const float vz = (e.y + side + top) / static_cast<float>(o.depth_bits - cell);
  const float step = vz * static_cast<float>(cell);
  const float ground = ground_height(scene, b.lo.y);
  // The origin a whole number of cells (and a hundredth of a voxel: kGroundLift) below the ground
  // and at least `side` below the bounds.
  const float below = (b.lo.y - ground) + std::ceil((ground - b.lo.y + side) / step) * step + kGroundLift * vz;
  g.origin = b.lo - Vec3{side, below, side};
  g.voxel_size = {(e.x + 2 * side) / o.columns, (e.z + 2 * side) / o.columns, vz};
  return g;
}

VoxelGrid voxelize_world(const Scene& scene, std::span<const MeshClosure> closure, const VoxelizeOptions& o, VoxelStats* stats,
                         std::span<const std::uint8_t> back) {
  o.validate();
  const Treatments treat = treatments(scene, closure, o.open_meshes, back);
  const bool room = rooms_by_parity(o, treat.of) > 0;
  float slab = 0;
  VoxelGrid g = world_grid_layout(scene, o, any_slab(treat.of) || room, slab_rises(scene, treat.of) || room, &slab);
  const Vec3 lo = g.origin;
  const WorldMap map{lo, {1.0f / g.voxel_size.x, 1.0f / g.voxel_size.y, 1.0f / g.voxel_size.z}, slab};
  const Vec3 origin = g.origin, size = g.voxel_size;
  voxelize_into<false>(
      g, scene, closure, o, treat, slab, std::max({g.voxel_size.x, g.voxel_size.y, g.voxel_size.z}), [&](std::vector<GridTri>& out, const Tri3& t) { emit_world(out, t, map, g.nx, g.ny); },
      [origin, size](int i, int j, int k) {
        return Vec3{origin.x + (static_cast<float>(i) + 0.5f) * size.x, origin.y + (static_cast<float>(k) + 0.5f) * size.z,
                    origin.z + (static_cast<float>(j) + 0.5f) * size.y};
      },
      stats);
  return g;
}

namespace {

// z_nearest per column of an eye grid whose camera, columns and z_far are set: the smallest
// G-buffer depth among the pixels whose centres it holds (eq. 2's local slice); columns that see no
// surface use `zmin`, the scene's nearest corner. Then the voxels per unit depth of each column.
void set_z_near(VoxelGrid& g, const GBuffer& gb, float zmin, float z_clip, int depth_bits) {
  const std::size_t ncol = static_cast<std::size_t>(g.nx) * g.ny;
  g.z_near.assign(ncol, kInfinity);
  for (int y = 0; y < g.camera.height; ++y) {
    const int j = std::min(g.ny - 1, static_cast<int>((y + 0.5f) / g.pixels_per_column_y));
    for (int x = 0; x < g.camera.width; ++x) {
      if (!gb.covered(x, y)) continue;
      const int i = std::min(g.nx - 1, static_cast<int>((x + 0.5f) / g.pixels_per_column_x));
      float& zn = g.z_near[static_cast<std::size_t>(j) * g.nx + i];
      zn = std::min(zn, gb.depth(x, y));
    }
  }
  g.voxels_per_unit.resize(ncol);
  for (std::size_t c = 0; c < ncol; ++c) {
    float& zn = g.z_near[c];
    if (!std::isfinite(zn)) zn = zmin;
    zn = std::clamp(zn, z_clip, g.z_far * 0.999f);
    g.voxels_per_unit[c] = static_cast<float>(depth_bits) / (g.z_far - zn);
  }
}

}  // namespace

VoxelGrid voxelize_eye(const Scene& scene, std::span<const MeshClosure> closure, const GBuffer& gb, const VoxelizeOptions& o, VoxelStats* stats,
                       std::span<const std::uint8_t> back) {
  o.validate();
  const Treatments treat = treatments(scene, closure, o.open_meshes, back);
  VoxelGrid g;
  g.space = GridSpace::Eye;
  const Camera& cam = gb.camera;
  const int W = cam.width, H = cam.height;
  if (W >= H) {
    g.nx = o.columns;
    g.ny = std::max(1, static_cast<int>(std::lround(static_cast<double>(o.columns) * H / W)));
  } else {
    g.ny = o.columns;
    g.nx = std::max(1, static_cast<int>(std::lround(static_cast<double>(o.columns) * W / H)));
  }
  g.camera = cam;
  g.pixels_per_column_x = static_cast<float>(W) / g.nx;
  g.pixels_per_column_y = static_cast<float>(H) / g.ny;

  const Bounds3 b = scene.bounds();
  if (b.empty()) throw InputError(scene.name + ": cannot voxelize an empty scene");
  const Frame basis = cam.basis();
  float zmin = kInfinity, zmax = 0;
  for (int c = 0; c < 8; ++c) {
    const Vec3 p{c & 1 ? b.hi.x : b.lo.x, c & 2 ? b.hi.y : b.lo.y, c & 4 ? b.hi.z : b.lo.z};
    const float d = -basis.to_local(p - cam.eye).z;
    zmin = std::min(zmin, d);
    zmax = std::max(zmax, d);
  }
  const float diag = b.diagonal();
  // Near clipping plane: 1e-4 of the scene diagonal in front of the eye, far enough from 0 for
  // 1/depth to stay finite, close enough that only geometry touching the eye is lost.
  const float z_clip = std::max(1e-4f * diag, 1e-6f);
  zmin = std::max(zmin, z_clip);
  // The slab extends behind the far corner too, and by one voxel so the last fragment fits.
  const float column_at_far = 2.0f * cam.tan_half_fov() * std::max(zmax, z_clip) / g.ny;
  const float v0 = std::max(column_at_far, (zmax - zmin) / o.depth_bits);
  const float slab = o.slab_thickness > 0 ? o.slab_thickness : 2.0f * v0;
  g.z_far = std::max(zmax + slab + v0, zmin * 2.0f);

  set_z_near(g, gb, zmin, z_clip, o.depth_bits);

  // Camera-space (x, y, depth) -> column: camera.project divided by the pixels per column.
  const float t = cam.tan_half_fov();
  EyeMap map;
  map.basis = basis;
  map.eye = cam.eye;
  map.sx = 0.5f * W / (t * cam.aspect()) / g.pixels_per_column_x;
  map.ox = 0.5f * W / g.pixels_per_column_x;
  map.sy = -0.5f * H / t / g.pixels_per_column_y;
  map.oy = 0.5f * H / g.pixels_per_column_y;
  map.z_clip = z_clip;
  map.slab = slab;
  // The inverse of eq. 2 and of the projection: column (i, j)'s centre is the view ray through
  // ((i + 0.5 - ox) / sx, (j + 0.5 - oy) / sy) per unit depth, voxel k at depth z_near + (k + 0.5) / vpu.
  const auto centre = [&g, &map](int i, int j, int k) {
    const std::size_t c = static_cast<std::size_t>(j) * g.nx + i;
    const float depth = g.z_near[c] + (static_cast<float>(k) + 0.5f) / g.voxels_per_unit[c];
    const Vec3 local{(static_cast<float>(i) + 0.5f - map.ox) / map.sx * depth, (static_cast<float>(j) + 0.5f - map.oy) / map.sy * depth, -depth};
    return map.eye + map.basis.to_world(local);
  };
  voxelize_into<true>(
      g, scene, closure, o, treat, slab, v0, [&](std::vector<GridTri>& out, const Tri3& tri) { emit_eye(out, tri, map, g.nx, g.ny); }, centre, stats);
  return g;
}

}  // namespace ao
