// SPDX-License-Identifier: Apache-2.0
// The filters of the methods on the GPU: the 4x4 depth-aware box filter of interleaved sampling
// (box_filter.comp; VAO and AT sec. 4.2) after containment, volumetric and transfer, and the
// separable cross-bilateral filter (bilateral.comp; Alchemy AO sec. 3.3) after Alchemy and cone
// tracing. Each computes what its CPU filter (interleave.h, bilateral.h) computes, with the same
// weights.
#include <cmath>
#include <vector>

#include "ao/methods/filters/filters_gpu_internal.h"

namespace ao::gpu_detail {

void set_rotations(Run& r, Program& p, const std::array<Rotation, 16>& rotations) {
  float values[32];
  for (std::size_t k = 0; k < 16; ++k) values[2 * k] = rotations[k].c, values[2 * k + 1] = rotations[k].s;
  r.c.gl.Uniform2fv(r.c.uniform(p, "u_rotation"), 16, values);
}

Texture box_filter(Run& r, const Texture& values, int channels, float depth_limit) {
  Texture out = r.image(channels == 4 ? GL_RGBA32F : GL_R32F);
  Program& p = r.begin("box_filter.comp", "filter", channels == 4 ? "#define CHANNELS 4\n" : "#define CHANNELS 1\n");
  r.set(p, "u_depth_limit", depth_limit);
  bind_texture(r.c, 6, values);
  r.finish(out);
  return out;
}

Texture bilateral_filter(Run& r, const Texture& values, const BilateralParams& params, const std::string& name) {
  params.validate();
  // The Gaussian across taps, as the CPU filter computes it.
  const int half = params.taps / 2;
  const float ss = params.effective_spatial_sigma();
  std::vector<float> spatial(static_cast<std::size_t>(params.taps));
  for (int j = -half; j <= half; ++j) spatial[static_cast<std::size_t>(j + half)] = std::exp(-0.5f * static_cast<float>(j * j) / (ss * ss));
  Texture tmp = r.image(GL_R32F), out = r.image(GL_R32F);
  Program& p = r.c.program({"bilateral.comp"});
  r.c.begin_pass(r.passes, name);
  r.use(p);
  r.set_rays(p);
  r.set(p, "u_taps", params.taps);
  r.c.gl.Uniform1fv(r.c.uniform(p, "u_spatial"), params.taps, spatial.data());
  r.set(p, "u_plane_sigma", params.plane_sigma);
  // The horizontal pass into tmp, then the vertical one into out, in one timed pass.
  for (int vertical = 0; vertical < 2; ++vertical) {
    r.set(p, "u_vertical", vertical);
    bind_texture(r.c, 6, vertical ? tmp : values);
    bind_image(r.c, 0, vertical ? out : tmp, GL_WRITE_ONLY);
    dispatch_2d(r.c, r.width(), r.height());
  }
  r.c.end_pass(r.passes);
  return out;
}

}  // namespace ao::gpu_detail
