// SPDX-License-Identifier: Apache-2.0
// Memory estimates: they grow with what they count, the check refuses what cannot fit with one
// line naming the size and the limit, and the available memory is known on Linux.
#include "ao/core/memory.h"

#include <gtest/gtest.h>

#include "ao/core/error.h"

namespace ao {
namespace {

TEST(Memory, EstimatesGrowWithWhatTheyCount) {
  const std::uint64_t small = estimate_render_memory({.width = 100, .height = 100});
  const std::uint64_t big = estimate_render_memory({.width = 1000, .height = 1000});
  // Per pixel at least the G-buffer's 53 bytes (core/gbuffer.h): 990,000 more pixels.
  EXPECT_GE(big - small, 990000u * 53u);
  EXPECT_GT(estimate_render_memory({.width = 100, .height = 100, .sun = true, .shaded = true, .gbuffer_out = true}), small);
  EXPECT_GT(estimate_bake_memory({.size = 2048}), estimate_bake_memory({.size = 1024}));
  // Histogram workers each hold their own accumulators and view.
  EXPECT_GT(estimate_bake_memory({.size = 1024, .threads = 8}), estimate_bake_memory({.size = 1024, .threads = 1}));
  EXPECT_GT(estimate_bake_memory({.size = 1024, .histogram = true}), estimate_bake_memory({.size = 1024, .histogram = false}));
  EXPECT_EQ(estimate_ray_scene_memory(0, 0), 0u);
  EXPECT_GT(estimate_ray_scene_memory(2000, 1000), estimate_ray_scene_memory(1000, 500));
  // At least the grid's bits: 4096^2 columns x 1024 bits = 2 GiB.
  EXPECT_GE(estimate_cone_grid_memory(4096, 1024), 4096ull * 4096ull * 1024ull / 8ull);
  EXPECT_EQ(estimate_cone_grid_memory(1 << 30, 1024), estimate_cone_grid_memory(4096, 1024));  // clamped to the method's range
}

TEST(Memory, FormatsBytesInDecimalUnits) {
  EXPECT_EQ(format_bytes(999), "999 B");
  EXPECT_EQ(format_bytes(1500), "1.5 kB");
  EXPECT_EQ(format_bytes(128849018880ull), "129 GB");
}

TEST(Memory, AvailableMemoryIsKnownOnLinux) {
  const auto avail = available_memory();
  ASSERT_TRUE(avail.has_value());
  EXPECT_GT(avail->bytes, 0u);
  EXPECT_TRUE(avail->source == "MemAvailable" || avail->source == "RLIMIT_AS") << avail->source;
}

TEST(Memory, CheckRefusesWhatCannotFitWithOneLine) {
  EXPECT_NO_THROW(check_memory(0, "nothing"));
  try {
    check_memory(~std::uint64_t{0}, "ao render: 1x1 pixels");
    ADD_FAILURE() << "no exception";
  } catch (const SystemError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_EQ(what.rfind("ao render: 1x1 pixels needs about ", 0), 0u) << what;
    EXPECT_NE(what.find("available"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace ao
