// SPDX-License-Identifier: Apache-2.0
// Internals of the GPU backend, not installed: the OpenGL functions it calls (resolved at run time,
// so libao links no GL library), the context a GpuDevice owns or borrows, and small RAII wrappers
// of GL objects. Only src/ao/gpu/ and its tests include this header.
#pragma once

// Without GL_GLEXT_PROTOTYPES the header declares the functions' pointer types only: nothing can
// call a GL function but through GlFunctions.
#include <GL/glcorearb.h>

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "ao/gpu/device.h"

namespace ao::gpu_detail {

// Every GL entry point the backend uses (OpenGL 4.3 core, nothing newer: a viewer's context may be
// exactly 4.3), as (pointer type, name without the gl prefix).
#define AO_GL_FUNCTIONS(X)                                                                                                   \
  X(PFNGLGETINTEGERVPROC, GetIntegerv)                                                                                       \
  X(PFNGLGETERRORPROC, GetError)                                                                                             \
  X(PFNGLCREATESHADERPROC, CreateShader)                                                                                     \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)                                                                                     \
  X(PFNGLCOMPILESHADERPROC, CompileShader)                                                                                   \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                                                                                       \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                                                                             \
  X(PFNGLDELETESHADERPROC, DeleteShader)                                                                                     \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram)                                                                                   \
  X(PFNGLATTACHSHADERPROC, AttachShader)                                                                                     \
  X(PFNGLLINKPROGRAMPROC, LinkProgram)                                                                                       \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                                                                                     \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                                                                           \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                                                                                   \
  X(PFNGLUSEPROGRAMPROC, UseProgram)                                                                                         \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                                                                         \
  X(PFNGLUNIFORM1IPROC, Uniform1i)                                                                                           \
  X(PFNGLUNIFORM2IPROC, Uniform2i)                                                                                           \
  X(PFNGLUNIFORM1UIPROC, Uniform1ui)                                                                                         \
  X(PFNGLUNIFORM1FPROC, Uniform1f)                                                                                           \
  X(PFNGLUNIFORM2FPROC, Uniform2f)                                                                                           \
  X(PFNGLUNIFORM3FPROC, Uniform3f)                                                                                           \
  X(PFNGLUNIFORM4FPROC, Uniform4f)                                                                                           \
  X(PFNGLUNIFORM1FVPROC, Uniform1fv)                                                                                         \
  X(PFNGLUNIFORM2FVPROC, Uniform2fv)                                                                                         \
  X(PFNGLUNIFORM3FVPROC, Uniform3fv)                                                                                         \
  X(PFNGLGENTEXTURESPROC, GenTextures)                                                                                       \
  X(PFNGLDELETETEXTURESPROC, DeleteTextures)                                                                                 \
  X(PFNGLBINDTEXTUREPROC, BindTexture)                                                                                       \
  X(PFNGLACTIVETEXTUREPROC, ActiveTexture)                                                                                   \
  X(PFNGLTEXSTORAGE2DPROC, TexStorage2D)                                                                                     \
  X(PFNGLTEXSUBIMAGE2DPROC, TexSubImage2D)                                                                                   \
  X(PFNGLTEXPARAMETERIPROC, TexParameteri)                                                                                   \
  X(PFNGLGETTEXIMAGEPROC, GetTexImage)                                                                                       \
  X(PFNGLPIXELSTOREIPROC, PixelStorei)                                                                                       \
  X(PFNGLBINDIMAGETEXTUREPROC, BindImageTexture)                                                                             \
  X(PFNGLGENBUFFERSPROC, GenBuffers)                                                                                         \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                                                                                   \
  X(PFNGLBINDBUFFERPROC, BindBuffer)                                                                                         \
  X(PFNGLBUFFERDATAPROC, BufferData)                                                                                         \
  X(PFNGLBINDBUFFERBASEPROC, BindBufferBase)                                                                                 \
  X(PFNGLGETBUFFERSUBDATAPROC, GetBufferSubData)                                                                             \
  X(PFNGLCLEARBUFFERDATAPROC, ClearBufferData)                                                                               \
  X(PFNGLFRAMEBUFFERPARAMETERIPROC, FramebufferParameteri)                                                                   \
  X(PFNGLDISPATCHCOMPUTEPROC, DispatchCompute)                                                                               \
  X(PFNGLMEMORYBARRIERPROC, MemoryBarrier)                                                                                   \
  X(PFNGLGENQUERIESPROC, GenQueries)                                                                                         \
  X(PFNGLDELETEQUERIESPROC, DeleteQueries)                                                                                   \
  X(PFNGLQUERYCOUNTERPROC, QueryCounter)                                                                                     \
  X(PFNGLFLUSHPROC, Flush)                                                                                                   \
  X(PFNGLGETQUERYOBJECTUI64VPROC, GetQueryObjectui64v)                                                                       \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                                                                               \
  X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                                                                         \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                                                                               \
  X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)                                                                     \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)                                                                 \
  X(PFNGLDRAWBUFFERSPROC, DrawBuffers)                                                                                       \
  X(PFNGLCLEARBUFFERFVPROC, ClearBufferfv)                                                                                   \
  X(PFNGLCLEARBUFFERUIVPROC, ClearBufferuiv)                                                                                 \
  X(PFNGLVIEWPORTPROC, Viewport)                                                                                             \
  X(PFNGLENABLEPROC, Enable)                                                                                                 \
  X(PFNGLDISABLEPROC, Disable)                                                                                               \
  X(PFNGLDEPTHFUNCPROC, DepthFunc)                                                                                           \
  X(PFNGLDEPTHMASKPROC, DepthMask)                                                                                           \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                                                                               \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)                                                                         \
  X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                                                                               \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)                                                                       \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)                                                               \
  X(PFNGLDISABLEVERTEXATTRIBARRAYPROC, DisableVertexAttribArray)                                                             \
  X(PFNGLVERTEXATTRIB2FPROC, VertexAttrib2f)                                                                                 \
  X(PFNGLDRAWELEMENTSPROC, DrawElements)

