#include "view/viewer.h"

#define GL_GLEXT_PROTOTYPES
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui_stdlib.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cctype>
#include <map>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <iostream>
#include <limits>
#include <malloc.h>
#include <memory>
#include <thread>

#include "ao/core/error.h"
#include "ao/core/params.h"
#include "ao/eval/metrics.h"
#include "ao/eval/shading.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/io/camera_json.h"
#include "ao/io/image_io.h"
#include "ao/registry/registry.h"
#include "ao/reference/ray_scene.h"
#include "view/orbit.h"
#include "view/progressive.h"

namespace ao::view {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

enum class ViewMode { AO, Shaded, Transfer, Map, Error };
constexpr const char* kViewNames[] = {"ao", "shaded", "transfer", "map", "error"};
constexpr int kViewCount = 5;
constexpr float kHeatRange = 0.25f;  // |signed error| at full colour, as ao compare's sheets
constexpr int kPanelWidth = 340;
// The reference adds this many rays per pixel per batch: a batch at 960x540 then takes tens of
// milliseconds on two cores, so a change of view never waits long for the batch in flight.
constexpr int kReferenceBatch = 4;
constexpr int kReferenceMax = 4096;

// Per-stage wall times of one frame, ms; a stage that did not run this frame is 0.
struct StageTimes {
  double gbuffer = 0, method = 0, filter = 0, display = 0, frame = 0;
  double image = 0;  // the part of display that builds and uploads the 8-bit image (0: unchanged)
};

// Averages over the frames of the last second (the HUD) and over the whole run (--json).
class StageStats {
 public:
  void add(const StageTimes& t) {
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
  /// The time of each stage the last time it ran.
  const StageTimes& last_run() const { return last_; }
  // Mean of each stage over the frames in which it ran during the last second, and frames per second.
  StageTimes recent(double& fps) const {
    StageTimes sum, n;
    for (const auto& [time, t] : recent_) {
      sum.gbuffer += t.gbuffer, sum.method += t.method, sum.filter += t.filter, sum.display += t.display, sum.frame += t.frame;
      n.gbuffer += t.gbuffer > 0, n.method += t.method > 0, n.filter += t.filter > 0, n.display += t.display > 0;
    }
    fps = static_cast<double>(recent_.size());
    return {mean(sum.gbuffer, n.gbuffer), mean(sum.method, n.method), mean(sum.filter, n.filter), mean(sum.display, n.display),
            mean(sum.frame, static_cast<double>(recent_.size()))};
  }
  nlohmann::json json() const {
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

 private:
  static double mean(double sum, double n) { return n > 0 ? sum / n : 0.0; }
  std::deque<std::pair<Clock::time_point, StageTimes>> recent_;
  StageTimes total_, runs_, last_;
  long frames_ = 0;
};

std::uint8_t to_byte(float v) {
  // As the PNG writer quantises linear V (io/image_io.cpp: lround(c * 255) of the clamped value), so
  // a screenshot of the AO view holds the same 8-bit values as `ao render -o x.png`. For c * 255 in
  // [0, 255] the double sum c * 255 + 0.5 is exact, so truncating it is lround, without its libm
  // call per channel. NaN lands on 0.
  const float c = v > 0.0f ? std::min(v, 1.0f) : 0.0f;
  return static_cast<std::uint8_t>(static_cast<int>(static_cast<double>(c * 255.0f) + 0.5));
}

// IEC 61966-2-1, as the PNG writer encodes --shaded pictures.
float srgb(float v) { return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f; }

std::string next_free_name(const std::string& stem) {
  for (int i = 1;; ++i) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s-%03d", stem.c_str(), i);
    if (!std::filesystem::exists(std::string(buf) + ".png")) return buf;
  }
}

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

class Viewer {
 public:
  explicit Viewer(ViewSetup setup) : s_(std::move(setup)), rays_(s_.scene), orbit_(s_.camera), progressive_(kReferenceBatch, s_.frames > 0 && s_.wait_reference_spp > 0 ? s_.wait_reference_spp : kReferenceMax) {
    width_ = s_.camera.width;
    height_ = s_.camera.height;
    method_ = s_.method;
    params_by_method_[method_] = s_.params;
    falloff_ = s_.falloff;
    if (s_.threads > 0) set_threads(s_.threads);
    for (const std::string& kv : s_.sets) apply_set(kv);
  }

