// SPDX-License-Identifier: Apache-2.0
// Voxel cone traced AO (Dalla Favera & Celes 2012, sec. III-C). See cone.h for the convention
// (we return V = 1 - the paper's blocked fraction) and voxelize.h for the grid.
#include "ao/methods/cone/cone.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>

#include "ao/core/error.h"
#include "ao/core/memory.h"
#include "ao/core/parallel.h"
#include "ao/core/params_table.h"
#include "ao/core/sampling.h"
#include "ao/methods/filters/bilateral.h"
#include "ao/methods/cone/cone_internal.h"
#include "ao/methods/cone/cone_pattern_internal.h"
#include "ao/methods/cone/cone_sides_internal.h"

namespace ao {

namespace {

using cone_internal::kOpaque;
using cone_internal::kTile;
using cone_internal::solid_length;

struct EyeSampler {
  const VoxelGrid& g;
  float sx, sy, ox, oy;  // camera-space (x/depth, y/depth) -> column coordinates
  const ConeSetup::Disk* disk;
  int np;
  std::vector<float> radius;  // world units, per sphere of the chain

  // As the world grid's near_limit (cone_world.cpp), with the voxel of the column the point projects to: its depth
  // 1 / voxels_per_unit and its width at the point's depth.
  float near_limit(Vec3 c) const {
    const float depth = -c.z;
    if (!(depth > 0)) return 0.0f;
    const float fx = c.x / depth * sx + ox, fy = c.y / depth * sy + oy;
    const int i = std::clamp(static_cast<int>(fx), 0, g.nx - 1), j = std::clamp(static_cast<int>(fy), 0, g.ny - 1);
    const float width = depth * std::max(1.0f / std::abs(sx), 1.0f / std::abs(sy));
    return 1.5f * std::max(1.0f / g.voxels_per_unit[static_cast<std::size_t>(j) * g.nx + i], width);
  }

