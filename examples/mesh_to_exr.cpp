// SPDX-License-Identifier: Apache-2.0
// Ambient occlusion of a mesh file, written as a float EXR image: one library call that renders as
// `ao render MESH -o OUT.exr -m METHOD` does, with its defaults (auto-framing, 1280x720, R = 0.1 x
// the objects' diagonal, the method's own samples).
// Usage: mesh_to_exr MESH [OUT.exr] [METHOD]   (METHOD: raytraced, volumetric, cone, ...)
// It includes the render job's header alone, which is all a program that renders needs (and parses
// in about 1.3 s: no JSON parser, no method's header; check_install.sh checks that it compiles with
// <nlohmann/json.hpp> unavailable, bench/tools/parse_time.py times it).
#include <cstdio>
#include <exception>

#include <ao/jobs/render.h>

int main(int argc, char** argv) try {
  if (argc < 2) return std::fprintf(stderr, "usage: %s MESH [OUT.exr] [METHOD]\n", argv[0]), 2;
  ao::RenderRequest request;
  request.scene.args = {argv[1]};                         // OBJ, PLY, OFF, STL, glTF; bad files throw ao::InputError
  request.method = argc > 3 ? argv[3] : "raytraced";      // any method of the registry by name
  request.outputs.visibility = argc > 2 ? argv[2] : "ao.exr";  // V in [0, 1] (1 = open), float; written atomically
  const ao::RenderResult out = ao::run_render(request);
  std::printf("%s: %dx%d, method %s, mean V %.3f over %zu pixels\n", out.scene.c_str(), out.gbuffer.width(), out.gbuffer.height(), out.method.c_str(),
              out.mean_visibility, out.covered_pixels);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "mesh_to_exr: %s\n", e.what());
  return 1;
}