  int run() {
    open_window();
    Clock::time_point last_input = Clock::now();
    for (frame_ = 0;; ++frame_) {
      if (glfwWindowShouldClose(window_)) break;
      if (s_.frames > 0 && frame_ >= s_.frames && reference_ready()) break;
      const Clock::time_point frame_start = Clock::now();
      StageTimes times;
      // Interactive and idle: sleep until input or the reference's next batch, instead of spinning.
      const bool idle = s_.frames == 0 && !s_.benchmark && !dirty_gbuffer_ && !dirty_method_ && Clock::now() - last_input > std::chrono::milliseconds(200);
      if (idle)
        glfwWaitEventsTimeout(0.05);
      else
        glfwPollEvents();
      for (const ScriptedEvent& e : s_.events)
        if (e.frame == frame_) apply_event(e);

      ImGui_ImplOpenGL3_NewFrame();
      ImGui_ImplGlfw_NewFrame();
      ImGui::NewFrame();
      if (handle_input()) last_input = Clock::now();
      if (show_panel_) draw_panel();
      if (s_.benchmark) dirty_gbuffer_ = true;
      update(times);
      const Clock::time_point display_start = Clock::now();
      const auto [fbw, fbh] = draw_frame();
      times.display = ms_since(display_start);
      times.image = image_ms_;
      if (screenshot_pending_) take_screenshot(fbw, fbh);
      glfwSwapBuffers(window_);
      times.frame = ms_since(frame_start);
      stats_.add(times);
    }
    if (!s_.screenshot.empty()) {
      // The last frame is still in the back buffer's twin: draw it once more and read it back.
      screenshot_path_ = s_.screenshot;
      camera_path_ = s_.camera_out;
      redraw_for_screenshot();
    }
    if (s_.json) std::cout << summary().dump(2) << "\n";
    close_window();
    return 0;
  }

 private:
  // --- window --------------------------------------------------------------------------------
  void open_window() {
    glfwSetErrorCallback([](int, const char* message) { last_glfw_error() = message ? message : ""; });
    if (!glfwInit())
      throw SystemError("ao view: no display (" + last_glfw_error() + "): set DISPLAY, or run it under xvfb-run");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);  // the window is the image: its size is the camera's
    window_ = glfwCreateWindow(width_, height_, ("ao view: " + s_.scene.name).c_str(), nullptr, nullptr);
    if (!window_) {
      glfwTerminate();
      throw SystemError("ao view: cannot open an OpenGL 3.3 core window (" + last_glfw_error() + ")");
    }
    glfwMakeContextCurrent(window_);
    glfwSwapInterval(s_.frames > 0 || s_.benchmark ? 0 : 1);
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // write nothing the user did not ask for
    ImGui::StyleColorsDark();
    ImGui_ImplGlfw_InitForOpenGL(window_, true);
    ImGui_ImplOpenGL3_Init("#version 330 core");
    for (Texture* t : {&grey_texture_, &rgba_texture_}) {
      glGenTextures(1, &t->id);
      glBindTexture(GL_TEXTURE_2D, t->id);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    const GLint grey_swizzle[] = {GL_RED, GL_RED, GL_RED, GL_ONE};  // grey codes drawn as (v, v, v, 1)
    glBindTexture(GL_TEXTURE_2D, grey_texture_.id);
    glTexParameteriv(GL_TEXTURE_2D, GL_TEXTURE_SWIZZLE_RGBA, grey_swizzle);
  }

  void close_window() {
    progressive_.stop();
    glDeleteTextures(1, &grey_texture_.id);
    glDeleteTextures(1, &rgba_texture_.id);
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    glfwDestroyWindow(window_);
    glfwTerminate();
  }

  static std::string& last_glfw_error() {
    static std::string message;
    return message;
  }

  // --- input ---------------------------------------------------------------------------------
  // Mouse: left drag orbits, right or middle drag pans, the wheel zooms. Keys: F frame all, Z
  // switch y-up / z-up, S screenshot, 1-4 views, P panel, H HUD. Returns whether anything moved.
  bool handle_input() {
    const ImGuiIO& io = ImGui::GetIO();
    bool any = false;
    if (!io.WantCaptureMouse) {
      const float dx = io.MouseDelta.x, dy = io.MouseDelta.y;
      if ((dx != 0 || dy != 0) && ImGui::IsMouseDown(ImGuiMouseButton_Left)) any |= on_drag(0, dx, dy);
      if ((dx != 0 || dy != 0) && (ImGui::IsMouseDown(ImGuiMouseButton_Right) || ImGui::IsMouseDown(ImGuiMouseButton_Middle)))
        any |= on_drag(1, dx, dy);
      if (io.MouseWheel != 0) any |= on_zoom(io.MouseWheel);
    }
    if (!io.WantCaptureKeyboard)
      for (int key : {GLFW_KEY_F, GLFW_KEY_Z, GLFW_KEY_S, GLFW_KEY_1, GLFW_KEY_2, GLFW_KEY_3, GLFW_KEY_4, GLFW_KEY_5, GLFW_KEY_P, GLFW_KEY_H})
        if (ImGui::IsKeyPressed(key, false)) any |= on_key(key);
    return any;
  }