  // centre in camera space; the prisms run along the camera's z (the grid's columns are view rays:
  // over one sphere they are close to parallel, the approximation the paper's texture fetch makes).
  float operator()(Vec3 c, int k, float scale, float rot_c, float rot_s) const {
    const float r = radius[k] * scale;
    float solid = 0, chord = 0;
    const float depth = -c.z;
    if (!(depth > 0)) return 0.0f;
    const float inv = 1.0f / depth;
    for (int s = 0; s < np; ++s) {
      const float u = disk[s].u * rot_c - disk[s].v * rot_s, v = disk[s].u * rot_s + disk[s].v * rot_c;
      const float half = disk[s].half_chord * r;
      chord += 2.0f * half;
      const float fx = (c.x + u * r) * inv * sx + ox, fy = (c.y + v * r) * inv * sy + oy;
      if (!(fx >= 0.0f && fy >= 0.0f && fx < static_cast<float>(g.nx) && fy < static_cast<float>(g.ny))) continue;
      const std::size_t col = static_cast<std::size_t>(static_cast<int>(fy)) * g.nx + static_cast<int>(fx);
      const float zn = g.z_near[col], vpu = g.voxels_per_unit[col];
      // eq. 2 for z_in and z_out; the solid length comes back in world units through 1 / vpu.
      solid += solid_length(g.bits.data() + col * g.words, g.words, g.depth_bits, (depth - half - zn) * vpu, (depth + half - zn) * vpu) / vpu;
    }
    return chord > 0 ? std::min(1.0f, solid / chord) : 0.0f;
  }
};

// Per sphere of a cone: where along the axis it sits (world units), which sphere of the chain it
// is (its prisms' half chords) and the scale of its radius. The chain of sphere k is scaled by the
// cone's s: sphere k at s d_k with radius s r_k, starting at s (d_k - r_k). A scaled chain ends at
// s R_max; the filler sphere, inscribed in [s R_max, R_max] along the axis, samples the rest: its
// radius (1 - s) R_max / 2 is at most the last sphere's (equal at s = 1/q), and it fits in the
// cone for s >= 1/q. `used` is false for spheres that start within near_limit of the apex and for
// a filler of (almost) no size.
struct ChainSphere {
  float distance, scale;
  int k;
  bool used;
};
void chain_spheres(const ConeSetup& setup, float r_max, float near, float chain_scale, ChainSphere* out) {
  const int ns = static_cast<int>(setup.sphere_distance.size());
  for (int k = 0; k < ns; ++k) {
    const float start = (setup.sphere_distance[k] - setup.sphere_radius[k]) * r_max * chain_scale;
    out[k] = {setup.sphere_distance[k] * r_max * chain_scale, chain_scale, k, start >= near};
  }
  const float filler = 0.5f * (1.0f - chain_scale) / setup.sphere_radius.back();  // radius / the last sphere's
  out[ns] = {0.5f * (1.0f + chain_scale) * r_max, std::min(filler, 1.0f), ns - 1, filler > 1e-3f};
}

// Front-to-back along one cone (sec. III-C2, Fig. 8): each sphere absorbs its obstructed fraction
// f of the rays that reach it, T *= 1 - f, until T <= kOpaque.
template <class Fraction>
float transmittance(const ChainSphere* chain, int n, Fraction&& fraction) {
  float t = 1.0f;
  for (int k = 0; k < n && t > kOpaque; ++k) {
    if (!chain[k].used) continue;
    t *= 1.0f - fraction(k);
  }
  return t;
}

// Eye grid: cone by cone, sphere by sphere.
void trace_eye(const GBuffer& gb, const EyeSampler& sample, float r_max, const ConeSetup& setup, const ConePattern& pat, ImageView<float> out,
               const ProgressFn& progress) {
  const int w = gb.width(), h = gb.height();
  const int nc = pat.cones, per_cone = static_cast<int>(setup.sphere_distance.size()) + 1;
  const float weight = 1.0f / static_cast<float>(nc);
  ProgressCounter counter(progress, static_cast<std::size_t>(w) * h);
  parallel_for_tiles(w, h, kTile, [&](const Tile& t) {
    std::vector<ChainSphere> chain(per_cone);
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) {
        if (!gb.covered(x, y)) {
          out(x, y) = 1.0f;
          continue;
        }
        const Vec3 pos = gb.position(x, y), n = gb.normal(x, y);
        const Frame frame = Frame::from_normal(n);
        const float near = sample.near_limit(pos);
        const int slot = pat.slot(x, y);
        const float rot_c = pat.rot[2 * slot], rot_s = pat.rot[2 * slot + 1];
        float v = 0;
        for (int c = 0; c < nc; ++c) {
          const ConePattern::Cone& cone = pat.cone[static_cast<std::size_t>(slot) * nc + c];
          chain_spheres(setup, r_max, near, cone.scale, chain.data());
          const Vec3 axis = frame.to_world({cone.x, cone.y, cone.z});
          v += weight * transmittance(chain.data(), per_cone, [&](int k) { return sample(pos + axis * chain[k].distance, chain[k].k, chain[k].scale, rot_c, rot_s); });
        }
        out(x, y) = std::clamp(v, 0.0f, 1.0f);
      }
    counter.add(static_cast<std::size_t>(t.x1 - t.x0) * (t.y1 - t.y0));
  });
}

}  // namespace

ConeParams cone_preset(ConeQuality q) {
  ConeParams p;
  p.preset = q;
  p.cones = 6;  // Table I fixes 6 cones for every setting
  p.spheres = q == ConeQuality::Low ? 3 : q == ConeQuality::Medium ? 5 : 7;
  p.prisms = q == ConeQuality::Low ? 3 : q == ConeQuality::Medium ? 6 : 12;
  return p;
}

ConeParams ConeParams::resolved() const {
  ConeParams r = *this;
  const ConeParams preset_counts = cone_preset(preset);
  if (!r.cones) r.cones = preset_counts.cones;
  if (!r.spheres) r.spheres = preset_counts.spheres;
  if (!r.prisms) r.prisms = preset_counts.prisms;
  return r;
}

