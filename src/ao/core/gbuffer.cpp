// SPDX-License-Identifier: Apache-2.0
#include "ao/core/gbuffer.h"


namespace ao {

Image<std::uint8_t> coverage_mask(const GBuffer& g) {
  Image<std::uint8_t> mask;
  mask.resize(g.width(), g.height());
  for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = g.object_id[i] != 0 ? 1 : 0;
  return mask;
}

}  // namespace ao
