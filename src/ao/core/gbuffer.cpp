#include "ao/core/gbuffer.h"

#include "ao/core/parallel.h"

namespace ao {

void depth_plane(const GBuffer& g, Image<float>& out) {
  const int w = g.width(), h = g.height();
  out.resize(w, h);
  // Rows of 64 x 16 pixels: each task streams 768 bytes of positions and 256 of ids per row.
  parallel_for_tiles(w, h, 64, 16, [&](const Tile& t) {
    for (int y = t.y0; y < t.y1; ++y) {
      const std::size_t row = static_cast<std::size_t>(y) * w;
      for (int x = t.x0; x < t.x1; ++x) out[row + x] = g.object_id[row + x] != 0 ? -g.position[row + x].z : kInfinity;
    }
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
