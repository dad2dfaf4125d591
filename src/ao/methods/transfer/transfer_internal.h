// SPDX-License-Identifier: Apache-2.0
// Internals of ambient transfer, not installed: the scratch buffers a caller that renders every
// frame (the benchmark, a viewer) keeps between calls, and the overloads that use them.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "ao/methods/transfer/transfer.h"

namespace ao {

/// What a caller that renders every frame keeps between calls (the viewer, the benchmark): the
/// result and the scratch planes, reused while the size stays the same. Fresh pages are not free:
/// at 1280x720 a call writes ~33 MB, and faulting that in cost about as much as the tests.
struct TransferBuffers {
  TransferImage result;
  std::array<Image<float>, 6> scratch;  ///< Unfiltered W (R, G, B) and O, filtered G and B.
  Image<std::uint32_t> depth_and_palette;  ///< The depth with an albedo index in its low bits (transfer.cpp).
  std::shared_ptr<Image<float>> depth = std::make_shared<Image<float>>();  ///< The G-buffer's depth plane, rebuilt in place.
};

/// The same into `buffers` (returns buffers.result), allocating only when the size changes.
template <class Characteristic>
const TransferImage& transfer_ao(TransferBuffers& buffers, const GBuffer& g, const Characteristic& ch, const Image<Vec3>& indirect,
                                 const Falloff& falloff, const TransferParams& params, std::uint32_t seed);

/// The screen-space method into `buffers`: depth buffer, G-buffer albedo.
const TransferImage& transfer_ao(TransferBuffers& buffers, const GBuffer& g, const Falloff& falloff, const TransferParams& params,
                                 std::uint32_t seed);

}  // namespace ao
