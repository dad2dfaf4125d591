// SPDX-License-Identifier: Apache-2.0
// Voxel cone tracing on the GPU (Dalla Favera & Celes 2012): the world voxel grid built by
// rasterization, each fragment XOR-ing its depth-slab mask into its column
// (cone_voxelize.vert, .geom, .frag; statistics: cone_count.comp), the cones of spheres and the
// prisms' bit counts in a compute shader (cone_trace.comp), and the cross-bilateral filter
// (filters_gpu.cpp). The sampling tables are the CPU kernel's
// (derive_cone_setup, make_cone_pattern), uploaded.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/gpu/run_internal.h"
#include "ao/methods/cone/cone_gpu_internal.h"
#include "ao/methods/filters/filters_gpu_internal.h"
#include "ao/methods/cone/voxelize_gpu.h"
#include "ao/methods/cone/cone_pattern_internal.h"
#include "ao/methods/cone/cone_sides_internal.h"

namespace ao {

namespace gpu_detail {

namespace {

// A world voxel grid built on the GPU and what it was built from.
struct GridCache {
  bool valid = false;
  VoxelizeOptions options;
  VoxelGrid layout;    // nx, ny, depth_bits, words, origin, voxel_size (bits stay on the GPU).
  Buffer bits;         // The columns as 32-bit words: column c's word w at c * (depth_bits / 32) + w.
  VoxelStats stats;
  VoxelGrid cpu;       // The grid with its bits when the CPU built it (open meshes): the pixels' sides read it.
};

// What cone keeps with a scene on the device (SceneBuffers::state): the closure of its meshes
// (analyze_closure, computed on first use: cone checks for open meshes) and the last world grid.
struct ConeGpuState {
  std::optional<std::vector<MeshClosure>> closure;
  GridCache grid;
};

ConeGpuState& state_of(SceneBuffers& sb) {
  return sb.state.get<ConeGpuState>([] { return std::make_unique<ConeGpuState>(); });
}

// voxelize_world's layout of the world grid (voxelize.h) when nothing is voxelized as a slab.
VoxelGrid world_layout(const Scene& scene, const VoxelizeOptions& o) { return world_grid_layout(scene, o, false, false); }

const std::vector<MeshClosure>& closure_of(SceneBuffers& sb) {
  std::optional<std::vector<MeshClosure>>& closure = state_of(sb).closure;
  if (!closure) closure = analyze_closure(*sb.scene);
  return *closure;
}

// Whether the GPU's rasterization (parity: each fragment flips its column beyond it) builds the
// grid these options ask for. The CPU's other modes change the solid of open surfaces (slabs), of
// holed meshes (winding number) and of closed meshes around the camera (the complement).
bool parity_suffices(const std::vector<MeshClosure>& closure, const VoxelizeOptions& o) {
  if (o.open_meshes == OpenMeshes::Parity) return true;
  const bool rooms = std::count(o.rooms.begin(), o.rooms.end(), std::uint8_t{1}) > 0;
  const bool open = std::any_of(closure.begin(), closure.end(), [](const MeshClosure& c) { return c.open_surface(); });
  const bool holed = std::any_of(closure.begin(), closure.end(), [](const MeshClosure& c) { return c.holed(); });
  return !rooms && !open && !(o.open_meshes == OpenMeshes::Winding && holed);
}

// A grid of nx x ny columns of depth_bits bits must fit in one storage buffer.
void check_storage(const Context& c, int nx, int ny, int depth_bits) {
  const std::size_t words = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) * static_cast<std::size_t>(depth_bits / 32);
  if (static_cast<double>(words) * 4 > static_cast<double>(c.max_storage_block))
    throw InputError("cone: a " + std::to_string(nx) + " x " + std::to_string(ny) + " x " + std::to_string(depth_bits) + " voxel grid (" +
                     std::to_string(words * 4 >> 20) + " MiB) exceeds this GPU's largest storage buffer (" +
                     std::to_string(c.max_storage_block >> 20) + " MiB, " + c.renderer + "): fewer columns or depth_bits");
}

// A CPU grid's columns as the 32-bit words the GPU's rasterization writes, in a new buffer: bit b
// of a column is bit b % 64 of its 64-bit word b / 64 (voxelize.h), so word k of the column holds
// the half k % 2 of 64-bit word k / 2.
Buffer upload_words(Context& c, const VoxelGrid& grid) {
  const int per_column = grid.depth_bits / 32;
  const std::size_t columns = static_cast<std::size_t>(grid.nx) * static_cast<std::size_t>(grid.ny);
  std::vector<std::uint32_t> words(columns * static_cast<std::size_t>(per_column));
  for (std::size_t col = 0; col < columns; ++col)
    for (int k = 0; k < per_column; ++k)
      words[col * static_cast<std::size_t>(per_column) + static_cast<std::size_t>(k)] =
          static_cast<std::uint32_t>(grid.bits[col * static_cast<std::size_t>(grid.words) + static_cast<std::size_t>(k / 2)] >> (32 * (k % 2)));
  return make_buffer(c, words.size() * sizeof(std::uint32_t), words.data());
}

// The grid of a scene whose open surfaces, holed meshes or rooms need the CPU's solid: the CPU
// voxelizes it (voxelize_world, the grid `ao render -m cone` traces, so both devices trace the same
// bits) and it is uploaded as 32-bit words, the layout the GPU's rasterization writes. Timed as the
// pass "voxelize on the CPU".
void upload_cpu_grid(Context& c, SceneBuffers& sb, const std::vector<MeshClosure>& closure, const VoxelizeOptions& o,
                     std::vector<PassQuery>& passes) {
  GridCache& cache = state_of(sb).grid;
  check_storage(c, o.columns, o.columns, o.depth_bits);  // before the CPU's work: the grid's shape is the options'
  c.begin_pass(passes, "voxelize on the CPU");
  c.gl.Flush();  // the first timestamp reaches the GPU before the CPU's work
  VoxelStats stats;
  VoxelGrid grid = voxelize_world(*sb.scene, closure, o, &stats);
  cache.bits = upload_words(c, grid);
  c.end_pass(passes);
  // The layout without the bits (they are on the GPU; the coarse occupancy masks are the CPU
  // kernel's), and the grid itself for the pixels' sides (run_gpu).
  cache.layout = grid;
  cache.layout.bits = {};
  cache.layout.block_bits = {};
  cache.layout.window = {};
  cache.cpu = std::move(grid);
  cache.stats = stats;
  cache.options = o;
  cache.valid = true;
}

void set_instance(Context& c, Program& p, const Scene& s, const SceneObject& ob) {
  const bool instance = ob.instance != SceneObject::kNoInstance;
  c.gl.Uniform1i(c.uniform(p, "u_instance"), instance ? 1 : 0);
  if (!instance) return;
  const Affine3& a = s.instances[ob.instance].object_to_world;
  const float to_world[12] = {a.c0.x, a.c0.y, a.c0.z, a.c1.x, a.c1.y, a.c1.z, a.c2.x, a.c2.y, a.c2.z, a.c3.x, a.c3.y, a.c3.z};
  c.gl.Uniform3fv(c.uniform(p, "u_to_world"), 4, to_world);
}

// Builds state_of(sb).grid for `o` on the GPU, as the passes "voxelize" (the XOR rasterization) and
// "count" (its statistics).
void build_grid(Context& c, SceneBuffers& sb, const VoxelizeOptions& o, std::vector<PassQuery>& passes) {
  o.validate();
  const std::vector<MeshClosure>& closure = closure_of(sb);
  GridCache& cache = state_of(sb).grid;
  cache.valid = false;
  cache.cpu = {};
  if (!parity_suffices(closure, o)) return upload_cpu_grid(c, sb, closure, o, passes);
  cache.layout = world_layout(*sb.scene, o);
  const VoxelGrid& g = cache.layout;
  if (g.nx > c.max_texture_size)
    throw InputError("cone: " + std::to_string(g.nx) + " columns exceed this GPU's largest framebuffer (" + std::to_string(c.max_texture_size) + ")");

  Program& raster = c.program({"cone_voxelize.vert", "cone_voxelize.geom", "cone_voxelize.frag"},
                              c.geometry_storage ? "" : "#define NO_GEOMETRY_COUNTER\n");
  Program& count = c.program({"cone_count.comp"});
  const std::size_t words = static_cast<std::size_t>(g.nx) * g.ny * (g.depth_bits / 32);
  check_storage(c, g.nx, g.ny, g.depth_bits);
  const GLuint zero[4] = {0, 0, 0, 0};
  Buffer counters = make_buffer(c, sizeof zero, zero);
  cache.bits = make_buffer(c, words * sizeof(std::uint32_t), nullptr);
  // A framebuffer without attachments, nx x ny: the fragments write the grid's buffer only.
  GLuint fbo_id = 0;
  c.gl.GenFramebuffers(1, &fbo_id);
  Framebuffer fbo(c, fbo_id);
  c.gl.BindFramebuffer(GL_FRAMEBUFFER, fbo_id);
  c.gl.FramebufferParameteri(GL_FRAMEBUFFER, GL_FRAMEBUFFER_DEFAULT_WIDTH, g.nx);
  c.gl.FramebufferParameteri(GL_FRAMEBUFFER, GL_FRAMEBUFFER_DEFAULT_HEIGHT, g.ny);
  if (c.gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw SystemError("--device gpu: a framebuffer without attachments is not supported by " + c.renderer);
  c.check("allocating the voxel grid");

  c.begin_pass(passes, "voxelize");
  c.gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, cache.bits.id());
  c.gl.ClearBufferData(GL_SHADER_STORAGE_BUFFER, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, zero);
  c.gl.Viewport(0, 0, g.nx, g.ny);
  c.gl.Disable(GL_DEPTH_TEST);
  c.gl.UseProgram(raster.id);
  const Vec3 inv{1.0f / g.voxel_size.x, 1.0f / g.voxel_size.y, 1.0f / g.voxel_size.z};
  c.gl.Uniform3f(c.uniform(raster, "u_origin"), g.origin.x, g.origin.y, g.origin.z);
  c.gl.Uniform3f(c.uniform(raster, "u_inv_size"), inv.x, inv.y, inv.z);
  c.gl.Uniform2i(c.uniform(raster, "u_columns"), g.nx, g.ny);
  c.gl.Uniform1i(c.uniform(raster, "u_depth_bits"), g.depth_bits);
  c.gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, cache.bits.id());
  c.gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, counters.id());
  for (const SceneObject& ob : sb.objects) {
    set_instance(c, raster, *sb.scene, ob);
    const SceneBuffers::MeshBuffers& mb = sb.meshes[ob.mesh];
    c.gl.BindVertexArray(mb.vao.id());
    c.gl.DrawElements(GL_TRIANGLES, mb.index_count, GL_UNSIGNED_INT, nullptr);
  }
  c.gl.BindVertexArray(0);
  c.gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  c.gl.MemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  c.end_pass(passes);

