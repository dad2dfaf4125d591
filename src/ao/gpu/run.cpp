// SPDX-License-Identifier: Apache-2.0
// What every GPU method's run does (run_internal.h: Run): its programs made current with the
// G-buffer bound and the camera's projection set, its passes timed, its results read back.
#include <vector>

#include "ao/core/camera.h"
#include "ao/gpu/run_internal.h"

namespace ao::gpu_detail {

void Run::use(Program& p) {
  c.gl.UseProgram(p.id);
  c.gl.Uniform2i(c.uniform(p, "u_size"), width(), height());
  const ScreenProjection pr = ScreenProjection::from_camera(g.camera);
  c.gl.Uniform4f(c.uniform(p, "u_projection"), pr.scale_x, pr.scale_y, pr.centre_x, pr.centre_y);
  g.bind();
}

void Run::set_rays(Program& p) {
  const float t = g.camera.tan_half_fov();
  const float ax = 2.0f * t * g.camera.aspect() / static_cast<float>(width()), bx = -t * g.camera.aspect();
  const float ay = -2.0f * t / static_cast<float>(height()), by = t;
  c.gl.Uniform4f(c.uniform(p, "u_rays"), ax, bx, ay, by);
}

Program& Run::begin(std::string_view shader, std::string name, std::string_view defines) {
  Program& p = c.program({shader}, defines);
  c.begin_pass(passes, std::move(name));
  use(p);
  return p;
}

void Run::finish(const Texture& out) {
  bind_image(c, 0, out, GL_WRITE_ONLY);
  dispatch_2d(c, width(), height());
  c.end_pass(passes);
}

Texture Run::map(std::string_view shader, std::string name, const Texture& in, GLenum format, std::string_view defines) {
  Texture out = image(format);
  begin(shader, std::move(name), defines);
  bind_texture(c, 6, in);
  finish(out);
  return out;
}

Image<float> read_float(Context& c, const Texture& t) {
  Image<float> img(t.width, t.height);
  download(c, t, GL_RED, GL_FLOAT, img.data(), img.size() * sizeof(float));
  return img;
}

Image<Vec3> read_rgb(Context& c, const Texture& t) {
  Image<Vec3> img(t.width, t.height);
  download(c, t, GL_RGB, GL_FLOAT, img.data(), img.size() * sizeof(Vec3));
  return img;
}

Image<float> read_alpha(Context& c, const Texture& t) {
  // Core profile reads no lone alpha channel: RGBA, then every fourth float.
  std::vector<float> rgba(4 * static_cast<std::size_t>(t.width) * t.height);
  download(c, t, GL_RGBA, GL_FLOAT, rgba.data(), rgba.size() * sizeof(float));
  Image<float> img(t.width, t.height);
  for (std::size_t i = 0; i < img.size(); ++i) img[i] = rgba[4 * i + 3];
  return img;
}

}  // namespace ao::gpu_detail
