// SPDX-License-Identifier: Apache-2.0
#include "view/window.h"

#define GL_GLEXT_PROTOTYPES
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include <cmath>

#include "ao/core/error.h"

namespace ao::view {

namespace {

std::string& last_glfw_error() {
  static std::string message;
  return message;
}

struct Texture {
  GLuint id = 0;
  int w = 0, h = 0;
};

}  // namespace

struct Window::Impl {
  GLFWwindow* window = nullptr;
  Texture grey, rgba;  // the grey views' GL_R8 and the others' GL_RGBA8
  Texture& texture(bool is_grey) { return is_grey ? grey : rgba; }
};

Window::Window(int width, int height, const std::string& title, bool vsync) : impl_(std::make_unique<Impl>()) {
  glfwSetErrorCallback([](int, const char* message) { last_glfw_error() = message ? message : ""; });
  if (!glfwInit()) throw SystemError("ao view: no display (" + last_glfw_error() + "): set DISPLAY, or run it under xvfb-run");
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);  // the image and the panel share a window of fixed size
  // 4.3 (compute shaders, for the GPU backend) when the driver has it, else 3.3 (the CPU's images).
  for (const int minor_of_4 : {3, -1}) {
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, minor_of_4 < 0 ? 3 : 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, minor_of_4 < 0 ? 3 : minor_of_4);
    impl_->window = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    if (impl_->window) break;
  }
  if (!impl_->window) {
    glfwTerminate();
    throw SystemError("ao view: cannot open an OpenGL 3.3 core window (" + last_glfw_error() + ")");
  }
  glfwMakeContextCurrent(impl_->window);
  glfwSwapInterval(vsync ? 1 : 0);
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // write nothing the user did not ask for
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(impl_->window, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");
  for (Texture* t : {&impl_->grey, &impl_->rgba}) {
    glGenTextures(1, &t->id);
    glBindTexture(GL_TEXTURE_2D, t->id);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  }
  const GLint grey_swizzle[] = {GL_RED, GL_RED, GL_RED, GL_ONE};  // grey codes drawn as (v, v, v, 1)
  glBindTexture(GL_TEXTURE_2D, impl_->grey.id);
  glTexParameteriv(GL_TEXTURE_2D, GL_TEXTURE_SWIZZLE_RGBA, grey_swizzle);
}

Window::~Window() {
  glDeleteTextures(1, &impl_->grey.id);
  glDeleteTextures(1, &impl_->rgba.id);
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(impl_->window);
  glfwTerminate();
}

bool Window::has_gl43() const {
  const int major = glfwGetWindowAttrib(impl_->window, GLFW_CONTEXT_VERSION_MAJOR);
  return major > 4 || (major == 4 && glfwGetWindowAttrib(impl_->window, GLFW_CONTEXT_VERSION_MINOR) >= 3);
}

GlProcLoader Window::gl_proc_loader() const { return glfwGetProcAddress; }

bool Window::should_close() const { return glfwWindowShouldClose(impl_->window); }
void Window::wait_events(double seconds) { glfwWaitEventsTimeout(seconds); }
void Window::poll_events() { glfwPollEvents(); }

void Window::begin_frame() {
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
}

// glTexSubImage2D into the persistent texture of its format (glTexImage2D only when the size
// changes). The formats are the textures' own (R8 from GL_RED bytes, RGBA8 from GL_RGBA bytes), so
// Mesa copies rows without converting. No pixel buffer object: a software driver (llvmpipe) copies
// from one on the CPU just the same, and there is no transfer to a device to overlap with the next
// frame.
void Window::upload(const std::vector<std::uint8_t>& pixels, int w, int h, bool grey, int x0) {
  Texture& tex = impl_->texture(grey);
  const GLenum format = grey ? GL_RED : GL_RGBA;
  glBindTexture(GL_TEXTURE_2D, tex.id);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, w);
  glPixelStorei(GL_UNPACK_SKIP_PIXELS, x0);
  if (w != tex.w || h != tex.h) {
    glTexImage2D(GL_TEXTURE_2D, 0, grey ? GL_R8 : GL_RGBA8, w, h, 0, format, GL_UNSIGNED_BYTE, pixels.data());
    tex.w = w, tex.h = h;
  } else {
    glTexSubImage2D(GL_TEXTURE_2D, 0, x0, 0, w - x0, h, format, GL_UNSIGNED_BYTE, pixels.data());
  }
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glPixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
}

bool Window::holds(bool grey, int w, int h) const {
  const Texture& tex = impl_->texture(grey);
  return tex.w == w && tex.h == h;
}

void Window::draw_image(bool grey, float wipe, bool wipe_line, int left) {
  const Texture& tex = impl_->texture(grey);
  if (tex.w == 0) return;
  const ImVec2 size = ImGui::GetIO().DisplaySize;
  const float x0 = static_cast<float>(left);
  // The image is opaque and covers its part of the window: drawn without blending, llvmpipe does
  // not read the framebuffer under it. The backend restores its own state (blending on) after it.
  ImDrawList* list = ImGui::GetBackgroundDrawList();
  list->AddCallback([](const ImDrawList*, const ImDrawCmd*) { glDisable(GL_BLEND); }, nullptr);
  list->AddImage(reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(tex.id)), ImVec2(x0, 0), size);
  list->AddCallback(ImDrawCallback_ResetRenderState, nullptr);
  if (wipe > 0 && wipe < 1 && wipe_line) {
    const float x = x0 + std::round(wipe * (size.x - x0));
    ImGui::GetForegroundDrawList()->AddLine(ImVec2(x, 0), ImVec2(x, size.y), IM_COL32(255, 200, 0, 255), 1.0f);
  }
}

std::pair<int, int> Window::render() {
  ImGui::Render();
  int fbw = 0, fbh = 0;
  glfwGetFramebufferSize(impl_->window, &fbw, &fbh);
  glViewport(0, 0, fbw, fbh);
  glClearColor(0.1f, 0.1f, 0.1f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  // Waits for the drawing, so the display stage counts it, not just its submission.
  glFinish();
  return {fbw, fbh};
}

void Window::swap() { glfwSwapBuffers(impl_->window); }

Image<Vec3> Window::read_back(int width, int height) const {
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(width) * height * 3);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, rgb.data());
  Image<Vec3> image(width, height);
  for (int y = 0; y < height; ++y)  // OpenGL's rows go upwards
    for (int x = 0; x < width; ++x) {
      const std::uint8_t* p = &rgb[(static_cast<std::size_t>(height - 1 - y) * width + x) * 3];
      image(x, y) = Vec3{p[0] / 255.0f, p[1] / 255.0f, p[2] / 255.0f};  // written back to the same bytes
    }
  return image;
}

}  // namespace ao::view
