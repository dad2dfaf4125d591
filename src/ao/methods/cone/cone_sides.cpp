// SPDX-License-Identifier: Apache-2.0
// Which side of each open mesh a pixel's point lies on (cone_sides_internal.h).
#include "ao/methods/cone/cone_sides_internal.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>

#include <tbb/parallel_for.h>

#include "ao/core/affine.h"
#include "ao/methods/cone/winding_number.h"

namespace ao::cone_internal {

namespace {

// Within this much of the threshold of w the hierarchy cannot tell the side (its truncation error
// is 0.005 at worst on the test meshes, winding_number_test.cpp). For a sheet that is where a
// point sees as much of its fronts as of its backs (beside the foot of an arch standing on the
// ground: the arch's near wall from outside, its far wall from inside behind it), and the side of
// the part of the sheet nearest to the point decides. Inside a solid with holes (w near 1/2 in
// the mouth of a hole) the point is taken as outside.
constexpr double kUndecided = 0.01;
// Lattice (SideSetup::Open::lattice): points R_max / 2 apart (farther apart for a lattice of more
// than 2^15 points); corners whose w is within 0.05 of the threshold leave the decision to the
// point itself.
constexpr double kLatticePoints = 32768;
constexpr float kLatticeMargin = 0.05f;
// Rims (beyond_rim): a point is beyond a sheet's rim when it lies out across the rim by more than
// kRimRatio times its height off the rim triangle's plane. Rim cells are at least R_max wide and
// at most kRimCells along the longest side of the sheet's reach.
constexpr float kRimRatio = 0.5f;
constexpr float kRimCells = 64.0f;

Bounds3 object_bounds(const Scene& scene, const SceneObject& ob) {
  const Bounds3 b = scene.meshes[ob.mesh].bounds();
  return ob.instance == SceneObject::kNoInstance ? b : transform_bounds(scene.instances[ob.instance].object_to_world, b);
}

bool overlap(const Bounds3& a, const Bounds3& b) {
  return !(a.hi.x < b.lo.x || b.hi.x < a.lo.x || a.hi.y < b.lo.y || b.hi.y < a.lo.y || a.hi.z < b.lo.z || b.hi.z < a.lo.z);
}

bool contains(const Bounds3& b, Vec3 p) {
  return p.x >= b.lo.x && p.x <= b.hi.x && p.y >= b.lo.y && p.y <= b.hi.y && p.z >= b.lo.z && p.z <= b.hi.z;
}

// The side of the nearest triangle of sheet `o` (0 in its plane).
int nearest_side(const SideSetup::Open& o, Vec3 world, std::size_t& evaluations) {
  ++evaluations;
  const double d = o.sign * o.closure->winding.get().signed_distance(o.instanced ? o.to_object.point(world) : world);
  return d > 0 ? 1 : d < 0 ? -1 : 0;
}

// +1 behind open object `o` (sign x w > threshold), -1 in front, 0 on it. Counts evaluations of w.
int side_of(const SideSetup::Open& o, Vec3 world, std::size_t& evaluations) {
  const Vec3 p = o.instanced ? o.to_object.point(world) : world;
  const MeshClosure& c = *o.closure;
  if (c.flat) {
    // A flat sheet's w has the sign of -(n.p + d) (voxelize.h, MeshClosure::plane).
    const double d = double(c.plane[0]) * p.x + double(c.plane[1]) * p.y + double(c.plane[2]) * p.z + c.plane[3];
    return d == 0 ? 0 : (o.sign * -d > 0 ? 1 : -1);
  }
  ++evaluations;
  const double v = o.sign * c.winding.get()(p) - o.threshold;
  if (std::abs(v) >= kUndecided) return v > 0 ? 1 : -1;
  return c.holed() ? -1 : nearest_side(o, world, evaluations);
}

// sign x w - threshold at the eight corners of p's lattice cell (the cell clamped to the lattice);
// `o.lattice` must not be empty.
std::array<float, 8> lattice_corners(const SideSetup::Open& o, Vec3 p) {
  const Vec3 f = (p - o.lattice_lo) / o.lattice_step;
  const int x = std::clamp(static_cast<int>(f.x), 0, o.lx - 2), y = std::clamp(static_cast<int>(f.y), 0, o.ly - 2),
            z = std::clamp(static_cast<int>(f.z), 0, o.lz - 2);
  std::array<float, 8> v;
  for (int k = 0; k < 8; ++k) {
    const std::size_t row = static_cast<std::size_t>(z + (k >> 2)) * static_cast<std::size_t>(o.ly) + static_cast<std::size_t>(y + ((k >> 1) & 1));
    v[static_cast<std::size_t>(k)] = o.lattice[row * static_cast<std::size_t>(o.lx) + static_cast<std::size_t>(x + (k & 1))];
  }
  return v;
}

// The side of `o` that its lattice gives for p: +1 / -1 when the corners of p's cell agree, else 0;
// `crossed` when they do not agree but all lie at least 0.25 from the threshold: the mesh itself
// passes through the cell, not the surface beyond its rim where w meets the threshold smoothly.
int lattice_side(const SideSetup::Open& o, Vec3 p, bool& crossed) {
  crossed = false;
  if (o.lattice.empty()) return 0;
  int behind = 0, front = 0, strong = 0;
  for (const float v : lattice_corners(o, p)) {
    behind += v >= kLatticeMargin, front += v <= -kLatticeMargin, strong += std::abs(v) >= 0.25f;
  }
  crossed = strong == 8;
  return behind == 8 ? 1 : front == 8 ? -1 : 0;
}

// The largest of sign x w - threshold at the corners of p's lattice cell (+infinity without a lattice).
float lattice_max(const SideSetup::Open& o, Vec3 p) {
  if (o.lattice.empty()) return std::numeric_limits<float>::infinity();
  const std::array<float, 8> v = lattice_corners(o, p);
  return *std::max_element(v.begin(), v.end());
}

// How far along its normal a surface point must go to be clear of its own surface's voxels: 1.5
// voxels, as the kernel's near limit (cone.cpp, cone_world.cpp).
float clearance(const VoxelGrid& g, Vec3 p) {
  if (g.space == GridSpace::World) return 1.5f * std::max({g.voxel_size.x, g.voxel_size.y, g.voxel_size.z});
  const Vec3 c = g.camera.world_to_camera_point(p);
  const float depth = -c.z;
  if (!(depth > 0)) return 0.0f;  // not in front of the camera: not a pixel's point
  const Vec2 pix = g.camera.project(c);
  const int i = std::clamp(static_cast<int>(pix.x / g.pixels_per_column_x), 0, g.nx - 1);
  const int j = std::clamp(static_cast<int>(pix.y / g.pixels_per_column_y), 0, g.ny - 1);
  const float width = 2.0f * g.camera.tan_half_fov() * depth / static_cast<float>(g.ny);
  return 1.5f * std::max(1.0f / g.voxels_per_unit[static_cast<std::size_t>(j) * g.nx + i], width);
}

// The voxel of `g` at world point p (false outside the grid).
bool solid_at(const VoxelGrid& g, Vec3 p) {
  float fx, fy, fk;
  std::size_t col;
  if (g.space == GridSpace::World) {
    fx = (p.x - g.origin.x) / g.voxel_size.x, fy = (p.z - g.origin.z) / g.voxel_size.y, fk = (p.y - g.origin.y) / g.voxel_size.z;
    if (!(fx >= 0.0f && fy >= 0.0f && fx < float(g.nx) && fy < float(g.ny))) return false;
    col = static_cast<std::size_t>(fy) * g.nx + static_cast<std::size_t>(fx);
  } else {
    const Vec3 c = g.camera.world_to_camera_point(p);
    const float depth = -c.z;
    if (!(depth > 0)) return false;
    const Vec2 pix = g.camera.project(c);
    fx = pix.x / g.pixels_per_column_x, fy = pix.y / g.pixels_per_column_y;
    if (!(fx >= 0.0f && fy >= 0.0f && fx < float(g.nx) && fy < float(g.ny))) return false;
    col = static_cast<std::size_t>(fy) * g.nx + static_cast<std::size_t>(fx);
    fk = (depth - g.z_near[col]) * g.voxels_per_unit[col];
  }
  if (!(fk >= 0.0f && fk < float(g.depth_bits))) return false;
  const int k = static_cast<int>(fk);
  return (g.bits[col * g.words + (k >> 6)] >> (k & 63)) & 1u;
}

// The rim cell holding coordinate v along an axis whose cells start at lo (n of them), clamped.
int rim_cell(const SideSetup::Open& o, float v, float lo, int n) { return std::clamp(static_cast<int>((v - lo) / o.rim_cell), 0, n - 1); }

// The free rims of sheet `o` (MeshClosure::free_rim, in world space: SideSetup::Open::rims) and
// their cells.
void add_rims(SideSetup::Open& o, const Mesh& m, const MeshClosure& c, const Affine3* tf, float r_max) {
  for (std::size_t e = 0; e < c.boundary.size(); ++e) {
    if (!c.free_rim[e]) continue;
    Vec3 v[3] = {m.positions[c.boundary[e][0]], m.positions[c.boundary[e][1]], m.positions[rim_apex(m, c, e)]};
    if (tf)
      for (Vec3& vk : v) vk = tf->point(vk);
    Vec3 out, n;
    if (rim_frame(v[0], v[1], v[2], out, n)) o.rims.push_back({v[0], v[1], out, n});
  }
  if (o.rims.empty()) return;
  const Vec3 e = o.reach.extent();
  o.rim_lo = o.reach.lo;
  o.rim_cell = std::max(r_max, std::max({e.x, e.y, e.z}) / kRimCells);
  o.rx = std::max(1, static_cast<int>(std::ceil(e.x / o.rim_cell)));
  o.ry = std::max(1, static_cast<int>(std::ceil(e.y / o.rim_cell)));
  o.rz = std::max(1, static_cast<int>(std::ceil(e.z / o.rim_cell)));
  // Two passes over each rim's box of cells: count, then list.
  o.rim_start.assign(static_cast<std::size_t>(o.rx) * o.ry * o.rz + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<std::uint32_t> fill;
    if (pass == 1) {
      for (std::size_t k = 1; k < o.rim_start.size(); ++k) o.rim_start[k] += o.rim_start[k - 1];
      o.rim_list.resize(o.rim_start.back());
      fill.assign(o.rim_start.begin(), o.rim_start.end() - 1);
    }
    for (std::uint32_t r = 0; r < o.rims.size(); ++r) {
      const Vec3 lo = min(o.rims[r].a, o.rims[r].b), hi = max(o.rims[r].a, o.rims[r].b);
      for (int z = rim_cell(o, lo.z, o.rim_lo.z, o.rz); z <= rim_cell(o, hi.z, o.rim_lo.z, o.rz); ++z)
        for (int y = rim_cell(o, lo.y, o.rim_lo.y, o.ry); y <= rim_cell(o, hi.y, o.rim_lo.y, o.ry); ++y)
          for (int x = rim_cell(o, lo.x, o.rim_lo.x, o.rx); x <= rim_cell(o, hi.x, o.rim_lo.x, o.rx); ++x) {
            const std::size_t at = (static_cast<std::size_t>(z) * o.ry + y) * o.rx + x;
            if (pass == 0) ++o.rim_start[at + 1];
            else o.rim_list[fill[at]++] = r;
          }
    }
  }
}

// Whether point p lies beyond a free rim of sheet `o`: out across its nearest rim within R_max by
// more than kRimRatio times its height off that rim triangle's plane. Behind a straight rim, the
// slab voxel at depth d under a face s in from the rim is hidden from a point x out and h off the
// plane only while d <= s h / x: a slab R_max deep shows over the rim as a wall the reference does
// not have (the ground in front of a mask's chin, beside a leaf lying on the ground), and what
// the point does not see of the sheet's hidden side lies behind a sheet it sees edge-on.
bool beyond_rim(const SideSetup::Open& o, Vec3 p, float r_max) {
  if (o.rims.empty() || !contains(o.reach, p)) return false;
  const int cx = rim_cell(o, p.x, o.rim_lo.x, o.rx), cy = rim_cell(o, p.y, o.rim_lo.y, o.ry), cz = rim_cell(o, p.z, o.rim_lo.z, o.rz);
  float best = r_max * r_max;
  const SideSetup::Open::Rim* nearest = nullptr;
  Vec3 at{};
  for (int z = std::max(0, cz - 1); z <= std::min(o.rz - 1, cz + 1); ++z)
    for (int y = std::max(0, cy - 1); y <= std::min(o.ry - 1, cy + 1); ++y)
      for (int x = std::max(0, cx - 1); x <= std::min(o.rx - 1, cx + 1); ++x) {
        const std::size_t c = (static_cast<std::size_t>(z) * o.ry + y) * o.rx + x;
        for (std::uint32_t k = o.rim_start[c]; k < o.rim_start[c + 1]; ++k) {
          const SideSetup::Open::Rim& r = o.rims[o.rim_list[k]];
          const Vec3 e = r.b - r.a;
          const Vec3 q = r.a + e * std::clamp(dot(p - r.a, e) / dot(e, e), 0.0f, 1.0f);
          const float d2 = dot(p - q, p - q);
          if (d2 < best) best = d2, nearest = &r, at = q;
        }
      }
  return nearest && dot(p - at, nearest->out) > kRimRatio * std::abs(dot(p - at, nearest->normal));
}

// Open object `oi` of the scene (not closed): where it is, how to test a point, its triangles'
// world normals, a sheet's free rims.
SideSetup::Open open_object(const Scene& scene, const SceneObject& ob, std::uint32_t oi, const MeshClosure& c, const Bounds3& bounds, float r_max) {
  SideSetup::Open o;
  o.object = oi;
  o.closure = &c;
  int det_sign = 1;
  const Affine3* tf = ob.instance == SceneObject::kNoInstance ? nullptr : &scene.instances[ob.instance].object_to_world;
  if (tf) {
    o.instanced = true;
    o.to_object = inverse(*tf);
    det_sign = tf->determinant() < 0 ? -1 : 1;  // a mirror turns fronts into backs
  }
  // A sheet's slab reaches R_max past it, and a point's cones R_max further: only points within
  // 2 R_max of it can tell its sides apart. A solid with holes is entered only inside its box
  // (grown by 1% of R_max: a ground it stands on lies on its box's face, and the G-buffer's points
  // of it a rounding error either side).
  const float pad = c.open_surface() ? 2.0f * r_max : 0.01f * r_max;
  o.reach = bounds;
  o.reach.lo -= Vec3{pad, pad, pad};
  o.reach.hi += Vec3{pad, pad, pad};
  o.sign = det_sign * (c.holed() ? c.orientation : 1);
  o.threshold = c.holed() ? 0.5 : 0.0;
  const Mesh& m = scene.meshes[ob.mesh];
  o.face.resize(m.triangle_count());
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    Vec3 v[3] = {m.positions[m.indices[3 * t]], m.positions[m.indices[3 * t + 1]], m.positions[m.indices[3 * t + 2]]};
    if (tf)
      for (Vec3& vk : v) vk = tf->point(vk);
    o.face[t] = cross(v[1] - v[0], v[2] - v[0]);
  }
  if (c.open_surface()) add_rims(o, m, c, tf, r_max);
  return o;
}

// How an object with box `b` within reach of open object `o` votes: entirely on one side of a flat
// sheet (its box's corners), that side; any other object is tested per pixel (Mixed: its vertices
// are too sparse a sample, a ground quad has four, none under a sheet that stands on it).
SideSetup::Vote vote_of(const SideSetup::Open& o, const Bounds3& b, std::size_t& evaluations) {
  if (!o.closure->flat) return SideSetup::Mixed;
  int behind = 0, front = 0;
  for (int k = 0; k < 8; ++k) {
    const int side = side_of(o, {k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y, k & 4 ? b.hi.z : b.lo.z}, evaluations);
    behind += side > 0, front += side < 0;
  }
  return behind == 0 ? SideSetup::Front : front == 0 ? SideSetup::Back : SideSetup::Mixed;
}

// The lattice of sign x w - threshold over o's reach (SideSetup::Open::lattice).
void fill_lattice(SideSetup::Open& o, float r_max) {
  const Vec3 e = o.reach.extent();
  const double cells = (double(e.x) / (0.5 * r_max) + 1) * (double(e.y) / (0.5 * r_max) + 1) * (double(e.z) / (0.5 * r_max) + 1);
  o.lattice_step = 0.5f * r_max * static_cast<float>(std::max(1.0, std::cbrt(cells / kLatticePoints)));
  o.lattice_lo = o.reach.lo;
  // At least one cell along each axis (a box flat along one).
  o.lx = std::max(2, static_cast<int>(std::ceil(e.x / o.lattice_step)) + 1);
  o.ly = std::max(2, static_cast<int>(std::ceil(e.y / o.lattice_step)) + 1);
  o.lz = std::max(2, static_cast<int>(std::ceil(e.z / o.lattice_step)) + 1);
  o.lattice.resize(static_cast<std::size_t>(o.lx) * o.ly * o.lz);
  tbb::parallel_for(0, o.lz, [&](int z) {
    for (int y = 0; y < o.ly; ++y)
      for (int x = 0; x < o.lx; ++x) {
        const Vec3 p = o.lattice_lo + Vec3{float(x), float(y), float(z)} * o.lattice_step;
        o.lattice[(static_cast<std::size_t>(z) * o.ly + y) * o.lx + x] =
            static_cast<float>(o.sign * o.closure->winding.get()(o.instanced ? o.to_object.point(p) : p) - o.threshold);
      }
  });
}

// Whether a pixel of open object `o` itself, at p with normal n, sees its back side.
// `camera_behind`: the camera is behind `o` (for a flat sheet); `offset` as in pixel_sides.
bool own_behind(const GBuffer& gb, int x, int y, const SideSetup::Open& o, bool camera_behind, Vec3 p, Vec3 n, float offset, std::size_t& evaluations) {
  // A flat sheet is seen from the camera's side of its plane, at every pixel.
  if (o.closure->flat) return camera_behind;
  if (!gb.primitive_id.empty() && gb.primitive_id(x, y) < o.face.size()) {
    // The side of its own triangle the camera sees (world winding, mirrors included).
    const bool sees_back = dot(o.face[gb.primitive_id(x, y)], n) < 0;
    // A sheet's back is its triangles' back; a solid's inside is its outside's back.
    // (o.sign < 0: the world fronts of the solid face in, mirrors and orientation included.)
    return o.closure->holed() ? sees_back != (o.sign < 0) : sees_back;
  }
  return side_of(o, p + n * offset, evaluations) > 0;
}

// Rays a point casts to tell which side of an open mesh it sees (seen_side): a fixed set over the
// hemisphere about its normal, cosine-distributed (a spherical Fibonacci spiral), so the answer
// depends on the point alone.
constexpr int kSideRays = 24;

// Which side of open mesh `o` the point p (normal n) sees: +1 its back (of the rays that meet it,
// at least twice as many first meet the backs of a sheet's triangles, the inner faces of a solid
// with holes, as the fronts), -1 its front (the other way round), 0 otherwise (no ray meets it, or
// it sees both sides about as much). A dome's w stays below 1/2 on the ground inside it, where the
// point sees nothing but the dome's inside (and the sky through its windows); w > 1/2 fills the
// dome's hollow, where no pixel lies. Beside a sheet's rim, where w is near 0, the side it sees.
int seen_side(const SideSetup::Open& o, Vec3 p, Vec3 n, float offset, std::size_t& evaluations) {
  static const std::array<Vec3, kSideRays> pattern = [] {
    std::array<Vec3, kSideRays> d{};
    const float golden = 2.39996323f;  // pi (3 - sqrt 5)
    for (int k = 0; k < kSideRays; ++k) {
      const float u = (static_cast<float>(k) + 0.5f) / kSideRays, z = std::sqrt(1.0f - u), r = std::sqrt(u);
      d[static_cast<std::size_t>(k)] = {r * std::cos(golden * static_cast<float>(k)), r * std::sin(golden * static_cast<float>(k)), z};
    }
    return d;
  }();
  ++evaluations;
  const Frame f = Frame::from_normal(n);
  const Vec3 origin = p + n * offset;
  const Vec3 q = o.instanced ? o.to_object.point(origin) : origin;
  const WindingNumber& w = o.closure->winding.get();
  int inner = 0, outer = 0;
  for (const Vec3& local : pattern) {
    const Vec3 d = f.to_world(local);
    const WindingNumber::Hit h = w.first_hit(q, o.instanced ? o.to_object.vector(d) : d, 0.0f, std::numeric_limits<float>::max());
    // o.sign: the world fronts face out of the solid (+1) or into it (-1).
    inner += h.side * o.sign > 0, outer += h.side * o.sign < 0;
  }
  return inner > 2 * outer ? 1 : outer > 2 * inner ? -1 : 0;
}

// Whether a point p (normal n) of another object lies behind open object `o`, on which its object
// votes `vote`.
bool voted_behind(const SideSetup& setup, const SideSetup::Open& o, SideSetup::Vote vote, const VoxelGrid& front, Vec3 p, Vec3 n,
                  std::size_t& evaluations) {
  if (vote != SideSetup::Mixed || !contains(o.reach, p)) return vote == SideSetup::Back;
  bool crossed;
  const int side = lattice_side(o, p, crossed);
  if (o.closure->holed()) {
    // Inside a solid with holes is what the point sees of it, not w > 1/2 (seen_side), but where
    // w < 1/4 all around (lattice_side's corners) the point is outside it.
    if (lattice_max(o, p) < -0.25f) return false;
    const int seen = seen_side(o, p, n, setup.r_max * 1e-3f, evaluations);
    if (seen != 0) return seen > 0;
  }
  if (side != 0) return side > 0;
  // Where the lattice cannot tell, the point lies within a cell's diagonal of the mesh or of where
  // w crosses its threshold. With cells R_max / 2 wide that is within 0.87 R_max: inside a solid
  // with holes, or behind a sheet that crosses its cell, its front is solid in the all-front grid
  // (the solid holds its inside; the sheet's slab is R_max thick), so only such points need w.
  // Elsewhere (beside a sheet's rim, under a hole in it) the side of the sheet's nearest triangle
  // decides: the side of the part of it that the point's cones reach, the same whichever way its
  // triangles face.
  const bool pretest = o.lattice_step * 1.7320508f < setup.r_max && (o.closure->holed() || crossed);
  if (pretest && !solid_at(front, p + n * clearance(front, p))) return false;
  if (o.closure->holed()) return side_of(o, p, evaluations) > 0;
  // Beside a sheet's rim or under a hole in it: the side it sees, else its nearest triangle's.
  const int seen = seen_side(o, p, n, setup.r_max * 1e-3f, evaluations);
  return (seen != 0 ? seen : nearest_side(o, p, evaluations)) > 0;
}

// A pixel whose point is behind some open objects or beyond their rims: per such object its index
// into SideSetup::open times 4 plus its flags (kBackSide, kBeyondRim).
struct Flagged {
  std::size_t pixel;
  std::vector<std::uint32_t> back;
};

// Groups the flagged pixels (per row) by their sides: the largest groups get the grids
// (kMaxSideGrids, kMinSidePixels). A pixel of a group without one that lies beyond some rims takes
// the grid of its sides without the rims if there is one (or the all-front grid when it is in front
// of every open object); the others are counted as unresolved.
void group_by_side(const GBuffer& gb, const SideSetup& setup, std::size_t objects, std::vector<std::vector<Flagged>>& rows, PixelSides& out) {
  std::map<std::vector<std::uint32_t>, std::size_t> count;
  for (auto& row : rows)
    for (Flagged& f : row) {
      std::sort(f.back.begin(), f.back.end());
      ++count[f.back];
    }
  std::vector<std::pair<std::size_t, const std::vector<std::uint32_t>*>> by_size;
  for (const auto& [back, n] : count) by_size.push_back({n, &back});
  std::stable_sort(by_size.begin(), by_size.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::size_t covered = 0;
  for (std::size_t i = 0; i < out.key_of.size(); ++i) covered += gb.covered(i) ? 1 : 0;
  const std::size_t least = std::min(kMinSidePixels, covered / 1000);
  std::map<std::vector<std::uint32_t>, std::uint8_t> index;
  for (const auto& [n, back] : by_size) {
    if (static_cast<int>(out.keys.size()) >= kMaxSideGrids || n < least) break;
    std::vector<std::uint8_t> key(objects, 0);
    for (std::uint32_t q : *back) key[setup.open[q >> 2].object] = static_cast<std::uint8_t>(q & 3);
    index.emplace(*back, static_cast<std::uint8_t>(out.keys.size()));
    out.keys.push_back(std::move(key));
  }
  const auto has = [](const std::vector<std::uint32_t>& back, std::uint32_t flag) {
    return std::any_of(back.begin(), back.end(), [flag](std::uint32_t q) { return (q & flag) != 0; });
  };
  for (const auto& row : rows)
    for (const Flagged& f : row) {
      const std::vector<std::uint32_t>* back = &f.back;
      auto it = index.find(*back);
      // A side beyond some rims that got no grid: the grid of its sides alone, with the slabs as
      // they are for points over the sheets, rather than the all-front one (none: all front).
      std::vector<std::uint32_t> sides_only;
      if (it == index.end() && has(*back, kBeyondRim)) {
        for (std::uint32_t q : *back)
          if (q & kBackSide) sides_only.push_back(q & ~std::uint32_t{kBeyondRim});
        back = &sides_only;
        it = index.find(sides_only);
        if (sides_only.empty()) continue;
      }
      if (it == index.end()) {
        ++out.unresolved;
        continue;
      }
      out.key_of[f.pixel] = it->second;
      out.back_pixels += has(*back, kBackSide) ? 1 : 0;
      out.rim_pixels += has(*back, kBeyondRim) ? 1 : 0;
    }
}

}  // namespace

SideSetup make_side_setup(const Scene& scene, std::span<const MeshClosure> closure, float r_max) {
  SideSetup s;
  s.r_max = r_max;
  const std::vector<SceneObject> objects = scene.objects();
  s.votes.resize(objects.size());
  std::vector<Bounds3> bounds;
  for (const SceneObject& ob : objects) bounds.push_back(object_bounds(scene, ob));
  for (std::size_t oi = 0; oi < objects.size(); ++oi) {
    const MeshClosure& c = closure[objects[oi].mesh];
    if (!c.closed()) s.open.push_back(open_object(scene, objects[oi], static_cast<std::uint32_t>(oi), c, bounds[oi], r_max));
  }
  for (std::uint32_t q = 0; q < s.open.size(); ++q)
    for (std::size_t a = 0; a < objects.size(); ++a) {
      if (a == s.open[q].object || !overlap(bounds[a], s.open[q].reach)) continue;
      const SideSetup::Vote vote = vote_of(s.open[q], bounds[a], s.evaluations);
      // A sheet with free rims: a point in front of it may yet lie beyond a rim.
      if (vote != SideSetup::Front || !s.open[q].rims.empty()) s.votes[a].push_back({q, vote});
    }
  // Lattices for the open meshes that some object votes Mixed on.
  std::vector<std::uint8_t> mixed(s.open.size(), 0);
  for (const auto& list : s.votes)
    for (const auto& [q, vote] : list) mixed[q] |= vote == SideSetup::Mixed && !s.open[q].closure->flat;
  for (std::uint32_t q = 0; q < s.open.size(); ++q)
    if (mixed[q]) {
      fill_lattice(s.open[q], r_max);
      s.evaluations += s.open[q].lattice.size();
    }
  return s;
}

PixelSides pixel_sides(const GBuffer& gb, const Scene& scene, const SideSetup& setup, const VoxelGrid& front) {
  PixelSides out;
  const std::vector<SceneObject> objects = scene.objects();
  out.keys.push_back({});
  out.key_of.assign(static_cast<std::size_t>(gb.width()) * gb.height(), 0);
  if (setup.open.empty()) return out;
  std::vector<int> open_of(objects.size(), -1);
  for (std::uint32_t q = 0; q < setup.open.size(); ++q) open_of[setup.open[q].object] = static_cast<int>(q);
  const Frame basis = gb.camera.basis();
  const Vec3 eye = gb.camera.eye;
  // A point just off the surface on the camera's side, to test a pixel of an open object whose
  // triangle is not known (a G-buffer built by hand): 1e-3 R_max, far below any feature the grid
  // resolves and far above the float error of the position.
  const float offset = 1e-3f * setup.r_max;
  std::vector<std::uint8_t> camera_behind(setup.open.size(), 0);
  std::size_t unused = 0;
  for (std::size_t q = 0; q < setup.open.size(); ++q) camera_behind[q] = setup.open[q].closure->flat && side_of(setup.open[q], eye, unused) > 0;
  // Rows in parallel; each pixel's back flags (open objects, in `open` order) go to its row's list.
  std::vector<std::vector<Flagged>> rows(gb.height());
  std::vector<std::size_t> evaluations(gb.height(), 0);
  tbb::parallel_for(0, gb.height(), [&](int y) {
    for (int x = 0; x < gb.width(); ++x) {
      if (!gb.covered(x, y)) continue;
      const std::uint32_t a = gb.object_id(x, y) - 1;
      if (a >= objects.size()) continue;
      const int own = open_of[a];
      if (own < 0 && setup.votes[a].empty()) continue;
      const Vec3 p = basis.to_world(gb.position(x, y)) + eye, n = basis.to_world(gb.normal(x, y));
      std::vector<std::uint32_t> back;
      if (own >= 0 && own_behind(gb, x, y, setup.open[own], camera_behind[own], p, n, offset, evaluations[y]))
        back.push_back(static_cast<std::uint32_t>(own) << 2 | kBackSide);
      for (const auto& [q, vote] : setup.votes[a]) {
        const std::uint32_t flags = (voted_behind(setup, setup.open[q], vote, front, p, n, evaluations[y]) ? kBackSide : 0u) |
                                    (beyond_rim(setup.open[q], p, setup.r_max) ? kBeyondRim : 0u);
        if (flags) back.push_back(q << 2 | flags);
      }
      if (!back.empty()) rows[y].push_back({static_cast<std::size_t>(y) * gb.width() + x, std::move(back)});
    }
  });
  for (std::size_t e : evaluations) out.evaluations += e;
  group_by_side(gb, setup, objects.size(), rows, out);
  return out;
}

Bounds3 side_region(const GBuffer& gb, const PixelSides& sides, std::size_t key, float r_max) {
  Bounds3 b;
  const Frame basis = gb.camera.basis();
  for (std::size_t i = 0; i < sides.key_of.size(); ++i)
    if (sides.key_of[i] == key && gb.covered(i)) b.extend(basis.to_world(gb.position[i]) + gb.camera.eye);
  b.lo -= Vec3{2 * r_max, 2 * r_max, 2 * r_max};
  b.hi += Vec3{2 * r_max, 2 * r_max, 2 * r_max};
  return b;
}

}  // namespace ao::cone_internal
