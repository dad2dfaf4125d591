// Voxel cone traced AO (Dalla Favera & Celes 2012, sec. III-C). See cone.h for the convention
// (we return V = 1 - the paper's blocked fraction) and voxelize.h for the grid.
#include "ao/methods/cone.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/core/sampling.h"

namespace ao {

namespace {

constexpr int kTile = 16;
// Below this transmittance the remaining spheres of a cone cannot change V by more than 1e-4.
constexpr float kOpaque = 1e-4f;

// Length of [zlo, zhi) (voxel units along the column) covered by solid voxels, counting the two
// end voxels by the part of them inside the range. The paper counts whole bits (Fig. 7); the
// fractional ends remove a bias of up to a voxel per prism, which matters for the small spheres
// near the apex whose chords are a few voxels long.
inline float solid_length(const std::uint64_t* col, int words, int nbits, float zlo, float zhi) {
  zlo = std::max(zlo, 0.0f);
  zhi = std::min(zhi, static_cast<float>(nbits));
  if (!(zhi > zlo)) return 0.0f;
  const int k0 = static_cast<int>(zlo);
  const int k1 = std::min(static_cast<int>(zhi), nbits - 1);
  const auto bit = [&](int k) { return static_cast<float>((col[k >> 6] >> (k & 63)) & 1u); };
  if (k0 >= k1) return bit(k0) * (zhi - zlo);
  // Whole voxels strictly between the end voxels: bitfieldExtract + bitCount of Fig. 7.
  return bit(k0) * (static_cast<float>(k0 + 1) - zlo) + static_cast<float>(count_bits(col, words, k0 + 1, k1)) +
         bit(k1) * (zhi - static_cast<float>(k1));
}

// Obstructed fraction of one sphere (sec. III-C1): prisms along the grid's z through the great
// disk's samples; each prism spans the sphere's chord [z_in, z_out] at its sample. Monte Carlo
// over the disk: volume ~ sum of chords, obstructed volume ~ sum of solid lengths, so the
// fraction is their ratio (as volumetric AO's pipes, the paper's [4]).
struct WorldSampler {
  const VoxelGrid& g;
  Vec3 inv;  // 1 / voxel size along (i, j, k)

  // centre in world space, radius in world units; disk points are (u, v) in the world x-z plane.
  float operator()(Vec3 c, float r, const ConeSetup::Disk* disk, int n, float rot_c, float rot_s) const {
    const float gx = (c.x - g.origin.x) * inv.x, gy = (c.z - g.origin.z) * inv.y, gz = (c.y - g.origin.y) * inv.z;
    const float rx = r * inv.x, ry = r * inv.y, rz = r * inv.z;
    // Empty-space skipping (not in the paper): if no block the sphere's bounding box touches has
    // a solid voxel in its z range, the sphere is unobstructed and its prisms need no lookups.
    {
      constexpr float kInvB = 1.0f / VoxelGrid::kBlock;
      const int bx0 = std::max(0, static_cast<int>(std::floor((gx - rx) * kInvB)));
      const int bx1 = std::min(g.bnx - 1, static_cast<int>(std::floor((gx + rx) * kInvB)));
      const int by0 = std::max(0, static_cast<int>(std::floor((gy - ry) * kInvB)));
      const int by1 = std::min(g.bny - 1, static_cast<int>(std::floor((gy + ry) * kInvB)));
      const int k0 = static_cast<int>(std::floor(std::max(gz - rz, -1.0f))), k1 = static_cast<int>(std::min(gz + rz, 1e6f)) + 1;
      bool any = false;
      for (int by = by0; by <= by1 && !any; ++by)
        for (int bx = bx0; bx <= bx1 && !any; ++bx) any = any_bits(g.block(bx, by), g.words, k0, k1);
      if (!any) return 0.0f;
    }
    float solid = 0, chord = 0;
    for (int s = 0; s < n; ++s) {
      const float u = disk[s].u * rot_c - disk[s].v * rot_s, v = disk[s].u * rot_s + disk[s].v * rot_c;
      const float half = disk[s].half_chord * rz;
      chord += 2.0f * half;
      const float fx = gx + u * rx, fy = gy + v * ry;
      if (!(fx >= 0.0f && fy >= 0.0f && fx < static_cast<float>(g.nx) && fy < static_cast<float>(g.ny))) continue;
      solid += solid_length(g.column(static_cast<int>(fx), static_cast<int>(fy)), g.words, g.depth_bits, gz - half, gz + half);
    }
    return chord > 0 ? std::min(1.0f, solid / chord) : 0.0f;
  }
};

struct EyeSampler {
  const VoxelGrid& g;
  float sx, sy, ox, oy;  // camera-space (x/depth, y/depth) -> column coordinates

