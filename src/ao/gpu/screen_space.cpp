// The screen-space methods of volumetric AO and ambient transfer on the GPU: containment,
// volumetric, transfer (shaders/containment.comp, volumetric.comp, transfer.comp) and the 4x4
// depth-aware box filter of their interleaved sampling (shaders/box_filter.comp). Each takes the
// CPU kernel's sample set (make_containment_samples, make_disk_samples) and 4x4 rotations
// (interleave_rotations) as uploaded tables, so both backends sample the same points.
#include <cmath>
#include <string>

#include "ao/core/error.h"
#include "ao/gpu/methods_internal.h"
#include "ao/methods/characteristic.h"

namespace ao::gpu_detail {

void Run::use(Program& p) {
  c.gl.UseProgram(p.id);
  c.gl.Uniform2i(c.uniform(p, "u_size"), width(), height());
  const ScreenProjection pr = ScreenProjection::from_camera(g.camera);
  c.gl.Uniform4f(c.uniform(p, "u_projection"), pr.scale_x, pr.scale_y, pr.centre_x, pr.centre_y);
  g.bind();
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

namespace {

// The uniforms containment, transfer and volumetric share: the depth-test bias, the 4x4
// rotations, the sample count and the silhouette elimination's limit (AT 4.3: a surface more than
// R in front of the test point, or of the pipe's entry, does not occlude it).
void set_sampling(Run& r, Program& p, int samples, float bias, bool silhouette_elimination, float radius, const InterleaveOptions& interleave,
                  std::uint32_t seed) {
  set_rotations(r, p, interleave_rotations(seed, interleave.interleave));
  r.set(p, "u_samples", samples);
  r.set(p, "u_bias", bias);
  r.set(p, "u_far_limit", silhouette_elimination ? -radius : -kInfinity);
  // One pixel's footprint at unit depth: the image plane spans 2 tan(fov/2) over `height` pixels.
  r.set(p, "u_footprint", 2.0f * r.g.camera.tan_half_fov() / static_cast<float>(r.height()));
}

// The containment-test offsets (X, Y, Z, r) of make_containment_samples, as vec4s.
Buffer containment_offsets(Run& r, int n, const Falloff& falloff) {
  const ContainmentSamples s = make_containment_samples(n, falloff);
  std::vector<float> v;
  for (int i = 0; i < s.size(); ++i) v.insert(v.end(), {s.x[i], s.y[i], s.z[i], s.r[i]});
  return make_buffer(r.c, std::span<const float>(v));
}

// The GPU shaders read one depth layer: a second one (a deep G-buffer) is the CPU's only.
void require_one_layer(const DepthLayers& layers, const char* method) {
  if (layers.layers != 1)
    throw InputError(std::string(method) + ": layers=2 (a second depth layer) runs on the CPU backend only; the GPU shaders read one layer");
}

// The filter after an interleaved pass, when the options ask for it.
Texture filtered(Run& r, Texture raw, int channels, const InterleaveOptions& o, float radius) {
  if (!(o.interleave && o.filter)) return raw;
  return box_filter(r, raw, channels, effective_depth_limit(o, radius));
}

}  // namespace

MethodOutput run_containment(Run& r, const Falloff& falloff, const ContainmentParams& params, std::uint32_t seed) {
  falloff.validate();
  require_one_layer(params.layers, "containment");
  const Buffer offsets = containment_offsets(r, params.samples, falloff);
  Texture raw = r.image(GL_R32F);
  Program& p = r.begin("containment.comp", "containment");
  set_sampling(r, p, params.samples, params.bias, params.silhouette_elimination, falloff.radius, params.interleave, seed);
  r.set(p, "u_ray_steps", params.ray_steps);
  r.bind(0, offsets);
  r.finish(raw);
  MethodOutput out;
  out.visibility = read_float(r.c, filtered(r, std::move(raw), 1, params.interleave, falloff.radius));
  return out;
}

MethodOutput run_volumetric(Run& r, const Falloff& falloff, const VolumetricParams& params, std::uint32_t seed) {
  Falloff{Membership::Cubic, falloff.radius}.validate();
  require_one_layer(params.layers, "volumetric");
  const float radius = falloff.radius;
  const DiskSamples s = make_disk_samples(params.samples);
  std::vector<float> disk;
  // Eq. 7's normaliser from the same disk points: F = R sum h_i (summed in order, as the CPU) or 2Rn/3.
  float sum_h = 0;
  for (int i = 0; i < s.size(); ++i) {
    disk.insert(disk.end(), {s.x[i], s.y[i], s.h[i], 0.0f});
    sum_h += s.h[i];
  }
  const float F = params.normalizer == VolumeNormalizer::WeightedImportance ? radius * sum_h : 2.0f * radius * static_cast<float>(params.samples) / 3.0f;
  const Buffer points = make_buffer(r.c, std::span<const float>(disk));
  Texture raw = r.image(GL_R32F);
  Program& p = r.begin("volumetric.comp", "volumetric");
  set_sampling(r, p, params.samples, params.bias, params.silhouette_elimination, radius, params.interleave, seed);
  r.set(p, "u_half_radius", 0.5f * radius);
  r.set(p, "u_inv_f", 1.0f / F);
  r.bind(0, points);
  r.finish(raw);
  MethodOutput out;
  out.visibility = read_float(r.c, filtered(r, std::move(raw), 1, params.interleave, radius));
  return out;
}

MethodOutput run_transfer(Run& r, const Falloff& falloff, const TransferParams& params, std::uint32_t seed) {
  falloff.validate();
  require_one_layer(params.layers, "transfer");
  if (!r.g.has_albedo) throw InputError("transfer: the indirect reflectance image must have the G-buffer's size (the G-buffer has no albedo)");
  const bool radiance = params.reflectance == TransferReflectance::Radiance;
  if (radiance && !r.g.direct)
    throw InputError("transfer: reflectance=radiance reads the occluders' direct light, and the G-buffer has no direct-light pass");
  const Buffer offsets = containment_offsets(r, params.samples, falloff);
  Texture raw = r.image(GL_RGBA32F);
  Program& p = r.begin("transfer.comp", "transfer");
  set_sampling(r, p, params.samples, params.bias, params.silhouette_elimination, falloff.radius, params.interleave, seed);
  r.set(p, "u_ray_steps", params.ray_steps);
  r.set(p, "u_albedo_scale", params.albedo_scale);
  r.set(p, "u_radiance", radiance ? 1 : 0);
  r.bind(0, offsets);
  r.finish(raw);
  // Sec. 4.2's filter on W and O alike, then the luminance of W.
  const Texture wo = filtered(r, std::move(raw), 4, params.interleave, falloff.radius);
  MethodOutput out;
  out.visibility = read_float(r.c, r.map("transfer_finish.comp", "luminance", wo, GL_R32F));
  out.color = read_rgb(r.c, wo);
  out.extras["obscurance"] = read_alpha(r.c, wo);
  return out;
}

}  // namespace ao::gpu_detail
