// SPDX-License-Identifier: Apache-2.0
// The GL layer of the GPU backend: function loading, programs from the embedded shader files,
// timer queries, textures and buffers (gl_internal.h).
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <set>
#include <sstream>

#include "ao/core/error.h"
#include "ao/gpu/gl_internal.h"

namespace ao::gpu_detail {

void GlFunctions::load(GlProcLoader loader) {
  const auto get = [&](auto& fn, const char* name) {
    fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(loader(name));
    if (!fn) throw SystemError(std::string("--device gpu: the OpenGL driver does not provide ") + name + " (OpenGL 4.3 core is needed)");
  };
#define AO_GL_LOAD(type, name) get(name, "gl" #name);
  AO_GL_FUNCTIONS(AO_GL_LOAD)
#undef AO_GL_LOAD
}

Context::~Context() = default;

bool Context::try_make_current() noexcept {
  try {
    make_current();
    return true;
  } catch (...) {
    return false;
  }
}

void Context::delete_programs() {
  if (!try_make_current()) return;
  for (auto& [key, p] : programs_) gl.DeleteProgram(p.id);
  programs_.clear();
}

void Context::initialise(GlProcLoader loader) {
  // glGetString first, alone: a context below 4.3 may lack later entry points, and the message
  // should then name the version, not a function.
  const auto get_string = reinterpret_cast<PFNGLGETSTRINGPROC>(loader("glGetString"));
  if (!get_string) throw SystemError("--device gpu: the OpenGL driver does not provide glGetString");
  const auto text = [&](GLenum e) {
    const auto* s = reinterpret_cast<const char*>(get_string(e));
    return std::string(s ? s : "");
  };
  version = text(GL_VERSION);
  renderer = text(GL_RENDERER);
  if (version.empty()) throw SystemError("--device gpu: no OpenGL context is current on this thread");
  int major = 0, minor = 0;
  if (std::sscanf(version.c_str(), "%d.%d", &major, &minor) != 2 || major * 10 + minor < 43)
    throw SystemError("--device gpu: OpenGL 4.3 core with compute shaders is needed, the context is '" + version + "' (" + renderer + ")");
  gl.load(loader);
  software = renderer.find("llvmpipe") != std::string::npos || renderer.find("softpipe") != std::string::npos ||
             renderer.find("Software") != std::string::npos;
  gl.GetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture_size);
  GLint block = 0;
  gl.GetIntegerv(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &block);
  max_storage_block = block;
  GLint geometry_blocks = 0;
  gl.GetIntegerv(GL_MAX_GEOMETRY_SHADER_STORAGE_BLOCKS, &geometry_blocks);
  geometry_storage = geometry_blocks > 0;
  while (gl.GetError() != GL_NO_ERROR) {
  }
}

void Context::check(std::string_view what) {
  GLenum first = GL_NO_ERROR;
  for (GLenum e = gl.GetError(); e != GL_NO_ERROR; e = gl.GetError())
    if (first == GL_NO_ERROR) first = e;
  if (first == GL_NO_ERROR) return;
  char code[16];
  std::snprintf(code, sizeof code, "0x%04X", first);
  const std::string name = first == GL_OUT_OF_MEMORY ? "out of GPU memory" : std::string("OpenGL error ") + code;
  throw SystemError("--device gpu: " + name + " in " + std::string(what) + " (" + renderer + ")");
}