  // centre in camera space; the prisms run along the camera's z (the grid's columns are view rays:
  // over one sphere they are close to parallel, the approximation the paper's texture fetch makes).
  float operator()(Vec3 c, float r, const ConeSetup::Disk* disk, int n, float rot_c, float rot_s) const {
    float solid = 0, chord = 0;
    const float depth = -c.z;
    if (!(depth > 0)) return 0.0f;
    const float inv = 1.0f / depth;
    for (int s = 0; s < n; ++s) {
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

template <class Sampler>
void trace(const GBuffer& gb, const Sampler& sample, bool world, float r_max, const ConeParams& p, const ConeSetup& setup, std::uint32_t seed,
           ImageView<float> out, const ProgressFn& progress) {
  const int w = gb.width(), h = gb.height();
  const Frame basis = gb.camera.basis();
  const Vec3 eye = gb.camera.eye;
  const int nc = static_cast<int>(setup.cones.size()), ns = static_cast<int>(setup.sphere_distance.size());
  const int np = static_cast<int>(setup.disk.size());
  const float weight = 1.0f / static_cast<float>(nc);  // every cone stands for a cell of equal measure
  ProgressCounter counter(progress, static_cast<std::size_t>(w) * h);
  parallel_for_tiles(w, h, kTile, [&](const Tile& t) {
    for (int y = t.y0; y < t.y1; ++y)
      for (int x = t.x0; x < t.x1; ++x) {
        if (!gb.covered(x, y)) {
          out(x, y) = 1.0f;
          continue;
        }
        Vec3 pos = gb.position(x, y), n = gb.normal(x, y);
        if (world) {
          pos = basis.to_world(pos) + eye;
          n = normalize(basis.to_world(n));
        }
        const Frame frame = Frame::from_normal(n);
        // Per-pixel rotations: psi of the cone pattern about the normal, beta of the prism pattern.
        float psi_c = 1, psi_s = 0, rot_c = 1, rot_s = 0;
        if (p.jitter) {
          const std::uint32_t ps = pixel_seed(seed, x, y);
          const float psi = 2.0f * kPi * to_unit_float(hash32(ps));
          const float beta = 2.0f * kPi * to_unit_float(hash_combine(ps, 1u));
          psi_c = std::cos(psi), psi_s = std::sin(psi);
          rot_c = std::cos(beta), rot_s = std::sin(beta);
        }
        float v = 0;
        for (int c = 0; c < nc; ++c) {
          const ConeSetup::Cone& cone = setup.cones[c];
          const float cp = cone.cos_phi * psi_c - cone.sin_phi * psi_s, sp = cone.sin_phi * psi_c + cone.cos_phi * psi_s;
          const Vec3 axis = frame.to_world({cone.sin_theta * cp, cone.sin_theta * sp, cone.cos_theta});
          // Front-to-back along the cone (sec. III-C2, Fig. 8): each sphere absorbs its
          // obstructed fraction of the rays that reach it.
          float transmittance = 1.0f;
          for (int k = 0; k < ns && transmittance > kOpaque; ++k) {
            const float d = setup.sphere_distance[k] * r_max, r = setup.sphere_radius[k] * r_max;
            transmittance *= 1.0f - sample(pos + axis * d, r, setup.disk.data(), np, rot_c, rot_s);
          }
          v += weight * transmittance;
        }
        out(x, y) = std::clamp(v, 0.0f, 1.0f);
      }
    counter.add(static_cast<std::size_t>(t.x1 - t.x0) * (t.y1 - t.y0));
  });
}

// Poisson-disk points on the unit disk: best-candidate dart throwing (Mitchell 1991) from a fixed
// hash sequence, relaxed by Lloyd iterations on a fine grid over the disk so that the points are
// evenly spread and well inside (a sample on the rim has a zero chord and would be wasted).
std::vector<ConeSetup::Disk> poisson_disk(int n) {
  std::vector<Vec2> pts;
  auto disk_point = [](std::uint32_t i) {
    const float r = std::sqrt(to_unit_float(hash32(2 * i + 17))), a = 2.0f * kPi * to_unit_float(hash32(2 * i + 18));
    return Vec2{r * std::cos(a), r * std::sin(a)};
  };
  std::uint32_t next = 0;
  for (int k = 0; k < n; ++k) {
    Vec2 best{};
    float best_d = -1;
    for (int c = 0; c < 16 * (k + 1); ++c) {
      const Vec2 q = disk_point(next++);
      float d = kInfinity;
      for (const Vec2& o : pts) d = std::min(d, (q.x - o.x) * (q.x - o.x) + (q.y - o.y) * (q.y - o.y));
      if (d > best_d) best_d = d, best = q;
    }
    pts.push_back(best);
  }
  constexpr int kGrid = 48, kIterations = 30;
  for (int it = 0; it < kIterations; ++it) {
    std::vector<Vec2> sum(n);
    std::vector<int> count(n, 0);
    for (int gy = 0; gy < kGrid; ++gy)
      for (int gx = 0; gx < kGrid; ++gx) {
        const float x = -1.0f + (gx + 0.5f) * 2.0f / kGrid, y = -1.0f + (gy + 0.5f) * 2.0f / kGrid;
        if (x * x + y * y > 1.0f) continue;
        int best = 0;
        float best_d = kInfinity;
        for (int k = 0; k < n; ++k) {
          const float d = (x - pts[k].x) * (x - pts[k].x) + (y - pts[k].y) * (y - pts[k].y);
          if (d < best_d) best_d = d, best = k;
        }
        sum[best].x += x, sum[best].y += y, ++count[best];
      }
    for (int k = 0; k < n; ++k)
      if (count[k] > 0) pts[k] = {sum[k].x / count[k], sum[k].y / count[k]};
  }
  std::vector<ConeSetup::Disk> out;
  for (const Vec2& q : pts) out.push_back({q.x, q.y, std::sqrt(std::max(0.0f, 1.0f - q.x * q.x - q.y * q.y))});
  return out;
}

void require_known_keys(const nlohmann::json& j, std::initializer_list<const char*> keys) {
  if (!j.is_object()) throw InputError("cone: parameters must be a JSON object");
  for (const auto& [key, value] : j.items()) {
    bool known = false;
    for (const char* k : keys) known = known || key == k;
    if (!known) throw InputError("cone: unknown parameter '" + key + "'");
  }
}

template <class E>
E parse_enum(const nlohmann::json& j, const char* key, std::initializer_list<std::pair<const char*, E>> names) {
  const std::string s = j.at(key).get<std::string>();
  std::string valid;
  for (const auto& [name, value] : names) {
    if (s == name) return value;
    valid += (valid.empty() ? "" : "|") + std::string(name);
  }
  throw InputError(std::string("cone: ") + key + " must be " + valid + ", got '" + s + "'");
}

const char* name(ConeQuality q) { return q == ConeQuality::Low ? "low" : q == ConeQuality::High ? "high" : "medium"; }

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

void ConeParams::validate() const {
  if (cones && (*cones < 1 || *cones > 64)) throw InputError("cone: cones must be in [1, 64] (null = preset), got " + std::to_string(*cones));
  if (spheres && (*spheres < 1 || *spheres > 16))
    throw InputError("cone: spheres must be in [1, 16] (null = preset), got " + std::to_string(*spheres));
  if (prisms && (*prisms < 1 || *prisms > 64)) throw InputError("cone: prisms must be in [1, 64] (null = preset), got " + std::to_string(*prisms));
  if (!(aperture_deg > 0.0f && aperture_deg < 90.0f))
    throw InputError("cone: aperture_deg must be in (0, 90) degrees, got " + std::to_string(aperture_deg));
  if (!(slab_fraction > 0.0f && slab_fraction <= 16.0f)) throw InputError("cone: slab_fraction must be in (0, 16], got " + std::to_string(slab_fraction));
  voxelize_options(1.0f).validate();
}

void to_json(nlohmann::json& j, const ConeParams& p) {
  const auto opt = [](const std::optional<int>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); };
  j = {{"preset", name(p.preset)},
       {"cones", opt(p.cones)},
       {"spheres", opt(p.spheres)},
       {"prisms", opt(p.prisms)},
       {"aperture_deg", p.aperture_deg},
       {"depth_bits", p.depth_bits},
       {"columns", p.columns},
       {"grid", p.grid == GridSpace::World ? "world" : "eye"},
       {"weighting", p.weighting == ConeWeighting::Cosine ? "cosine" : "uniform"},
       {"open_meshes", p.open_meshes == OpenMeshes::Slab ? "slab" : "parity"},
       {"slab_fraction", p.slab_fraction},
       {"jitter", p.jitter}};
}

void from_json(const nlohmann::json& j, ConeParams& p) {
  require_known_keys(j, {"preset", "cones", "spheres", "prisms", "aperture_deg", "depth_bits", "columns", "grid", "weighting", "open_meshes",
                         "slab_fraction", "jitter"});
  try {
    if (j.contains("preset"))
      p.preset = parse_enum<ConeQuality>(j, "preset", {{"low", ConeQuality::Low}, {"medium", ConeQuality::Medium}, {"high", ConeQuality::High}});
    const auto opt = [&](const char* key, std::optional<int>& v) {
      if (j.contains(key)) v = j.at(key).is_null() ? std::nullopt : std::optional<int>(j.at(key).get<int>());
    };
    opt("cones", p.cones);
    opt("spheres", p.spheres);
    opt("prisms", p.prisms);
    if (j.contains("aperture_deg")) p.aperture_deg = j.at("aperture_deg").get<float>();
    if (j.contains("depth_bits")) p.depth_bits = j.at("depth_bits").get<int>();
    if (j.contains("columns")) p.columns = j.at("columns").get<int>();
    if (j.contains("grid")) p.grid = parse_enum<GridSpace>(j, "grid", {{"world", GridSpace::World}, {"eye", GridSpace::Eye}});
    if (j.contains("weighting"))
      p.weighting = parse_enum<ConeWeighting>(j, "weighting", {{"cosine", ConeWeighting::Cosine}, {"uniform", ConeWeighting::Uniform}});
    if (j.contains("open_meshes")) p.open_meshes = parse_enum<OpenMeshes>(j, "open_meshes", {{"slab", OpenMeshes::Slab}, {"parity", OpenMeshes::Parity}});
    if (j.contains("slab_fraction")) p.slab_fraction = j.at("slab_fraction").get<float>();
    if (j.contains("jitter")) p.jitter = j.at("jitter").get<bool>();
  } catch (const nlohmann::json::exception& e) {
    throw InputError(std::string("cone: bad parameter type: ") + e.what());
  }
}

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
    for (int k = 0; k < rings[ri]; ++k) {
      // Odd rings are turned by half a step so that cones of neighbouring rings interleave.
      const float phi = 2.0f * kPi * (static_cast<float>(k) + 0.5f * static_cast<float>(ri % 2)) / static_cast<float>(rings[ri]);
      s.cones.push_back({std::sin(theta), std::cos(theta), std::cos(phi), std::sin(phi)});
    }
    before += rings[ri];
  }

