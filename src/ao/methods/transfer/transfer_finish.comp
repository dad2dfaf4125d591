#version 430
// SPDX-License-Identifier: Apache-2.0
// Ambient transfer's scalar visibility (src/ao/methods/transfer/transfer.h): the Rec. 709 luminance of W,
// 0.2126 W_r + 0.7152 W_g + 0.0722 W_b (color_shared.h), from transfer.comp's (W, O) after the filter.
//
// Uniforms: u_size (common.glsl).
#include "common.glsl"
#include "ao/core/color_shared.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 6) uniform sampler2D u_values;
layout(binding = 0, r32f) uniform writeonly image2D o_visibility;

void main() {
  const ivec2 pix = ivec2(gl_GlobalInvocationID.xy);
  if (pix.x >= u_size.x || pix.y >= u_size.y) return;
  const vec3 w = texelFetch(u_values, pix, 0).rgb;
  imageStore(o_visibility, pix, vec4(luminance(w.r, w.g, w.b)));
}