VoxelizeOptions ConeParams::voxelize_options(float r_max) const { return {columns, depth_bits, open_meshes, slab_fraction * r_max}; }

const ParamTable<ConeParams>& cone_param_table() {
  using P = Param<ConeParams>;
  static const ParamTable<ConeParams> table{
      "cone",
      {P::enumeration<ConeQuality>("preset", &ConeParams::preset, {{"low", ConeQuality::Low}, {"medium", ConeQuality::Medium}, {"high", ConeQuality::High}},
                                   "Table I; fills cones, spheres, prisms left null"),
       P::optional_integer("cones", &ConeParams::cones, Range::closed(1, 64), "", "cones per pixel; null = from the preset (6)"),
       P::optional_integer("spheres", &ConeParams::spheres, Range::closed(1, 16), "", "spheres per cone; null = from the preset (3/5/7)"),
       P::optional_integer("prisms", &ConeParams::prisms, Range::closed(1, 64), "", "prisms per sphere; null = from the preset (3/6/12)"),
       P::real("aperture_deg", &ConeParams::aperture_deg, Range::open(0, 90), "degrees", "full apex angle of each cone (sec. III-C: 30)"),
       P::integer("depth_bits", &ConeParams::depth_bits, Range::closed(32, 1024), "", "voxels per grid column, a multiple of 32 (paper: 128)"),
       P::integer("columns", &ConeParams::columns, Range::closed(8, 4096), "", "grid columns per side (world) or along the longer image side (eye)"),
       P::enumeration<GridSpace>("grid", &ConeParams::grid, {{"world", GridSpace::World}, {"eye", GridSpace::Eye}}, "world grid, or the paper's eye-space grid"),
       P::enumeration<ConeWeighting>("weighting", &ConeParams::weighting, {{"cosine", ConeWeighting::Cosine}, {"uniform", ConeWeighting::Uniform}},
                                     "cone cells of equal cosine-weighted measure or of equal solid angle"),
       P::enumeration<OpenMeshes>("open_meshes", &ConeParams::open_meshes,
                                  {{"winding", OpenMeshes::Winding}, {"slab", OpenMeshes::Slab}, {"parity", OpenMeshes::Parity}},
                                  "open meshes by their winding number: solids with holes where w > 1/2, sheets as slabs on their far side from each point; "
                                  "slab: sheets as slabs behind their fronts; parity: as they are (the paper)"),
       P::real("slab_fraction", &ConeParams::slab_fraction, Range::open_closed(0, 16), "R_max", "thickness of the slab behind open meshes"),
       P::boolean("jitter", &ConeParams::jitter, "per pixel: random cone axes in their cells, sphere-chain scale, prism turn (noise instead of rings)"),
       P::integer("filter_taps", &ConeParams::filter_taps, Range::closed(1, 63), "", "taps per pass of the cross-bilateral filter on V, odd; 1 = no filter")}};
  return table;
}

void ConeParams::validate() const {
  cone_param_table().validate(*this);
  if (filter_taps % 2 == 0) throw InputError("cone: filter_taps must be odd (1 = no filter), got " + std::to_string(filter_taps));
  voxelize_options(1.0f).validate();
}

void to_json(nlohmann::json& j, const ConeParams& p) { j = cone_param_table().to_json(p); }
void from_json(const nlohmann::json& j, ConeParams& p) { cone_param_table().from_json(j, p); }

