// Bake an AO map in a mesh's UVs (outside-in histogram method) and save it as a PNG.
// Usage: bake_map MESH_WITH_UVS [OUT.png] [SIZE]
#include <cstdio>
#include <cstdlib>
#include <exception>

#include <ao/ao.h>

int main(int argc, char** argv) try {
  if (argc < 2) return std::fprintf(stderr, "usage: %s MESH_WITH_UVS [OUT.png] [SIZE]\n", argv[0]), 2;
  const int size = argc > 3 ? std::atoi(argv[3]) : 256;
  // 1. Load the mesh; its first UV set is the map's layout. A glTF's instances become copies: each
  //    placed mesh gets its own AO.
  const ao::Scene scene = ao::load_scene_file(argv[1], {.flatten_instances = true});
  // 2. Which surface point each texel of the size x size map covers.
  const ao::TexelCoverage coverage = ao::compute_texel_coverage(scene, size);
  // 3. Bake: z-buffered views from 128 directions, histogrammed per texel.
  ao::HistogramParams params;
  params.directions = 128;
  ao::BakeResult result = ao::bake_histogram(scene, coverage, params);
  // 4. Pad 16 texels beyond the charts so that mipmaps and filtering do not bleed background in.
  ao::pad(result.visibility, ao::nearest_valid_texel(result.mask, ao::kDefaultPadding));
  // 5. Write the map (linear 8-bit PNG).
  ao::write_image(argc > 2 ? argv[2] : "ao_map.png", result.visibility);
  std::printf("%s: %zu texels baked from %d directions\n", scene.name.c_str(), result.covered_texels, result.directions);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "bake_map: %s\n", e.what());
  return 1;
}
