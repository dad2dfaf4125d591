// SPDX-License-Identifier: Apache-2.0
// libFuzzer harness of ao bake's glTF round trip: each input is the content of a .gltf or .glb
// (AO_FUZZ_EXTENSION) loaded as a GltfDocument, whose first bakeable mesh's world scene is built,
// given a map and COLOR_0, and saved as GLB. InputError is the expected answer to bad input; a
// crash, a sanitizer report, an allocation over libFuzzer's -malloc_limit_mb, a timeout or any
// other exception is a finding. Run through scripts/fuzz.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "ao/core/error.h"
#include "ao/io/gltf_document.h"

namespace {

namespace fs = std::filesystem;

/// The input and the output of one fuzzing process, in memory when /dev/shm exists; the input
/// sits in a folder of its own, so the files a glTF may name beside it are only these two.
const fs::path& work_dir() {
  static const fs::path dir = [] {
    const fs::path base = fs::exists("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
    const fs::path d = base / ("ao-fuzz-doc-" + std::to_string(getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

struct RemoveAtExit {
  ~RemoveAtExit() {
    std::error_code ec;
    fs::remove_all(work_dir(), ec);
  }
} remove_at_exit;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const fs::path in = work_dir() / (std::string("in") + AO_FUZZ_EXTENSION), out = work_dir() / "out.glb";
  {
    std::ofstream f(in, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    ao::GltfDocument doc(in, 0);
    const std::vector<int> meshes = doc.instanced_meshes(true);
    // The flattened scene can be the file's vertices times its nodes: callers check its size
    // first (ao bake estimates the BVH's memory), so the harness does too.
    if (!meshes.empty() && doc.world_vertex_count() < 4'000'000 && doc.world_triangle_count() < 4'000'000) {
      const ao::GltfWorldScene w = doc.world_scene(meshes.front());
      for (std::size_t i = 0; i < w.sources.size(); ++i)
        if (w.sources[i].first_instance) doc.set_vertex_ao(w.sources[i].mesh, w.sources[i].primitive, std::vector<float>(w.scene.meshes[i].positions.size(), 0.5f));
      doc.add_occlusion_map(meshes.front(), std::string("\x89PNG\r\n\x1a\n", 8));
    }
    (void)doc.save_glb(out);
  } catch (const ao::InputError&) {
  }
  return 0;
}
