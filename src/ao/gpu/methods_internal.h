// Internals of the GPU backend, not installed: what the per-method files (screen_space.cpp,
// alchemy.cpp, gtao.cpp, cone.cpp) share, and their entry points, called by methods.cpp.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "ao/core/image.h"
#include "ao/core/membership.h"
#include "ao/gpu/gl_internal.h"
#include "ao/gpu/resources_internal.h"
#include "ao/methods/alchemy.h"
#include "ao/methods/cone.h"
#include "ao/methods/containment.h"
#include "ao/methods/gtao.h"
#include "ao/registry/registry.h"
#include "ao/methods/samples.h"
#include "ao/methods/transfer.h"
#include "ao/methods/volumetric.h"

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
};

/// The 16 (cos, sin) of interleave_rotations as the shaders' u_rotation[16].
void set_rotations(Run& r, Program& p, const std::array<Rotation, 16>& rotations);
/// box_filter.comp over `values` (CHANNELS 1: R32F; 4: RGBA32F) as the pass "filter".
Texture box_filter(Run& r, const Texture& values, int channels, float depth_limit);
/// bilateral.comp's two passes over the R32F `values` (bilateral.h), as the pass `name`.
Texture bilateral_filter(Run& r, const Texture& values, const BilateralParams& params, const std::string& name);

/// The image of an R32F texture, and the RGB of an RGBA32F one.
Image<float> read_float(Context& c, const Texture& t);
Image<Vec3> read_rgb(Context& c, const Texture& t);
/// The A channel of an RGBA32F texture.
Image<float> read_alpha(Context& c, const Texture& t);

// The methods. Parameters are validated by the caller's parse through their tables.
MethodOutput run_containment(Run& r, const Falloff& falloff, const ContainmentParams& params, std::uint32_t seed);
MethodOutput run_volumetric(Run& r, const Falloff& falloff, const VolumetricParams& params, std::uint32_t seed);
MethodOutput run_transfer(Run& r, const Falloff& falloff, const TransferParams& params, std::uint32_t seed);
MethodOutput run_alchemy(Run& r, const Falloff& falloff, const AlchemyParams& params, std::uint32_t seed);
MethodOutput run_gtao(Run& r, const Falloff& falloff, const GtaoParams& params, std::uint32_t seed);
MethodOutput run_cone(Run& r, SceneBuffers& scene, const Falloff& falloff, const ConeParams& params, std::uint32_t seed);

}  // namespace ao::gpu_detail