ConeSetup derive_cone_setup(const ConeParams& p) {
  ConeSetup s;
  const float alpha = 0.5f * p.aperture_deg * kPi / 180.0f;  // half-angle of the cone
  const float sa = std::sin(alpha);

  // Cones: one at the normal, then rings of 5, 11, 17, ... about it, placed regularly in
  // spherical coordinates (sec. III-C, Fig. 5a). Each cone owns a cell of 1/n of the hemisphere's
  // measure: cosine-weighted (s = sin^2 theta is uniform in that measure) or solid angle
  // (1 - cos theta is uniform). Its axis sits at the middle of its ring's band of that measure,
  // but never lower than 90 deg - alpha, so the cone stays above the tangent plane.
  const int n = p.cones.value_or(6);
  std::vector<int> rings{1};
  for (int left = n - 1, cap = 5; left > 0; cap += 6) {
    rings.push_back(std::min(left, cap));
    left -= rings.back();
  }
  int before = 0;
  for (std::size_t ri = 0; ri < rings.size(); ++ri) {
    const float f0 = static_cast<float>(before) / n, f1 = static_cast<float>(before + rings[ri]) / n;
    float theta = 0;
    if (ri > 0) {
      const float mid = 0.5f * (f0 + f1);
      theta = p.weighting == ConeWeighting::Cosine ? std::asin(std::sqrt(mid)) : std::acos(1.0f - mid);
    }
    theta = std::min(theta, 0.5f * kPi - alpha);
    const float dphi = 2.0f * kPi / static_cast<float>(rings[ri]);
    for (int k = 0; k < rings[ri]; ++k) {
      // Odd rings are turned by half a step so that cones of neighbouring rings interleave.
      const float phi = dphi * (static_cast<float>(k) + 0.5f * static_cast<float>(ri % 2));
      s.cones.push_back({std::sin(theta), std::cos(theta), std::cos(phi), std::sin(phi), f0, f1, phi - 0.5f * dphi, dphi});
    }
    before += rings[ri];
  }
  s.sin_theta_max = std::cos(alpha);
  s.cosine = p.weighting == ConeWeighting::Cosine;

  // Sphere chain (Fig. 5b): a sphere at distance d from the apex, inscribed in a cone of
  // half-angle alpha, has radius r = d sin(alpha); tangency of neighbours,
  // d_{k+1} - r_{k+1} = d_k + r_k, gives d_{k+1} = d_k (1 + sin a) / (1 - sin a). The last sphere
  // ends at R_max: d_{K-1} (1 + sin a) = R_max. The first sphere then starts at
  // d_0 (1 - sin a) > 0, clear of the surface at the apex.
  const float q = (1.0f + sa) / (1.0f - sa);
  s.chain_ratio = q;
  const int K = p.spheres.value_or(5);
  s.sphere_distance.resize(K);
  s.sphere_radius.resize(K);
  float d = 1.0f / (1.0f + sa);
  for (int k = K - 1; k >= 0; --k) {
    s.sphere_distance[k] = d;
    s.sphere_radius[k] = d * sa;
    d /= q;
  }
  s.disk = cone_disk_points(p.prisms.value_or(6));  // poisson_disk keeps the relaxed sets: a copy of at most 64 points
  return s;
}

void compute_cone(const GBuffer& gb, const VoxelGrid& g, float r_max, const ConeParams& params, std::uint32_t seed, ImageView<float> out,
                  const ProgressFn& progress) {
  params.validate();
  if (!params.cones || !params.spheres || !params.prisms) throw InputError("cone: compute_cone needs resolved parameters");
  if (!(r_max > 0.0f) || !std::isfinite(r_max)) throw InputError("cone: R_max must be a finite number > 0");
  if (out.width != gb.width() || out.height != gb.height()) throw InputError("cone: output and G-buffer sizes differ");
  const ConeSetup setup = derive_cone_setup(params);
  const ConePattern pattern = make_cone_pattern(setup, params.jitter, seed);
  if (g.space == GridSpace::World) {
    cone_internal::trace_world(gb, g, r_max, setup, pattern, out, progress);
  } else {
    const Camera& cam = g.camera;
    const float t = cam.tan_half_fov();
    EyeSampler s{g, 0.5f * cam.width / (t * cam.aspect()) / g.pixels_per_column_x, -0.5f * cam.height / t / g.pixels_per_column_y,
                 0.5f * cam.width / g.pixels_per_column_x, 0.5f * cam.height / g.pixels_per_column_y, setup.disk.data(),
                 static_cast<int>(setup.disk.size()), {}};
    for (float rk : setup.sphere_radius) s.radius.push_back(rk * r_max);
    trace_eye(gb, s, r_max, setup, pattern, out, progress);
  }
}

