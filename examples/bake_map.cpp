// SPDX-License-Identifier: Apache-2.0
// Bake an AO map in a mesh's UVs and save it: one library call that bakes as `ao bake MESH -o OUT
// --size SIZE` does, with its defaults (ray-traced, 64 rays per texel, texture-space denoising,
// 16 texels of padding).
// Usage: bake_map MESH_WITH_UVS [OUT.png] [SIZE]
#include <cstdio>
#include <cstdlib>
#include <exception>

#include <ao/ao.h>

int main(int argc, char** argv) try {
  if (argc < 2) return std::fprintf(stderr, "usage: %s MESH_WITH_UVS [OUT.png] [SIZE]\n", argv[0]), 2;
  ao::BakeRequest request;
  request.inputs = {argv[1]};  // its first UV set is the map's layout
  request.outputs.map = argc > 2 ? argv[2] : "ao_map.png";  // .png, .tif, .tga, .jpg or .exr; linear
  if (argc > 3) request.size = ao::parse_map_size(argv[3]);  // "512" or "1024x512"; default 1024
  const ao::BakeBatchResult out = ao::run_bake(request);
  const ao::BakeResult& map = out.meshes.at(0).map;
  std::printf("%s: %dx%d map, %zu texels baked\n", argv[1], map.visibility.width(), map.visibility.height(), map.covered_texels);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "bake_map: %s\n", e.what());
  return 1;
}