  bool on_drag(int button, float dx, float dy) {
    if (button == 0)
      orbit_.orbit(dx, dy, height_);
    else
      orbit_.pan(dx, dy, height_);
    camera_moved();
    return true;
  }
  bool on_zoom(float steps) {
    orbit_.zoom(steps);
    camera_moved();
    return true;
  }
  bool on_key(int key) {
    switch (key) {
      case GLFW_KEY_F: orbit_.frame(s_.scene.bounds()); camera_moved(); break;
      case GLFW_KEY_Z: orbit_.set_up_axis(orbit_.up_axis() == UpAxis::Y ? UpAxis::Z : UpAxis::Y); camera_moved(); break;
      case GLFW_KEY_S: {
        const std::string stem = next_free_name("ao-view");
        screenshot_path_ = stem + ".png";
        camera_path_ = stem + ".json";
        screenshot_pending_ = true;
        break;
      }
      case GLFW_KEY_1: case GLFW_KEY_2: case GLFW_KEY_3: case GLFW_KEY_4: case GLFW_KEY_5:
        set_view(static_cast<ViewMode>(key - GLFW_KEY_1));
        break;
      case GLFW_KEY_P: show_panel_ = !show_panel_; break;
      case GLFW_KEY_H: show_hud_ = !show_hud_; break;
      default: return false;
    }
    return true;
  }

  void apply_event(const ScriptedEvent& e) {
    if (e.kind == "orbit" || e.kind == "pan") {
      const auto [dx, dy] = parse_xy(e.args, e.kind);
      on_drag(e.kind == "orbit" ? 0 : 1, dx, dy);
    } else if (e.kind == "zoom") {
      on_zoom(std::stof(e.args));
    } else if (e.kind == "key") {
      on_key(key_code(e.args));
    } else if (e.kind == "set") {
      apply_set(e.args);
    }
  }

  static int key_code(const std::string& name) {
    if (name.size() == 1 && std::isalpha(static_cast<unsigned char>(name[0]))) return GLFW_KEY_A + (std::toupper(name[0]) - 'A');
    if (name.size() == 1 && name[0] >= '1' && name[0] <= '5') return GLFW_KEY_1 + (name[0] - '1');
    throw InputError("--event: unknown key '" + name + "' (keys: F, Z, S, P, H, 1-5)");
  }

  void camera_moved() {
    moved_ = true;
    dirty_gbuffer_ = true;
    progressive_.stop();  // lets go of the G-buffer, so the next one can reuse its storage
  }

  // --set key=value: the viewer's own settings, else a parameter of the current method.
  void apply_set(const std::string& kv) {
    const std::vector<std::string> parts = split_pair(kv, '=');
    if (parts.size() != 2 || parts[0].empty()) throw InputError("--set: expected key=value, got '" + kv + "'");
    const std::string& key = parts[0];
    const std::string& value = parts[1];
    auto number = [&](float lo, float hi) {
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
    };
    if (key == "method") {
      find_method(value);
      select_method(value);
    } else if (key == "view") {
      for (int i = 0; i < kViewCount; ++i)
        if (value == kViewNames[i]) return set_view(static_cast<ViewMode>(i));
      throw InputError("--set view: one of ao, shaded, transfer, map, error, got '" + value + "'");
    } else if (key == "wipe") {
      wipe_ = number(0, 1);
      dirty_display_ = true;
    } else if (key == "scale") {
      const float v = number(1, 4);
      if (v != 1 && v != 2 && v != 4) throw InputError("--set scale: 1, 2 or 4 (the image is computed at 1/scale of the window), got " + value);
      scale_ = static_cast<int>(v);
      dirty_gbuffer_ = true;
    } else if (key == "seed") {
      s_.seed = static_cast<std::uint32_t>(number(0, 4294967295.0f));
      dirty_method_ = true;
    } else if (key == "threads") {
      set_threads(static_cast<int>(number(1, 1024)));
    } else if (key == "radius") {
      falloff_.radius = number(1e-30f, 1e30f);
      dirty_method_ = true;
    } else if (key == "radius_fraction") {
      falloff_.radius = number(1e-6f, 10) * s_.radius_basis;
      dirty_method_ = true;
    } else if (key == "membership") {
      const auto m = parse_membership(value);
      if (!m) throw InputError("--set membership: one of " + membership_names() + ", got '" + value + "'");
      falloff_.membership = *m;
      dirty_method_ = true;
    } else if (key == "up") {
      if (value != "y" && value != "z") throw InputError("--set up: y or z, got '" + value + "'");
      orbit_.set_up_axis(value == "y" ? UpAxis::Y : UpAxis::Z);
      camera_moved();
    } else if (key == "panel" || key == "hud") {
      if (value != "on" && value != "off") throw InputError("--set " + key + ": on or off, got '" + value + "'");
      (key == "panel" ? show_panel_ : show_hud_) = value == "on";
    } else {
      nlohmann::json& params = current_params();
      if (!params.contains(key)) {
        std::string known = "method, view, wipe, scale, seed, threads, radius, radius_fraction, membership, up, panel, hud";
        for (const auto& [k, v] : params.items()) known += ", " + k;
        throw InputError("--set: unknown key '" + key + "' (viewer settings and parameters of " + method_ + ": " + known + ")");
      }
      const nlohmann::json parsed = nlohmann::json::parse(value, nullptr, /*allow_exceptions=*/false);
      params[key] = parsed.is_discarded() ? nlohmann::json(value) : parsed;
      dirty_method_ = true;
    }
  }

  void set_view(ViewMode v) {
    view_ = v;
    dirty_display_ = true;
  }

  void set_threads(int n) {
    threads_ = n;
    limit_.reset();
    limit_ = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(n));
  }