namespace {

double ms_between(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

ConeParams checked_resolved(const ConeParams& params, float r_max) {
  const ConeParams p = params.resolved();
  p.validate();
  if (!(r_max > 0.0f) || !std::isfinite(r_max)) throw InputError("cone: R_max must be a finite number > 0");
  return p;
}

// The voxelization options of a render: the parameters' and the rooms around the camera (a camera
// that walks out of a room needs another grid).
VoxelizeOptions voxelize_options(const Scene& scene, std::span<const MeshClosure> closure, const GBuffer& gb, const ConeParams& p, float r_max) {
  VoxelizeOptions o = p.voxelize_options(r_max);
  o.rooms = closed_meshes_around(scene, closure, gb.camera.eye);
  return o;
}

VoxelGrid voxelize(const Scene& scene, std::span<const MeshClosure> closure, const GBuffer& gb, const ConeParams& p, VoxelizeOptions o,
                   VoxelStats* stats, std::span<const std::uint8_t> back = {}, const Bounds3& region = {}) {
  o.slab_region = region;
  return p.grid == GridSpace::World ? voxelize_world(scene, closure, o, stats, back) : voxelize_eye(scene, closure, gb, o, stats, back);
}

// The kernel, on each side's grid over that side's pixels (one grid: all pixels at once), then
// the filter over the whole image.
void trace_and_filter(const GBuffer& gb, std::span<const VoxelGrid* const> grids, const cone_internal::PixelSides& sides, float r_max,
                      const ConeParams& p, std::uint32_t seed, const ProgressFn& progress, ConeResult& r) {
  using Clock = std::chrono::steady_clock;
  const auto t1 = Clock::now();
  r.visibility = Image<float>(gb.width(), gb.height(), 1.0f);
  if (grids.size() == 1) {
    compute_cone(gb, *grids[0], r_max, p, seed, r.visibility.view(), progress);
  } else {
    // Each pass sees only its pixels as covered; the kernel works per pixel, so the pixels of a
    // pass come out as they would in one pass over a scene with that side's grid.
    GBuffer part = gb;
    Image<float> v(gb.width(), gb.height(), 1.0f);
    for (std::size_t k = 0; k < grids.size(); ++k) {
      for (std::size_t i = 0; i < part.object_id.size(); ++i) part.object_id[i] = sides.key_of[i] == k ? gb.object_id[i] : 0u;
      compute_cone(part, *grids[k], r_max, p, seed, v.view(), k == 0 ? progress : ProgressFn{});
      for (std::size_t i = 0; i < v.size(); ++i)
        if (sides.key_of[i] == k && gb.covered(i)) r.visibility[i] = v[i];
    }
  }
  const auto t2 = Clock::now();
  if (p.filter_taps > 1) {
    BilateralParams f;
    f.taps = p.filter_taps;
    bilateral_filter(gb, r.visibility, f);
  }
  r.trace_ms = ms_between(t1, t2);
  r.filter_ms = ms_between(t2, Clock::now());
  r.grid_nx = grids[0]->nx;
  r.grid_ny = grids[0]->ny;
  r.side_grids = static_cast<int>(grids.size());
  r.back_pixels = sides.back_pixels;
  r.rim_pixels = sides.rim_pixels;
  r.unresolved_pixels = sides.unresolved;
}

std::vector<OpenMeshInfo> open_mesh_info(const Scene& scene, std::span<const MeshClosure> closure) {
  std::vector<OpenMeshInfo> out;
  for (std::size_t m = 0; m < closure.size(); ++m)
    if (!closure[m].closed()) out.push_back({scene.meshes[m].name, closure[m].kind, closure[m].boundary_edges, closure[m].holes, closure[m].enclosure});
  return out;
}

void add_grid_stats(ConeResult& r, const VoxelStats& s) {
  r.voxel_stats.winding_evaluations += s.winding_evaluations;
  r.voxel_stats.winding_voxels_changed += s.winding_voxels_changed;
}

}  // namespace

ConeResult render_cone(const Scene& scene, std::span<const MeshClosure> closure, const GBuffer& gb, float r_max, const ConeParams& params,
                       std::uint32_t seed, const ProgressFn& progress) {
  const ConeParams p = checked_resolved(params, r_max);
  ConeResult r;
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<VoxelGrid> grids;
  const VoxelizeOptions options = voxelize_options(scene, closure, gb, p, r_max);
  grids.push_back(voxelize(scene, closure, gb, p, options, &r.voxel_stats));
  const auto t1 = std::chrono::steady_clock::now();
  const cone_internal::PixelSides sides = cone_internal::pixel_sides(
      gb, scene, p.open_meshes == OpenMeshes::Winding ? cone_internal::make_side_setup(scene, closure, r_max) : cone_internal::SideSetup{}, grids[0]);
  const auto t2 = std::chrono::steady_clock::now();
  for (std::size_t k = 1; k < sides.keys.size(); ++k) {
    VoxelStats s;
    grids.push_back(voxelize(scene, closure, gb, p, options, &s, sides.keys[k], cone_internal::side_region(gb, sides, k, r_max)));
    add_grid_stats(r, s);
  }
  r.voxelize_ms = ms_between(t0, t1) + ms_between(t2, std::chrono::steady_clock::now());
  r.sides_ms = ms_between(t1, t2);
  r.side_evaluations = sides.evaluations;
  r.open_meshes = open_mesh_info(scene, closure);
  r.open_mode = p.open_meshes;
  std::vector<const VoxelGrid*> use;
  for (const VoxelGrid& g : grids) use.push_back(&g);
  trace_and_filter(gb, use, sides, r_max, p, seed, progress, r);
  return r;
}

ConeContext::ConeContext(const Scene& scene) : scene_(scene), closure_(analyze_closure(scene)) {}

bool ConeContext::grid_is_current(const GBuffer& gb, GridSpace space, const VoxelizeOptions& o) const {
  if (!valid_ || space != space_ || o.columns != options_.columns || o.depth_bits != options_.depth_bits || o.open_meshes != options_.open_meshes ||
      o.slab_thickness != options_.slab_thickness || o.rooms != options_.rooms)
    return false;
  if (space == GridSpace::World) return true;
  const Camera& c = gb.camera;
  if (!(c.eye == camera_.eye && c.target == camera_.target && c.up == camera_.up && c.vertical_fov_deg == camera_.vertical_fov_deg &&
        c.width == camera_.width && c.height == camera_.height && gb.object_id.size() == depth_.size() && depth_.size() == coverage_.size()))
    return false;
  for (std::size_t i = 0; i < depth_.size(); ++i)
    if (gb.depth(i) != depth_[i] || (gb.covered(i) ? 1 : 0) != coverage_[i]) return false;
  return true;
}

ConeResult ConeContext::render(const GBuffer& gb, float r_max, const ConeParams& params, std::uint32_t seed, const ProgressFn& progress) {
  const ConeParams p = checked_resolved(params, r_max);
  const VoxelizeOptions options = voxelize_options(scene_, closure_, gb, p, r_max);
  ConeResult r;
  const int builds_before = builds_;
  if (!grid_is_current(gb, p.grid, options)) {
    valid_ = false;  // until the inputs below are recorded (a build that throws leaves no grid)
    grids_.clear();
    options_ = options;
    space_ = p.grid;
    if (p.grid == GridSpace::Eye) {
      camera_ = gb.camera;
      depth_.resize(gb.object_id.size());
      coverage_.resize(gb.object_id.size());
      for (std::size_t i = 0; i < depth_.size(); ++i) depth_[i] = gb.depth(i), coverage_[i] = gb.covered(i) ? 1 : 0;
    }
    valid_ = true;
  }
  double voxelize_ms = 0;
  const auto grid_for = [&](const std::vector<std::uint8_t>& back) -> const CachedGrid& {
    std::vector<std::uint32_t> key;  // the objects seen from their back or beyond their rims, and how
    for (std::size_t o = 0; o < back.size(); ++o)
      if (back[o]) key.push_back(static_cast<std::uint32_t>(o) << 2 | back[o]);
    auto it = grids_.find(key);
    if (it == grids_.end()) {
      const auto t = std::chrono::steady_clock::now();
      CachedGrid c;
      c.grid = voxelize(scene_, closure_, gb, p, options_, &c.stats, back);
      it = grids_.emplace(key, std::move(c)).first;
      ++builds_;
      voxelize_ms += ms_between(t, std::chrono::steady_clock::now());
    }
    return it->second;
  };
  std::vector<const VoxelGrid*> use{&grid_for({}).grid};
  r.voxel_stats = grid_for({}).stats;
  const auto t1 = std::chrono::steady_clock::now();
  if (p.open_meshes == OpenMeshes::Winding && (!sides_ || sides_->r_max != r_max))
    sides_ = std::make_shared<cone_internal::SideSetup>(cone_internal::make_side_setup(scene_, closure_, r_max));
  const cone_internal::PixelSides sides =
      cone_internal::pixel_sides(gb, scene_, p.open_meshes == OpenMeshes::Winding ? *sides_ : cone_internal::SideSetup{}, *use[0]);
  r.sides_ms = ms_between(t1, std::chrono::steady_clock::now());
  for (std::size_t k = 1; k < sides.keys.size(); ++k) {
    const CachedGrid& c = grid_for(sides.keys[k]);
    use.push_back(&c.grid);
    add_grid_stats(r, c.stats);
  }
  r.grid_reused = builds_ == builds_before;
  r.voxelize_ms = voxelize_ms;
  r.side_evaluations = sides.evaluations;
  r.open_meshes = open_mesh_info(scene_, closure_);
  r.open_mode = p.open_meshes;
  trace_and_filter(gb, use, sides, r_max, p, seed, progress, r);
  return r;
}

namespace {

const char* kind_name(MeshKind k) { return k == MeshKind::Closed ? "closed" : k == MeshKind::SolidWithHoles ? "solid with holes" : "sheet"; }

// "a, b and 2 more": the names of the open meshes of one kind, for a warning.
std::string names_of(const std::vector<OpenMeshInfo>& meshes, MeshKind kind) {
  std::vector<std::string> n;
  for (const OpenMeshInfo& m : meshes)
    if (m.kind == kind) n.push_back(m.name.empty() ? "unnamed" : m.name);
  std::string out;
  for (std::size_t i = 0; i < n.size() && i < 3; ++i) out += (i ? ", " : "") + n[i];
  if (n.size() > 3) out += " and " + std::to_string(n.size() - 3) + " more";
  return out;
}

}  // namespace

nlohmann::json cone_stats(const ConeResult& r) {
  const VoxelStats& v = r.voxel_stats;
  nlohmann::json warnings = nlohmann::json::array();
  if (v.odd_columns > 0)
    warnings.push_back("cone: " + std::to_string(v.odd_columns) +
                       " voxel columns end with odd parity: the scene is not watertight there, voxels behind the leak are wrong");
  const bool winding = r.open_mode == OpenMeshes::Winding;
  if (v.open_meshes > 0 && r.open_mode != OpenMeshes::Parity)
    warnings.push_back("cone: " + std::to_string(v.open_meshes) + " sheet(s) (" + names_of(r.open_meshes, MeshKind::Sheet) + "; " +
                       std::to_string(v.boundary_edges) + " boundary edges in all meshes): " +
                       (winding ? "two-sided, each a slab on its far side from the pixel (" + std::to_string(r.side_grids) + " grid(s), " +
                                      std::to_string(r.back_pixels) + " pixels on a back side, " + std::to_string(r.rim_pixels) +
                                      " beyond a rim, where a sheet has no slab)"
                                : std::string("filled as one-sided slabs behind their front faces")));
  if (v.holed_meshes > 0)
    warnings.push_back("cone: " + std::to_string(v.holed_meshes) + " solid(s) with holes (" + names_of(r.open_meshes, MeshKind::SolidWithHoles) +
                       "; " + std::to_string(v.holes) + " hole(s)): " +
                       (winding ? "solid where the generalized winding number exceeds 1/2 (holes closed by fans, w evaluated at " +
                                      std::to_string(v.winding_evaluations) + " voxels next to holes that are not flat)"
                                : std::string("voxelized by parity, wrong in the columns through the holes")));
  if (r.unresolved_pixels > 0)
    warnings.push_back("cone: " + std::to_string(r.unresolved_pixels) +
                       " pixels lie on a side of the open meshes that got no grid of its own (over 8 sides, or too few pixels): traced as if in front of all");
  nlohmann::json meshes = nlohmann::json::array();
  for (const OpenMeshInfo& m : r.open_meshes)
    meshes.push_back({{"name", m.name}, {"kind", kind_name(m.kind)}, {"boundary_edges", m.boundary_edges}, {"holes", m.holes}, {"enclosure", m.enclosure}});
  return {{"grid_columns", {r.grid_nx, r.grid_ny}},
          {"triangles_rasterised", v.triangles},
          {"fragments", v.fragments},
          {"odd_columns", v.odd_columns},
          {"open_meshes", v.open_meshes},
          {"boundary_edges", v.boundary_edges},
          {"holed_meshes", v.holed_meshes},
          {"holes", v.holes},
          {"open_mesh_kinds", meshes},
          {"winding_evaluations", v.winding_evaluations},
          {"winding_voxels_changed", v.winding_voxels_changed},
          {"side_grids", r.side_grids},
          {"back_pixels", r.back_pixels},
          {"rim_pixels", r.rim_pixels},
          {"side_evaluations", r.side_evaluations},
          {"unresolved_pixels", r.unresolved_pixels},
          {"set_voxels", v.set_voxels},
          {"voxelize_ms", r.voxelize_ms},
          {"sides_ms", r.sides_ms},
          {"trace_ms", r.trace_ms},
          {"filter_ms", r.filter_ms},
          {"grid_reused", r.grid_reused},
          {"warnings", warnings}};
}

MethodOutput run(const MethodInput& in, const ConeParams& params) {
  if (!in.scene) throw InputError("method cone voxelizes the scene, and a G-buffer file has none: give a scene instead of --gbuffer-in");
  params.validate();
  ConeResult r;
  if (in.cache) {
    const Scene& scene = *in.scene;
    ConeContext& context = in.cache->get<ConeContext>([&] { return std::make_unique<ConeContext>(scene); },
                                                      [&](const ConeContext& c) { return &c.scene() == &scene; });
    r = context.render(in.gbuffer, in.falloff.radius, params, in.seed, in.progress);
  } else {
    const std::vector<MeshClosure> closure = analyze_closure(*in.scene);
    r = render_cone(*in.scene, closure, in.gbuffer, in.falloff.radius, params, in.seed, in.progress);
  }
  MethodOutput out;
  out.stats = cone_stats(r);
  out.visibility = std::move(r.visibility);
  return out;
}

void check_gpu(const ConeParams& params) {
  if (params.resolved().grid == GridSpace::Eye) throw InputError("cone on the GPU traces the world grid only: grid=eye runs on the CPU (--device cpu)");
}

MethodMemory memory(const ConeParams& params) {
  return {estimate_cone_grid_memory(params.columns, params.depth_bits),
          "a " + std::to_string(params.columns) + "^2 x " + std::to_string(params.depth_bits) + " voxel grid"};
}

}  // namespace ao