/// The GL functions, resolved once per device.
struct GlFunctions {
#define AO_GL_MEMBER(type, name) type name = nullptr;
  AO_GL_FUNCTIONS(AO_GL_MEMBER)
#undef AO_GL_MEMBER
  /// Resolves every function through `loader`; SystemError naming the first one it does not give.
  void load(GlProcLoader loader);
};

/// One pass's GPU time: GL_TIMESTAMP queries before and after its commands, read when the run is over.
struct PassQuery {
  std::string name;
  std::array<GLuint, 2> query{};
};

/// A compiled program: its GL name and the uniform locations looked up so far.
struct Program {
  GLuint id = 0;
  std::map<std::string, GLint, std::less<>> uniforms;
};

/// The GL context of a GpuDevice and what is built once per context: programs (compiling a shader
/// on Mesa's llvmpipe takes tens of milliseconds) and the device limits the backend checks.
class Context {
 public:
  Context() = default;
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
  virtual ~Context();

  GlFunctions gl;
  std::string renderer, version;
  bool software = false;   ///< Mesa's llvmpipe (or another software renderer).
  int max_texture_size = 0;
  std::int64_t max_storage_block = 0;  ///< GL_MAX_SHADER_STORAGE_BLOCK_SIZE, bytes.
  bool geometry_storage = false;       ///< Geometry shaders may write storage buffers (GL 4.3 allows 0 of them).

  /// Makes the context current on the calling thread (a headless device binds it; a borrowed
  /// context must already be current: SystemError otherwise).
  virtual void make_current() = 0;
  /// make_current for destructors: false (and nothing thrown) when the context cannot be bound.
  bool try_make_current() noexcept;
  /// Deletes the compiled programs (a borrowed context outlives the device).
  void delete_programs();

  /// Resolves the functions, reads the renderer and limits, and checks for OpenGL 4.3: SystemError
  /// naming what is missing. Called with the context current.
  void initialise(GlProcLoader loader);

  /// The program made of the embedded shader files `stages` (by file name; the stage follows from
  /// the extension: .comp, .vert, .geom, .frag), compiled and linked on first use, with `defines`
  /// ("#define CHANNELS 4\n") inserted after each file's #version line. SystemError with the
  /// compiler's log on failure (a shader bug or a driver that rejects valid GLSL).
  Program& program(std::initializer_list<std::string_view> stages, std::string_view defines = {});
  /// Location of uniform `name` in `p` (-1 when the compiler removed it: setting it is then a no-op).
  GLint uniform(Program& p, std::string_view name);

  /// Throws SystemError naming `what` when a GL error is pending (GL_OUT_OF_MEMORY above all).
  void check(std::string_view what);

  /// Starts a timed pass at the end of `passes`, and ends the last one begun there (one at a time).
  void begin_pass(std::vector<PassQuery>& passes, std::string name);
  void end_pass(std::vector<PassQuery>& passes);
  /// The milliseconds of every pass (waits for the GPU to finish them); deletes the queries.
  std::vector<GpuPassTime> resolve(std::vector<PassQuery>& passes);

