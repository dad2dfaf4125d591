#version 430
// SPDX-License-Identifier: Apache-2.0
// The linear depth plane of an uploaded G-buffer (core/gbuffer.h GBuffer::depth): -P.z where
// covered, +infinity where not. Every method's depth lookups read this plane.
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, r32f) uniform writeonly image2D o_depth;

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= u_size.x || p.y >= u_size.y) return;
  imageStore(o_depth, p, vec4(covered(p) ? -texelFetch(u_position, p, 0).z : kInfinity));
}
