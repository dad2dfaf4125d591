// SPDX-License-Identifier: Apache-2.0
#include "view/panel.h"

#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <thread>

#include "ao/core/params.h"
#include "ao/registry/registry.h"

namespace ao::view {

namespace {

void tooltip(const std::string& text) {
  if (!text.empty() && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", text.c_str());
}

// An optional parameter left to its preset: says so, and offers to set it. Returns whether it changed.
bool draw_unset(const ParamSpec& spec, nlohmann::json& value, double one) {
  ImGui::TextDisabled("%s: from the preset", spec.name.c_str());
  ImGui::SameLine();
  const bool changed = ImGui::SmallButton(("set##" + spec.name).c_str());
  if (changed) value = spec.type == ParamType::OptionalInt ? nlohmann::json(static_cast<int>(one)) : nlohmann::json(static_cast<float>(one));
  return changed;
}

// One widget for one parameter: a checkbox, an enum combo, an integer or number field clamped to
// the valid range. Returns whether the value changed.
bool draw_parameter(const ParamSpec& spec, nlohmann::json& value) {
  const char* label = spec.name.c_str();
  const auto clamp_to = [&](double v) {
    const double lo = std::isfinite(spec.range.min) ? spec.range.min : v, hi = std::isfinite(spec.range.max) ? spec.range.max : v;
    return std::clamp(v, lo, hi);
  };
  if (value.is_null()) return draw_unset(spec, value, clamp_to(1));
  bool changed = false;
  switch (spec.type) {
    case ParamType::Bool: {
      bool b = value.get<bool>();
      if ((changed = ImGui::Checkbox(label, &b))) value = b;
      break;
    }
    case ParamType::Enum: {
      const std::string current = value.get<std::string>();
      if (ImGui::BeginCombo(label, current.c_str())) {
        for (const std::string& name : spec.enum_names)
          if (ImGui::Selectable(name.c_str(), name == current)) value = name, changed = true;
        ImGui::EndCombo();
      }
      break;
    }
    case ParamType::Int:
    case ParamType::OptionalInt: {
      int v = value.get<int>();
      if ((changed = ImGui::InputInt(label, &v, 1, 10, ImGuiInputTextFlags_EnterReturnsTrue))) value = static_cast<int>(clamp_to(v));
      break;
    }
    case ParamType::Float:
    case ParamType::OptionalFloat: {
      float v = value.get<float>();
      if ((changed = ImGui::InputFloat(label, &v, 0, 0, "%.6g", ImGuiInputTextFlags_EnterReturnsTrue))) value = static_cast<float>(clamp_to(v));
      break;
    }
  }
  return changed;
}

// One widget per parameter of the method, generated from its parameter table (core/params.h), with
// the unit, range and one-line help as the tooltip.
void draw_parameters(ViewerState& state) {
  nlohmann::json& params = state.params();
  for (const ParamSpec& spec : find_method(state.method).params().specs()) {
    if (!params.contains(spec.name)) continue;
    const bool changed = draw_parameter(spec, params[spec.name]);
    tooltip(spec.help + "\n" + spec.valid_text());
    if (changed) state.dirty_method = true;
  }
}

void draw_neighbourhood(ViewerState& state) {
  const std::string membership(to_string(state.falloff.membership));
  if (ImGui::BeginCombo("membership", membership.c_str())) {
    for (Membership m : {Membership::Step, Membership::Linear, Membership::Sqrt, Membership::Cubic, Membership::Exp, Membership::Alchemy})
      if (ImGui::Selectable(std::string(to_string(m)).c_str(), m == state.falloff.membership)) {
        state.falloff.membership = m;
        state.dirty_method = true;
      }
    ImGui::EndCombo();
  }
  const float basis = state.radius_basis;
  float radius = state.falloff.radius, fraction = state.falloff.radius / basis;
  if (ImGui::DragFloat("R (world)", &radius, 0.005f * basis, 1e-6f * basis, 10 * basis, "%.4g")) {
    state.falloff.radius = std::max(radius, 1e-6f * basis);
    state.dirty_method = true;
  }
  tooltip("neighbourhood radius R, world units");
  if (ImGui::DragFloat("R / diagonal", &fraction, 0.002f, 1e-4f, 10.0f, "%.4f")) {
    state.falloff.radius = std::max(fraction, 1e-6f) * basis;
    state.dirty_method = true;
  }
  tooltip("R as a fraction of the scene diagonal (" + std::to_string(basis) + " world units)");
  int seed = static_cast<int>(state.seed);
  if (ImGui::InputInt("seed", &seed)) {
    state.seed = static_cast<std::uint32_t>(std::max(seed, 0));
    state.dirty_method = true;
  }
}

void draw_view_settings(ViewerState& state, ViewerControls& controls) {
  int view = static_cast<int>(state.view);
  for (int i = 0; i < kViewCount; ++i) {
    if (i > 0) ImGui::SameLine();
    if (ImGui::RadioButton(kViewNames[i], &view, i)) state.set_view(static_cast<ViewMode>(view));
  }
  if (ImGui::SliderFloat("wipe", &state.wipe, 0.0f, 1.0f, "%.2f")) state.dirty_display = true;
  tooltip("left of the line: the method; right: the reference");
  int scale = state.scale == 1 ? 0 : state.scale == 2 ? 1 : 2;
  const char* scales[] = {"1", "1/2", "1/4"};
  if (ImGui::Combo("resolution", &scale, scales, 3)) {
    state.scale = 1 << scale;
    state.dirty_gbuffer = true;
  }
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  int threads = state.threads > 0 ? state.threads : cores;
  if (ImGui::SliderInt("threads", &threads, 1, cores)) controls.set_threads(threads);
  if (ImGui::Button("frame all (F)")) press_key(Key::F, state, controls);
  ImGui::SameLine();
  if (ImGui::Button(controls.up_axis() == UpAxis::Y ? "y-up (Z)" : "z-up (Z)")) press_key(Key::Z, state, controls);
  ImGui::SameLine();
  if (ImGui::Button("screenshot (S)")) press_key(Key::S, state, controls);
}

}  // namespace

int panel_width(PanelMode mode, int window_width) { return mode == PanelMode::Open ? std::min(kPanelWidth, window_width / 2) : 0; }

void draw_panel(ViewerState& state, ViewerControls& controls, const ViewerReadout& readout) {
  constexpr ImGuiWindowFlags fixed = ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoSavedSettings;
  if (state.panel == PanelMode::Off) return;
  if (state.panel == PanelMode::Collapsed) {
    ImGui::SetNextWindowPos(ImVec2(4, 4), ImGuiCond_Always);
    ImGui::SetNextWindowBgAlpha(0.6f);
    ImGui::Begin("ao view (collapsed)", nullptr, fixed | ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize);
    if (ImGui::SmallButton("> panel (P)")) state.panel = PanelMode::Open;
    ImGui::End();
    return;
  }
  // Docked: the window's full height at its left edge, opaque; it scrolls when taller.
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  ImGui::SetNextWindowPos(ImVec2(0, 0), ImGuiCond_Always);
  ImGui::SetNextWindowSize(ImVec2(static_cast<float>(panel_width(state.panel, static_cast<int>(display.x))), display.y), ImGuiCond_Always);
  ImGui::SetNextWindowBgAlpha(1.0f);
  ImGui::Begin("ao view", nullptr, fixed | ImGuiWindowFlags_NoTitleBar | ImGuiWindowFlags_NoBringToFrontOnFocus);
  ImGui::TextDisabled("ao view");
  ImGui::SameLine();
  if (ImGui::SmallButton("< collapse (P)")) state.panel = PanelMode::Collapsed;
  ImGui::PushItemWidth(-150.0f);  // room for the longest parameter name
  if (ImGui::BeginCombo("method", state.method.c_str())) {
    for (const MethodInfo& m : all_methods()) {
      if (ImGui::Selectable(std::string(m.name).c_str(), m.name == state.method)) state.select_method(std::string(m.name));
      tooltip(std::string(m.summary));
    }
    ImGui::EndCombo();
  }
  tooltip(std::string(find_method(state.method).summary));
  int device = state.device == Device::Gpu ? 1 : 0;
  ImGui::TextUnformatted("device");
  for (int i = 0; i < 2; ++i) {
    ImGui::SameLine();
    if (ImGui::RadioButton(i == 0 ? "cpu" : "gpu", &device, i)) state.device = i == 0 ? Device::Cpu : Device::Gpu, state.dirty_method = true;
  }
  tooltip("where the method runs: the CPU, or the GPU backend (OpenGL 4.3 compute shaders in this window's context)");
  if (ImGui::CollapsingHeader("parameters", ImGuiTreeNodeFlags_DefaultOpen)) draw_parameters(state);
  if (ImGui::CollapsingHeader("neighbourhood", ImGuiTreeNodeFlags_DefaultOpen)) draw_neighbourhood(state);
  if (ImGui::CollapsingHeader("view", ImGuiTreeNodeFlags_DefaultOpen)) draw_view_settings(state, controls);
  if (ImGui::CollapsingHeader("reference", ImGuiTreeNodeFlags_DefaultOpen)) {
    if (readout.benchmark) {
      if (ImGui::Checkbox("accumulate (R)", &state.reference_in_benchmark)) state.dirty_method = true;
      tooltip("--benchmark recomputes the method every frame, so no reference accumulates; this pauses it and accumulates one");
    }
    ImGui::Text("%d rays/pixel, std error %s", readout.reference_spp, readout.std_error.c_str());
    if (readout.rmse >= 0) ImGui::Text("RMSE of %s: %.4f", state.method.c_str(), readout.rmse);
  }
  if (!readout.error.empty()) ImGui::TextWrapped("%s", readout.error.c_str());
  ImGui::PopItemWidth();
  ImGui::End();
}

}  // namespace ao::view