  nlohmann::json& current_params() {
    auto it = params_by_method_.find(method_);
    if (it == params_by_method_.end()) it = params_by_method_.emplace(method_, find_method(method_).default_params()).first;
    return it->second;
  }

  void select_method(const std::string& name) {
    method_ = name;
    current_params();
    dirty_method_ = true;
  }

  // --- work ----------------------------------------------------------------------------------
  Camera current_camera() const {
    const int w = std::max(1, width_ / scale_), h = std::max(1, height_ / scale_);
    // Until the user moves, the start view exactly as ao render chose it (no trip through yaw and pitch).
    Camera c = moved_ ? orbit_.camera(w, h) : s_.camera;
    c.width = w;
    c.height = h;
    return c;
  }

  void update(StageTimes& times) {
    try {
      if (dirty_gbuffer_) {
        const Clock::time_point t = Clock::now();
        Camera cam = current_camera();
        cam.validate();
        // Render into the G-buffer of the previous frame when the reference no longer holds it: a
        // moving camera then touches no fresh pages (half of a cold G-buffer is page faults).
        if (gbuffer_ && gbuffer_.use_count() == 1)
          render_gbuffer(rays_, cam, *gbuffer_);
        else
          gbuffer_ = std::make_shared<GBuffer>(render_gbuffer(rays_, cam));
        times.gbuffer = ms_since(t);
        dirty_gbuffer_ = false;
        dirty_method_ = true;
      }
      if (dirty_method_) {
        const Clock::time_point t = Clock::now();
        const MethodInfo& m = find_method(method_);
        nlohmann::json params = current_params();
        if (method_ == "raytraced") {
          result_ = MethodOutput{};  // the view shows the progressive reference itself
        } else {
          result_ = m.run(MethodInput{*gbuffer_, &rays_, falloff_, s_.seed, {}, &s_.scene.analytic, &method_cache_}, params);
        }
        times.method = ms_since(t);
        if (result_.stats.contains("filter_ms")) {
          times.filter = result_.stats["filter_ms"].get<double>();
          times.method = std::max(0.0, times.method - times.filter);
        }
        dirty_method_ = false;
        dirty_display_ = true;
        restart_reference(m, params);
        error_.clear();
      }
    } catch (const InputError& e) {
      if (s_.frames > 0) throw;  // a scripted run must fail loudly
      error_ = e.what();
      dirty_gbuffer_ = dirty_method_ = false;
    }
    const std::uint64_t v = progressive_.version();
    if (v != reference_version_) {
      reference_version_ = v;
      ref_ = progressive_.snapshot();
      if (const std::string e = progressive_.error(); !e.empty()) error_ = "reference: " + e;
      update_rmse();
      if (view_ == ViewMode::Error || method_ == "raytraced")
        dirty_display_ = true;
      else if (wipe_ < 1)
        dirty_reference_side_ = true;
    }
  }

  void restart_reference(const MethodInfo& m, const nlohmann::json& params) {
    if (s_.benchmark) {  // a moving camera: nothing to accumulate
      progressive_.stop();
      return;
    }
    ReferenceJob job;
    job.gbuffer = gbuffer_;
    job.scene = &rays_;
    job.spec = m.reference(falloff_, params);
    job.seed = s_.seed;
    progressive_.restart(std::move(job));
  }

  void update_rmse() {
    rmse_ = -1;
    if (ref_.visibility.empty() || result_.visibility.empty() || !gbuffer_) return;
    if (ref_.visibility.size() != result_.visibility.size()) return;
    double sum = 0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < gbuffer_->object_id.size(); ++i) {
      if (!gbuffer_->covered(i)) continue;
      const double d = static_cast<double>(result_.visibility[i]) - ref_.visibility[i];
      sum += d * d;
      ++n;
    }
    rmse_ = n > 0 ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
  }

  bool reference_ready() const { return s_.wait_reference_spp <= 0 || ref_.samples_per_pixel >= s_.wait_reference_spp || !progressive_.error().empty(); }

  // --- display -------------------------------------------------------------------------------
  // The images the shaded and map views show, made when they are shown (library calls).
  void prepare_view() {
    const GBuffer& g = *gbuffer_;
    try {
      if (view_ == ViewMode::Shaded) {
        const Image<float>& v = method_ == "raytraced" && !ref_.visibility.empty() ? ref_.visibility : result_.visibility;
        shaded_ = v.size() == g.object_id.size() ? shade_for_display(g, v, result_.color) : Image<Vec3>();
      }
      if (view_ == ViewMode::Map && !s_.ao_map.empty()) map_v_ = visibility_from_ao_map(g, s_.scene, s_.ao_map, "--ao-map");
    } catch (const InputError& e) {
      error_ = e.what();
    }
  }

  // The AO and map views are grey: one byte per pixel into a GL_R8 texture whose swizzle repeats
  // red into green and blue (a quarter of the bytes to build and upload). The others are RGBA8.
  bool grey_view() const { return view_ == ViewMode::AO || view_ == ViewMode::Map; }

