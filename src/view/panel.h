// SPDX-License-Identifier: Apache-2.0
// The panel of `ao view` (Dear ImGui): the method and one widget per parameter, generated from its
// parameter table; the neighbourhood (membership, R, seed); the view (mode, wipe, resolution,
// threads, frame all, up axis, screenshot); the reference's state; the last error. Open, it is
// docked at the window's left edge and the image takes the rest of the window, so it never covers
// the picture; collapsed, it is one button in the image's corner.
#pragma once

#include <string>

#include "view/input.h"
#include "view/state.h"
#include "view/hud.h"

namespace ao::view {

/// The open panel's width, pixels: 340, but at most half the window.
inline constexpr int kPanelWidth = 340;
/// Below this window width the panel starts collapsed: docked, it would take over a quarter of the
/// window's width from the image.
inline constexpr int kOpenPanelMinWindowWidth = 1280;

/// The columns the panel takes from the left of a window `window_width` pixels wide: 0 unless open.
int panel_width(PanelMode mode, int window_width);

/// Declares the panel for this frame (nothing when it is off).
void draw_panel(ViewerState& state, ViewerControls& controls, const ViewerReadout& readout);

}  // namespace ao::view