  c.begin_pass(passes, "count");
  c.gl.UseProgram(count.id);
  c.gl.Uniform2i(c.uniform(count, "u_columns"), g.nx, g.ny);
  c.gl.Uniform1i(c.uniform(count, "u_depth_bits"), g.depth_bits);
  dispatch_2d(c, g.nx, g.ny);
  c.end_pass(passes);
  c.check("voxelizing the scene");

  GLuint counts[4] = {0, 0, 0, 0};
  c.gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, counters.id());
  c.gl.GetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, sizeof counts, counts);
  VoxelStats& s = cache.stats;
  s = {};
  s.triangles = counts[0], s.fragments = counts[1], s.set_voxels = counts[2], s.odd_columns = counts[3];
  for (const MeshClosure& m : closure) {
    s.open_meshes += m.open_surface() ? 1 : 0;
    s.holed_meshes += m.holed() ? 1 : 0;
    s.holes += m.holed() ? m.holes : 0;
    s.boundary_edges += m.boundary_edges;
  }
  cache.options = o;
  cache.valid = true;
}

bool grid_is_current(const GridCache& cache, const VoxelizeOptions& o) {
  return cache.valid && cache.options.columns == o.columns && cache.options.depth_bits == o.depth_bits && cache.options.open_meshes == o.open_meshes &&
         cache.options.slab_thickness == o.slab_thickness && cache.options.rooms == o.rooms;
}

