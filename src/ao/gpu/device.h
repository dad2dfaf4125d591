// SPDX-License-Identifier: Apache-2.0
// The GPU backend's device: an OpenGL 4.3+ core context that runs the methods as compute shaders
// (docs/gpu.md). Either headless through EGL (no window, no X: Mesa's software renderer llvmpipe
// where there is no GPU) or the caller's current context (a viewer's window).
//
// libEGL and the GL functions are resolved at run time, so a program linked with libao starts on a
// machine without any GL; only opening a device then fails, with a SystemError naming what is
// missing. A library built without the backend (CMake AO_GPU=OFF) keeps this API, and opening a
// device says so.
#pragma once

#include <memory>
#include <string>
#include <utility>

namespace ao {

namespace gpu_detail {
class Context;
struct Access;
}  // namespace gpu_detail

/// An OpenGL function as a loader returns it (cast to its real type before calling).
using GlProc = void (*)();
/// Resolves an OpenGL function of the current context by name ("glDispatchCompute"), or returns
/// null: glfwGetProcAddress, eglGetProcAddress, SDL_GL_GetProcAddress...
using GlProcLoader = GlProc (*)(const char* name);

/// How GpuDevice::open picks its device.
struct GpuDeviceOptions {
  /// True: Mesa's software renderer (llvmpipe) even when a GPU is present, so that results do not
  /// depend on the machine's GPU and driver (the tests). False (default): the first hardware EGL
  /// device, else the software one.
  bool software = false;
};

/// One time measured on the GPU (a GL_TIME_ELAPSED query around one pass's commands).
struct GpuPassTime {
  std::string name;  ///< "upload", "gbuffer", "containment", "filter", "voxelize", ...
  double ms = 0;     ///< GPU milliseconds.
};

/// An OpenGL context the backend runs in. Copies share it. Not for concurrent use: every call that
/// takes a device makes its context current on the calling thread (a borrowed one must be current).
class GpuDevice {
 public:
  /// A headless OpenGL 4.3+ core context through EGL (EGL_EXT_platform_device, else Mesa's
  /// surfaceless platform). SystemError, one line naming what is missing, when there is no libEGL,
  /// no EGL device, no OpenGL 4.3 core context, or the library was built without AO_GPU.
  static GpuDevice open(const GpuDeviceOptions& options = {});
  /// The caller's current context (a viewer's window), whose functions `loader` resolves. It must
  /// be OpenGL 4.3 core or newer (SystemError otherwise) and be current whenever the device is used.
  /// The backend changes GL state (bound programs, framebuffer, textures, viewport); the caller
  /// restores what it relies on.
  static GpuDevice from_current_context(GlProcLoader loader);

  /// GL_RENDERER: "llvmpipe (LLVM 15.0.6, 256 bits)" for Mesa's software renderer, else the GPU.
  const std::string& renderer() const;
  /// GL_VERSION, e.g. "4.5 (Core Profile) Mesa 22.3.6".
  const std::string& version() const;
  /// True for a software renderer (llvmpipe, softpipe): GPU times then measure the CPU.
  bool software() const;

 private:
  friend struct gpu_detail::Access;
  explicit GpuDevice(std::shared_ptr<gpu_detail::Context> c) : context_(std::move(c)) {}
  std::shared_ptr<gpu_detail::Context> context_;
};

}  // namespace ao
