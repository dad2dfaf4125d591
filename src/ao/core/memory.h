// SPDX-License-Identifier: Apache-2.0
// Memory a run needs, estimated before the big allocations, against the memory the machine can
// give (SPEC, "Behaviour on bad input": never an endless allocation). The estimates are upper
// bounds in bytes built from what the code allocates (per-pixel, per-texel, per-triangle terms
// with the byte counts written beside them), compared in memory.cpp with peak resident sizes
// measured with /usr/bin/time, and checked to bound the measured peak by
// tests/cli/outputs_cli_test.cpp. Reading /proc/meminfo is the one system query here.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace ao {

/// What `ao render` allocates that grows with the image.
struct RenderMemoryInput {
  int width = 0, height = 0;  ///< Pixels.
  bool sun = false;           ///< A direct-light pass (12 bytes per pixel more).
  bool shaded = false;        ///< A shaded RGB image is written too.
  bool gbuffer_out = false;   ///< The G-buffer is written to EXR too.
};
/// Peak bytes of a render's images: the G-buffer, the method's results and scratch (the largest
/// of the registry's methods), and the encoded outputs, plus a fixed 64 MiB for the process.
std::uint64_t estimate_render_memory(const RenderMemoryInput& in);

/// What `ao compare` allocates that grows with the image.
struct CompareMemoryInput {
  int width = 0, height = 0;  ///< Pixels.
  int methods = 0;            ///< Methods compared (rows of the table and the sheet).
  int references = 0;         ///< Distinct references rendered.
  int sheet_columns = 3;      ///< Images per row of the contact sheet (V, reference, heat map; 5 with the GPU).
};
/// Peak bytes of a comparison's images: the G-buffer, the scratch of the method that runs (the
/// largest of the registry's), each method's V and heat map and each reference's V (kept for the
/// table and the sheet), and the contact sheet (its rows, then the joined sheet, and its
/// encoding), plus a fixed 64 MiB for the process.
std::uint64_t estimate_compare_memory(const CompareMemoryInput& in);

/// Peak bytes of cone tracing's voxel grid of columns x columns x depth_bits voxels (ConeParams;
/// the eye grid has at most that many): the bit grid, its coarser levels and the voxelizer's
/// scratch, about twice the grid's bits, plus 16 bytes of masks per column. Arguments are clamped
/// to ConeParams' ranges.
std::uint64_t estimate_cone_grid_memory(int columns, int depth_bits);

/// Peak bytes of the ray-traced scene (Embree BVH and its copy of the geometry) for a scene of
/// `triangles` triangles and `vertices` vertices held in memory (Scene::stored_triangle_count,
/// an instanced mesh once) and `instances` instances, beyond the Scene itself.
std::uint64_t estimate_ray_scene_memory(std::size_t triangles, std::size_t vertices, std::size_t instances = 0);

/// What `ao bake` allocates that grows with the map.
struct BakeMemoryInput {
  int size = 0;               ///< Map width, texels.
  int height = 0;             ///< Map height, texels; 0: equal to `size` (a square map).
  bool histogram = true;      ///< The histogram baker (per-thread accumulators and views), else raytraced.
  bool bent_normals = false;  ///< Bent normals are accumulated and written too.
  float pixels_per_texel = 1; ///< Histogram view resolution (HistogramParams::pixels_per_texel).
  int threads = 1;            ///< Worker threads (each histogram worker has its own accumulators and view).
  bool denoise = false;       ///< The ray-traced map is filtered (RaytracedBakeParams::denoise > 0): its guides and a copy of the map.
};
/// Peak bytes of a map bake: coverage, accumulators, result, padding and the encoded output.
std::uint64_t estimate_bake_memory(const BakeMemoryInput& in);

/// Memory this process can still allocate: the smaller of /proc/meminfo's MemAvailable and, when
/// RLIMIT_AS is set, the limit minus the address space already in use. `source` says which.
struct AvailableMemory {
  std::uint64_t bytes = 0;
  std::string source;  ///< "MemAvailable" or "RLIMIT_AS".
};
/// Nullopt when neither is known (no /proc, no limit): then nothing is refused up front.
std::optional<AvailableMemory> available_memory();

/// "12.3 GB" (decimal units, three significant digits).
std::string format_bytes(std::uint64_t bytes);

/// Throws SystemError "`what` needs about X, more than the Y available (source)" when `bytes`
/// exceeds available_memory(); does nothing when it fits or nothing is known.
void check_memory(std::uint64_t bytes, const std::string& what);

}  // namespace ao