// The world sampler's constants of cone_world.cpp: per chain sphere its radii in voxels and the
// sum of its prisms' chords, per prism the disk point and per sphere its half chord; per sphere
// slot of a cone the affine forms of its distance, radius scale and "is sampled" test in the chain
// scale s (ConeLanes).
struct TraceTables {
  std::vector<float> spheres, prisms, lanes;
};

TraceTables trace_tables(const ConeSetup& setup, const VoxelGrid& g, float r_max) {
  TraceTables t;
  const Vec3 inv{1.0f / g.voxel_size.x, 1.0f / g.voxel_size.y, 1.0f / g.voxel_size.z};
  const int np = static_cast<int>(setup.disk.size()), ns = static_cast<int>(setup.sphere_radius.size());
  for (const ConeSetup::Disk& d : setup.disk) t.prisms.insert(t.prisms.end(), {d.u, d.v});
  for (int k = 0; k < ns; ++k) {
    const float r = setup.sphere_radius[static_cast<std::size_t>(k)] * r_max;
    const float rz = r * inv.z;
    float chord = 0;
    for (int s = 0; s < np; ++s) {
      const float h = setup.disk[static_cast<std::size_t>(s)].half_chord * rz;
      t.prisms.push_back(h);
      chord += 2.0f * h;
    }
    t.spheres.insert(t.spheres.end(), {r * inv.x, r * inv.y, rz, chord});
  }
  // Spheres that start nearer the apex than 1.5 voxels are skipped (the surface's own voxels).
  const float near = 1.5f * std::max({g.voxel_size.x, g.voxel_size.y, g.voxel_size.z});
  const float inv_last_radius = 1.0f / setup.sphere_radius.back();
  for (int j = 0; j <= ns; ++j) {
    const float k = static_cast<float>(std::min(j, ns - 1));
    if (j < ns) {
      const auto js = static_cast<std::size_t>(j);
      t.lanes.insert(t.lanes.end(), {setup.sphere_distance[js] * r_max, 0.0f, 1.0f, 0.0f,
                                     (setup.sphere_distance[js] - setup.sphere_radius[js]) * r_max, -near, k, 0.0f});
    } else {
      // The filler sphere, inscribed in [s R_max, R_max] along the axis (cone.cpp chain_spheres).
      t.lanes.insert(t.lanes.end(), {0.5f * r_max, 0.5f * r_max, -0.5f * inv_last_radius, 0.5f * inv_last_radius, -0.5f * inv_last_radius,
                                     0.5f * inv_last_radius - 1e-3f, k, 0.0f});
    }
  }
  return t;
}