 private:
  std::map<std::string, Program, std::less<>> programs_;
};

/// The embedded text of shader file `name`, with every `#include "file"` line replaced by that
/// file's text (once per file and program; a file is found by its name, whatever folders its path
/// names); SystemError for an unknown name.
std::string shader_source(std::string_view name);
/// `text` with its includes expanded as shader_source expands a file's.
std::string expand_includes(std::string_view text);

/// The embedded shader files, by name (generated at build time from the shaders under src/ao/ and
/// the *_shared.h headers they include).
struct EmbeddedShader {
  const char* name;
  const char* text;
};
std::span<const EmbeddedShader> embedded_shaders();

/// RAII GL objects of one context. Moves transfer ownership.
template <void (*Delete)(Context&, GLuint)>
class Object {
 public:
  Object() = default;
  Object(Context& c, GLuint id) : context_(&c), id_(id) {}
  Object(Object&& o) noexcept : context_(o.context_), id_(std::exchange(o.id_, 0)) {}
  Object& operator=(Object&& o) noexcept {
    if (this != &o) reset(), context_ = o.context_, id_ = std::exchange(o.id_, 0);
    return *this;
  }
  ~Object() { reset(); }
  GLuint id() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
  void reset() {
    if (id_) Delete(*context_, id_);
    id_ = 0;
  }

 private:
  Context* context_ = nullptr;
  GLuint id_ = 0;
};

// Deleters: an object whose context cannot be bound any more is left to the context's destruction.
inline void delete_texture(Context& c, GLuint id) {
  if (c.try_make_current()) c.gl.DeleteTextures(1, &id);
}
inline void delete_buffer(Context& c, GLuint id) {
  if (c.try_make_current()) c.gl.DeleteBuffers(1, &id);
}
inline void delete_framebuffer(Context& c, GLuint id) {
  if (c.try_make_current()) c.gl.DeleteFramebuffers(1, &id);
}
inline void delete_vertex_array(Context& c, GLuint id) {
  if (c.try_make_current()) c.gl.DeleteVertexArrays(1, &id);
}
using Buffer = Object<delete_buffer>;
using Framebuffer = Object<delete_framebuffer>;
using VertexArray = Object<delete_vertex_array>;

/// A 2-D texture with immutable storage, its size and format.
struct Texture {
  Object<delete_texture> object;
  int width = 0, height = 0;
  GLenum format = 0;  ///< Sized internal format (GL_R32F, GL_RGBA32F, GL_R32UI, ...).
  GLuint id() const { return object.id(); }
  explicit operator bool() const { return static_cast<bool>(object); }
};

/// InputError when a width x height image exceeds the device's largest texture.
void check_image_size(const Context& c, int width, int height);
/// A texture of `format` (nearest filtering, clamp to edge: the shaders read it with texelFetch).
Texture make_texture(Context& c, int width, int height, GLenum format);
/// Uploads `data` (width * height pixels of `pixel_format` x `type`) into `t`.
void upload(Context& c, const Texture& t, GLenum pixel_format, GLenum type, const void* data);
/// Reads `t` back into `out` (width * height pixels of `pixel_format` x `type`; `bytes` long).
void download(Context& c, const Texture& t, GLenum pixel_format, GLenum type, void* out, std::size_t bytes);
/// A shader storage buffer holding `bytes` bytes of `data` (null: uninitialised).
Buffer make_buffer(Context& c, std::size_t bytes, const void* data);
template <class T>
Buffer make_buffer(Context& c, std::span<const T> data) {
  return make_buffer(c, data.size_bytes(), data.data());
}

/// Binds `t` as image unit `unit` for imageLoad / imageStore (`access`: GL_READ_ONLY, ...).
void bind_image(Context& c, GLuint unit, const Texture& t, GLenum access);
/// Binds `t` to texture unit `unit` (texelFetch through a sampler uniform set to `unit`).
void bind_texture(Context& c, GLuint unit, const Texture& t);
/// Runs the bound compute program over width x height items in groups of kGroup x kGroup, then
/// makes its image and buffer writes visible to what follows.
void dispatch_2d(Context& c, int width, int height);
/// The work group side every per-pixel compute shader declares (local_size_x = local_size_y).
inline constexpr int kGroup = 8;

}  // namespace ao::gpu_detail
