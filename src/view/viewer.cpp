// SPDX-License-Identifier: Apache-2.0
// The frame loop of `ao view`: input, then the work through the job layer (FrameRenderer: the
// G-buffer of the camera and the method on it), the progressive reference, and the display. The
// window and GL are window.cpp, input and scripted events input.cpp, the panel panel.cpp, the HUD
// and the frame statistics hud.cpp, the image's bytes display.cpp.
#include "view/viewer.h"

#include <nlohmann/json.hpp>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <numbers>
#include <optional>

#include "ao/core/error.h"
#include "ao/gpu/device.h"
#include "ao/eval/shading.h"
#include "ao/io/camera_json.h"
#include "ao/io/image_io.h"
#include "ao/jobs/frames.h"
#include "ao/jobs/provenance.h"
#include "ao/registry/registry.h"
#include "view/display.h"
#include "view/hud.h"
#include "view/input.h"
#include "view/orbit.h"
#include "view/panel.h"
#include "view/progressive.h"
#include "view/window.h"

namespace ao::view {

namespace {

// The reference adds this many rays per pixel per batch: a batch at 960x540 then takes tens of
// milliseconds on two cores, so a change of view never waits long for the batch in flight.
constexpr int kReferenceBatch = 4;
constexpr int kReferenceMax = 4096;

std::string next_free_name(const std::string& stem) {
  for (int i = 1;; ++i) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s-%03d", stem.c_str(), i);
    if (!std::filesystem::exists(std::string(buf) + ".png")) return buf;
  }
}

class Viewer final : public ViewerControls {
 public:
  explicit Viewer(ViewSetup setup)
      : s_(std::move(setup)),
        frames_(PreparedScene(s_.scene, "ao view", BvhOptions{})),
        orbit_(s_.camera),
        progressive_(kReferenceBatch, s_.frames > 0 && s_.wait_reference_spp > 0 ? s_.wait_reference_spp : kReferenceMax) {
    width_ = s_.camera.width;
    height_ = s_.camera.height;
    state_.method = s_.method;
    state_.params_by_method[state_.method] = s_.params;
    state_.falloff = s_.falloff;
    state_.radius_basis = s_.radius_basis;
    state_.seed = s_.seed;
    state_.device = s_.device;
    state_.panel = width_ >= kOpenPanelMinWindowWidth ? PanelMode::Open : PanelMode::Collapsed;
    image_width_ = image_width();
    orbit_.set_fov_deg(fov_for(image_width_));
    if (s_.threads > 0) set_threads(s_.threads);
    for (const std::string& kv : s_.sets) apply_set(kv, state_, *this);
  }

  int run() {
    window_ = std::make_unique<Window>(width_, height_, "ao view: " + s_.scene->name, !(s_.frames > 0 || s_.benchmark));
    sync_device();  // --device gpu without a GL 4.3 window stops here
    Clock::time_point last_input = Clock::now();
    for (frame_ = 0;; ++frame_) {
      if (window_->should_close()) break;
      if (s_.frames > 0 && frame_ >= s_.frames && reference_ready()) break;
      run_frame(last_input);
    }
    if (!s_.screenshot.empty()) {
      // The last frame is still in the back buffer's twin: draw it once more and read it back.
      screenshot_path_ = s_.screenshot;
      camera_path_ = s_.camera_out;
      redraw_for_screenshot();
    }
    if (s_.json) std::cout << summary().dump(2) << "\n";
    progressive_.stop();
    release_gpu();
    window_.reset();
    return 0;
  }

  ~Viewer() { release_gpu(); }
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;

