// SPDX-License-Identifier: Apache-2.0
#include "ao/methods/gtao/gtao.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/core/color_shared.h"
#include "ao/core/params_table.h"
#include "ao/core/sampling.h"
#include "ao/methods/gtao/gtao_internal.h"
#include "ao/methods/gtao/gtao_kernel_internal.h"
#include "ao/methods/gtao/gtao_shared.h"
#include "ao/methods/screen_space_method_internal.h"
#include "ao/simd/depth_plane.h"

namespace ao {

namespace {

using gtao_internal::kMaxSlices;
using gtao_internal::kMaxSteps;
// Tiles of 128 x 16 pixels, as the other screen-space kernels: long row segments for the SIMD
// loops over pixels, few rows per tile.
constexpr int kTileWidth = 128, kTileHeight = 16;
static_assert(kTileWidth <= simd::kMaxGtaoSegment);

// The 4x4 pattern (the paper's spatial noise, undone by its 4x4 denoiser): per pattern entry p, the
// rotation of the slice set (a fraction of pi / slices) and the offset of the samples along a slice
// (a fraction of one step). Both stratified over the 16 entries with independent seeded
// permutations and jitter, so a 4x4 block holds 16 distinct rotations and offsets; without
// interleaving every entry is the same seeded value.
struct Pattern {
  std::array<float, 16> rotation, offset, sector;
};

Pattern make_pattern(std::uint32_t seed, bool interleave) {
  Pattern p;
  auto permutation = [&](std::uint32_t salt) {
    std::array<int, 16> perm;
    for (int k = 0; k < 16; ++k) perm[static_cast<std::size_t>(k)] = k;
    // Fisher-Yates with hashed choices: depends only on the seed.
    for (int k = 15; k > 0; --k) {
      const int j = static_cast<int>(hash_combine(hash_combine(seed, salt), static_cast<std::uint32_t>(k)) % static_cast<std::uint32_t>(k + 1));
      std::swap(perm[static_cast<std::size_t>(k)], perm[static_cast<std::size_t>(j)]);
    }
    return perm;
  };
  const std::array<int, 16> pr = permutation(0x51u), po = permutation(0xA7u), pb = permutation(0xB3u);
  for (int k = 0; k < 16; ++k) {
    const auto i = static_cast<std::size_t>(k);
    const float jr = to_unit_float(hash_combine(hash_combine(seed, 0x1Du), static_cast<std::uint32_t>(k)));
    const float jo = to_unit_float(hash_combine(hash_combine(seed, 0x2Eu), static_cast<std::uint32_t>(k)));
    p.rotation[i] = interleave ? (static_cast<float>(pr[i]) + jr) / 16.0f : to_unit_float(hash_combine(seed, 0x3Fu));
    p.offset[i] = interleave ? (static_cast<float>(po[i]) + jo) / 16.0f : to_unit_float(hash_combine(seed, 0x40u));
    const float jb = to_unit_float(hash_combine(hash_combine(seed, 0x3Cu), static_cast<std::uint32_t>(k)));
    p.sector[i] = interleave ? (static_cast<float>(pb[i]) + jb) / 16.0f : to_unit_float(hash_combine(seed, 0x41u));
  }
  return p;
}

}  // namespace

const ParamTable<GtaoParams>& gtao_param_table() {
  using P = Param<GtaoParams>;
  static const ParamTable<GtaoParams> table{
      "gtao",
      {{P::integer("slices", &GtaoParams::slices, Range::closed(1, kMaxSlices), "", "slice directions per pixel (the outer integral over phi)"),
        P::integer("steps", &GtaoParams::steps, Range::closed(1, kMaxSteps), "", "depth-buffer samples on each side of a slice (the horizon search)"),
        P::real("step_power", &GtaoParams::step_power, Range::closed(1, 4), "", "samples at ((j + u) / steps)^step_power of the screen radius"),
        P::boolean("multi_bounce", &GtaoParams::multi_bounce, "the multi-bounce fit with the G-buffer albedo"),
        thickness_param(&GtaoParams::layers)},
       interleave_params(&GtaoParams::interleave),
       depth_layer_params(&GtaoParams::layers)}};
  return table;
}

namespace gtao_internal {

Tables make_tables(const GtaoParams& params, std::uint32_t seed) {
  const int slices = params.slices, steps = params.steps;
  const Pattern pattern = make_pattern(seed, params.interleave.interleave);
  Tables t;
  // Slice k of pattern entry p has screen angle phi = pi (k + rotation_p) / slices: the slices
  // split the half circle evenly (a slice covers both of its sides), rotated per pixel.
  for (int k = 0; k < slices; ++k)
    for (int p = 0; p < 16; ++p) {
      const double phi = kPi * (k + pattern.rotation[static_cast<std::size_t>(p)]) / slices;
      t.dir_c[static_cast<std::size_t>(k)][static_cast<std::size_t>(p)] = static_cast<float>(std::cos(phi));
      t.dir_s[static_cast<std::size_t>(k)][static_cast<std::size_t>(p)] = static_cast<float>(std::sin(phi));
    }
  // The bitmask's points (slabs) of slice k and entry p lie at (i + xi) / 32 of the slice's measure:
  // xi stratified over the 16 entries, and moved on by the golden ratio's fraction from slice to slice.
  for (int k = 0; k < slices; ++k)
    for (int p = 0; p < 16; ++p) {
      const double xi = pattern.sector[static_cast<std::size_t>(p)] + 0.6180339887498949 * k;
      t.sector_offset[static_cast<std::size_t>(k)][static_cast<std::size_t>(p)] = static_cast<float>(xi - std::floor(xi));
    }
  // Step j of pattern entry p lies at t = ((j + offset_p) / steps)^step_power of the screen radius.
  for (int j = 0; j < steps; ++j)
    for (int p = 0; p < 16; ++p)
      t.step_t[static_cast<std::size_t>(j)][static_cast<std::size_t>(p)] =
          std::pow((static_cast<float>(j) + pattern.offset[static_cast<std::size_t>(p)]) / static_cast<float>(steps), params.step_power);
  return t;
}

}  // namespace gtao_internal

void GtaoParams::validate() const {
  gtao_param_table().validate(*this);
  check_thickness(layers, "gtao");
}
void to_json(nlohmann::json& j, const GtaoParams& p) { j = gtao_param_table().to_json(p); }
void from_json(const nlohmann::json& j, GtaoParams& p) { gtao_param_table().from_json(j, p); }

float gtao_multi_bounce(float v, float rho) {
  return shared::multi_bounce_fit(v, rho);
}

GtaoImage gtao_ao(const GBuffer& g, float radius, const GtaoParams& params, std::uint32_t seed) {
  if (params.layers.layers < 2) return gtao_ao(g, nullptr, radius, params, seed);
  const float separation = effective_separation(params.layers, radius);
  if (!has_second_layer(g, separation)) throw_missing_second_layer("gtao", separation);
  return gtao_ao(g, &g.second_depth, radius, params, seed);
}

GtaoImage gtao_ao(const GBuffer& g, const Image<float>* second_layer, float radius, const GtaoParams& params, std::uint32_t seed) {
  params.validate();
  if (!(radius > 0.0f) || !std::isfinite(radius)) throw InputError("gtao: radius R must be a positive number of world units");
  if (params.layers.layers == 2 && !second_layer) throw_missing_second_layer("gtao", effective_separation(params.layers, radius));
  const int w = g.width(), h = g.height();
  const int slices = params.slices, steps = params.steps;
  const gtao_internal::Tables tables = gtao_internal::make_tables(params, seed);

  // Camera rays through pixel centres: ray(x, y) = (ax (x + 0.5) + bx, ay (y + 0.5) + by, -1), so a
  // sample's camera-space point is depth * ray (one 4-byte gather per sample).
  const float t = g.camera.tan_half_fov();
  const Image<float> depth_image = depth_plane(g);  // also the filter's
  simd::GtaoInputs in;
  // Both image axes have 0.5 h / tan(fov/2) pixels per unit of x/(-z): R at depth z spans R * that / z pixels.
  static_cast<simd::DepthView&>(in) = simd::depth_view(depth_image.data(), &g.normal.data()->x, g.object_id.data(), w, h, t, g.camera.aspect());
  in.radius = radius;
  in.slices = slices, in.steps = steps;
  // The kernel reads each table as one row-major array, [k * 16 + p].
  static_assert(sizeof(tables.dir_c) == sizeof(float) * kMaxSlices * 16 && sizeof(tables.step_t) == sizeof(float) * kMaxSteps * 16);
  in.dir_c = tables.dir_c[0].data(), in.dir_s = tables.dir_s[0].data(), in.step_t = tables.step_t[0].data();
  in.sector_offset = tables.sector_offset[0].data();
  if (params.layers.layers == 2) {
    if (second_layer->width() != w || second_layer->height() != h) throw InputError("gtao: the second depth layer must have the G-buffer's size");
    in.second = second_layer->data(), in.separation = effective_separation(params.layers, radius);
  } else {
    in.thickness = params.layers.thickness;
  }

  // V = 1 where nothing is covered: each tile fills its own rows (fresh pages touched in parallel).
  Image<float> v;
  v.resize(w, h);
  parallel_for_tiles(w, h, kTileWidth, kTileHeight, [&](const Tile& tile) {
    for (int y = tile.y0; y < tile.y1; ++y) {
      std::fill_n(&v(tile.x0, y), tile.x1 - tile.x0, 1.0f);
      simd::gtao_row(in, y, tile.x0, tile.x1, &v(tile.x0, y));
    }
  });
  if (params.interleave.interleave && params.interleave.filter) v = depth_aware_box_filter(v, g, effective_depth_limit(params.interleave, radius), &depth_image);
  GtaoImage out;
  if (params.multi_bounce) {
    out.color = Image<Vec3>(w, h, Vec3{1, 1, 1});
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (!g.covered(x, y)) continue;
        const Vec3 a = g.albedo(x, y);
        const float vis = v(x, y);
        out.color(x, y) = {gtao_multi_bounce(vis, a.x), gtao_multi_bounce(vis, a.y), gtao_multi_bounce(vis, a.z)};
        v(x, y) = gtao_multi_bounce(vis, shared::luminance(a.x, a.y, a.z));
      }
  }
  out.visibility = std::move(v);
  return out;
}

MethodOutput run(const MethodInput& in, const GtaoParams& params) {
  params.validate();
  // Two layers: the G-buffer's second layer, or one traced for this run.
  std::shared_ptr<const Image<float>> second;
  if (params.layers.layers == 2) second = detail::second_layer_for(in, effective_separation(params.layers, in.falloff.radius), "gtao");
  GtaoImage img = gtao_ao(in.gbuffer, second.get(), in.falloff.radius, params, in.seed);
  MethodOutput out;
  out.visibility = std::move(img.visibility);
  out.color = std::move(img.color);
  return out;
}

void check_gpu(const GtaoParams& params) {
  if (params.layers.layers != 1 || params.layers.thickness > 0)
    throw InputError("gtao: slabs (thickness > 0 or layers=2) run on the CPU backend only; the GPU shader reads the horizon form");
}

}  // namespace ao
