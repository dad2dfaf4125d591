// ao bake's glTF round trip: a glTF/GLB input baked to --gltf (or --per-vertex out.glb) keeps its
// document (gltf_document.h). Each glTF mesh with the UV set is baked once, into a map of its own,
// at its first instance with every other instance and mesh occluding; per-vertex AO becomes each
// primitive's COLOR_0. bake.cpp chooses this path and supplies the bakers.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/bake/bake_result.h"
#include "ao/io/output_set.h"
#include "ao/scene/mesh.h"

namespace ao::cli {

struct GltfRoundTrip {
  std::filesystem::path input;
  std::filesystem::path gltf;        ///< --gltf output, or empty.
  std::filesystem::path per_vertex;  ///< --per-vertex .glb output, or empty.
  std::filesystem::path map;         ///< -o map file (written only when the document bakes one mesh), or empty.
  int uv_set = 0, width = 1024, height = 1024, png_bits = 8, padding = 0;
  bool json = false;
  /// The extra occluders (--occluder, --floor) for a world scene with these bounds.
  std::function<std::vector<Mesh>(const Scene& world)> occluders;
  /// V per texel of a width x height map of the scene's meshes that have UVs (the others occlude);
  /// `label` names the baked mesh for the progress bar.
  std::function<BakeResult(const Scene& scene, const std::string& label)> bake_map;
  /// V per vertex of every mesh of the scene, concatenated; `rays` (may be null) gets the ray count.
  std::function<std::vector<float>(const Scene& scene, std::uint64_t* rays)> bake_vertices;
};

/// Bakes and writes the outputs of `job` through `outputs` (renamed together by the caller's
/// commit). Returns the --json summary of the input. Throws InputError for a document without
/// a mesh to bake, and -o when more than one mesh is baked (each has its own map).
nlohmann::json bake_gltf_round_trip(const GltfRoundTrip& job, OutputSet& outputs);

}  // namespace ao::cli