  // ViewerControls: what input drives.
  void orbit(float dx, float dy) override { orbit_.orbit(dx, dy, height_), camera_moved(); }
  void pan(float dx, float dy) override { orbit_.pan(dx, dy, height_), camera_moved(); }
  void zoom(float steps) override { orbit_.zoom(steps), camera_moved(); }
  void frame_all() override { orbit_.frame(s_.scene->bounds(), image_width(), height_), camera_moved(); }
  UpAxis up_axis() const override { return orbit_.up_axis(); }
  void set_up_axis(UpAxis axis) override { orbit_.set_up_axis(axis), camera_moved(); }
  void screenshot() override {
    const std::string stem = next_free_name("ao-view");
    screenshot_path_ = stem + ".png";
    camera_path_ = stem + ".json";
    screenshot_pending_ = true;
  }
  void set_threads(int n) override {
    state_.threads = n;
    limit_.reset();
    limit_ = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(n));
  }

 private:
  void run_frame(Clock::time_point& last_input) {
    const Clock::time_point frame_start = Clock::now();
    StageTimes times;
    // Interactive and idle: sleep until input or the reference's next batch, instead of spinning.
    const bool idle = s_.frames == 0 && !s_.benchmark && !state_.dirty_gbuffer && !state_.dirty_method &&
                      Clock::now() - last_input > std::chrono::milliseconds(200);
    if (idle) window_->wait_events(0.05);
    else window_->poll_events();
    for (const ScriptedEvent& e : s_.events)
      if (e.frame == frame_) apply_event(e, state_, *this);
    window_->begin_frame();
    if (handle_input(state_, *this)) last_input = Clock::now();
    draw_panel(state_, *this, readout());
    fit_image_to_panel();
    if (benchmarking()) state_.dirty_gbuffer = true;
    update(times);
    const Clock::time_point display_start = Clock::now();
    const auto [fbw, fbh] = draw_frame();
    times.display = ms_since(display_start);
    times.image = image_ms_;
    if (screenshot_pending_) take_screenshot(fbw, fbh);
    window_->swap();
    times.frame = ms_since(frame_start);
    stats_.add(times);
  }

  void camera_moved() {
    state_.camera_moved();
    progressive_.stop();  // lets go of the G-buffer, so the next one can reuse its storage
  }

  // --benchmark, unless the user asked for the reference, which pauses it.
  bool benchmarking() const { return s_.benchmark && !state_.reference_in_benchmark; }

  // The image's width in the window: what the docked panel leaves.
  int image_width() const { return width_ - panel_width(state_.panel, width_); }

  // The vertical field of view that shows, in an image `w` pixels wide and as tall as the window,
  // what the start camera shows across the whole window: the same horizontal field, more above and
  // below. The start camera's own at the window's width.
  float fov_for(int w) const {
    const float fov = s_.camera.vertical_fov_deg;
    if (w == width_) return fov;
    const double degree = std::numbers::pi / 180.0;
    const double t = std::tan(0.5 * fov * degree) * width_ / std::max(w, 1);
    return static_cast<float>(std::min(2.0 * std::atan(t) / degree, 179.0));
  }

  // The panel was opened or collapsed: the image changed width, so the camera keeps its horizontal
  // field in the new width, and the G-buffer is redone.
  void fit_image_to_panel() {
    const int w = image_width();
    if (w == image_width_) return;
    image_width_ = w;
    orbit_.set_fov_deg(fov_for(w));
    state_.dirty_gbuffer = true;
    progressive_.stop();
  }

  const MethodInfo& method() const { return find_method(state_.method); }

  // The method's device as the state asks: the GPU backend borrows the window's context.
  void sync_device() {
    if (state_.device == frames_.device()) return;
    if (state_.device == Device::Gpu && !gpu_) {
      if (!window_->has_gl43())
        throw SystemError("--device gpu: the window's OpenGL context is older than 4.3, which the GPU backend's compute shaders need; "
                          "use --device cpu");
      gpu_.emplace(GpuDevice::from_current_context(window_->gl_proc_loader()));
    }
    frames_.set_device(state_.device, gpu_ ? &*gpu_ : nullptr);
  }

  // What the GPU backend holds in the window's context goes before the context does.
  void release_gpu() {
    frames_.set_device(Device::Cpu);
    gpu_.reset();
  }