namespace {

GLenum stage_of(std::string_view file) {
  const auto ends = [&](std::string_view ext) { return file.size() >= ext.size() && file.substr(file.size() - ext.size()) == ext; };
  if (ends(".comp")) return GL_COMPUTE_SHADER;
  if (ends(".vert")) return GL_VERTEX_SHADER;
  if (ends(".geom")) return GL_GEOMETRY_SHADER;
  if (ends(".frag")) return GL_FRAGMENT_SHADER;
  throw SystemError("gpu: shader file '" + std::string(file) + "' has no stage extension (.comp, .vert, .geom, .frag)");
}

const char* find_embedded(std::string_view name) {
  for (const EmbeddedShader& s : embedded_shaders())
    if (name == s.name) return s.text;
  throw SystemError("gpu: no embedded shader '" + std::string(name) + "'");
}

// `text` with its #include "file" lines expanded, each file once (the GLSL files have no guards).
// A file is found by its name: `#include "ao/core/hash_shared.h"`, the path a C++ compiler takes
// in a header both read, names the embedded hash_shared.h.
void expand(std::string_view text, std::set<std::string, std::less<>>& seen, std::string& out) {
  std::istringstream in{std::string(text)};
  std::string line;
  while (std::getline(in, line)) {
    const std::size_t at = line.find("#include \"");
    if (at != std::string::npos && line.find_first_not_of(' ') == at) {
      const std::size_t end = line.find('"', at + 10);
      const std::string path = line.substr(at + 10, end - at - 10);
      const std::string file = path.substr(path.rfind('/') + 1);  // npos + 1 = 0: a bare name
      if (seen.insert(file).second) expand(find_embedded(file), seen, out);
      continue;
    }
    out += line;
    out += '\n';
  }
}

}  // namespace

std::string shader_source(std::string_view name) { return expand_includes(find_embedded(name)); }

std::string expand_includes(std::string_view text) {
  std::set<std::string, std::less<>> seen;
  std::string out;
  expand(text, seen, out);
  return out;
}

Program& Context::program(std::initializer_list<std::string_view> stages, std::string_view defines) {
  std::string key(defines);
  for (std::string_view s : stages) key += std::string(s) + ";";
  if (auto it = programs_.find(key); it != programs_.end()) return it->second;
  const GLuint prog = gl.CreateProgram();
  std::vector<GLuint> shaders;
  const auto log_of = [&](GLuint object, bool is_program) {
    GLint length = 0;
    (is_program ? gl.GetProgramiv : gl.GetShaderiv)(object, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
    (is_program ? gl.GetProgramInfoLog : gl.GetShaderInfoLog)(object, length, nullptr, log.data());
    // One line: the first message of the compiler's log.
    log = log.substr(0, log.find('\n'));
    return log.substr(0, log.find('\0'));
  };
  for (std::string_view s : stages) {
    std::string source = shader_source(s);
    source.insert(source.find('\n') + 1, defines);
    const GLuint sh = gl.CreateShader(stage_of(s));
    const char* text = source.c_str();
    gl.ShaderSource(sh, 1, &text, nullptr);
    gl.CompileShader(sh);
    GLint ok = 0;
    gl.GetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
      const std::string log = log_of(sh, false);
      gl.DeleteShader(sh);
      for (GLuint o : shaders) gl.DeleteShader(o);
      gl.DeleteProgram(prog);
      throw SystemError("gpu: shader " + std::string(s) + " does not compile on " + renderer + ": " + log);
    }
    gl.AttachShader(prog, sh);
    shaders.push_back(sh);
  }
  gl.LinkProgram(prog);
  for (GLuint o : shaders) gl.DeleteShader(o);  // flagged; freed with the program
  GLint ok = 0;
  gl.GetProgramiv(prog, GL_LINK_STATUS, &ok);
  if (!ok) {
    const std::string log = log_of(prog, true);
    gl.DeleteProgram(prog);
    throw SystemError("gpu: program " + key + " does not link on " + renderer + ": " + log);
  }
  return programs_.emplace(key, Program{prog, {}}).first->second;
}

GLint Context::uniform(Program& p, std::string_view name) {
  if (auto it = p.uniforms.find(name); it != p.uniforms.end()) return it->second;
  const GLint at = gl.GetUniformLocation(p.id, std::string(name).c_str());
  p.uniforms.emplace(std::string(name), at);
  return at;
}

