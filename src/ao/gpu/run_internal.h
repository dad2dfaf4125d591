// SPDX-License-Identifier: Apache-2.0
// Internals of the GPU backend, not installed: a method's run on the device (Run), which each
// method's GPU file (methods/<name>/<name>_gpu.cpp) drives, and reading its results back.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "ao/core/image.h"
#include "ao/core/math.h"
#include "ao/gpu/gl_internal.h"
#include "ao/gpu/resources_internal.h"

namespace ao::gpu_detail {

/// One method run: the context, its G-buffer, and the timed passes so far.
struct Run {
  Context& c;
  const GBufferTextures& g;
  std::vector<PassQuery> passes;

  int width() const { return g.camera.width; }
  int height() const { return g.camera.height; }
  /// Makes `p` current and sets common.glsl's u_size and u_projection, and binds the G-buffer.
  void use(Program& p);
  /// Sets `p`'s u_rays: camera_direction(px, py) = (ax px + bx, ay py + by, -1) for continuous
  /// pixel coordinates (the view ray through a pixel, camera space).
  void set_rays(Program& p);
  /// A texture of the G-buffer's size.
  Texture image(GLenum format) { return make_texture(c, width(), height(), format); }
  /// The compute program of `shader` (compiled first: compiling is not part of the pass's time),
  /// made current by use() inside the timed pass `name`, which finish() ends.
  Program& begin(std::string_view shader, std::string name, std::string_view defines = {});
  /// Runs the pass over every pixel, writing `out` through image unit 0, and ends it.
  void finish(const Texture& out);
  /// A whole pass of `shader` that reads `in` (texture unit 6) into a new texture of `format`.
  Texture map(std::string_view shader, std::string name, const Texture& in, GLenum format, std::string_view defines = {});
  /// Uniform `name` of `p`.
  void set(Program& p, std::string_view name, int v) { c.gl.Uniform1i(c.uniform(p, name), v); }
  void set(Program& p, std::string_view name, float v) { c.gl.Uniform1f(c.uniform(p, name), v); }
  void set(Program& p, std::string_view name, std::uint32_t v) { c.gl.Uniform1ui(c.uniform(p, name), v); }
  void set(Program& p, std::string_view name, Vec3 v) { c.gl.Uniform3f(c.uniform(p, name), v.x, v.y, v.z); }
  /// Binds `b` as shader storage buffer `binding`.
  void bind(GLuint binding, const Buffer& b) { c.gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, b.id()); }
  /// After the run, the stats entry `name` of the method's output is the sum of the GPU times of
  /// the passes `passes` (milliseconds): the CPU method's own timing fields from the passes that do
  /// their work.
  void report_ms(std::string name, std::vector<std::string> pass_names) { reported_ms.emplace_back(std::move(name), std::move(pass_names)); }

  std::vector<std::pair<std::string, std::vector<std::string>>> reported_ms;  ///< What report_ms asked for, in order.
};

/// The image of an R32F texture, and the RGB of an RGBA32F one.
Image<float> read_float(Context& c, const Texture& t);
Image<Vec3> read_rgb(Context& c, const Texture& t);
/// The A channel of an RGBA32F texture.
Image<float> read_alpha(Context& c, const Texture& t);

}  // namespace ao::gpu_detail