// The grids of the pixels on the back side of open meshes (cone_sides_internal.h), as on the CPU
// (render_cone): the sides from the G-buffer read back, each side's grid voxelized on the CPU for its
// pixels' reach; `result`'s side statistics. None for a grid the GPU rasterized (closed meshes only).
struct SideGrids {
  std::vector<Buffer> bits;
  std::vector<VoxelGrid> layout;  // a side's grid has its own frame (its slabs may rise above the scene)
  Buffer keys;                    // per pixel its grid (PixelSides::key_of) as 32-bit words
};
SideGrids side_grids(Run& r, SceneBuffers& sb, const GpuGBuffer& gbuffer, const ConeParams& p, const VoxelizeOptions& options, float r_max,
                     ConeResult& result) {
  SideGrids out;
  result.side_grids = 1;
  if (p.open_meshes != OpenMeshes::Winding || state_of(sb).grid.cpu.bits.empty()) return out;
  const auto t0 = std::chrono::steady_clock::now();
  const GBuffer gb = gbuffer.download();
  const std::vector<MeshClosure>& closure = closure_of(sb);
  const cone_internal::PixelSides sides =
      cone_internal::pixel_sides(gb, *sb.scene, cone_internal::make_side_setup(*sb.scene, closure, r_max), state_of(sb).grid.cpu);
  result.sides_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  result.side_evaluations = sides.evaluations;
  result.unresolved_pixels = sides.unresolved;
  result.back_pixels = sides.back_pixels;
  result.rim_pixels = sides.rim_pixels;
  if (sides.keys.size() < 2) return out;
  r.c.begin_pass(r.passes, "voxelize sides on the CPU");
  r.c.gl.Flush();  // the first timestamp reaches the GPU before the CPU's work
  for (std::size_t k = 1; k < sides.keys.size(); ++k) {
    VoxelizeOptions side = options;
    side.slab_region = cone_internal::side_region(gb, sides, k, r_max);
    VoxelStats stats;
    VoxelGrid grid = voxelize_world(*sb.scene, closure, side, &stats, sides.keys[k]);
    out.bits.push_back(upload_words(r.c, grid));
    grid.bits = {}, grid.block_bits = {}, grid.window = {};
    out.layout.push_back(std::move(grid));
    result.voxel_stats.winding_evaluations += stats.winding_evaluations;
    result.voxel_stats.winding_voxels_changed += stats.winding_voxels_changed;
  }
  r.c.end_pass(r.passes);
  const std::vector<std::uint32_t> key_of(sides.key_of.begin(), sides.key_of.end());
  out.keys = make_buffer(r.c, key_of.size() * sizeof(std::uint32_t), key_of.data());
  result.side_grids = static_cast<int>(sides.keys.size());
  return out;
}