  // The method's V (or what the view asks for) as 8-bit codes, left of the wipe; the reference
  // right of it. Only the columns [x0, w) are built (x0 > 0: the reference side alone changed).
  // Rows in parallel: every pixel is independent.
  void build_display(int x0) {
    const GBuffer& g = *gbuffer_;
    const int w = g.width(), h = g.height();
    const bool grey = grey_view();
    const int channels = grey ? 1 : 4;
    pixels_.resize(static_cast<std::size_t>(w) * h * channels);
    const bool have_ref = !ref_.visibility.empty() && ref_.visibility.width() == w && ref_.visibility.height() == h;
    const Image<float>& method_v = method_ == "raytraced" && have_ref ? ref_.visibility : result_.visibility;
    const int split = have_ref ? static_cast<int>(std::lround(wipe_ * w)) : w;
    const ViewMode view = view_;
    const bool transfer = view == ViewMode::Transfer && !result_.color.empty();
    const bool shaded = view == ViewMode::Shaded && !shaded_.empty();
    const bool map = view == ViewMode::Map && !map_v_.empty();
    tbb::parallel_for(tbb::blocked_range<int>(0, h, 8), [&](const tbb::blocked_range<int>& rows) {
      for (int y = rows.begin(); y < rows.end(); ++y) {
        const std::size_t row = static_cast<std::size_t>(y) * w;
        std::uint8_t* out = &pixels_[row * channels];
        if (grey) {
          // Method side, then reference side: two plain loops.
          const float* v = map ? &map_v_[row] : method_v.empty() ? nullptr : &method_v[row];
          for (int x = x0; x < std::min(split, w); ++x) out[x] = v ? to_byte(v[x]) : 255;
          for (int x = std::max(x0, split); x < w; ++x) out[x] = to_byte(ref_.visibility[row + x]);
          continue;
        }
        for (int x = x0; x < w; ++x) {
          const std::size_t i = row + x;
          Vec3 c{1, 1, 1};
          if (view == ViewMode::Error) {
            if (!g.covered(i)) {
              c = {0.5f, 0.5f, 0.5f};
            } else if (have_ref && !method_v.empty()) {
              c = signed_error_colour(method_v[i] - ref_.visibility[i], kHeatRange);
            }
          } else if (x >= split) {
            const float v = ref_.visibility[i];
            c = {v, v, v};
          } else if (transfer) {
            c = result_.color[i];
          } else if (shaded) {
            c = {srgb(shaded_[i].x), srgb(shaded_[i].y), srgb(shaded_[i].z)};
          } else if (!method_v.empty()) {
            const float v = method_v[i];
            c = {v, v, v};
          }
          std::uint8_t* px = out + 4 * x;
          px[0] = to_byte(c.x), px[1] = to_byte(c.y), px[2] = to_byte(c.z), px[3] = 255;
        }
      }
    });
  }

