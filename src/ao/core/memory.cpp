// SPDX-License-Identifier: Apache-2.0
#include "ao/core/memory.h"

#include <sys/mman.h>
#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <new>
#include <sstream>

#include "ao/core/error.h"
#include "ao/core/image.h"
#include "ao/core/math.h"

namespace ao {

namespace {

// --- render, bytes per pixel --------------------------------------------------------------------
// G-buffer (core/gbuffer.h): position 12 + normal 12 + albedo 12 + object id 4 + triangle index 4
// + uv 8 (depth and coverage are derived; the depth plane a screen-space pass builds, 4, is its
// scratch, within kMethodBytes).
constexpr std::uint64_t kGBufferBytes = 52;
constexpr std::uint64_t kDirectBytes = 12;  // GBuffer::direct, RGB float
// The method's result and scratch, the largest over the registry: ambient transfer keeps V (4),
// W (RGB, 12), obscurance (4) and its per-row buffers. Measured peak resident size per pixel at
// 1448 x 1448 (plane, 1 thread, /usr/bin/time -v, minus the same run at 64 x 64), G-buffer
// included: transfer 98 B, raytraced 63, alchemy 63, volumetric 59, containment 59.
constexpr std::uint64_t kMethodBytes = 48;
constexpr std::uint64_t kShadedBytes = 12 + 6;     // the RGB float image + its 16-bit PNG encoding
constexpr std::uint64_t kVisibilityOutBytes = 2;   // the 16-bit PNG encoding (an EXR is written from the float image)
constexpr std::uint64_t kGBufferOutBytes = 16;     // OpenEXR's line buffers and the channel list (measured: < 16 B/pixel)

// --- ray-traced scene --------------------------------------------------------------------------
// Embree's copies of the geometry (vertices 12 B with its padding, indices 12 B per triangle)
// and a high-quality BVH, which takes up to about 2 nodes and one leaf reference per triangle
// (~90 B), with room for the builder's temporary primitive array (32 B per triangle).
constexpr std::uint64_t kBvhBytesPerTriangle = 12 + 90 + 32;
constexpr std::uint64_t kBvhBytesPerVertex = 16;
// An instance (scene/mesh.h): Embree's instance geometry object with its transform, its share of
// the top-level BVH, the Scene's Instance and the per-instance normal matrix. Measured
// (BENCHMARKS.md, "Instanced glTF"): 2.2 KB per instance at the peak, load included (assimp's
// nodes and JSON, freed before the BVH is built), so 2 KB bounds what the BVH adds.
constexpr std::uint64_t kBytesPerInstance = 2048;

// --- bake, bytes per texel ---------------------------------------------------------------------
// Texel coverage (texel_coverage.h): offsets 4 + world area 4 + UV area 4 + mask 1 + about two
// 16-byte fragments per texel.
constexpr std::uint64_t kCoverageBytes = 45;
// Result and finishing: V 4 + mask 1 + padding's nearest texel 4 + refill masks (4) + encoded
// output (2); the histogram baker adds its numerator, denominator and count (3 x 8).
constexpr std::uint64_t kResultBytes = 4 + 1 + 4 + 4 + 2;
constexpr std::uint64_t kHistogramResultBytes = 24;
constexpr std::uint64_t kBentResultBytes = 12 + 24;  // bent normal image + its integer sums
constexpr std::uint64_t kHistogramThreadBytes = 8;   // per worker: the 64-bit histogram sum
constexpr std::uint64_t kHistogramThreadBentBytes = 24;
constexpr std::uint64_t kViewPixelBytes = 8;         // per worker and view pixel: depth 4 + id 4
constexpr std::uint64_t kMaxViewPixels = 8192ull * 8192ull;  // histogram.cpp coarsens larger views

// Fixed overhead of the process (libraries, thread stacks, allocator pools).
constexpr std::uint64_t kBaseBytes = 64ull << 20;

std::optional<std::uint64_t> mem_available() {
  std::ifstream f("/proc/meminfo");
  std::string line;
  while (std::getline(f, line)) {
    std::istringstream in(line);
    std::string key;
    std::uint64_t kib = 0;
    if (in >> key >> kib && key == "MemAvailable:") return kib * 1024;
  }
  return std::nullopt;
}

std::optional<std::uint64_t> address_space_left() {
  rlimit lim{};
  if (::getrlimit(RLIMIT_AS, &lim) != 0 || lim.rlim_cur == RLIM_INFINITY) return std::nullopt;
  std::ifstream f("/proc/self/statm");
  std::uint64_t pages = 0;
  f >> pages;  // total program size, pages
  const std::uint64_t used = pages * 4096;
  return lim.rlim_cur > used ? lim.rlim_cur - used : 0;
}

}  // namespace

std::uint64_t estimate_render_memory(const RenderMemoryInput& in) {
  const std::uint64_t pixels = static_cast<std::uint64_t>(std::max(in.width, 0)) * static_cast<std::uint64_t>(std::max(in.height, 0));
  std::uint64_t per_pixel = kGBufferBytes + kMethodBytes + kVisibilityOutBytes;
  if (in.sun) per_pixel += kDirectBytes;
  if (in.shaded) per_pixel += kShadedBytes;
  if (in.gbuffer_out) per_pixel += kGBufferOutBytes;
  return kBaseBytes + pixels * per_pixel;
}

std::uint64_t estimate_compare_memory(const CompareMemoryInput& in) {
  const std::uint64_t pixels = static_cast<std::uint64_t>(std::max(in.width, 0)) * static_cast<std::uint64_t>(std::max(in.height, 0));
  const std::uint64_t methods = static_cast<std::uint64_t>(std::max(in.methods, 0));
  const std::uint64_t columns = static_cast<std::uint64_t>(std::max(in.sheet_columns, 0));
  // Per pixel: the G-buffer, its coverage mask, one method's scratch at a time; per method its V
  // (4) and heat map (RGB float, 12); per reference its V (4); per sheet cell an RGB float pixel
  // in its row band and again in the joined sheet (2 x 12), and the sheet's 8-bit encoding (3).
  // Measured (plane, 1024 x 1024, peak resident size, /usr/bin/time): the six methods 730 MB
  // (estimate 812), gtao alone 182 MB (estimate 283).
  const std::uint64_t per_pixel = kGBufferBytes + 1 + kMethodBytes + methods * (4 + 12) + static_cast<std::uint64_t>(std::max(in.references, 0)) * 4 +
                                  methods * columns * (2 * 12 + 3);
  return kBaseBytes + pixels * per_pixel;
}

// Measured (default scene, 64 x 48 pixels, /usr/bin/time, minus columns=256): 2048 columns x 128
// bits 129 MB (estimate 201), 2048 x 512 bits 522 MB (estimate 604): 1.9-1.95 x the grid's bits.
std::uint64_t estimate_cone_grid_memory(int columns, int depth_bits) {
  // Clamped to ConeParams' ranges (columns <= 4096, depth_bits <= 1024): a value beyond them is
  // refused by the method's validate() with its range, not here as a memory error.
  const std::uint64_t c = static_cast<std::uint64_t>(std::clamp(columns, 0, 4096));
  return c * c * (static_cast<std::uint64_t>(std::clamp(depth_bits, 0, 1024)) / 4 + 16);
}

std::uint64_t estimate_ray_scene_memory(std::size_t triangles, std::size_t vertices, std::size_t instances) {
  return kBvhBytesPerTriangle * triangles + kBvhBytesPerVertex * vertices + kBytesPerInstance * instances;
}

std::uint64_t estimate_bake_memory(const BakeMemoryInput& in) {
  const int height = in.height > 0 ? in.height : in.size;
  const std::uint64_t texels = static_cast<std::uint64_t>(std::max(in.size, 0)) * static_cast<std::uint64_t>(std::max(height, 0));
  const std::uint64_t threads = static_cast<std::uint64_t>(std::max(in.threads, 1));
  std::uint64_t bytes = kBaseBytes + texels * (kCoverageBytes + kResultBytes + (in.bent_normals ? kBentResultBytes : 0));
  // The filter's guides (a position and a normal per texel) and its copy of the map.
  if (in.denoise && !in.histogram) bytes += texels * (2 * sizeof(Vec3) + sizeof(float));
  // Measured (grid of 20,000 triangles, 2 threads, 2048^2 minus 256^2, /usr/bin/time -v): histogram
  // 90 B per texel (estimate 116), raytraced 60 (estimate 60).
  if (in.histogram) {
    bytes += texels * kHistogramResultBytes;
    bytes += threads * texels * (kHistogramThreadBytes + (in.bent_normals ? kHistogramThreadBentBytes : 0));
    // A view spans the mesh's bounding square at about pixels_per_texel^2 pixels per texel of
    // surface; charts cover at most the map, so texels x ppt^2 bounds it for meshes that fill
    // their bounding square no less than they fill their UV square.
    const double ppt = std::clamp(static_cast<double>(in.pixels_per_texel), 0.0, 8.0);
    const auto view = static_cast<std::uint64_t>(std::min(static_cast<double>(kMaxViewPixels), static_cast<double>(texels) * ppt * ppt));
    bytes += threads * view * kViewPixelBytes;
  }
  return bytes;
}

std::optional<AvailableMemory> available_memory() {
  const std::optional<std::uint64_t> avail = mem_available();
  const std::optional<std::uint64_t> as_left = address_space_left();
  if (as_left && (!avail || *as_left < *avail)) return AvailableMemory{*as_left, "RLIMIT_AS"};
  if (avail) return AvailableMemory{*avail, "MemAvailable"};
  return std::nullopt;
}

std::string format_bytes(std::uint64_t bytes) {
  const char* units[] = {"B", "kB", "MB", "GB", "TB", "PB", "EB"};
  double v = static_cast<double>(bytes);
  int u = 0;
  while (v >= 1000.0 && u < 6) {
    v /= 1000.0;
    ++u;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, u == 0 ? "%.0f %s" : "%.3g %s", v, units[u]);
  return buf;
}

void check_memory(std::uint64_t bytes, const std::string& what) {
  const std::optional<AvailableMemory> avail = available_memory();
  if (!avail || bytes <= avail->bytes) return;
  throw SystemError(what + " needs about " + format_bytes(bytes) + " of memory, more than the " + format_bytes(avail->bytes) + " available (" +
                    avail->source + ")");
}

namespace detail {

namespace {
constexpr std::size_t kCacheLine = 64, kHugePage = std::size_t{2} << 20, kPage = 4096;
}  // namespace

void* allocate_pixels(std::size_t bytes) {
  if (bytes < kHugePage) return ::operator new(bytes, std::align_val_t{kCacheLine});
  void* p = ::operator new(bytes, std::align_val_t{kHugePage});
#ifdef MADV_HUGEPAGE
  // Advice only (the kernel may have THP off or no huge page free): the result is not checked.
  // The range ends at the last whole 4 KiB page of the block, which is all madvise may be given.
  madvise(p, bytes / kPage * kPage, MADV_HUGEPAGE);
#endif
  return p;
}

void free_pixels(void* p, std::size_t bytes) noexcept {
  ::operator delete(p, std::align_val_t{bytes < kHugePage ? kCacheLine : kHugePage});
}

}  // namespace detail

}  // namespace ao
