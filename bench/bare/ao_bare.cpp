// SPDX-License-Identifier: Apache-2.0
// ao_bare: the bare Embree loop of bench/bare_embree.h as a process of its own, for comparing
// cold runs with `ao render --method raytraced --json` (BENCHMARKS.md). It takes the camera, R and
// ray count from the command line, as `ao render` reports them, and prints the times of its BVH
// build, primary pass and AO pass as JSON.
//
//   ao_bare MESH... --eye x,y,z --target x,y,z --fov DEG --radius R [--spp 64] [--ground]
//                   [--width 1280 --height 720]
// --ground adds the ground quad of bench_scenes.h (mesh_on_ground) under the meshes.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "../bare_embree.h"
#include "ao/io/mesh_io.h"
#include "ao/scene/procedural.h"

namespace {

ao::Vec3 parse3(const char* s) {
  ao::Vec3 v;
  if (std::sscanf(s, "%f,%f,%f", &v.x, &v.y, &v.z) != 3) {
    std::fprintf(stderr, "ao_bare: expected x,y,z, got %s\n", s);
    std::exit(1);
  }
  return v;
}

double ms_since(std::chrono::steady_clock::time_point& t) {
  const auto now = std::chrono::steady_clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - t).count();
  t = now;
  return ms;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> meshes;
  ao::Camera cam;
  cam.width = 1280;
  cam.height = 720;
  float radius = 0.1f;
  int spp = 64;
  bool ground = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto next = [&] {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "ao_bare: %s needs a value\n", a.c_str());
        std::exit(1);
      }
      return argv[++i];
    };
    if (a == "--eye") cam.eye = parse3(next());
    else if (a == "--target") cam.target = parse3(next());
    else if (a == "--up") cam.up = parse3(next());
    else if (a == "--fov") cam.vertical_fov_deg = std::strtof(next(), nullptr);
    else if (a == "--radius") radius = std::strtof(next(), nullptr);
    else if (a == "--spp") spp = std::atoi(next());
    else if (a == "--width") cam.width = std::atoi(next());
    else if (a == "--height") cam.height = std::atoi(next());
    else if (a == "--ground") ground = true;
    else meshes.push_back(a);
  }
  auto clock = std::chrono::steady_clock::now();
  ao::Scene scene;
  for (const std::string& m : meshes) {
    ao::Scene s = ao::load_scene_file(m);
    for (ao::Mesh& mesh : s.meshes) scene.meshes.push_back(std::move(mesh));
  }
  if (ground) {
    const ao::Bounds3 b = scene.bounds();
    const ao::Vec3 c = b.center(), e = b.extent() * 1.5f;
    const float y = b.lo.y;
    scene.meshes.push_back(ao::make_quad({c.x - e.x, y, c.z + e.z}, {c.x + e.x, y, c.z + e.z}, {c.x + e.x, y, c.z - e.z}, {c.x - e.x, y, c.z - e.z}));
  }
  ao::validate_and_prepare(scene);
  const double load_ms = ms_since(clock);
  const ao::bench::bare::Loop loop(scene);
  const double bvh_ms = ms_since(clock);
  std::vector<ao::bench::bare::Hit> hits;
  loop.primary(cam, hits);
  const double primary_ms = ms_since(clock);
  std::uint64_t rays = 0;
  const std::uint64_t open = loop.ambient_occlusion(hits, cam.width, cam.height, radius, spp, 1e-6f * scene.bounds().diagonal(), &rays);
  const double ao_ms = ms_since(clock);
  std::printf("{\"load_ms\": %.2f, \"bvh_ms\": %.2f, \"primary_ms\": %.2f, \"ao_ms\": %.2f, \"rays\": %llu, \"mean_visibility\": %.5f}\n", load_ms,
              bvh_ms, primary_ms, ao_ms, static_cast<unsigned long long>(rays), rays ? static_cast<double>(open) / static_cast<double>(rays) : 1.0);
  return 0;
}
