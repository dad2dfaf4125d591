// SPDX-License-Identifier: Apache-2.0
// Load, BVH and trace costs of one mesh file, as BENCHMARKS.md's "Loading big meshes" reports them:
//   ao_load_timer /tmp/elephant-30M.ply [--quality low|medium|high] [--compact 0|1] [--flatten] [--trace] [--bake N [--distance R]]
// prints the triangle count, the load's wall and CPU seconds, the BVH build's wall and CPU seconds
// (all threads), and the peak resident memory after each step, per triangle. --quality and
// --compact override RayScene's size rule (BvhOptions). --flatten loads a glTF's instances as
// copies (LoadOptions::flatten_instances); the triangle count printed is of the triangles drawn.
// --trace then renders a 480x270 G-buffer
// of the auto-framed scene and 64 ray-traced AO rays per pixel with R = 2% of the scene's diagonal,
// and prints the trace's CPU seconds and rays per CPU second: the trace speed of a BVH. --bake N
// runs the ray-traced per-vertex bake with N rays per vertex (unlimited distance, or R with
// --distance) and prints its rays per CPU second. CPU times are the numbers to compare on a
// shared, loaded machine.
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "ao/bake/raytraced_bake.h"
#include "ao/core/camera.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/io/mesh_io.h"
#include "ao/reference/ray_scene.h"
#include "ao/reference/raytraced.h"

namespace {

double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double peak_rss_bytes() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmHWM:", 0) == 0) return 1024.0 * std::stod(line.substr(6));
  return 0;
}

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

const char* quality_name(ao::BvhQuality q) {
  return q == ao::BvhQuality::High ? "high" : q == ao::BvhQuality::Medium ? "medium" : "low";
}

}  // namespace

int main(int argc, char** argv) {
  const char* usage = "usage: ao_load_timer MESH [--quality low|medium|high] [--compact 0|1] [--flatten] [--trace] [--bake N [--distance R]]\n";
  if (argc < 2) {
    std::fputs(usage, stderr);
    return 2;
  }
  ao::BvhOptions options;
  bool trace = false, flatten = false;
  int bake_samples = 0;
  float distance = 0;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--trace") {
      trace = true;
    } else if (a == "--flatten") {
      flatten = true;
    } else if (a == "--quality" && i + 1 < argc) {
      const std::string q = argv[++i];
      options.quality = q == "low" ? ao::BvhQuality::Low : q == "medium" ? ao::BvhQuality::Medium : ao::BvhQuality::High;
    } else if (a == "--bake" && i + 1 < argc) {
      bake_samples = std::atoi(argv[++i]);
    } else if (a == "--distance" && i + 1 < argc) {
      distance = static_cast<float>(std::atof(argv[++i]));
    } else if (a == "--compact" && i + 1 < argc) {
      options.compact = std::strcmp(argv[++i], "0") != 0;
    } else {
      std::fputs(usage, stderr);
      return 2;
    }
  }
  try {
    double wall = now(), cpu = cpu_seconds();
    const ao::Scene scene = ao::load_scene_file(argv[1], {.flatten_instances = flatten});
    const double load_wall = now() - wall, load_cpu = cpu_seconds() - cpu, load_peak = peak_rss_bytes();
    const double triangles = static_cast<double>(scene.triangle_count());
    wall = now();
    cpu = cpu_seconds();
    const ao::RayScene rs(scene, options);
    const double bvh_wall = now() - wall, bvh_cpu = cpu_seconds() - cpu, bvh_peak = peak_rss_bytes();
    std::printf("%s: %.0f triangles (%zu stored, %zu instances); load %.2f s wall, %.2f s CPU, peak %.0f MB (%.0f B/triangle); "
                "BVH (%s%s) %.2f s wall, %.2f s CPU, peak %.0f MB (%.0f B/triangle)\n",
                argv[1], triangles, scene.stored_triangle_count(), scene.instances.size(), load_wall, load_cpu, load_peak / 1e6, load_peak / triangles, quality_name(rs.quality()),
                rs.compact() ? ", compact" : "", bvh_wall, bvh_cpu, bvh_peak / 1e6, bvh_peak / triangles);
    if (trace) {
      const ao::Bounds3 b = scene.bounds();
      const ao::Camera cam = ao::frame_bounds(b, ao::Vec3{1, 0.4f, 1}, 45.0f, 480, 270);
      ao::Falloff falloff;
      falloff.radius = 0.02f * ao::length(b.extent());
      ao::RaytracedParams params;
      params.samples = 64;
      params.min_samples = 64;
      cpu = cpu_seconds();
      const ao::GBuffer g = ao::render_gbuffer(rs, cam);
      const ao::RaytracedImage img = ao::render_raytraced(rs, g, falloff, params, 1);
      const double trace_cpu = cpu_seconds() - cpu;
      const double rays = static_cast<double>(img.rays) + 480.0 * 270.0;
      std::printf("trace: %.0f rays (primary + AO) in %.2f s CPU, %.2f M rays per CPU second\n", rays, trace_cpu, rays / trace_cpu / 1e6);
    }
    if (bake_samples > 0) {
      ao::RaytracedBakeParams params;
      params.samples = bake_samples;
      if (distance > 0) params.max_distance = distance;
      std::uint64_t rays = 0;
      cpu = cpu_seconds();
      wall = now();
      ao::bake_vertices_raytraced(rs, params, &rays);
      const double bake_cpu = cpu_seconds() - cpu, bake_wall = now() - wall;
      std::printf("per-vertex bake: %llu rays in %.2f s CPU (%.2f s wall), %.2f M rays per CPU second\n", static_cast<unsigned long long>(rays),
                  bake_cpu, bake_wall, static_cast<double>(rays) / bake_cpu / 1e6);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ao_load_timer: %s\n", e.what());
    return 1;
  }
}