  // Sphere chain (Fig. 5b): a sphere at distance d from the apex, inscribed in a cone of
  // half-angle alpha, has radius r = d sin(alpha); tangency of neighbours,
  // d_{k+1} - r_{k+1} = d_k + r_k, gives d_{k+1} = d_k (1 + sin a) / (1 - sin a). The last sphere
  // ends at R_max: d_{K-1} (1 + sin a) = R_max. The first sphere then starts at
  // d_0 (1 - sin a) > 0, clear of the surface at the apex.
  const float q = (1.0f + sa) / (1.0f - sa);
  const int K = p.spheres.value_or(5);
  s.sphere_distance.resize(K);
  s.sphere_radius.resize(K);
  float d = 1.0f / (1.0f + sa);
  for (int k = K - 1; k >= 0; --k) {
    s.sphere_distance[k] = d;
    s.sphere_radius[k] = d * sa;
    d /= q;
  }
  s.disk = poisson_disk(p.prisms.value_or(6));
  return s;
}

void compute_cone(const GBuffer& gb, const VoxelGrid& g, float r_max, const ConeParams& params, std::uint32_t seed, ImageView<float> out,
                  const ProgressFn& progress) {
  params.validate();
  if (!params.cones || !params.spheres || !params.prisms) throw InputError("cone: compute_cone needs resolved parameters");
  if (!(r_max > 0.0f) || !std::isfinite(r_max)) throw InputError("cone: R_max must be a finite number > 0");
  if (out.width != gb.width() || out.height != gb.height()) throw InputError("cone: output and G-buffer sizes differ");
  const ConeSetup setup = derive_cone_setup(params);
  if (g.space == GridSpace::World) {
    const WorldSampler s{g, {1.0f / g.voxel_size.x, 1.0f / g.voxel_size.y, 1.0f / g.voxel_size.z}};
    trace(gb, s, true, r_max, params, setup, seed, out, progress);
  } else {
    const Camera& cam = g.camera;
    const float t = cam.tan_half_fov();
    const EyeSampler s{g, 0.5f * cam.width / (t * cam.aspect()) / g.pixels_per_column_x, -0.5f * cam.height / t / g.pixels_per_column_y,
                       0.5f * cam.width / g.pixels_per_column_x, 0.5f * cam.height / g.pixels_per_column_y};
    trace(gb, s, false, r_max, params, setup, seed, out, progress);
  }
}

ConeResult render_cone(const Scene& scene, std::span<const MeshClosure> closure, const GBuffer& gb, float r_max, const ConeParams& params,
                       std::uint32_t seed, const ProgressFn& progress) {
  const ConeParams p = params.resolved();
  p.validate();
  using Clock = std::chrono::steady_clock;
  const auto ms = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
  ConeResult r;
  const auto t0 = Clock::now();
  if (!(r_max > 0.0f) || !std::isfinite(r_max)) throw InputError("cone: R_max must be a finite number > 0");
  const VoxelGrid g = p.grid == GridSpace::World ? voxelize_world(scene, closure, p.voxelize_options(r_max), &r.voxel_stats)
                                                 : voxelize_eye(scene, closure, gb, p.voxelize_options(r_max), &r.voxel_stats);
  const auto t1 = Clock::now();
  r.visibility = Image<float>(gb.width(), gb.height(), 1.0f);
  compute_cone(gb, g, r_max, p, seed, r.visibility.view(), progress);
  const auto t2 = Clock::now();
  r.voxelize_ms = ms(t0, t1);
  r.trace_ms = ms(t1, t2);
  r.grid_nx = g.nx;
  r.grid_ny = g.ny;
  return r;
}

nlohmann::json cone_stats(const ConeResult& r) {
  const VoxelStats& v = r.voxel_stats;
  nlohmann::json warnings = nlohmann::json::array();
  if (v.odd_columns > 0)
    warnings.push_back("cone: " + std::to_string(v.odd_columns) +
                       " voxel columns end with odd parity: the scene is not watertight there, voxels behind the leak are wrong");
  if (v.open_meshes > 0)
    warnings.push_back("cone: " + std::to_string(v.open_meshes) + " open mesh(es) with " + std::to_string(v.boundary_edges) +
                       " boundary edges: filled as one-sided slabs behind their front faces (open_meshes=slab)");
  return {{"grid_columns", {r.grid_nx, r.grid_ny}},
          {"triangles_rasterised", v.triangles},
          {"fragments", v.fragments},
          {"odd_columns", v.odd_columns},
          {"open_meshes", v.open_meshes},
          {"boundary_edges", v.boundary_edges},
          {"set_voxels", v.set_voxels},
          {"voxelize_ms", r.voxelize_ms},
          {"trace_ms", r.trace_ms},
          {"warnings", warnings}};
}

}  // namespace ao
