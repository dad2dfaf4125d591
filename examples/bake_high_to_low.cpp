// SPDX-License-Identifier: Apache-2.0
// The two other bakes of `ao bake`, as library calls with its defaults:
//   1. high to low: the AO of a detailed mesh baked into a simple mesh's UVs
//      (`ao bake LOW --high HIGH -o LOW_ao.png`): rays start on a cage pushed out from the low
//      mesh, find the high surface, and trace the AO from there;
//   2. per-vertex AO of a mesh (`ao bake HIGH --per-vertex HIGH_ao.ply`): a PLY with the AO as vertex
//      colour and float quality, for meshes without UVs.
// Usage: bake_high_to_low LOW_WITH_UVS HIGH [SIZE]
#include <cstdio>
#include <exception>

#include <ao/ao.h>

int main(int argc, char** argv) try {
  if (argc < 3) return std::fprintf(stderr, "usage: %s LOW_WITH_UVS HIGH [SIZE]\n", argv[0]), 2;
  ao::BakeRequest low;
  low.inputs = {argv[1]};
  low.high = {argv[2]};
  low.outputs.map = "low_ao.png";
  if (argc > 3) low.size = ao::parse_map_size(argv[3]);
  // mesh() on the temporary result moves the mesh's outcome out of it: `map` stays valid.
  const ao::MeshBake baked = ao::run_bake(low).mesh();
  const ao::BakeResult& map = baked.map;

  ao::BakeRequest high;
  high.inputs = {argv[2]};
  high.outputs.per_vertex = "high_ao.ply";
  const ao::BakeBatchResult per_vertex = ao::run_bake(high);  // or keep the whole result
  const std::vector<float>& vertex_ao = per_vertex.mesh().vertex_ao;
  double mean = 0;
  for (float v : vertex_ao) mean += v / static_cast<double>(vertex_ao.size());
  std::printf("low_ao.png: %zu texels from the high mesh; high_ao.ply: %zu vertices, mean V %.3f\n", map.covered_texels, vertex_ao.size(), mean);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "bake_high_to_low: %s\n", e.what());
  return 1;
}
