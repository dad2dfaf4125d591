// Alchemy AO on the GPU (shaders/alchemy.comp) and the separable cross-bilateral filter
// (shaders/bilateral.comp) that follows it and cone tracing. The sample pattern is the CPU's:
// alchemy_internal.h's rotation table and golden-angle directions are uploaded, the per-pixel
// jitter and rotation index come from the same hash of the seed and the pixel.
#include <cmath>
#include <vector>

#include "ao/core/error.h"
#include "ao/gpu/methods_internal.h"
#include "ao/methods/alchemy_internal.h"

namespace ao::gpu_detail {

namespace {

// camera_direction(px, py) = (ax px + bx, ay py + by, -1) for continuous pixel coordinates.
void set_rays(Run& r, Program& p) {
  const Camera& cam = r.g.camera;
  const float t = cam.tan_half_fov();
  const float ax = 2.0f * t * cam.aspect() / static_cast<float>(r.width()), bx = -t * cam.aspect();
  const float ay = -2.0f * t / static_cast<float>(r.height()), by = t;
  r.c.gl.Uniform4f(r.c.uniform(p, "u_rays"), ax, bx, ay, by);
}

}  // namespace

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
  set_rays(r, p);
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

MethodOutput run_alchemy(Run& r, const Falloff& falloff, const AlchemyParams& params, std::uint32_t seed) {
  const AlchemyConstants k = alchemy_constants(params, falloff.radius);
  if (params.layers.layers != 1)
    throw InputError("alchemy: layers=2 (a second depth layer) runs on the CPU backend only; the GPU shaders read one layer");
  const int s = params.samples;
  // The pattern's tables, as (cos, sin) pairs.
  const alchemy_internal::RotationTable& rot = alchemy_internal::rotations();
  std::vector<float> rotations, directions;
  for (int i = 0; i < alchemy_internal::kRotations; ++i) rotations.insert(rotations.end(), {rot.c[i], rot.s[i]});
  const alchemy_internal::Directions d = alchemy_internal::sample_directions(s);
  for (int i = 0; i < s; ++i) directions.insert(directions.end(), {d.x[i], d.y[i]});
  const Buffer rotation_buffer = make_buffer(r.c, std::span<const float>(rotations));
  const Buffer direction_buffer = make_buffer(r.c, std::span<const float>(directions));

  Texture raw = r.image(GL_R32F);
  Program& p = r.begin("alchemy.comp", "alchemy");
  set_rays(r, p);
  // Screen radius of the world disk: both image axes have 0.5 h / tan(fov/2) pixels per unit of
  // x/(-z), so the disk of radius r at depth z_C spans r * that / z_C pixels (sec. 2.3).
  const float px_per_unit = 0.5f * static_cast<float>(r.height()) / r.g.camera.tan_half_fov();
  r.set(p, "u_samples", s);
  r.set(p, "u_seed", seed);
  r.set(p, "u_radius_px", k.radius * px_per_unit);
  r.set(p, "u_r2", k.radius * k.radius);
  // 2 sigma / s: eq. 9's 2 pi u / s (uniform directions) times the paper's nominal 1/pi, u in sigma.
  r.set(p, "u_scale", 2.0f * k.sigma / static_cast<float>(s));
  r.set(p, "u_epsilon", k.epsilon);
  r.set(p, "u_beta", k.beta);
  r.set(p, "u_contrast", params.contrast);
  r.bind(0, rotation_buffer);
  r.bind(1, direction_buffer);
  r.finish(raw);

  MethodOutput out;
  if (params.filter && params.bilateral.taps > 1) {
    out.extras["unfiltered"] = read_float(r.c, raw);
    out.visibility = read_float(r.c, bilateral_filter(r, raw, params.bilateral, "filter"));
  } else {
    out.visibility = read_float(r.c, raw);
    if (params.filter) out.extras["unfiltered"] = out.visibility;
  }
  return out;
}

}  // namespace ao::gpu_detail