// One pass of cone_trace.comp on grid `g` (its words in `bits`) into `out`: every pixel (key -1), or
// the pixels whose entry of `keys` is `key`.
void trace_pass(Run& r, const VoxelGrid& g, const Buffer& bits, const Buffer* keys, int key, const ConeSetup& setup, const ConePattern& pattern,
                const Buffer& pattern_buffer, float r_max, const Texture& out) {
  const TraceTables tables = trace_tables(setup, g, r_max);
  const Buffer lane_buffer = make_buffer(r.c, std::span<const float>(tables.lanes));
  const Buffer sphere_buffer = make_buffer(r.c, std::span<const float>(tables.spheres));
  const Buffer prism_buffer = make_buffer(r.c, std::span<const float>(tables.prisms));
  Program& prog = r.begin("cone_trace.comp", "cone");
  const Camera& cam = r.g.camera;
  const Frame basis = cam.basis();
  r.set(prog, "u_eye", cam.eye);
  r.set(prog, "u_basis_x", basis.t);
  r.set(prog, "u_basis_y", basis.b);
  r.set(prog, "u_basis_z", basis.n);
  r.set(prog, "u_origin", g.origin);
  r.set(prog, "u_inv_size", Vec3{1.0f / g.voxel_size.x, 1.0f / g.voxel_size.y, 1.0f / g.voxel_size.z});
  r.c.gl.Uniform2i(r.c.uniform(prog, "u_columns"), g.nx, g.ny);
  r.set(prog, "u_depth_bits", g.depth_bits);
  r.set(prog, "u_cones", pattern.cones);
  r.set(prog, "u_per_cone", static_cast<int>(setup.sphere_distance.size()) + 1);
  r.set(prog, "u_prisms", static_cast<int>(setup.disk.size()));
  r.set(prog, "u_period", pattern.period);
  r.set(prog, "u_key", key);
  r.bind(0, bits);
  r.bind(1, keys ? *keys : pattern_buffer);  // bound either way (read only with u_key >= 0)
  r.bind(2, pattern_buffer);
  r.bind(3, lane_buffer);
  r.bind(4, sphere_buffer);
  r.bind(5, prism_buffer);
  r.finish(out);
}

}  // namespace

