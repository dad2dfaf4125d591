// SPDX-License-Identifier: Apache-2.0
// Tile-parallel loops over images. The same code runs serial (one thread) or parallel; results
// never depend on the thread count because per-pixel work is independent and seeded per pixel.
#pragma once

#include <utility>

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

namespace ao {

/// Image tile: pixels [x0, x1) x [y0, y1).
struct Tile {
  int x0, y0, x1, y1;
};

/// Calls fn(Tile) for tiles of at most tile_width x tile_height pixels covering width x height,
/// spread over TBB's worker threads (limit them with tbb::global_control).
template <class Fn>
void parallel_for_tiles(int width, int height, int tile_width, int tile_height, Fn&& fn) {
  tbb::parallel_for(
      tbb::blocked_range2d<int>(0, height, tile_height, 0, width, tile_width),
      [&](const tbb::blocked_range2d<int>& r) { fn(Tile{r.cols().begin(), r.rows().begin(), r.cols().end(), r.rows().end()}); },
      tbb::simple_partitioner());
}

/// Square tiles of at most tile_size x tile_size pixels.
template <class Fn>
void parallel_for_tiles(int width, int height, int tile_size, Fn&& fn) {
  parallel_for_tiles(width, height, tile_size, tile_size, std::forward<Fn>(fn));
}

}  // namespace ao