  // Each GPU pass's time, summed over the run for --json, in the order the passes first ran.
  void add_gpu_passes(const std::vector<GpuPassTime>& passes) {
    for (const GpuPassTime& p : passes) {
      auto it = std::find_if(gpu_totals_.begin(), gpu_totals_.end(), [&](const PassTotal& t) { return t.name == p.name; });
      if (it == gpu_totals_.end()) it = gpu_totals_.insert(gpu_totals_.end(), PassTotal{p.name});
      it->ms += p.ms;
      ++it->runs;
    }
  }

  // The camera of the image at full resolution (the window's height, the width the panel leaves).
  Camera image_camera() const {
    Camera c = current_camera();
    c.width = image_width(), c.height = height_;
    return c;
  }

  Camera current_camera() const {
    const int w = std::max(1, image_width() / state_.scale), h = std::max(1, height_ / state_.scale);
    // Until the user moves, the start view exactly as ao render chose it (no trip through yaw and
    // pitch), with the field of view fitted to the image's width beside the panel.
    Camera c = s_.camera;
    if (state_.moved) c = orbit_.camera(w, h);
    else c.vertical_fov_deg = fov_for(image_width());
    c.width = w;
    c.height = h;
    return c;
  }

  // The work of the frame: the G-buffer when the camera moved, the method when anything it reads
  // changed (the ground truth shows the progressive reference itself), then the reference.
  void update(StageTimes& times) {
    try {
      sync_device();
    } catch (const SystemError& e) {  // the panel asked for the GPU in a window that cannot run it
      if (s_.frames > 0) throw;
      error_ = e.what();
      state_.device = Device::Cpu;
    }
    try {
      if (state_.dirty_gbuffer) {
        const Clock::time_point t = Clock::now();
        frames_.render_gbuffer(current_camera());
        times.gbuffer = ms_since(t);
        state_.dirty_gbuffer = false;
        state_.dirty_method = true;
      }
      if (state_.dirty_method) run_method(times);
    } catch (const InputError& e) {
      if (s_.frames > 0) throw;  // a scripted run must fail loudly
      error_ = e.what();
      state_.dirty_gbuffer = state_.dirty_method = false;
    }
    const std::uint64_t v = progressive_.version();
    if (v == reference_version_) return;
    reference_version_ = v;
    ref_ = progressive_.snapshot();
    if (const std::string e = progressive_.error(); !e.empty()) error_ = "reference: " + e;
    update_rmse();
    if (state_.view == ViewMode::Error || method().ground_truth) state_.dirty_display = true;
    else if (state_.wipe < 1) state_.dirty_reference_side = true;
  }

  void run_method(StageTimes& times) {
    const Clock::time_point t = Clock::now();
    const MethodInfo& m = method();
    const MethodParams params = m.decode(state_.params());
    result_ = m.ground_truth ? MethodOutput{} : frames_.run(params, state_.falloff, state_.seed);
    times.method = ms_since(t);
    add_gpu_passes(frames_.gpu_passes());
    if (result_.stats->contains("filter_ms")) {
      times.filter = result_.stats["filter_ms"].get<double>();
      times.method = std::max(0.0, times.method - times.filter);
    }
    state_.dirty_method = false;
    state_.dirty_display = true;
    if (benchmarking()) {  // a moving camera: nothing to accumulate
      progressive_.stop();
    } else {
      progressive_.restart({frames_.shared_gbuffer(), frames_.scene().rays.get(), matched_reference(state_.falloff, params), state_.seed});
    }
    error_.clear();
  }

