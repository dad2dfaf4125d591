// SPDX-License-Identifier: Apache-2.0
// Internals of the screen-space methods (containment, volumetric, transfer), not installed: their
// inputs in the form of their SIMD kernels (screen_space_kernel_internal.h), which take a
// row's covered pixels as structure-of-arrays and runs the loops over samples across pixels.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <type_traits>

#include "ao/methods/characteristic.h"
#include "ao/methods/depth_layers.h"
#include "ao/methods/samples.h"
#include "ao/methods/screen_space_kernel_internal.h"

namespace ao {

/// The interleaving pattern's rotations as the kernels take them.
inline simd::Rotations16 simd_rotations(const std::array<Rotation, 16>& r) {
  simd::Rotations16 out;
  for (std::size_t k = 0; k < 16; ++k) out.c[k] = r[k].c, out.s[k] = r[k].s;
  return out;
}

/// The depth plane a depth-buffer characteristic reads, with its projection, and its second layer
/// when `layers` reads one (two layers, or one layer's sheets of a thickness).
inline simd::DepthPlane simd_depth_plane(const DepthBufferCharacteristic& ch, const DepthLayers& layers = {}) {
  const ScreenProjection& p = ch.projection;
  const bool two = reads_second_layer(layers);
  return {ch.depth, p.scale_x, p.scale_y, p.centre_x, p.centre_y, p.width, p.height, two ? ch.second : nullptr, two ? ch.separation : 0.0f,
          two ? ch.normals : nullptr};
}

/// The depth characteristic of `g` with the layers `d` asks for: its second layer (not copied: `g`
/// must outlive the result) when d.layers = 2, InputError when `g` has none at the separation in effect;
/// with one layer and a thickness, nothing behind any pixel at that thickness (depth_layers.h).
/// `built`: g's depth plane built already (depth_plane(g)), or null to build it.
inline DepthBufferCharacteristic depth_characteristic(const GBuffer& g, const DepthLayers& d, float radius, const std::string& method,
                                                      std::shared_ptr<const Image<float>> built = nullptr) {
  check_thickness(d, method);
  const float separation = layer_separation(d, radius);
  if (d.layers == 2 && !has_second_layer(g, separation)) throw_missing_second_layer(method, separation);
  DepthBufferCharacteristic ch = built ? DepthBufferCharacteristic(g, std::move(built)) : DepthBufferCharacteristic(g);
  if (d.layers == 2) ch.add_second_layer(g, std::shared_ptr<const Image<float>>(std::shared_ptr<void>(), &g.second_depth), separation);
  else if (d.thickness > 0) ch.add_second_layer(g, nothing_behind(g), separation);
  return ch;
}

/// InputError unless `ch` can give what `d` asks for: two layers, or one layer's sheets of a
/// thickness, are the depth buffer's, with the second layer they read (at the separation in effect
/// for R = `radius`). `d` is a validated parameter's (check_thickness ran in its validate()).
template <class C>
void check_layers(const C& ch, const DepthLayers& d, float radius, const std::string& method) {
  if (!reads_second_layer(d)) return;
  if constexpr (std::is_same_v<C, DepthBufferCharacteristic>) {
    if (ch.second) return;
    if (d.layers == 2) throw_missing_second_layer(method, effective_separation(d, radius));
    throw InputError(method + ": thickness reads its sheets from the depth characteristic, and this one was built without them: build "
                              "it with depth_characteristic");
  } else {
    throw InputError(method + ": " + (d.layers == 2 ? "layers=2 is a second layer" : "thickness is a sheet model") +
                     " of the depth buffer; an analytic characteristic function has its own solid");
  }
}

/// Test-point offsets (X_i, Y_i, Z_i) as the kernels take them.
inline simd::TestPoints simd_points(const ContainmentSamples& s) { return {s.x.data(), s.y.data(), s.z.data(), s.size()}; }
/// Disk samples (x_i, y_i, h_i) as the kernels take them (h_i in z).
inline simd::TestPoints simd_points(const DiskSamples& s) { return {s.x.data(), s.y.data(), s.h.data(), s.size()}; }

}  // namespace ao
