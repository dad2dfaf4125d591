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
#include "ao/methods/registry.h"
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