  void update_rmse() {
    rmse_ = -1;
    const GBuffer* g = frames_.gbuffer();
    if (ref_.visibility.empty() || result_.visibility.empty() || !g || ref_.visibility.size() != result_.visibility.size()) return;
    double sum = 0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < g->object_id.size(); ++i) {
      if (!g->covered(i)) continue;
      const double d = static_cast<double>(result_.visibility[i]) - ref_.visibility[i];
      sum += d * d;
      ++n;
    }
    rmse_ = n > 0 ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
  }

  // --wait-reference is met, or cannot be: a benchmark accumulates nothing.
  bool reference_ready() const {
    return s_.wait_reference_spp <= 0 || benchmarking() || ref_.samples_per_pixel >= s_.wait_reference_spp || !progressive_.error().empty();
  }

  // The method's V, or the reference's for the ground truth.
  const Image<float>& shown_visibility() const {
    return method().ground_truth && !ref_.visibility.empty() ? ref_.visibility : result_.visibility;
  }

  // The images the shaded and map views show, made when they are shown (library calls).
  void prepare_view() {
    const GBuffer& g = *frames_.gbuffer();
    try {
      if (state_.view == ViewMode::Shaded) {
        const Image<float>& v = shown_visibility();
        shaded_ = v.size() == g.object_id.size() ? shade_for_display(g, v, result_.color) : Image<Vec3>();
      }
      if (state_.view == ViewMode::Map && !s_.ao_map.empty()) map_v_ = visibility_from_ao_map(g, *s_.scene, s_.ao_map, "--ao-map");
    } catch (const InputError& e) {
      error_ = e.what();
    }
  }

  // Builds what changed and uploads it. When only the reference changed and the view shows the
  // method left of the wipe, only the columns right of it are rebuilt and sent. Returns whether
  // anything was uploaded.
  bool upload_if_needed() {
    const GBuffer* g = frames_.gbuffer();
    if (!g || (!state_.dirty_display && !state_.dirty_reference_side)) return false;
    const int w = g->width(), h = g->height();
    const bool grey = grey_view(state_.view);
    int x0 = 0;
    if (state_.dirty_display || grey != shown_grey_ || !window_->holds(grey, w, h)) prepare_view();
    else x0 = std::clamp(static_cast<int>(std::lround(state_.wipe * w)), 0, w);
    state_.dirty_display = state_.dirty_reference_side = false;
    shown_grey_ = grey;
    if (x0 >= w) return false;
    build_display(pixels_, {g, state_.view, &shown_visibility(), &ref_.visibility, &result_.color, &shaded_, &map_v_, state_.wipe}, x0);
    window_->upload(pixels_, w, h, grey, x0);
    return true;
  }

  // Uploads the image if it changed and draws it with the HUD and the panel built this frame.
  // Returns the framebuffer's size.
  std::pair<int, int> draw_frame() {
    const Clock::time_point image_start = Clock::now();
    image_ms_ = upload_if_needed() ? ms_since(image_start) : 0.0;
    const int left = panel_width(state_.panel, width_);
    window_->draw_image(shown_grey_, state_.wipe, state_.view != ViewMode::Error, left);
    if (const std::string why = why_no_reference(); !why.empty()) draw_notice(why, static_cast<float>(left));
    if (state_.show_hud) draw_hud(stats_, readout());
    return window_->render();
  }

  // Why the view, which needs the reference, shows none; empty when it has one or needs none.
  std::string why_no_reference() const {
    const GBuffer* g = frames_.gbuffer();
    const bool needs = state_.view == ViewMode::Error || state_.wipe < 1 || method().ground_truth;
    if (!needs || !g || ref_.visibility.size() == g->object_id.size()) return "";
    if (!progressive_.error().empty()) return "No reference: " + progressive_.error();
    if (benchmarking())
      return "No reference: --benchmark recomputes the method every frame, as a moving camera would, so none accumulates. "
             "Press R (or --set reference=on) to pause the benchmark and accumulate one.";
    return "The reference is accumulating: its first rays per pixel are on their way.";
  }

  ViewerReadout readout() const {
    ViewerReadout r{.reference_spp = ref_.samples_per_pixel, .std_error = "-", .rmse = rmse_, .error = error_, .benchmark = s_.benchmark};
    if (ref_.mean_std_error) {
      char text[32];
      std::snprintf(text, sizeof text, "%.4f", *ref_.mean_std_error);
      r.std_error = text;
    }
    if (const GBuffer* g = frames_.gbuffer()) r.width = g->width(), r.height = g->height();
    if (frames_.device() == Device::Gpu) r.gl_renderer = gpu_->renderer(), r.gpu_passes = frames_.gpu_passes();
    return r;
  }

  void take_screenshot(int fbw, int fbh) {
    screenshot_pending_ = false;
    write_rgb_image(screenshot_path_, window_->read_back(fbw, fbh));
    if (!camera_path_.empty()) write_camera_file(camera_path_, image_camera());
    if (s_.frames == 0) std::fprintf(stderr, "wrote %s%s%s\n", screenshot_path_.c_str(), camera_path_.empty() ? "" : " and ", camera_path_.c_str());
  }

  void redraw_for_screenshot() {
    window_->begin_frame();
    draw_panel(state_, *this, readout());
    state_.dirty_display = true;
    const auto [fbw, fbh] = draw_frame();
    take_screenshot(fbw, fbh);
  }

  nlohmann::json summary() const {
    nlohmann::json j = stats_.json();
    j["ao"] = build_info();
    j["method"] = state_.method;
    j["parameters"] = state_.params();
    j["membership"] = to_string(state_.falloff.membership);
    j["radius"] = state_.falloff.radius;
    j["width"] = width_;
    j["height"] = height_;
    j["image_width"] = image_width();  // the window's width less the docked panel's
    j["scale"] = state_.scale;
    j["threads"] = state_.threads;
    j["device"] = to_string(state_.device);
    if (gpu_) {
      j["gl_renderer"] = gpu_->renderer();
      nlohmann::json passes = nlohmann::json::array();  // mean GPU ms of each pass over the runs it was in
      for (const PassTotal& p : gpu_totals_) passes.push_back({{"name", p.name}, {"ms", p.ms / static_cast<double>(p.runs)}, {"runs", p.runs}});
      j["gpu_passes"] = passes;
    }
    j["benchmark"] = s_.benchmark;
    j["camera"] = camera_to_json(current_camera());
    j["reference"] = {{"samples_per_pixel", ref_.samples_per_pixel},
                      {"batches", ref_.batches},
                      {"mean_std_error", ref_.mean_std_error ? nlohmann::json(*ref_.mean_std_error) : nlohmann::json()},
                      {"rmse", rmse_ >= 0 ? nlohmann::json(rmse_) : nlohmann::json()}};
    return j;
  }

  ViewSetup s_;
  FrameRenderer frames_;
  OrbitCamera orbit_;
  ProgressiveReference progressive_;
  ReferenceSnapshot ref_{};
  std::uint64_t reference_version_ = 0;
  ViewerState state_;
  std::unique_ptr<Window> window_;
  std::optional<GpuDevice> gpu_;  // the window's context, borrowed when the GPU device is first chosen
  struct PassTotal {
    std::string name;
    double ms = 0;
    long runs = 0;
  };
  std::vector<PassTotal> gpu_totals_;
  bool shown_grey_ = true;  // which of the window's textures the frame shows
  std::vector<std::uint8_t> pixels_;
  int width_ = 0, height_ = 0;
  int image_width_ = 0;  // the image's width the camera was last fitted to
  long frame_ = 0;
  MethodOutput result_;
  Image<Vec3> shaded_;
  Image<float> map_v_;
  double rmse_ = -1;
  std::string error_;
  bool screenshot_pending_ = false;
  std::string screenshot_path_, camera_path_;
  std::unique_ptr<tbb::global_control> limit_;
  StageStats stats_;
  double image_ms_ = 0;  // building and uploading the image in the last draw_frame
};

}  // namespace

int run_view(ViewSetup setup) {
  Viewer viewer(std::move(setup));
  return viewer.run();
}

}  // namespace ao::view
