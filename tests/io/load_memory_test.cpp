// SPDX-License-Identifier: Apache-2.0
// Issue 27, "memory estimated before expansion": a small glTF whose meshes share accessors, or
// whose node tree uses one mesh many times, describes far more geometry than its size; the loader
// counts it from the JSON and refuses a load that does not fit before assimp copies anything
// (exit 3, one line with the estimate). Embree's own failures are one line in words.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/io/gltf_check.h"
#include "ao/reference/embree_scene_internal.h"
#include "ao/reference/ray_scene.h"
#include "ao/scene/procedural.h"
#include "support/bytes.h"
#include "support/run.h"

namespace ao {
namespace {

using nlohmann::json;
using test::TempDir;

constexpr int kVertices = 30000;  // 10,000 triangles per mesh, 360 KB of positions in the file

/// `meshes` meshes that all use one 30,000-vertex accessor, and `nodes` nodes using them in turn.
std::string shared_accessor_gltf(int meshes, int nodes) {
  std::string bytes;
  std::vector<float> p;
  for (int v = 0; v < kVertices; ++v) p.insert(p.end(), {static_cast<float>(v % 3 == 1), static_cast<float>(v % 3 == 2), static_cast<float>(v / 3)});
  test::append(bytes, p);
  json j = json::parse(R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[]}],
    "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":360000}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":30000,"type":"VEC3","min":[0,0,0],"max":[1,1,10000]}]})");
  j["buffers"] = json::array({{{"byteLength", bytes.size()}, {"uri", "data:application/octet-stream;base64," + test::base64(bytes)}}});
  j["meshes"] = json::array();
  for (int m = 0; m < meshes; ++m) j["meshes"].push_back({{"primitives", json::array({{{"attributes", {{"POSITION", 0}}}}})}});
  j["nodes"] = json::array();
  for (int n = 0; n < nodes; ++n) {
    j["nodes"].push_back({{"mesh", n % meshes}, {"translation", {0, 0, n * 2e4}}});
    j["scenes"][0]["nodes"].push_back(n);
  }
  return j.dump();
}

TEST(LoadMemory, TheCheckCountsWhatSharingAndInstancingDescribe) {
  TempDir dir;
  const std::string text = shared_accessor_gltf(3, 12);
  const GltfSize s = check_gltf(dir.write("s.gltf", text), text);
  EXPECT_EQ(s.stored.triangles, 3u * kVertices / 3);
  EXPECT_EQ(s.world.triangles, 12u * kVertices / 3);
  EXPECT_EQ(s.uses, 12u);
  EXPECT_EQ(s.world.vertices, 12u * kVertices);
  EXPECT_EQ(s.stored.bytes, 3u * (kVertices * 12u + kVertices / 3 * 48u));
}

void expect_refused_up_front(const test::RunResult& r) {
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("needs about"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("available (RLIMIT_AS)"), std::string::npos) << r.err;
}

TEST(LoadMemory, ManyCopiesAndManyMeshesAreRefusedBeforeTheyAreMade) {
#ifdef AO_SANITIZED
  GTEST_SKIP() << "address-space limits mean nothing under AddressSanitizer's shadow memory";
#endif
  TempDir dir;
  // 20,000 uses of one mesh: 200M triangles once flattened (bake), 10,000 stored when instanced.
  dir.write("instances.gltf", shared_accessor_gltf(1, 20000));
  // 20,000 meshes over one accessor: 200M triangles stored whatever the reader does.
  dir.write("meshes.gltf", shared_accessor_gltf(20000, 20000));
  const std::string limit = "-v 2097152";  // 2 GiB of address space
  expect_refused_up_front(test::run_ao_limited(limit, "bake instances.gltf --per-vertex pv.ply -q --spp 2", dir.path()));
  expect_refused_up_front(test::run_ao_limited(limit, "render meshes.gltf -o m.png --width 16 --height 16 --spp 1 -q", dir.path()));
  expect_refused_up_front(test::run_ao_limited(limit, "bake meshes.gltf --per-vertex pv.ply -q --spp 2", dir.path()));
  // Instanced, the same 20,000 uses fit: the mesh is kept once (the render then goes on).
  const test::RunResult r = test::run_ao_limited(limit, "render instances.gltf -o i.png --width 16 --height 16 --spp 1 -q", dir.path());
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

TEST(EmbreeErrors, CodesAreSaidInWords) {
  EXPECT_NE(detail::embree_error_text(RTC_ERROR_OUT_OF_MEMORY).find("out of memory"), std::string::npos);
  EXPECT_NE(detail::embree_error_text(RTC_ERROR_UNSUPPORTED_CPU).find("processor"), std::string::npos);
  EXPECT_NE(detail::embree_error_text(77).find("unknown Embree error 77"), std::string::npos);
}

TEST(EmbreeErrors, ABvhBeyondTheAddressSpaceIsAOneLineSystemError) {
#ifdef AO_SANITIZED
  GTEST_SKIP() << "address-space limits mean nothing under AddressSanitizer's shadow memory";
#endif
  // In a child: 2.9M triangles (70 MB of mesh), then an address-space limit 250 MB above what the
  // process uses: enough for Embree's device, not for the BVH (about 130 bytes per triangle at
  // high quality, 370 MB).
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(fds[0]);
    std::string message = "no error";
    try {
      Scene scene;
      scene.name = "big";
      scene.meshes.push_back(make_sphere({0, 0, 0}, 1, 1200, 1200));
      validate_and_prepare(scene);
      rlimit limit{};
      long pages = 0;
      if (FILE* f = std::fopen("/proc/self/statm", "r")) {
        if (std::fscanf(f, "%ld", &pages) != 1) pages = 0;
        std::fclose(f);
      }
      limit.rlim_cur = limit.rlim_max = static_cast<rlim_t>(pages) * 4096 + (250u << 20);
      ::setrlimit(RLIMIT_AS, &limit);
      const RayScene rays(scene);
    } catch (const SystemError& e) {
      message = std::string("SystemError: ") + e.what();
    } catch (const std::exception& e) {
      message = std::string("other: ") + e.what();
    }
    if (::write(fds[1], message.data(), message.size()) < 0) ::_exit(2);
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string got;
  char buf[512];
  for (ssize_t n; (n = ::read(fds[0], buf, sizeof buf)) > 0;) got.append(buf, static_cast<std::size_t>(n));
  ::close(fds[0]);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "the child died (signal " << WTERMSIG(status) << "): " << got;
  EXPECT_EQ(got.rfind("SystemError: embree: ", 0), 0u) << got;
  EXPECT_NE(got.find("out of memory"), std::string::npos) << got;
  EXPECT_EQ(got.find('\n'), std::string::npos) << got;
}

}  // namespace
}  // namespace ao
