// SPDX-License-Identifier: Apache-2.0
// The GPU device: a headless context through EGL, the caller's current context, and the one-line
// SystemError when there is no usable GL.
#include <gtest/gtest.h>

#include <dlfcn.h>

#include <cstdio>
#include <memory>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "ao/core/error.h"
#include "ao/registry/methods_gpu.h"
#include "gpu/gpu_support.h"

namespace ao {
namespace {

using test::gpu_device;

TEST(GpuDevice, OpensMesaSoftwareRendererWithOpenGl43) {
  GpuDevice& d = gpu_device();
  EXPECT_NE(d.renderer().find("llvmpipe"), std::string::npos) << d.renderer();
  EXPECT_TRUE(d.software());
  int major = 0, minor = 0;
  ASSERT_EQ(std::sscanf(d.version().c_str(), "%d.%d", &major, &minor), 2) << d.version();
  EXPECT_GE(major * 10 + minor, 43) << d.version();
}

// A machine with libEGL but no driver: glvnd finds no vendor library, so no EGL display can be
// initialised. In a process of its own (tests/gpu/tools/open_device.cpp): this one has set up EGL.
TEST(GpuDevice, NoUsableGlIsAOneLineSystemError) {
  const std::string command = std::string("__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent/vendor.json ") + AO_GPU_OPEN_DEVICE_PATH + " 2>&1";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  ASSERT_TRUE(pipe);
  std::string out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, pipe.get())) out += buf;
  const std::size_t at = out.find("SystemError[");
  ASSERT_NE(at, std::string::npos) << out;
  const std::string message = out.substr(at + 12, out.find(']', at) - at - 12);
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_NE(message.find("--device gpu: no usable OpenGL"), std::string::npos) << message;
  EXPECT_NE(message.find("no EGL display"), std::string::npos) << message;
}

// eglGetProcAddress as a GlProcLoader, for the tests that borrow a context.
GlProc egl_loader(const char* name) {
  static void* const lib = dlopen("libEGL.so.1", RTLD_NOW | RTLD_LOCAL);
  using GetProc = GlProc (*)(const char*);
  static const auto get = lib ? reinterpret_cast<GetProc>(dlsym(lib, "eglGetProcAddress")) : nullptr;
  return get ? get(name) : nullptr;
}

TEST(GpuDevice, BorrowsTheCurrentContextAndComputesTheSame) {
  const test::GpuFixture f = test::gpu_fixture("sphere-on-plane", 48, 32);
  // gpu_device()'s context is current on this thread since it was last used: borrow it, as a
  // viewer lends its window's context.
  const MethodInput in{f.g, f.rays.get(), {Membership::Step, 1.0f}, 4};
  const Image<float> own = run_gpu_method(gpu_device(), in, find_method("volumetric").decode(nlohmann::json::object())).output.visibility;
  GpuDevice borrowed = GpuDevice::from_current_context(egl_loader);
  EXPECT_EQ(borrowed.renderer(), gpu_device().renderer());
  const Image<float> lent = run_gpu_method(borrowed, in, find_method("volumetric").decode(nlohmann::json::object())).output.visibility;
  EXPECT_TRUE(std::equal(own.pixels().begin(), own.pixels().end(), lent.pixels().begin()));
}

TEST(GpuDevice, BorrowingWithoutACurrentContextIsASystemError) {
  std::string message;
  std::thread([&] {  // a thread on which no context is current
    try {
      GpuDevice::from_current_context(egl_loader);
    } catch (const SystemError& e) {
      message = e.what();
    }
  }).join();
  EXPECT_NE(message.find("no OpenGL context is current"), std::string::npos) << message;
  EXPECT_THROW(GpuDevice::from_current_context(nullptr), SystemError);
}

TEST(GpuDevice, AGBufferOfAnotherDeviceIsRefused) {
  const test::GpuFixture f = test::gpu_fixture("sphere-on-plane", 16, 16);
  const GpuGBuffer g = GpuGBuffer::upload(gpu_device(), f.g);
  GpuDevice other = GpuDevice::from_current_context(egl_loader);
  EXPECT_THROW(run_gpu_method(other, GpuMethodInput{g, nullptr, {Membership::Step, 1.0f}, 1}, find_method("gtao").decode(nlohmann::json::object())), InputError);
}

}  // namespace
}  // namespace ao
