// SPDX-License-Identifier: Apache-2.0
// run_bake as a library user meets it: a BakeRequest with nothing but its input and output bakes
// exactly what `ao bake` bakes with no options.
#include "ao/jobs/bake.h"

#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "ao/io/image_io.h"
#include "support/run.h"

namespace ao {
namespace {

// A 4 x 4 floor with UVs (the whole unit square) and a unit box on it without UVs, an occluder of
// the floor's map, as OBJ text.
std::string floor_and_box_obj() {
  std::ostringstream obj;
  obj << "o floor\n";
  const int corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (const auto& c : corner) obj << "v " << 4 * c[0] - 2 << " 0 " << 4 * c[1] - 2 << "\n";
  for (const auto& c : corner) obj << "vt " << c[0] << " " << c[1] << "\n";
  obj << "f 1/1 4/4 3/3 2/2\no box\n";
  for (int i = 0; i < 8; ++i) obj << "v " << (i & 1) - 0.5 << " " << (i >> 1 & 1) << " " << (i >> 2 & 1) - 0.5 << "\n";
  // Faces outward: -z, +z, -y, +y, -x, +x (vertices 5..12: bit 0 x, bit 1 y, bit 2 z).
  obj << "f 5 7 8 6\nf 9 10 12 11\nf 5 6 10 9\nf 7 11 12 8\nf 5 9 11 7\nf 6 8 12 10\n";
  return obj.str();
}

TEST(BakeJob, DefaultRequestBakesWhatTheCommandBakes) {
  test::TempDir dir;
  const auto mesh = dir.write("scene.obj", floor_and_box_obj());
  const test::RunResult cli = test::run_ao("bake scene.obj -o cli.exr --size 96", dir.path());
  ASSERT_EQ(cli.exit_code, 0) << cli.err;

  BakeRequest request;
  request.inputs = {mesh};
  request.outputs.map = dir / "lib.exr";
  request.size = MapSize{96, 96};
  const BakeBatchResult out = run_bake(request);
  ASSERT_EQ(out.meshes.size(), 1u);
  const Image<float> from_cli = read_image(dir / "cli.exr"), from_lib = read_image(dir / "lib.exr");
  const Image<float>& in_memory = out.meshes[0].map.visibility;
  ASSERT_EQ(from_cli.width(), 96);
  ASSERT_EQ(from_lib.width(), 96);
  ASSERT_EQ(in_memory.width(), 96);
  std::size_t open_texels = 0, occluded_texels = 0;
  for (std::size_t i = 0; i < from_cli.size(); ++i) {
    ASSERT_EQ(from_lib[i], from_cli[i]) << "texel " << i;
    ASSERT_EQ(in_memory[i], from_cli[i]) << "texel " << i;
    open_texels += from_cli[i] > 0.99f;
    occluded_texels += from_cli[i] < 0.9f;
  }
  // The map is a bake, not a constant: open floor far from the box, occluded floor beside it.
  EXPECT_GT(open_texels, 0u);
  EXPECT_GT(occluded_texels, 0u);
}

}  // namespace
}  // namespace ao