  // Builds what changed and uploads it into the persistent texture of its format with
  // glTexSubImage2D (glTexImage2D only when the size changes). The formats are the textures' own
  // (R8 from GL_RED bytes, RGBA8 from GL_RGBA bytes), so Mesa copies rows without converting. No
  // pixel buffer object: a software driver (llvmpipe) copies from one on the CPU just the same, and
  // there is no transfer to a device to overlap with the next frame. When only the reference changed and the
  // view shows the method left of the wipe, only the columns right of it are rebuilt and sent.
  // Returns whether anything was uploaded.
  bool upload_if_needed() {
    if (!gbuffer_ || (!dirty_display_ && !dirty_reference_side_)) return false;
    const int w = gbuffer_->width(), h = gbuffer_->height();
    const bool grey = grey_view();
    Texture& tex = grey ? grey_texture_ : rgba_texture_;
    int x0 = 0;
    if (dirty_display_ || grey != shown_grey_ || tex.w != w || tex.h != h) {
      prepare_view();
    } else {
      x0 = std::clamp(static_cast<int>(std::lround(wipe_ * w)), 0, w);
    }
    dirty_display_ = dirty_reference_side_ = false;
    shown_grey_ = grey;
    if (x0 >= w) return false;
    build_display(x0);
    const GLenum format = grey ? GL_RED : GL_RGBA;
    glBindTexture(GL_TEXTURE_2D, tex.id);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, w);
    glPixelStorei(GL_UNPACK_SKIP_PIXELS, x0);
    if (w != tex.w || h != tex.h) {
      glTexImage2D(GL_TEXTURE_2D, 0, grey ? GL_R8 : GL_RGBA8, w, h, 0, format, GL_UNSIGNED_BYTE, pixels_.data());
      tex.w = w, tex.h = h;
    } else {
      glTexSubImage2D(GL_TEXTURE_2D, 0, x0, 0, w - x0, h, format, GL_UNSIGNED_BYTE, pixels_.data());
    }
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glPixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
    return true;
  }

  void draw_image() {
    const Texture& tex = shown_grey_ ? grey_texture_ : rgba_texture_;
    if (tex.w == 0) return;
    const ImVec2 size = ImGui::GetIO().DisplaySize;
    // The image is opaque and covers the window: drawn without blending, llvmpipe does not read the
    // framebuffer under it. The backend restores its own state (blending on) after it.
    ImDrawList* list = ImGui::GetBackgroundDrawList();
    list->AddCallback([](const ImDrawList*, const ImDrawCmd*) { glDisable(GL_BLEND); }, nullptr);
    list->AddImage(reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(tex.id)), ImVec2(0, 0), size);
    list->AddCallback(ImDrawCallback_ResetRenderState, nullptr);
    if (wipe_ > 0 && wipe_ < 1 && view_ != ViewMode::Error) {
      const float x = std::round(wipe_ * size.x);
      ImGui::GetForegroundDrawList()->AddLine(ImVec2(x, 0), ImVec2(x, size.y), IM_COL32(255, 200, 0, 255), 1.0f);
    }
  }

  static void tooltip(const std::string& text) {
    if (!text.empty() && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", text.c_str());
  }

  // One widget per parameter of the method, generated from its parameter table (core/params.h):
  // checkboxes, enum combos, integer and number fields clamped to the valid range, and the unit,
  // range and one-line help as the tooltip. A value the table refuses shows its one-line error.
  void draw_parameters() {
    const MethodInfo& m = find_method(method_);
    nlohmann::json& params = current_params();
    const std::vector<ParamSpec>& specs = m.params().specs();
    for (const ParamSpec& spec : specs) {
      if (!params.contains(spec.name)) continue;
      nlohmann::json& value = params[spec.name];
      const char* label = spec.name.c_str();
      const auto clamp_to = [&](double v) {
        const double lo = std::isfinite(spec.range.min) ? spec.range.min : v, hi = std::isfinite(spec.range.max) ? spec.range.max : v;
        return std::clamp(v, lo, hi);
      };
      bool changed = false;
      if (value.is_null()) {  // an optional parameter left to its preset: say so, offer to set it
        ImGui::TextDisabled("%s: from the preset", label);
        ImGui::SameLine();
        if ((changed = ImGui::SmallButton(("set##" + spec.name).c_str())))
          value = spec.type == ParamType::OptionalInt ? nlohmann::json(static_cast<int>(clamp_to(1))) : nlohmann::json(static_cast<float>(clamp_to(1)));
        tooltip(spec.help + "\n" + spec.valid_text());
        if (changed) dirty_method_ = true;
        continue;
      }
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
              if (ImGui::Selectable(name.c_str(), name == current)) {
                value = name;
                changed = true;
              }
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
      tooltip(spec.help + "\n" + spec.valid_text());
      if (changed) dirty_method_ = true;
    }
    // Registry-level keys without a table row (e.g. characteristic, reference): a text field.
    for (auto item : params.items()) {  // no structured binding: Clang 14 cannot capture one in the lambda
      const std::string& key = item.key();
      nlohmann::json& value = item.value();
      if (std::any_of(specs.begin(), specs.end(), [&](const ParamSpec& s) { return s.name == key; }) || !value.is_string()) continue;
      std::string v = value.get<std::string>();
      if (ImGui::InputText(key.c_str(), &v, ImGuiInputTextFlags_EnterReturnsTrue)) {
        value = v;
        dirty_method_ = true;
      }
    }
  }

  void draw_panel() {
    ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_Once);
    // As tall as its contents, but never taller than the window (it scrolls then).
    const float max_height = std::max(100.0f, ImGui::GetIO().DisplaySize.y - 16.0f);
    ImGui::SetNextWindowSizeConstraints(ImVec2(kPanelWidth, 0), ImVec2(kPanelWidth, max_height));
    ImGui::SetNextWindowBgAlpha(0.85f);
    ImGui::Begin("ao view", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
    ImGui::PushItemWidth(-150.0f);  // room for the longest parameter name
    if (ImGui::BeginCombo("method", method_.c_str())) {
      for (const MethodInfo& m : all_methods()) {
        if (ImGui::Selectable(std::string(m.name).c_str(), m.name == method_)) select_method(std::string(m.name));
        tooltip(std::string(m.summary));
      }
      ImGui::EndCombo();
    }
    tooltip(std::string(find_method(method_).summary));
    if (ImGui::CollapsingHeader("parameters", ImGuiTreeNodeFlags_DefaultOpen)) draw_parameters();
    if (ImGui::CollapsingHeader("neighbourhood", ImGuiTreeNodeFlags_DefaultOpen)) {
      const std::string membership(to_string(falloff_.membership));
      if (ImGui::BeginCombo("membership", membership.c_str())) {
        for (Membership m : {Membership::Step, Membership::Linear, Membership::Sqrt, Membership::Cubic, Membership::Exp, Membership::Alchemy})
          if (ImGui::Selectable(std::string(to_string(m)).c_str(), m == falloff_.membership)) {
            falloff_.membership = m;
            dirty_method_ = true;
          }
        ImGui::EndCombo();
      }
      float radius = falloff_.radius, fraction = falloff_.radius / s_.radius_basis;
      if (ImGui::DragFloat("R (world)", &radius, 0.005f * s_.radius_basis, 1e-6f * s_.radius_basis, 10 * s_.radius_basis, "%.4g")) {
        falloff_.radius = std::max(radius, 1e-6f * s_.radius_basis);
        dirty_method_ = true;
      }
      tooltip("neighbourhood radius R, world units");
      if (ImGui::DragFloat("R / diagonal", &fraction, 0.002f, 1e-4f, 10.0f, "%.4f")) {
        falloff_.radius = std::max(fraction, 1e-6f) * s_.radius_basis;
        dirty_method_ = true;
      }
      tooltip("R as a fraction of the scene diagonal (" + std::to_string(s_.radius_basis) + " world units)");
      int seed = static_cast<int>(s_.seed);
      if (ImGui::InputInt("seed", &seed)) {
        s_.seed = static_cast<std::uint32_t>(std::max(seed, 0));
        dirty_method_ = true;
      }
    }
    if (ImGui::CollapsingHeader("view", ImGuiTreeNodeFlags_DefaultOpen)) {
      int view = static_cast<int>(view_);
      for (int i = 0; i < kViewCount; ++i) {
        if (i > 0) ImGui::SameLine();
        if (ImGui::RadioButton(kViewNames[i], &view, i)) set_view(static_cast<ViewMode>(view));
      }
      if (ImGui::SliderFloat("wipe", &wipe_, 0.0f, 1.0f, "%.2f")) dirty_display_ = true;
      tooltip("left of the line: the method; right: the reference");
      int scale = scale_ == 1 ? 0 : scale_ == 2 ? 1 : 2;
      const char* scales[] = {"1", "1/2", "1/4"};
      if (ImGui::Combo("resolution", &scale, scales, 3)) {
        scale_ = 1 << scale;
        dirty_gbuffer_ = true;
      }
      int threads = threads_ > 0 ? threads_ : static_cast<int>(std::thread::hardware_concurrency());
      if (ImGui::SliderInt("threads", &threads, 1, std::max(1, static_cast<int>(std::thread::hardware_concurrency())))) set_threads(threads);
      if (ImGui::Button("frame all (F)")) on_key(GLFW_KEY_F);
      ImGui::SameLine();
      if (ImGui::Button(orbit_.up_axis() == UpAxis::Y ? "y-up (Z)" : "z-up (Z)")) on_key(GLFW_KEY_Z);
      ImGui::SameLine();
      if (ImGui::Button("screenshot (S)")) on_key(GLFW_KEY_S);
    }
    if (ImGui::CollapsingHeader("reference", ImGuiTreeNodeFlags_DefaultOpen)) {
      ImGui::Text("%d rays/pixel, std error %s", ref_.samples_per_pixel, std_error_text().c_str());
      if (rmse_ >= 0) ImGui::Text("RMSE of %s: %.4f", method_.c_str(), rmse_);
    }
    if (!error_.empty()) ImGui::TextWrapped("%s", error_.c_str());
    ImGui::PopItemWidth();
    ImGui::End();
  }

  void draw_hud() {
    double fps = 0;
    StageTimes t = stats_.recent(fps);
    // A stage that has not run in the last second (nothing changed) shows its last time.
    const StageTimes& last = stats_.last_run();
    for (auto [now, then] : {std::pair{&t.gbuffer, last.gbuffer}, {&t.method, last.method}, {&t.filter, last.filter}, {&t.display, last.display}})
      if (*now == 0) *now = then;
    const ImVec2 size = ImGui::GetIO().DisplaySize;
    ImGui::SetNextWindowPos(ImVec2(size.x - 8, 8), ImGuiCond_Always, ImVec2(1, 0));
    ImGui::SetNextWindowBgAlpha(0.6f);
    ImGui::Begin("hud", nullptr,
                 ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoInputs | ImGuiWindowFlags_NoSavedSettings);
    ImGui::Text("%.0f fps  (%d x %d)", fps, gbuffer_ ? gbuffer_->width() : 0, gbuffer_ ? gbuffer_->height() : 0);
    ImGui::Text("G-buffer %6.1f ms", t.gbuffer);
    ImGui::Text("method   %6.1f ms", t.method);
    ImGui::Text("filter   %6.1f ms", t.filter);
    ImGui::Text("display  %6.1f ms", t.display);
    ImGui::Text("ref %d spp, se %s", ref_.samples_per_pixel, std_error_text().c_str());
    if (rmse_ >= 0) ImGui::Text("RMSE %.4f", rmse_);
    ImGui::End();
  }

  // --- output --------------------------------------------------------------------------------
  void take_screenshot(int fbw, int fbh) {
    screenshot_pending_ = false;
    std::vector<std::uint8_t> rgb(static_cast<std::size_t>(fbw) * fbh * 3);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_BACK);
    glReadPixels(0, 0, fbw, fbh, GL_RGB, GL_UNSIGNED_BYTE, rgb.data());
    Image<Vec3> image(fbw, fbh);
    for (int y = 0; y < fbh; ++y)  // OpenGL's rows go upwards
      for (int x = 0; x < fbw; ++x) {
        const std::uint8_t* p = &rgb[(static_cast<std::size_t>(fbh - 1 - y) * fbw + x) * 3];
        image(x, y) = Vec3{p[0] / 255.0f, p[1] / 255.0f, p[2] / 255.0f};  // written back to the same bytes
      }
    write_rgb_image(screenshot_path_, image);
    if (!camera_path_.empty()) {
      Camera cam = current_camera();
      cam.width = width_, cam.height = height_;
      write_camera_file(camera_path_, cam);
    }
    if (s_.frames == 0) std::fprintf(stderr, "wrote %s%s%s\n", screenshot_path_.c_str(), camera_path_.empty() ? "" : " and ", camera_path_.c_str());
  }

  void redraw_for_screenshot() {
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    if (show_panel_) draw_panel();
    dirty_display_ = true;
    const auto [fbw, fbh] = draw_frame();
    take_screenshot(fbw, fbh);
  }

  // Uploads the image if it changed, draws it with the HUD and the panel built this frame into the
  // back buffer, and waits for the drawing (so the display stage counts it, not just its
  // submission). Returns the framebuffer's size.
  std::pair<int, int> draw_frame() {
    const Clock::time_point image_start = Clock::now();
    image_ms_ = upload_if_needed() ? ms_since(image_start) : 0.0;
    draw_image();
    if (show_hud_) draw_hud();
    ImGui::Render();
    int fbw = 0, fbh = 0;
    glfwGetFramebufferSize(window_, &fbw, &fbh);
    glViewport(0, 0, fbw, fbh);
    glClearColor(0.1f, 0.1f, 0.1f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    glFinish();
    return {fbw, fbh};
  }

  // The reference's standard error as shown: "-" until two batches allow an estimate.
  std::string std_error_text() const {
    if (!ref_.mean_std_error) return "-";
    char text[32];
    std::snprintf(text, sizeof text, "%.4f", *ref_.mean_std_error);
    return text;
  }

  nlohmann::json summary() const {
    nlohmann::json j = stats_.json();
    j["method"] = method_;
    j["parameters"] = params_by_method_.at(method_);
    j["membership"] = to_string(falloff_.membership);
    j["radius"] = falloff_.radius;
    j["width"] = width_;
    j["height"] = height_;
    j["scale"] = scale_;
    j["threads"] = threads_;
    j["benchmark"] = s_.benchmark;
    j["camera"] = camera_to_json(current_camera());
    j["reference"] = {{"samples_per_pixel", ref_.samples_per_pixel},
                      {"batches", ref_.batches},
                      {"mean_std_error", ref_.mean_std_error ? nlohmann::json(*ref_.mean_std_error) : nlohmann::json()},
                      {"rmse", rmse_ >= 0 ? nlohmann::json(rmse_) : nlohmann::json()}};
    return j;
  }

  ViewSetup s_;
  RayScene rays_;
  OrbitCamera orbit_;
  ProgressiveReference progressive_;
  ReferenceSnapshot ref_{};
  std::uint64_t reference_version_ = 0;
  GLFWwindow* window_ = nullptr;
  struct Texture {
    GLuint id = 0;
    int w = 0, h = 0;
  };
  Texture grey_texture_, rgba_texture_;  // the grey views' GL_R8 and the others' GL_RGBA8
  bool shown_grey_ = true;               // which of them the frame shows
  std::vector<std::uint8_t> pixels_;
  int width_ = 0, height_ = 0, scale_ = 1, threads_ = 0;
  long frame_ = 0;
  std::string method_;
  std::map<std::string, nlohmann::json> params_by_method_;
  Falloff falloff_;
  std::shared_ptr<GBuffer> gbuffer_;
  MethodOutput result_;
  MethodCache method_cache_;  // cone's voxel grid, transfer's scratch images: kept from frame to frame
  Image<Vec3> shaded_;
  Image<float> map_v_;
  double rmse_ = -1;
  std::string error_;
  ViewMode view_ = ViewMode::AO;
  float wipe_ = 1.0f;
  bool moved_ = false, show_panel_ = true, show_hud_ = true;
  bool dirty_gbuffer_ = true, dirty_method_ = true, dirty_display_ = true;
  bool dirty_reference_side_ = false;  // only the reference (right of the wipe) changed
  bool screenshot_pending_ = false;
  std::string screenshot_path_, camera_path_;
  std::unique_ptr<tbb::global_control> limit_;
  StageStats stats_;
  double image_ms_ = 0;  // building and uploading the image in the last draw_frame
};

}  // namespace

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

int run_view(ViewSetup setup) {
  // Every frame allocates and frees images of the same few sizes (G-buffer planes, method outputs
  // and scratch). glibc would return most of them to the kernel (blocks above the mmap threshold,
  // and the heap's free top beyond the trim threshold), and the next frame would fault in fresh
  // zeroed pages (BENCHMARKS.md, "ao view", measures what that cost). Keep freed memory in the
  // process instead: blocks up to 32 MB (glibc's largest mmap threshold) come from the heap, and
  // the heap is never trimmed, so the process keeps the most memory it ever used at once.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, std::numeric_limits<int>::max());
  Viewer viewer(std::move(setup));
  return viewer.run();
}

}  // namespace ao::view
