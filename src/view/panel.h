// SPDX-License-Identifier: Apache-2.0
// The panel of `ao view` (Dear ImGui): the method and one widget per parameter, generated from its
// parameter table; the neighbourhood (membership, R, seed); the view (mode, wipe, resolution,
// threads, frame all, up axis, screenshot); the reference's state; the last error.
#pragma once

#include <string>

#include "view/input.h"
#include "view/state.h"
#include "view/hud.h"

namespace ao::view {

void draw_panel(ViewerState& state, ViewerControls& controls, const ViewerReadout& readout);

}  // namespace ao::view
