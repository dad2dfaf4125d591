// Load and BVH costs of one mesh file, as BENCHMARKS.md's "Loading big meshes" reports them:
//   ao_load_timer /tmp/elephant-30M.ply
// prints the triangle count, the load's wall and CPU seconds (load_scene_file is single-threaded,
// so its CPU time is its time on an idle machine), the BVH build's wall and CPU seconds (all
// threads), and the peak resident memory after each step, per triangle. CPU times are the numbers
// to compare on a shared, loaded machine.
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>

#include "ao/io/mesh_io.h"
#include "ao/reference/ray_scene.h"

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

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: ao_load_timer MESH\n");
    return 2;
  }
  try {
    double wall = now(), cpu = cpu_seconds();
    const ao::Scene scene = ao::load_scene_file(argv[1]);
    const double load_wall = now() - wall, load_cpu = cpu_seconds() - cpu, load_peak = peak_rss_bytes();
    const double triangles = static_cast<double>(scene.triangle_count());
    wall = now();
    cpu = cpu_seconds();
    const ao::RayScene rs(scene);
    const double bvh_wall = now() - wall, bvh_cpu = cpu_seconds() - cpu, bvh_peak = peak_rss_bytes();
    std::printf("%s: %.0f triangles; load %.2f s wall, %.2f s CPU, peak %.0f MB (%.0f B/triangle); "
                "BVH %.2f s wall, %.2f s CPU, peak %.0f MB (%.0f B/triangle)\n",
                argv[1], triangles, load_wall, load_cpu, load_peak / 1e6, load_peak / triangles, bvh_wall, bvh_cpu, bvh_peak / 1e6,
                bvh_peak / triangles);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ao_load_timer: %s\n", e.what());
    return 1;
  }
}
