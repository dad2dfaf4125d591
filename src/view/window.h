// SPDX-License-Identifier: Apache-2.0
// The window of `ao view` and everything OpenGL: GLFW, Dear ImGui's context, the two textures the
// image is shown from, the frame's drawing, and reading it back for screenshots. The rest of the
// viewer never calls GL (the GPU backend, src/ao/gpu/, computes in this window's context when the
// viewer runs the method there).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ao/core/image.h"
#include "ao/core/math.h"
#include "ao/gpu/device.h"

namespace ao::view {

class Window {
 public:
  /// Opens a width x height window with an OpenGL 4.3 core context (what the GPU backend needs),
  /// else 3.3 core (enough to show images), and Dear ImGui on it; `vsync` paces frames to the
  /// display. SystemError with one line when there is no display or no GL 3.3.
  Window(int width, int height, const std::string& title, bool vsync);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  /// The context is OpenGL 4.3 core: GpuDevice::from_current_context(gl_proc_loader()) can borrow it.
  bool has_gl43() const;
  /// glfwGetProcAddress: the context's GL functions, for GpuDevice::from_current_context.
  GlProcLoader gl_proc_loader() const;

  bool should_close() const;
  /// Waits for input for at most `seconds` (an idle interactive window), or only polls.
  void wait_events(double seconds);
  void poll_events();
  /// Starts Dear ImGui's frame: widgets can be declared until render().
  void begin_frame();

  /// Uploads an image of w x h (grey: one byte per pixel into an R8 texture shown as grey; else
  /// RGBA8), columns [x0, w) of it when the texture already has that size.
  void upload(const std::vector<std::uint8_t>& pixels, int w, int h, bool grey, int x0);
  /// Whether the texture of that kind holds an image of w x h.
  bool holds(bool grey, int w, int h) const;
  /// Draws the last uploaded image of that kind over the window right of column `left` (the
  /// docked panel's width; 0: the whole window), and the wipe line at `wipe` (a fraction of the
  /// image's width) when it is inside (0, 1) and `wipe_line`.
  void draw_image(bool grey, float wipe, bool wipe_line, int left);
  /// Renders the frame's widgets over the image into the back buffer and waits for the drawing.
  /// Returns the framebuffer's size.
  std::pair<int, int> render();
  void swap();
  /// The back buffer as linear-coded RGB (each byte b as b / 255), top row first.
  Image<Vec3> read_back(int width, int height) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ao::view
