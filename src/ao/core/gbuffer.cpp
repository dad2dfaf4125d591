#include "ao/core/gbuffer.h"

#include "ao/core/parallel.h"
#include "ao/simd/depth_internal.h"

namespace ao {

void depth_plane(const GBuffer& g, Image<float>& out) {
  const int w = g.width(), h = g.height();
  out.resize(w, h);
  // Rows of 64 x 16 pixels: each task streams 768 bytes of positions and 256 of ids per row.
  parallel_for_tiles(w, h, 64, 16, [&](const Tile& t) {
    simd::depth_plane_tile(g.position.data(), g.object_id.data(), w, t.x0, t.x1, t.y0, t.y1, out.data());  // the SIMD kernel layer
  });
}

Image<float> depth_plane(const GBuffer& g) {
  Image<float> out;
  depth_plane(g, out);
  return out;
}

Image<std::uint8_t> coverage_mask(const GBuffer& g) {
  Image<std::uint8_t> mask;
  mask.resize(g.width(), g.height());
  for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = g.object_id[i] != 0 ? 1 : 0;
  return mask;
}

}  // namespace ao