MethodOutput run_gpu(Run& r, const GpuMethodInput& in, const ConeParams& params) {
  if (!in.scene) throw InputError("method cone voxelizes the scene, and a G-buffer file has none: give a scene instead of --gbuffer-in");
  if (Access::buffers(*in.scene).context != Access::textures(in.gbuffer).context)
    throw InputError("--device gpu: the scene was uploaded to another device");
  SceneBuffers& sb = Access::buffers(*in.scene);
  const std::uint32_t seed = in.seed;
  const ConeParams p = params.resolved();
  p.validate();
  check_gpu(p);
  const float r_max = in.falloff.radius;
  if (!(r_max > 0.0f) || !std::isfinite(r_max)) throw InputError("cone: R_max must be a finite number > 0");
  // The CPU method's own timings in --json, from the GPU passes that do their work.
  r.report_ms("voxelize_ms", {"voxelize", "count", "voxelize on the CPU", "voxelize sides on the CPU"});
  r.report_ms("trace_ms", {"cone"});
  r.report_ms("filter_ms", {"filter"});
  VoxelizeOptions options = p.voxelize_options(r_max);
  options.rooms = closed_meshes_around(*sb.scene, closure_of(sb), r.g.camera.eye);
  ConeResult result;
  result.grid_reused = grid_is_current(state_of(sb).grid, options);
  if (!result.grid_reused) build_grid(r.c, sb, options, r.passes);
  const VoxelGrid& front = state_of(sb).grid.layout;
  const ConeSetup setup = derive_cone_setup(p);
  const ConePattern pattern = make_cone_pattern(setup, p.jitter, seed);
  std::vector<float> pattern_table;
  const int slots = pattern.period * pattern.period;
  for (int s = 0; s < slots; ++s) {
    pattern_table.insert(pattern_table.end(), {pattern.rot[2 * static_cast<std::size_t>(s)], pattern.rot[2 * static_cast<std::size_t>(s) + 1], 0.0f, 0.0f});
    for (int c = 0; c < pattern.cones; ++c) {
      const ConePattern::Cone& k = pattern.cone[static_cast<std::size_t>(s) * pattern.cones + c];
      pattern_table.insert(pattern_table.end(), {k.x, k.y, k.z, k.scale});
    }
  }
  const Buffer pattern_buffer = make_buffer(r.c, std::span<const float>(pattern_table));

  const SideGrids sides = side_grids(r, sb, in.gbuffer, p, options, r_max, result);
  // One pass per grid, each writing its side's pixels (u_key; -1: every pixel, one grid).
  Texture raw = r.image(GL_R32F);
  for (int k = 0; k < result.side_grids; ++k) {
    const bool front_grid = k == 0;
    const VoxelGrid& g = front_grid ? front : sides.layout[static_cast<std::size_t>(k) - 1];
    const Buffer& bits = front_grid ? state_of(sb).grid.bits : sides.bits[static_cast<std::size_t>(k) - 1];
    trace_pass(r, g, bits, sides.bits.empty() ? nullptr : &sides.keys, sides.bits.empty() ? -1 : k, setup, pattern, pattern_buffer, r_max, raw);
  }

  MethodOutput out;
  if (p.filter_taps > 1) {
    BilateralParams f;
    f.taps = p.filter_taps;
    out.visibility = read_float(r.c, bilateral_filter(r, raw, f, "filter"));
  } else {
    out.visibility = read_float(r.c, raw);
  }
  // The front grid's statistics, with the side grids' winding numbers added (as render_cone).
  const VoxelStats sides_stats = result.voxel_stats;
  result.voxel_stats = state_of(sb).grid.stats;
  result.voxel_stats.winding_evaluations += sides_stats.winding_evaluations;
  result.voxel_stats.winding_voxels_changed += sides_stats.winding_voxels_changed;
  result.grid_nx = front.nx;
  result.grid_ny = front.ny;
  out.stats = cone_stats(result);  // the timings are the passes' GPU times (stats "gpu_ms")
  return out;
}

}  // namespace gpu_detail

VoxelGrid gpu_voxelize_world(GpuDevice& device, const GpuScene& scene, const VoxelizeOptions& options, VoxelStats* stats) {
  using namespace gpu_detail;
  Context& c = Access::context(device);
  c.make_current();
  SceneBuffers& sb = Access::buffers(scene);
  if (sb.context.get() != &c) throw InputError("--device gpu: the scene was uploaded to another device");
  std::vector<PassQuery> passes;
  build_grid(c, sb, options, passes);
  c.resolve(passes);
  VoxelGrid g = state_of(sb).grid.layout;
  const std::size_t words32 = static_cast<std::size_t>(g.nx) * g.ny * (g.depth_bits / 32);
  std::vector<std::uint32_t> w(words32);
  c.gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, state_of(sb).grid.bits.id());
  c.gl.GetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(words32 * sizeof(std::uint32_t)), w.data());
  c.check("reading the voxel grid back");
  // 32-bit words to the CPU grid's 64-bit ones: bit b of a column is bit b % 64 of word b / 64, and
  // the high half of a last word past depth_bits stays zero.
  const int per_column = g.depth_bits / 32;
  g.bits.assign(static_cast<std::size_t>(g.nx) * g.ny * g.words, 0);
  for (std::size_t col = 0; col < static_cast<std::size_t>(g.nx) * g.ny; ++col)
    for (int k = 0; k < per_column; ++k)
      g.bits[col * g.words + static_cast<std::size_t>(k / 2)] |= static_cast<std::uint64_t>(w[col * per_column + static_cast<std::size_t>(k)]) << (32 * (k % 2));
  if (stats) *stats = state_of(sb).grid.stats;
  return g;
}

}  // namespace ao
