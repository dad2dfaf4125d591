// SPDX-License-Identifier: Apache-2.0
// What the user of `ao view` has chosen (method and parameters, neighbourhood, view, wipe,
// resolution) and what has to be redone because of it. Input, the panel and --set change it; the
// viewer's frame loop reads it.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "ao/core/membership.h"
#include "ao/jobs/device.h"

namespace ao::view {

/// What the window shows: the method's V, a shaded picture, transfer's RGB W, a baked AO map, or
/// the signed error against the reference.
enum class ViewMode { AO, Shaded, Transfer, Map, Error };
inline constexpr const char* kViewNames[] = {"ao", "shaded", "transfer", "map", "error"};
inline constexpr int kViewCount = 5;

/// The panel: docked beside the image (open; the image takes the rest of the window), a button in
/// the image's corner (collapsed), or not drawn at all (off: screenshots of the image alone).
enum class PanelMode { Open, Collapsed, Off };

struct ViewerState {
  std::string method;
  std::map<std::string, nlohmann::json> params_by_method;  ///< Each method's parameters as last set.
  Falloff falloff;
  float radius_basis = 1.0f;  ///< The length R fractions refer to (the diagonal ao render uses), > 0.
  std::uint32_t seed = 1;
  Device device = Device::Cpu;  ///< Where the method runs: the CPU, or the GPU backend in the window's context.
  ViewMode view = ViewMode::AO;
  float wipe = 1.0f;          ///< Left of wipe x width: the method; right: the reference.
  int scale = 1;              ///< The image is computed at 1/scale of the window: 1, 2 or 4.
  int threads = 0;            ///< 0: all cores.
  PanelMode panel = PanelMode::Open;
  bool show_hud = true;
  /// With --benchmark: accumulate the reference anyway (key R, --set reference=on), which pauses
  /// the benchmark's recomputation so that the camera is still.
  bool reference_in_benchmark = false;
  bool moved = false;         ///< The camera has left the start view.
  bool dirty_gbuffer = true, dirty_method = true, dirty_display = true;
  bool dirty_reference_side = false;  ///< Only the reference (right of the wipe) changed.

  /// The current method's parameters, its defaults on first use.
  nlohmann::json& params();
  const nlohmann::json& params() const { return params_by_method.at(method); }
  void select_method(const std::string& name);
  void set_view(ViewMode v);
  /// The camera moved: a new G-buffer.
  void camera_moved();
};

}  // namespace ao::view
