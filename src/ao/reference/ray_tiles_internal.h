// SPDX-License-Identifier: Apache-2.0
// The one tile loop of every Embree pass (the references, the sun pass, the G-buffer, the bakers):
// the packet width chosen once for the scene, the image cut into tiles spread over TBB's threads,
// flush-to-zero and denormals-are-zero on the thread that traces, and a fresh intersect context per
// tile. Each pass says what one tile does and how much work it was, and progress is reported in
// those units (covered pixels, texels, vertices), so a bar's rate is not skewed by tiles of
// background. The denormal mode is the tile's own and is restored after it, so code that runs on a
// pool thread later does not inherit it. Internal to the ray-tracing passes (namespace detail).
#pragma once

#include <algorithm>
#include <cstddef>

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include "ao/core/parallel.h"
#include "ao/core/progress.h"
#include "ao/reference/embree_scene_internal.h"
#include "ao/reference/packets_internal.h"

namespace ao::detail {

/// How a pass cuts its image into tiles and traces them.
struct RayTiling {
  int tile_width = 16;   ///< Pixels (texels, items) per tile, across. >= 1.
  int tile_height = 16;  ///< Per tile, down. >= 1.
  /// Embree's hint for the rays of a tile: incoherent (its default) for AO rays spread over the
  /// hemisphere, coherent for primary and sun rays of neighbouring pixels.
  RTCIntersectContextFlags flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  /// false: one TBB task per tile (tiles of very uneven cost, such as AO rays over a G-buffer with
  /// background). true: TBB's auto partitioner over the grid of tile indices hands each thread
  /// blocks of tiles, splitting further only when a thread runs dry: fewer task switches where
  /// every tile costs about the same (the G-buffer's primary rays).
  bool blocks_of_tiles = false;
};

/// Calls fn.template operator()<N>(ctx, tile) for tiles covering [0, width) x [0, height), in
/// parallel, N the scene's packet width (dispatch_packet_width), ctx an intersect context with
/// `tiling.flags` made for that tile, under FlushDenormalsScope. fn returns the units of work the tile held (any unit the
/// pass's total is in), which are added to `progress`. Which thread runs a tile is not
/// deterministic, so a tile's result may depend only on its own pixels.
template <class Fn>
void for_each_ray_tile(const RayScene& rs, int width, int height, const RayTiling& tiling, ProgressCounter& progress, Fn&& fn) {
  dispatch_packet_width(rs.native_packet_width(), [&]<int N>() {
    const auto run = [&](const Tile& t) {
      const FlushDenormalsScope ftz;
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      ctx.flags = tiling.flags;
      progress.add(fn.template operator()<N>(ctx, t));
    };
    if (!tiling.blocks_of_tiles) {
      parallel_for_tiles(width, height, tiling.tile_width, tiling.tile_height, run);
      return;
    }
    // The range is of tile indices, so the tiles are the same however TBB splits it.
    const int columns = (width + tiling.tile_width - 1) / tiling.tile_width, rows = (height + tiling.tile_height - 1) / tiling.tile_height;
    tbb::parallel_for(tbb::blocked_range2d<int>(0, rows, 0, columns), [&](const tbb::blocked_range2d<int>& r) {
      for (int ty = r.rows().begin(); ty < r.rows().end(); ++ty)
        for (int tx = r.cols().begin(); tx < r.cols().end(); ++tx)
          run(Tile{tx * tiling.tile_width, ty * tiling.tile_height, std::min((tx + 1) * tiling.tile_width, width),
                   std::min((ty + 1) * tiling.tile_height, height)});
    });
  });
}

/// Work outside a tile loop (one point's estimate): fn.template operator()<N>(ctx) with a fresh
/// intersect context, N the scene's packet width; returns what fn returns.
template <class Fn>
decltype(auto) with_ray_context(const RayScene& rs, Fn&& fn) {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  return dispatch_packet_width(rs.native_packet_width(), [&]<int N>() -> decltype(auto) { return fn.template operator()<N>(ctx); });
}

}  // namespace ao::detail
