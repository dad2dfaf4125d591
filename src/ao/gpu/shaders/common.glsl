// SPDX-License-Identifier: Apache-2.0
// Shared by the GPU backend's compute shaders (each method's, in its folder): the G-buffer's bindings
// and conventions, the integer hashes of src/ao/core/sampling.h, and small helpers every method uses.
// A shader that includes this file (`#include "common.glsl"`, expanded by the loader in
// src/ao/gpu/gl.cpp) can be used elsewhere by pasting the file in place of that line.
//
// The G-buffer (docs/gbuffer.md): camera space is right-handed, +x right, +y up, the camera looks
// down -z; pixel (0, 0) is the top-left one, pixel centres at +0.5; texel (x, y) of every texture is
// pixel (x, y) of the image (row 0 at the top).
//   binding 0  u_depth     R32F     linear depth -P.z, world units; +infinity where not covered
//   binding 1  u_position  RGBA32F  camera-space position P (xyz); 0 where not covered
//   binding 2  u_normal    RGBA32F  unit camera-space normal facing the camera (xyz)
//   binding 3  u_albedo    RGBA32F  linear diffuse albedo (rgb)
//   binding 4  u_object    R32UI    1 + object index; 0 where not covered (the coverage)
//   binding 5  u_direct    RGBA32F  direct-light radiance in units of the ambient (rgb; transfer's radiance mode)

layout(binding = 0) uniform sampler2D u_depth;
layout(binding = 1) uniform sampler2D u_position;
layout(binding = 2) uniform sampler2D u_normal;
layout(binding = 3) uniform sampler2D u_albedo;
layout(binding = 4) uniform usampler2D u_object;
layout(binding = 5) uniform sampler2D u_direct;

// u_size: the image's width and height, pixels.
uniform ivec2 u_size;

const float kInfinity = uintBitsToFloat(0x7f800000u);

float depth_at(ivec2 p) { return texelFetch(u_depth, p, 0).r; }
bool covered(ivec2 p) { return texelFetch(u_object, p, 0).r != 0u; }

// sampling.h: the "lowbias32" finaliser, hash_combine, pixel_seed and to_unit_float, the same
// definitions the C++ compiler reads.
#include "ao/core/hash_shared.h"

// math.h Frame::from_normal (Duff et al. 2017): tangent and bitangent of a unit normal. The sign is
// that of n.z's sign bit, as std::copysign(1, n.z) (-0 counts as negative).
void frame_from_normal(vec3 n, out vec3 t, out vec3 b) {
  const float sign = (floatBitsToUint(n.z) >> 31) != 0u ? -1.0 : 1.0;
  const float a = -1.0 / (sign + n.z);
  const float c = n.x * n.y * a;
  t = vec3(1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x);
  b = vec3(c, sign + n.y * n.y * a, -n.y);
}

// characteristic.h ScreenProjection::locate: the pixel holding camera-space point q's projection,
// clamped to the image (a point projecting outside reads the nearest border pixel); `valid` is
// false (and the pixel (0, 0)) for a point not in front of the camera.
// u_projection: scale_x, scale_y (pixels per unit of x/(-z), y/(-z)), centre_x, centre_y (pixels).
uniform vec4 u_projection;
ivec2 locate(vec3 q, out bool valid) {
  const float inv = -1.0 / q.z;
  valid = q.z < 0.0;
  const float fx = valid ? q.x * inv * u_projection.x + u_projection.z : 0.0;
  const float fy = valid ? u_projection.w - q.y * inv * u_projection.y : 0.0;
  return ivec2(int(min(max(fx, 0.0), float(u_size.x - 1))), int(min(max(fy, 0.0), float(u_size.y - 1))));
}
