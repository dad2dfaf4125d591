// SPDX-License-Identifier: Apache-2.0
// Cone tracing on the GPU: the voxel grid built by rasterization with XOR is the CPU's, bit for bit.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <string>

#include "ao/core/error.h"
#include "ao/methods/cone/voxelize_gpu.h"
#include "ao/io/mesh_io.h"
#include "gpu/gpu_support.h"

namespace ao {
namespace {

using test::gpu_device;

struct GridCase {
  std::string scene;
  int columns, depth_bits;
  OpenMeshes open_meshes = OpenMeshes::Parity;  ///< Slab, Winding: the CPU's solid, voxelized there and uploaded.
};

class GpuVoxelGrid : public ::testing::TestWithParam<GridCase> {};

TEST_P(GpuVoxelGrid, IsBitIdenticalToTheCpuGrid) {
  const GridCase& k = GetParam();
  const Scene scene = k.scene == "dragon"        ? load_scene_file(std::filesystem::path(AO_TEST_MESHES) / "ChineseDragon-10kv.off")
                      : k.scene == "instanced" ? test::instanced_scene()
                                               : make_builtin_scene(k.scene);
  const GpuScene gpu_scene = GpuScene::upload(gpu_device(), scene);
  VoxelizeOptions o;
  o.columns = k.columns;
  o.depth_bits = k.depth_bits;
  o.open_meshes = k.open_meshes;
  VoxelStats cpu_stats, gpu_stats;
  const VoxelGrid cpu = voxelize_world(scene, analyze_closure(scene), o, &cpu_stats);
  const VoxelGrid gpu = gpu_voxelize_world(gpu_device(), gpu_scene, o, &gpu_stats);
  ASSERT_EQ(gpu.nx, cpu.nx);
  ASSERT_EQ(gpu.ny, cpu.ny);
  ASSERT_EQ(gpu.words, cpu.words);
  EXPECT_TRUE(gpu.origin == cpu.origin);
  EXPECT_TRUE(gpu.voxel_size == cpu.voxel_size);
  ASSERT_EQ(gpu.bits.size(), cpu.bits.size());
  std::size_t differing = 0, first = gpu.bits.size();
  for (std::size_t w = 0; w < gpu.bits.size(); ++w)
    if (gpu.bits[w] != cpu.bits[w]) ++differing, first = std::min(first, w);
  EXPECT_EQ(differing, 0u) << k.scene << ": first differing word " << first << " (column " << first / cpu.words << ")";
  EXPECT_GT(cpu_stats.set_voxels, 0u);
  EXPECT_EQ(gpu_stats.set_voxels, cpu_stats.set_voxels);
  EXPECT_EQ(gpu_stats.odd_columns, cpu_stats.odd_columns);
  EXPECT_EQ(gpu_stats.fragments, cpu_stats.fragments);
  EXPECT_EQ(gpu_stats.triangles, cpu_stats.triangles);
}

INSTANTIATE_TEST_SUITE_P(Scenes, GpuVoxelGrid,
                         ::testing::Values(GridCase{"box-room", 128, 128}, GridCase{"default", 256, 128}, GridCase{"sphere-on-plane", 96, 96},
                                           GridCase{"default", 64, 1024}, GridCase{"wedge", 64, 32}, GridCase{"dragon", 512, 128},
                                           GridCase{"instanced", 200, 160}, GridCase{"default", 128, 128, OpenMeshes::Winding},
                                           GridCase{"sphere-on-plane", 96, 96, OpenMeshes::Slab}),
                         [](const ::testing::TestParamInfo<GridCase>& p) {
                           std::string n = p.param.scene + "_" + std::to_string(p.param.columns) + "_" + std::to_string(p.param.depth_bits) +
                                           (p.param.open_meshes == OpenMeshes::Winding ? "_winding" : p.param.open_meshes == OpenMeshes::Slab ? "_slab" : "");
                           for (char& ch : n)
                             if (ch == '-') ch = '_';
                           return n;
                         });

}  // namespace
}  // namespace ao

namespace ao {
namespace {

TEST(GpuVoxelGridLimits, AGridBeyondTheLargestStorageBufferIsAnInputError) {
  const Scene scene = make_builtin_scene("box-room");
  const GpuScene gpu_scene = GpuScene::upload(test::gpu_device(), scene);
  VoxelizeOptions o;
  o.open_meshes = OpenMeshes::Parity;  // the paper's voxelization, the GPU's
  o.columns = 4096;
  o.depth_bits = 1024;  // 2 GiB of bits
  try {
    gpu_voxelize_world(test::gpu_device(), gpu_scene, o);
    ADD_FAILURE() << "no error for a 2 GiB grid";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("exceeds this GPU's largest storage buffer"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace ao
