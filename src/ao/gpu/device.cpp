// SPDX-License-Identifier: Apache-2.0
// GpuDevice: a headless OpenGL context through EGL, or the caller's current one (device.h).
// libEGL is opened with dlopen and every EGL and GL function is resolved through
// eglGetProcAddress (EGL_KHR_get_all_proc_addresses, EGL 1.5), so libao links no GL library.
#define EGL_EGL_PROTOTYPES 0
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <dlfcn.h>

#include <cstring>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "ao/core/error.h"
#include "ao/gpu/device.h"
#include "ao/gpu/gl_internal.h"

namespace ao {

namespace gpu_detail {

namespace {

constexpr const char* kNoGl = "--device gpu: no usable OpenGL: ";
constexpr const char* kMesaHint = "(Debian: libegl1, and Mesa's libegl-mesa0 and libgl1-mesa-dri for its software renderer)";

// libEGL and the EGL entry points, resolved once per process. The library stays loaded and the
// displays initialised until the process ends: EGL displays are not reference counted, so
// terminating one when a device closes would pull it from under another device.
struct Egl {
  PFNEGLGETPROCADDRESSPROC GetProcAddress = nullptr;
  PFNEGLGETERRORPROC GetError = nullptr;
  PFNEGLQUERYSTRINGPROC QueryString = nullptr;
  PFNEGLGETPLATFORMDISPLAYEXTPROC GetPlatformDisplayEXT = nullptr;
  PFNEGLQUERYDEVICESEXTPROC QueryDevicesEXT = nullptr;
  PFNEGLQUERYDEVICESTRINGEXTPROC QueryDeviceStringEXT = nullptr;
  PFNEGLINITIALIZEPROC Initialize = nullptr;
  PFNEGLBINDAPIPROC BindAPI = nullptr;
  PFNEGLCHOOSECONFIGPROC ChooseConfig = nullptr;
  PFNEGLCREATECONTEXTPROC CreateContext = nullptr;
  PFNEGLDESTROYCONTEXTPROC DestroyContext = nullptr;
  PFNEGLCREATEPBUFFERSURFACEPROC CreatePbufferSurface = nullptr;
  PFNEGLDESTROYSURFACEPROC DestroySurface = nullptr;
  PFNEGLMAKECURRENTPROC MakeCurrent = nullptr;
  PFNEGLGETCURRENTCONTEXTPROC GetCurrentContext = nullptr;
  std::map<void*, EGLDisplay> displays;  // initialised displays by device (null: the surfaceless platform)
  std::mutex mutex;
};

Egl& egl() {
  static Egl* const instance = [] {
    void* lib = dlopen("libEGL.so.1", RTLD_NOW | RTLD_LOCAL);
    if (!lib) throw SystemError(std::string(kNoGl) + "libEGL.so.1 is not installed " + kMesaHint);
    auto* e = new Egl;  // never freed: see Egl
    e->GetProcAddress = reinterpret_cast<PFNEGLGETPROCADDRESSPROC>(dlsym(lib, "eglGetProcAddress"));
    if (!e->GetProcAddress) throw SystemError(std::string(kNoGl) + "libEGL.so.1 has no eglGetProcAddress");
    const auto get = [&](auto& fn, const char* name) {
      fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(e->GetProcAddress(name));
      if (!fn) fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(dlsym(lib, name));
    };
    get(e->GetError, "eglGetError");
    get(e->QueryString, "eglQueryString");
    get(e->GetPlatformDisplayEXT, "eglGetPlatformDisplayEXT");
    get(e->QueryDevicesEXT, "eglQueryDevicesEXT");
    get(e->QueryDeviceStringEXT, "eglQueryDeviceStringEXT");
    get(e->Initialize, "eglInitialize");
    get(e->BindAPI, "eglBindAPI");
    get(e->ChooseConfig, "eglChooseConfig");
    get(e->CreateContext, "eglCreateContext");
    get(e->DestroyContext, "eglDestroyContext");
    get(e->CreatePbufferSurface, "eglCreatePbufferSurface");
    get(e->DestroySurface, "eglDestroySurface");
    get(e->MakeCurrent, "eglMakeCurrent");
    get(e->GetCurrentContext, "eglGetCurrentContext");
    if (!e->GetError || !e->QueryString || !e->Initialize || !e->BindAPI || !e->CreateContext || !e->MakeCurrent || !e->GetCurrentContext ||
        !e->DestroyContext || !e->ChooseConfig)
      throw SystemError(std::string(kNoGl) + "libEGL.so.1 lacks EGL 1.4 entry points");
    return e;
  }();
  return *instance;
}

bool has_extension(const char* list, const char* name) {
  if (!list) return false;
  const std::size_t n = std::strlen(name);
  for (const char* p = std::strstr(list, name); p; p = std::strstr(p + 1, name))
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

GlProc egl_proc(const char* name) { return reinterpret_cast<GlProc>(egl().GetProcAddress(name)); }

class EglContext final : public Context {
 public:
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  EGLSurface surface = EGL_NO_SURFACE;

  void make_current() override {
    Egl& e = egl();
    if (e.GetCurrentContext() == context) return;
    if (!e.MakeCurrent(display, surface, surface, context))
      throw SystemError("--device gpu: eglMakeCurrent failed (EGL error " + std::to_string(e.GetError()) + ")");
  }
  ~EglContext() override {
    Egl& e = egl();
    if (context != EGL_NO_CONTEXT) {
      if (e.GetCurrentContext() == context) e.MakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      e.DestroyContext(display, context);  // frees every object of the context
    }
    if (surface != EGL_NO_SURFACE && e.DestroySurface) e.DestroySurface(display, surface);
  }
};

// The caller's context: nothing to bind, nothing of its own to destroy but the programs.
class BorrowedContext final : public Context {
 public:
  void make_current() override {}
  ~BorrowedContext() override { delete_programs(); }
};

// An initialised display of `device` (EGL_EXT_platform_device), or of Mesa's surfaceless platform
// when `device` is null; EGL_NO_DISPLAY when it cannot be initialised.
EGLDisplay display_of(Egl& e, void* device) {
  const std::lock_guard lock(e.mutex);
  if (auto it = e.displays.find(device); it != e.displays.end()) return it->second;
  EGLDisplay d = EGL_NO_DISPLAY;
  if (e.GetPlatformDisplayEXT)
    d = device ? e.GetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, device, nullptr)
               : e.GetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  EGLint major = 0, minor = 0;
  if (d != EGL_NO_DISPLAY && !e.Initialize(d, &major, &minor)) d = EGL_NO_DISPLAY;
  if (d != EGL_NO_DISPLAY) e.displays.emplace(device, d);
  return d;
}

// The displays to try, in order of preference: the EGL devices (hardware first unless `software`;
// only Mesa's software device with `software`), then the surfaceless platform.
std::vector<EGLDisplay> candidate_displays(Egl& e, bool software, std::string& tried) {
  const char* client = e.QueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  std::vector<EGLDisplay> out;
  if (has_extension(client, "EGL_EXT_platform_device") && e.QueryDevicesEXT && e.QueryDeviceStringEXT) {
    EGLint n = 0;
    e.QueryDevicesEXT(0, nullptr, &n);
    std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(std::max(n, 0)));
    if (n > 0) e.QueryDevicesEXT(n, devices.data(), &n);
    std::vector<EGLDeviceEXT> hardware, soft;
    for (EGLDeviceEXT d : devices) (has_extension(e.QueryDeviceStringEXT(d, EGL_EXTENSIONS), "EGL_MESA_device_software") ? soft : hardware).push_back(d);
    tried += std::to_string(hardware.size()) + " hardware and " + std::to_string(soft.size()) + " software EGL device(s)";
    if (!software)
      for (EGLDeviceEXT d : hardware)
        if (EGLDisplay disp = display_of(e, d); disp != EGL_NO_DISPLAY) out.push_back(disp);
    for (EGLDeviceEXT d : soft)
      if (EGLDisplay disp = display_of(e, d); disp != EGL_NO_DISPLAY) out.push_back(disp);
  }
  if (has_extension(client, "EGL_MESA_platform_surfaceless") && (!software || out.empty())) {
    tried += std::string(tried.empty() ? "" : ", ") + "Mesa's surfaceless platform";
    if (EGLDisplay disp = display_of(e, nullptr); disp != EGL_NO_DISPLAY && (!software || out.empty())) out.push_back(disp);
  }
  return out;
}

// A context of OpenGL 4.3 core or newer on `display`, current on this thread; null when the display
// has none.
std::shared_ptr<EglContext> create_context(Egl& e, EGLDisplay display) {
  if (!e.BindAPI(EGL_OPENGL_API)) return nullptr;
  const char* ext = e.QueryString(display, EGL_EXTENSIONS);
  EGLConfig config = nullptr;  // EGL_NO_CONFIG_KHR
  const bool configless = has_extension(ext, "EGL_KHR_no_config_context") || has_extension(ext, "EGL_MESA_configless_context");
  const bool surfaceless = has_extension(ext, "EGL_KHR_surfaceless_context");
  if (!configless || !surfaceless) {
    const EGLint wanted[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLint n = 0;
    if (!e.ChooseConfig(display, wanted, &config, 1, &n) || n < 1) return nullptr;
  }
  // The driver returns the newest version compatible with 4.3 core (4.5 on Mesa).
  const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
                               EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  auto c = std::make_shared<EglContext>();
  c->display = display;
  c->context = e.CreateContext(display, config, EGL_NO_CONTEXT, attributes);
  if (c->context == EGL_NO_CONTEXT) return nullptr;
  if (!surfaceless) {
    const EGLint size[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
    c->surface = e.CreatePbufferSurface ? e.CreatePbufferSurface(display, config, size) : EGL_NO_SURFACE;
    if (c->surface == EGL_NO_SURFACE) return nullptr;
  }
  if (!e.MakeCurrent(display, c->surface, c->surface, c->context)) return nullptr;
  return c;
}

}  // namespace

}  // namespace gpu_detail

GpuDevice GpuDevice::open(const GpuDeviceOptions& options) {
  using namespace gpu_detail;
  Egl& e = egl();
  std::string tried;
  const std::vector<EGLDisplay> displays = candidate_displays(e, options.software, tried);
  if (displays.empty())
    throw SystemError(std::string(kNoGl) + "no EGL display could be initialised" + (tried.empty() ? "" : " (tried " + tried + ")") +
                      (options.software ? ", and a software renderer was asked for " : " ") + kMesaHint);
  for (EGLDisplay d : displays)
    if (std::shared_ptr<EglContext> c = create_context(e, d)) {
      c->initialise(egl_proc);
      return GpuDevice(std::move(c));
    }
  throw SystemError(std::string(kNoGl) + "no EGL display offers an OpenGL 4.3 core context (tried " + tried + ")");
}

GpuDevice GpuDevice::from_current_context(GlProcLoader loader) {
  if (!loader) throw SystemError("--device gpu: no OpenGL function loader was given");
  auto c = std::make_shared<gpu_detail::BorrowedContext>();
  c->initialise(loader);
  return GpuDevice(std::move(c));
}

const std::string& GpuDevice::renderer() const { return context_->renderer; }
const std::string& GpuDevice::version() const { return context_->version; }
bool GpuDevice::software() const { return context_->software; }

}  // namespace ao