void Context::begin_pass(std::vector<PassQuery>& passes, std::string name) {
  // Two GL_TIMESTAMP counters per pass, not a GL_TIME_ELAPSED query: llvmpipe reports no elapsed
  // time for compute dispatches, while its timestamps (and every GPU's) bracket them.
  PassQuery q{std::move(name), {0, 0}};
  gl.GenQueries(2, q.query.data());
  gl.QueryCounter(q.query[0], GL_TIMESTAMP);
  passes.push_back(std::move(q));
}

void Context::end_pass(std::vector<PassQuery>& passes) {
  if (!passes.empty()) gl.QueryCounter(passes.back().query[1], GL_TIMESTAMP);
}

std::vector<GpuPassTime> Context::resolve(std::vector<PassQuery>& passes) {
  std::vector<GpuPassTime> out;
  for (PassQuery& p : passes) {
    GLuint64 t0 = 0, t1 = 0;
    gl.GetQueryObjectui64v(p.query[0], GL_QUERY_RESULT, &t0);  // waits for the pass to finish
    gl.GetQueryObjectui64v(p.query[1], GL_QUERY_RESULT, &t1);
    gl.DeleteQueries(2, p.query.data());
    out.push_back({p.name, t1 > t0 ? static_cast<double>(t1 - t0) * 1e-6 : 0.0});
  }
  passes.clear();
  return out;
}

void check_image_size(const Context& c, int width, int height) {
  if (width > c.max_texture_size || height > c.max_texture_size)
    throw InputError("--device gpu: a " + std::to_string(width) + "x" + std::to_string(height) + " image exceeds this GPU's largest texture (" +
                     std::to_string(c.max_texture_size) + " per side, " + c.renderer + ")");
}

Texture make_texture(Context& c, int width, int height, GLenum format) {
  check_image_size(c, width, height);
  GLuint id = 0;
  c.gl.GenTextures(1, &id);
  Texture t{{c, id}, width, height, format};
  c.gl.BindTexture(GL_TEXTURE_2D, id);
  c.gl.TexStorage2D(GL_TEXTURE_2D, 1, format, std::max(width, 1), std::max(height, 1));
  c.gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  c.gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  c.gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  c.gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  c.check("allocating a texture");
  return t;
}

void upload(Context& c, const Texture& t, GLenum pixel_format, GLenum type, const void* data) {
  c.gl.BindTexture(GL_TEXTURE_2D, t.id());
  c.gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  c.gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, t.width, t.height, pixel_format, type, data);
  c.check("uploading a texture");
}

void download(Context& c, const Texture& t, GLenum pixel_format, GLenum type, void* out, std::size_t) {
  c.gl.MemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);  // imageStore writes before the read
  c.gl.BindTexture(GL_TEXTURE_2D, t.id());
  c.gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  c.gl.GetTexImage(GL_TEXTURE_2D, 0, pixel_format, type, out);
  c.check("reading a texture back");
}

Buffer make_buffer(Context& c, std::size_t bytes, const void* data) {
  GLuint id = 0;
  c.gl.GenBuffers(1, &id);
  Buffer b(c, id);
  c.gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, id);
  // An empty table still gets storage: a zero-sized buffer cannot be bound.
  c.gl.BufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(std::max<std::size_t>(bytes, 16)), bytes ? data : nullptr, GL_STATIC_DRAW);
  c.check("allocating a buffer");
  return b;
}

void bind_image(Context& c, GLuint unit, const Texture& t, GLenum access) {
  c.gl.BindImageTexture(unit, t.id(), 0, GL_FALSE, 0, access, t.format);
}

void bind_texture(Context& c, GLuint unit, const Texture& t) {
  c.gl.ActiveTexture(GL_TEXTURE0 + unit);
  c.gl.BindTexture(GL_TEXTURE_2D, t.id());
  c.gl.ActiveTexture(GL_TEXTURE0);
}

void dispatch_2d(Context& c, int width, int height) {
  c.gl.DispatchCompute(static_cast<GLuint>((width + kGroup - 1) / kGroup), static_cast<GLuint>((height + kGroup - 1) / kGroup), 1);
  c.gl.MemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT |
                     GL_TEXTURE_UPDATE_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
}

}  // namespace ao::gpu_detail
