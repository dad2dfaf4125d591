// SPDX-License-Identifier: Apache-2.0
#include "view/hud.h"

#include <imgui.h>

#include <algorithm>

namespace ao::view {

namespace {
double mean(double sum, double n) { return n > 0 ? sum / n : 0.0; }
}  // namespace

double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

void StageStats::add(const StageTimes& t) {
  const Clock::time_point now = Clock::now();
  recent_.push_back({now, t});
  while (!recent_.empty() && now - recent_.front().first > std::chrono::seconds(1)) recent_.pop_front();
  total_.gbuffer += t.gbuffer, total_.method += t.method, total_.filter += t.filter, total_.display += t.display, total_.frame += t.frame;
  runs_.gbuffer += t.gbuffer > 0, runs_.method += t.method > 0, runs_.filter += t.filter > 0, runs_.display += t.display > 0;
  if (t.gbuffer > 0) last_.gbuffer = t.gbuffer;
  if (t.method > 0) last_.method = t.method;
  if (t.filter > 0) last_.filter = t.filter;
  if (t.display > 0) last_.display = t.display;
  total_.image += t.image, runs_.image += t.image > 0;
  ++frames_;
}

StageTimes StageStats::recent(double& fps) const {
  StageTimes sum, n;
  for (const auto& [time, t] : recent_) {
    sum.gbuffer += t.gbuffer, sum.method += t.method, sum.filter += t.filter, sum.display += t.display, sum.frame += t.frame;
    n.gbuffer += t.gbuffer > 0, n.method += t.method > 0, n.filter += t.filter > 0, n.display += t.display > 0;
  }
  fps = static_cast<double>(recent_.size());
  return {mean(sum.gbuffer, n.gbuffer), mean(sum.method, n.method), mean(sum.filter, n.filter), mean(sum.display, n.display),
          mean(sum.frame, static_cast<double>(recent_.size()))};
}

nlohmann::json StageStats::json() const {
  const double frame = mean(total_.frame, static_cast<double>(frames_));
  return {{"frames", frames_},
          {"fps", frame > 0 ? 1000.0 / frame : 0.0},
          {"frame_ms", frame},
          {"gbuffer_ms", mean(total_.gbuffer, runs_.gbuffer)},
          {"method_ms", mean(total_.method, runs_.method)},
          {"filter_ms", mean(total_.filter, runs_.filter)},
          {"display_ms", mean(total_.display, runs_.display)},
          {"image_ms", mean(total_.image, runs_.image)},
          {"gbuffer_runs", runs_.gbuffer},
          {"method_runs", runs_.method}};
}

void draw_hud(const StageStats& stats, const ViewerReadout& readout) {
  double fps = 0;
  StageTimes t = stats.recent(fps);
  // A stage that has not run in the last second (nothing changed) shows its last time.
  const StageTimes& last = stats.last_run();
  for (auto [now, then] : {std::pair{&t.gbuffer, last.gbuffer}, {&t.method, last.method}, {&t.filter, last.filter}, {&t.display, last.display}})
    if (*now == 0) *now = then;
  const ImVec2 size = ImGui::GetIO().DisplaySize;
  ImGui::SetNextWindowPos(ImVec2(size.x - 8, 8), ImGuiCond_Always, ImVec2(1, 0));
  ImGui::SetNextWindowBgAlpha(0.6f);
  ImGui::Begin("hud", nullptr, ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoInputs | ImGuiWindowFlags_NoSavedSettings);
  ImGui::Text("%.0f fps  (%d x %d)", fps, readout.width, readout.height);
  ImGui::Text("G-buffer %6.1f ms", t.gbuffer);
  ImGui::Text("method   %6.1f ms", t.method);
  ImGui::Text("filter   %6.1f ms", t.filter);
  ImGui::Text("display  %6.1f ms", t.display);
  ImGui::Text("ref %d spp, se %s", readout.reference_spp, readout.std_error.c_str());
  if (readout.rmse >= 0) ImGui::Text("RMSE %.4f", readout.rmse);
  if (!readout.gl_renderer.empty()) {
    ImGui::Text("GPU %s", readout.gl_renderer.c_str());
    for (const GpuPassTime& p : readout.gpu_passes) ImGui::Text("  %-11s %6.2f ms", p.name.c_str(), p.ms);
  }
  ImGui::End();
}

void draw_notice(const std::string& text, float left) {
  const ImVec2 size = ImGui::GetIO().DisplaySize;
  ImGui::SetNextWindowPos(ImVec2(0.5f * (left + size.x), 0.5f * size.y), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSize(ImVec2(std::min(420.0f, 0.9f * (size.x - left)), 0), ImGuiCond_Always);
  ImGui::SetNextWindowBgAlpha(0.75f);
  ImGui::Begin("notice", nullptr, ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoInputs | ImGuiWindowFlags_NoSavedSettings);
  ImGui::TextWrapped("%s", text.c_str());
  ImGui::End();
}

}  // namespace ao::view
