// SPDX-License-Identifier: Apache-2.0
// Input of `ao view`: the mouse and keys, scripted events (--event) and settings (--set), all
// turned into the same changes of the viewer's state and camera, so a script drives exactly what a
// user would. Mouse: left drag orbits, right or middle drag pans, the wheel zooms. Keys: F frame
// all, Z switch y-up / z-up, S screenshot, 1-5 views, P panel, H HUD.
#pragma once

#include <string>

#include "view/orbit.h"
#include "view/state.h"
#include "view/viewer.h"

namespace ao::view {

/// What input drives beyond the state: the camera, the thread count, screenshots.
class ViewerControls {
 public:
  virtual void orbit(float dx, float dy) = 0;
  virtual void pan(float dx, float dy) = 0;
  virtual void zoom(float steps) = 0;
  virtual void frame_all() = 0;
  virtual UpAxis up_axis() const = 0;
  virtual void set_up_axis(UpAxis axis) = 0;
  virtual void screenshot() = 0;
  virtual void set_threads(int n) = 0;

 protected:
  ~ViewerControls() = default;
};

/// The keys the viewer knows, by name.
enum class Key { F, Z, S, P, H, R, View1, View2, View3, View4, View5 };

/// Applies one key press. Returns whether it was a key the viewer knows.
bool press_key(Key key, ViewerState& state, ViewerControls& controls);

/// This frame's mouse and keyboard (Dear ImGui's view of them, outside its widgets). Returns
/// whether anything moved.
bool handle_input(ViewerState& state, ViewerControls& controls);

/// Applies a scripted event as the mouse or keys would.
void apply_event(const ScriptedEvent& event, ViewerState& state, ViewerControls& controls);

/// --set key=value: a viewer setting (method, view, wipe, scale, seed, threads, radius,
/// radius_fraction, membership, up, panel, hud, reference), else a parameter of the current method.
/// InputError with one line naming the key and what is valid.
void apply_set(const std::string& kv, ViewerState& state, ViewerControls& controls);

}  // namespace ao::view
