// SPDX-License-Identifier: Apache-2.0
// libFuzzer harness: each input is the content of a mesh file named *AO_FUZZ_EXTENSION, loaded with
// load_scene_file. InputError is the expected answer to bad input; a crash, a sanitizer report, an
// allocation over libFuzzer's -malloc_limit_mb, a timeout or any other exception is a finding.
// Run through scripts/fuzz.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "ao/core/error.h"
#include "ao/io/mesh_io.h"

namespace {

/// One file per fuzzing process, in memory when /dev/shm exists (the loader reads a path).
const std::filesystem::path& input_path() {
  static const std::filesystem::path path = [] {
    const std::filesystem::path dir = std::filesystem::exists("/dev/shm") ? std::filesystem::path("/dev/shm") : std::filesystem::temp_directory_path();
    return dir / ("ao-fuzz-" + std::to_string(getpid()) + AO_FUZZ_EXTENSION);
  }();
  return path;
}

struct RemoveAtExit {
  ~RemoveAtExit() {
    std::error_code ec;
    std::filesystem::remove(input_path(), ec);
  }
} remove_at_exit;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  {
    std::ofstream out(input_path(), std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    (void)ao::load_scene_file(input_path());
  } catch (const ao::InputError&) {
  }
  return 0;
}
