// SPDX-License-Identifier: Apache-2.0
#include "view/input.h"

#include <GLFW/glfw3.h>
#include <imgui.h>

#include <cctype>
#include <stdexcept>
#include <vector>

#include "ao/core/closest_name.h"
#include "ao/core/error.h"
#include "ao/io/json_text.h"
#include "ao/registry/registry.h"

namespace ao::view {

namespace {

std::vector<std::string> split_pair(const std::string& text, char sep) {
  const auto at = text.find(sep);
  if (at == std::string::npos) return {text};
  return {text.substr(0, at), text.substr(at + 1)};
}

std::pair<float, float> parse_xy(const std::string& text, const std::string& what) {
  const std::vector<std::string> xy = split_pair(text, ',');
  try {
    if (xy.size() == 2) return {std::stof(xy[0]), std::stof(xy[1])};
  } catch (const std::exception&) {
  }
  throw InputError("--event: " + what + " takes dx,dy in pixels, got '" + text + "'");
}

Key key_from_name(const std::string& name) {
  if (name.size() == 1) {
    switch (std::toupper(static_cast<unsigned char>(name[0]))) {
      case 'F': return Key::F;
      case 'Z': return Key::Z;
      case 'S': return Key::S;
      case 'P': return Key::P;
      case 'H': return Key::H;
      case 'R': return Key::R;
      case '1': case '2': case '3': case '4': case '5': return static_cast<Key>(static_cast<int>(Key::View1) + (name[0] - '1'));
      default: break;
    }
  }
  throw InputError("--event: unknown key '" + name + "' (keys: F, Z, S, P, H, R, 1-5)");
}

// `value` as a number in [lo, hi]; InputError naming --set `key` otherwise.
float set_number(const std::string& key, const std::string& value, float lo, float hi) {
  float v = 0;
  try {
    std::size_t used = 0;
    v = std::stof(value, &used);
    if (used != value.size()) throw std::invalid_argument(value);
  } catch (const std::exception&) {
    throw InputError("--set " + key + ": expected a number, got '" + value + "'");
  }
  if (!(v >= lo && v <= hi)) throw InputError("--set " + key + ": must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + value);
  return v;
}

// --set of a parameter of the current method.
void set_parameter(const std::string& key, const std::string& value, ViewerState& state) {
  nlohmann::json& params = state.params();
  if (!params.contains(key)) {
    std::string known = "method, view, wipe, scale, seed, threads, radius, radius_fraction, membership, up, panel, hud, reference";
    for (const auto& [k, v] : params.items()) known += ", " + k;
    throw InputError("--set: unknown key '" + key + "' (viewer settings and parameters of " + state.method + ": " + known + ")" + did_you_mean(key, known));
  }
  std::optional<nlohmann::json> parsed = parse_json_limited(value, "--set " + key);
  params[key] = parsed ? std::move(*parsed) : nlohmann::json(value);
  state.dirty_method = true;
}

// --set of the view: view, wipe, scale, panel, hud, reference. Returns whether `key` was one of them.
bool set_display(const std::string& key, const std::string& value, ViewerState& state) {
  if (key == "view") {
    for (int i = 0; i < kViewCount; ++i)
      if (value == kViewNames[i]) {
        state.set_view(static_cast<ViewMode>(i));
        return true;
      }
    throw InputError("--set view: one of ao, shaded, transfer, map, error, got '" + value + "'" + did_you_mean(value, "ao, shaded, transfer, map, error"));
  }
  if (key == "wipe") {
    state.wipe = set_number(key, value, 0, 1);
    state.dirty_display = true;
  } else if (key == "scale") {
    const float v = set_number(key, value, 1, 4);
    if (v != 1 && v != 2 && v != 4) throw InputError("--set scale: 1, 2 or 4 (the image is computed at 1/scale of the window), got " + value);
    state.scale = static_cast<int>(v);
    state.dirty_gbuffer = true;
  } else if (key == "panel") {
    // "on" is "open", as before the panel could collapse.
    if (value == "open" || value == "on") state.panel = PanelMode::Open;
    else if (value == "collapsed") state.panel = PanelMode::Collapsed;
    else if (value == "off") state.panel = PanelMode::Off;
    else throw InputError("--set panel: open, collapsed or off, got '" + value + "'" + did_you_mean(value, "open, collapsed, off"));
  } else if (key == "hud" || key == "reference") {
    if (value != "on" && value != "off") throw InputError("--set " + key + ": on or off, got '" + value + "'");
    if (key == "hud") {
      state.show_hud = value == "on";
    } else {
      state.reference_in_benchmark = value == "on";
      state.dirty_method = true;  // the reference restarts (or stops) with the next run of the method
    }
  } else {
    return false;
  }
  return true;
}

}  // namespace

bool press_key(Key key, ViewerState& state, ViewerControls& controls) {
  switch (key) {
    case Key::F: controls.frame_all(); break;
    case Key::Z: controls.set_up_axis(controls.up_axis() == UpAxis::Y ? UpAxis::Z : UpAxis::Y); break;
    case Key::S: controls.screenshot(); break;
    case Key::P: state.panel = state.panel == PanelMode::Open ? PanelMode::Collapsed : PanelMode::Open; break;
    case Key::H: state.show_hud = !state.show_hud; break;
    case Key::R:
      state.reference_in_benchmark = !state.reference_in_benchmark;
      state.dirty_method = true;
      break;
    default: state.set_view(static_cast<ViewMode>(static_cast<int>(key) - static_cast<int>(Key::View1))); break;
  }
  return true;
}

bool handle_input(ViewerState& state, ViewerControls& controls) {
  const ImGuiIO& io = ImGui::GetIO();
  bool any = false;
  if (!io.WantCaptureMouse) {
    const float dx = io.MouseDelta.x, dy = io.MouseDelta.y;
    if ((dx != 0 || dy != 0) && ImGui::IsMouseDown(ImGuiMouseButton_Left)) controls.orbit(dx, dy), any = true;
    if ((dx != 0 || dy != 0) && (ImGui::IsMouseDown(ImGuiMouseButton_Right) || ImGui::IsMouseDown(ImGuiMouseButton_Middle)))
      controls.pan(dx, dy), any = true;
    if (io.MouseWheel != 0) controls.zoom(io.MouseWheel), any = true;
  }
  if (io.WantCaptureKeyboard) return any;
  const std::pair<int, Key> keys[] = {{GLFW_KEY_F, Key::F},     {GLFW_KEY_Z, Key::Z},     {GLFW_KEY_S, Key::S},     {GLFW_KEY_1, Key::View1},
                                      {GLFW_KEY_2, Key::View2}, {GLFW_KEY_3, Key::View3}, {GLFW_KEY_4, Key::View4}, {GLFW_KEY_5, Key::View5},
                                      {GLFW_KEY_P, Key::P},     {GLFW_KEY_H, Key::H},     {GLFW_KEY_R, Key::R}};
  for (const auto& [code, key] : keys)
    if (ImGui::IsKeyPressed(code, false)) any |= press_key(key, state, controls);
  return any;
}

void apply_event(const ScriptedEvent& e, ViewerState& state, ViewerControls& controls) {
  if (e.kind == "orbit" || e.kind == "pan") {
    const auto [dx, dy] = parse_xy(e.args, e.kind);
    if (e.kind == "orbit") controls.orbit(dx, dy);
    else controls.pan(dx, dy);
  } else if (e.kind == "zoom") {
    controls.zoom(std::stof(e.args));
  } else if (e.kind == "key") {
    press_key(key_from_name(e.args), state, controls);
  } else if (e.kind == "set") {
    apply_set(e.args, state, controls);
  }
}

void apply_set(const std::string& kv, ViewerState& state, ViewerControls& controls) {
  const std::vector<std::string> parts = split_pair(kv, '=');
  if (parts.size() != 2 || parts[0].empty()) throw InputError("--set: expected key=value, got '" + kv + "'");
  const std::string& key = parts[0];
  const std::string& value = parts[1];
  if (set_display(key, value, state)) return;
  if (key == "method") {
    find_method(value);
    state.select_method(value);
  } else if (key == "device") {
    state.device = device_from_name(value);
    state.dirty_method = true;
  } else if (key == "seed") {
    state.seed = static_cast<std::uint32_t>(set_number(key, value, 0, 4294967295.0f));
    state.dirty_method = true;
  } else if (key == "threads") {
    controls.set_threads(static_cast<int>(set_number(key, value, 1, 1024)));
  } else if (key == "radius") {
    state.falloff.radius = set_number(key, value, 1e-30f, 1e30f);
    state.dirty_method = true;
  } else if (key == "radius_fraction") {
    state.falloff.radius = set_number(key, value, 1e-6f, 10) * state.radius_basis;
    state.dirty_method = true;
  } else if (key == "membership") {
    const auto m = parse_membership(value);
    if (!m) throw InputError("--set membership: one of " + membership_names() + ", got '" + value + "'" + did_you_mean(value, membership_names()));
    state.falloff.membership = *m;
    state.dirty_method = true;
  } else if (key == "up") {
    if (value != "y" && value != "z") throw InputError("--set up: y or z, got '" + value + "'");
    controls.set_up_axis(value == "y" ? UpAxis::Y : UpAxis::Z);
  } else {
    set_parameter(key, value, state);
  }
}

ScriptedEvent parse_event(const std::string& text) {
  const std::vector<std::string> a = split_pair(text, ':');
  if (a.size() == 2) {
    const std::vector<std::string> b = split_pair(a[1], ':');
    if (b.size() == 2) {
      ScriptedEvent e;
      try {
        std::size_t used = 0;
        e.frame = std::stoi(a[0], &used);
        if (used != a[0].size() || e.frame < 0) throw std::invalid_argument(a[0]);
      } catch (const std::exception&) {
        throw InputError("--event: the frame must be a whole number >= 0, got '" + a[0] + "' in '" + text + "'");
      }
      e.kind = b[0];
      e.args = b[1];
      if (e.kind == "orbit" || e.kind == "pan" || e.kind == "zoom" || e.kind == "key" || e.kind == "set") return e;
      throw InputError("--event: unknown kind '" + e.kind + "' (orbit, pan, zoom, key, set) in '" + text + "'");
    }
  }
  throw InputError("--event: expected FRAME:KIND:ARGS (e.g. 3:orbit:40,0 or 5:key:F), got '" + text + "'");
}

}  // namespace ao::view
