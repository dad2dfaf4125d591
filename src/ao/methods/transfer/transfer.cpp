// SPDX-License-Identifier: Apache-2.0
// Ambient transfer (Szirmay-Kalos, Antal, Csonka, "Ambient Transfer: Efficient Methods for Ambient
// Lighting"): W of eq. 6 estimated by eq. 9 from containment tests (sec. 4) of cosine-distributed
// rays r = mu^-1(xi) (eq. 8), a~ read at the nearest occluded test point's pixel, with interleaved
// sampling and its 4x4 filter (sec. 4.2), silhouette-shadow elimination (sec. 4.3) and the radiance
// variant of sec. 4.1 (docs/methods/transfer.md, eq. 9'). The depth-buffer tests run in the SIMD
// kernel layer (simd::transfer_rays); the analytic characteristic functions one pixel at a time here.
#include "ao/methods/transfer/transfer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "ao/core/color_shared.h"
#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/core/params_table.h"
#include "ao/methods/characteristic.h"
#include "ao/methods/containment/containment.h"
#include "ao/methods/samples.h"
#include "ao/methods/screen_space_internal.h"
#include "ao/methods/screen_space_method_internal.h"
#include "ao/methods/transfer/transfer_internal.h"
#include "ao/methods/transfer/transfer_kernel_internal.h"
#include "ao/simd/depth_plane.h"

namespace ao {

namespace {
constexpr float kInfinityLike = 1e30f;
// Tiles of 128 x 16 pixels (faster than 64 x 64 in bench transfer/0/2).
constexpr int kTileWidth = 128, kTileHeight = 16;
constexpr int kMaxRaySteps = 8;
constexpr int kPaletteSize = 32;                  // distinct reflectances a packed palette holds
constexpr std::uint32_t kPaletteMask = 0x1F;      // its index's bits in a packed depth word (simd::TransferInputs)

// Rec. 709 luminance of W: the method's scalar visibility.
inline float luminance(Vec3 c) { return shared::luminance(c.x, c.y, c.z); }
}

const ParamTable<TransferParams>& transfer_param_table() {
  using P = Param<TransferParams>;
  static const ParamTable<TransferParams> table{
      "transfer",
      {{P::integer("samples", &TransferParams::samples, Range::closed(1, kMaxScreenSpaceSamples), "", "n in eq. 9: rays per pixel"),
        P::integer("ray_steps", &TransferParams::ray_steps, Range::closed(1, kMaxRaySteps), "", "m: containment tests per ray (sec. 4)"),
        P::boolean("silhouette_elimination", &TransferParams::silhouette_elimination,
                   "AT 4.3: occluded only if the surface in front is less than R in front"),
        P::real("bias", &TransferParams::bias, Range::at_least(0), "world units", "depth-test bias; 0 = auto (as containment)"),
        P::real("albedo_scale", &TransferParams::albedo_scale, Range::closed(0, 1), "", "multiplies a~ and Ld~ (W -> O as it goes to 0)"),
        P::enumeration<TransferReflectance>("reflectance", &TransferParams::reflectance,
                                            {{"albedo", TransferReflectance::Albedo}, {"radiance", TransferReflectance::Radiance}},
                                            "what occluders send back: albedo (eq. 9) or also their direct light (sec. 4.1, needs --sun)")},
       interleave_params(&TransferParams::interleave), depth_layer_params(&TransferParams::layers),
       {thickness_param(&TransferParams::layers)},
       {characteristic_param(&TransferParams::characteristic)}}};
  return table;
}

void TransferParams::validate() const {
  transfer_param_table().validate(*this);
  check_thickness(layers, "transfer");
}
void to_json(nlohmann::json& j, const TransferParams& p) { j = transfer_param_table().to_json(p); }
void from_json(const nlohmann::json& j, TransferParams& p) { transfer_param_table().from_json(j, p); }


namespace {

// Eq. 9 for one pixel from its sums over the n rays: sum I (`open`), sum (1 - I) a~ (`lost`) and, in
// the radiance mode, sum (1 - I) Ld~ (`gain`). The denominator is >= sum I since a~ <= 1; with no
// open ray at all W = 0 (0/0 when every ray is blocked by white surfaces: no sky light ever
// enters). The radiance mode (transfer.h): the occluders' direct light joins the numerator, not
// clamped (lit occluders can send more light than the sky they hide); 0 when nothing arrives, or
// when the denominator is 0 (every ray blocked by white surfaces: with light arriving, the bounces
// of eq. 6 then sum to infinity). With Ld~ = 0 the same value as the albedo mode: num = o, and
// o > 0 implies den >= o > 0 for a~ <= 1, where the clamp does nothing. simd::transfer_rays
// computes the same lane-wise.
float transfer_ratio(bool radiance, float n, float scale, float open, float lost, float gain) {
  if (radiance) {
    const float num = open + scale * gain, den = n - scale * lost;
    return num > 0 && den > 0 ? num / den : 0.0f;
  }
  return open > 0 ? std::min(open / (n - scale * lost), 1.0f) : 0.0f;
}

// AT sec. 4 and eq. 9 with an analytic characteristic function: the rays of simd::transfer_rays,
// one pixel at a time (the analytic scenes are small test scenes). The nearest of a ray's m test
// points found occluded names the pixel whose a~ (and Ld~) the ray brings back: the pixel the point
// projects to, or the shaded pixel's own when the point is behind the camera (locally homogeneous
// material).
template <class Characteristic>
void transfer_rays(const simd::CoveredPixels& row, const Characteristic& ch, const ScreenProjection& projection, const ContainmentSamples& s,
                   int m, float far_limit, const float* albedo, const float* direct, float scale, std::size_t row_base,
                   const simd::TransferOutputs& out) {
  const float inv_m = 1.0f / static_cast<float>(m), n = static_cast<float>(s.size());
  for (int k = 0; k < row.count; ++k) {
    const auto e = static_cast<std::size_t>(k);
    const std::size_t own = row_base + static_cast<std::size_t>(row.index[e]);
    const Vec3 x{row.px[e], row.py[e], row.pz[e]}, t{row.tx[e], row.ty[e], row.tz[e]}, b{row.bx[e], row.by[e], row.bz[e]},
        nn{row.nx[e], row.ny[e], row.nz[e]};
    float open = 0;
    std::array<float, 3> lost{}, gain{};
    for (int i = 0; i < s.size(); ++i) {
      const auto si = static_cast<std::size_t>(i);
      const Vec3 w = t * s.x[si] + b * s.y[si] + nn * s.z[si];  // w r of eq. 8
      long long at = -1;
      for (int j = 1; j <= m && at < 0; ++j) {  // sec. 4: the first occluded test point, from x outwards
        const Vec3 q = x + w * (static_cast<float>(j) * inv_m);
        const float d = ch.distance(q.x, q.y, q.z);
        // AT 4.3; -inf (implicit surfaces: inner along the whole line) is never a distant foreground object.
        const bool near = d > far_limit || d < -kInfinityLike;
        if (d < -row.bias[e] && near) {
          int p;
          at = projection.locate(q.x, q.y, q.z, p) ? p : static_cast<long long>(own);
        }
      }
      if (at < 0) {
        open += 1.0f;
        continue;
      }
      for (std::size_t c = 0; c < 3; ++c) {
        lost[c] += albedo[3 * static_cast<std::size_t>(at) + c];             // (1 - I) a~ of eq. 9's denominator
        if (direct) gain[c] += direct[3 * static_cast<std::size_t>(at) + c];  // (1 - I) Ld~ in the numerator of eq. 9'
      }
    }
    const bool radiance = direct != nullptr;
    const float wr = transfer_ratio(radiance, n, scale, open, lost[0], gain[0]), wg = transfer_ratio(radiance, n, scale, open, lost[1], gain[1]),
                wb = transfer_ratio(radiance, n, scale, open, lost[2], gain[2]);
    out.r[own] = wr, out.g[own] = wg, out.b[own] = wb, out.o[own] = open / n;  // O: eq. 5 from the same tests
  }
}

// An exact palette of the reflectance image: at most 32 distinct RGB triples (bitwise equal),
// whose index per pixel is packed into the low 5 mantissa bits of the pixel's depth. G-buffer
// albedo is per-material constant, so this usually exists. A test's depth gather then also
// brings the index of the albedo a blocked ray reads, and a~ is three table lookups (in registers
// on AVX-512): no second gather, no second array in the cache (the gathers' misses are most of the
// pass's time). The depth kernel keeps its tests exact (simd::transfer_rays). Returns false,
// and the caller reads the image in place, when there are more than 32 values or a depth is
// neither +infinity nor a positive normal float (the packing's bound needs one of those).
bool make_palette(const Image<Vec3>& img, const Image<float>& depth, Image<std::uint32_t>& packed, std::array<float, 96>& planes) {
  const std::size_t n = img.size();
  const Vec3* px = img.data();
  std::array<Vec3, kPaletteSize> entries;
  int used = 0;
  auto find = [&](const Vec3& v) {
    int e = 0;
    while (e < used && std::memcmp(&v, &entries[static_cast<std::size_t>(e)], sizeof(Vec3)) != 0) ++e;
    return e;
  };
  // The distinct values and the depth check, per band in parallel (a band stops at 33 values),
  // then merged in band order, so the palette is the same for any thread count.
  struct Band {
    std::array<Vec3, kPaletteSize + 1> values;
    int count = 0;
    bool depth_ok = true;
  };
  constexpr std::size_t kBand = 1 << 15;
  std::vector<Band> bands((n + kBand - 1) / kBand);
  tbb::parallel_for(std::size_t{0}, bands.size(), [&](std::size_t b) {
    Band& band = bands[b];
    Vec3 last{};
    for (std::size_t i = b * kBand; i < std::min(n, (b + 1) * kBand); ++i) {
      const float z = depth[i];
      band.depth_ok &= z == kInfinity || (z >= std::numeric_limits<float>::min() && z <= std::numeric_limits<float>::max());
      const Vec3 v = px[i];
      if (band.count > 0 && std::memcmp(&v, &last, sizeof(Vec3)) == 0) continue;
      last = v;
      int e = 0;
      while (e < band.count && std::memcmp(&v, &band.values[static_cast<std::size_t>(e)], sizeof(Vec3)) != 0) ++e;
      if (e < band.count) continue;
      if (band.count == kPaletteSize + 1) return;  // too many: the merge fails anyway
      band.values[static_cast<std::size_t>(band.count++)] = v;
    }
  });
  for (const Band& band : bands) {
    if (!band.depth_ok) return false;
    for (int k = 0; k < band.count; ++k) {
      const Vec3 v = band.values[static_cast<std::size_t>(k)];
      if (find(v) < used) continue;
      if (used == kPaletteSize) return false;
      entries[static_cast<std::size_t>(used++)] = v;
    }
  }
  packed.resize(img.width(), img.height());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<std::size_t>& r) {
    int last = -1;
    Vec3 last_v{};
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      const Vec3 v = px[i];
      if (last < 0 || std::memcmp(&v, &last_v, sizeof(Vec3)) != 0) last = find(v), last_v = v;
      const float z = depth[i];
      std::uint32_t bits;
      std::memcpy(&bits, &z, sizeof bits);
      // +infinity (background) stays exact: it is never an occluder, so it needs no index.
      packed[i] = z == kInfinity ? bits : (bits & ~kPaletteMask) | static_cast<std::uint32_t>(last);
    }
  });
  for (int e = 0; e < used; ++e) {
    const Vec3 v = entries[static_cast<std::size_t>(e)];
    planes[static_cast<std::size_t>(e)] = v.x, planes[static_cast<std::size_t>(32 + e)] = v.y, planes[static_cast<std::size_t>(64 + e)] = v.z;
  }
  return true;
}

// What transfer reads beyond the G-buffer's depth and normals: the reflectance image at its size,
// and for reflectance=radiance its direct-light pass.
void check_transfer_inputs(const GBuffer& g, const Image<Vec3>& indirect, const TransferParams& params) {
  const int w = g.width(), h = g.height();
  if (indirect.width() != w || indirect.height() != h) throw InputError("transfer: the indirect reflectance image must have the G-buffer's size");
  if (params.reflectance != TransferReflectance::Radiance) return;
  if (g.direct.empty())
    throw InputError("transfer: reflectance=radiance reads the occluders' direct light, and the G-buffer has no direct-light pass");
  if (g.direct.width() != w || g.direct.height() != h) throw InputError("transfer: the G-buffer's direct-light pass must have its size");
}

// Where the kernel writes W (R, G, B planes) and O: planar, the filter's input, so its depth tests
// are shared by all four. Unfiltered, R goes where the luminance will be and O to its final place;
// when the depth-buffer kernel writes the final images itself, `final_rgb` is W interleaved (and
// raw_g, raw_b are unused).
struct RawPlanes {
  float* r;
  float* g;
  float* b;
  float* o;
  Vec3* final_rgb;
};

RawPlanes raw_planes(TransferBuffers& buffers, int w, int h, bool filter, bool kernel_writes_final) {
  TransferImage& out = buffers.result;
  out.transfer.resize(w, h), out.obscurance.resize(w, h), out.luminance.resize(w, h);
  for (Image<float>& p : buffers.scratch) p.resize(w, h);
  return {filter ? buffers.scratch[0].data() : out.luminance.data(), buffers.scratch[1].data(), buffers.scratch[2].data(),
          filter ? buffers.scratch[3].data() : out.obscurance.data(), kernel_writes_final ? out.transfer.data() : nullptr};
}

// Sec. 4.2's filter on W and O alike (filtered R goes where the luminance will be), then W
// interleaved and its luminance over the R plane in place (each pixel reads R before writing).
void finish_transfer(TransferBuffers& buffers, const RawPlanes& raw, const GBuffer& g, bool filter, float depth_limit,
                     const Image<float>* carried_depth) {
  TransferImage& out = buffers.result;
  float* fr = raw.r;
  float* fg = raw.g;
  float* fb = raw.b;
  if (filter) {
    fr = out.luminance.data(), fg = buffers.scratch[4].data(), fb = buffers.scratch[5].data();
    const std::array<const float*, 4> src{raw.r, raw.g, raw.b, raw.o};
    const std::array<float*, 4> dst{fr, fg, fb, out.obscurance.data()};
    depth_aware_box_filter_planes(src, dst, g, depth_limit, carried_depth);
  }
  const int w = g.width();
  parallel_for_tiles(w, g.height(), kTileWidth, [&](const Tile& t) {
    for (int y = t.y0; y < t.y1; ++y) {
      const std::size_t i = static_cast<std::size_t>(y) * w + t.x0;
      simd::interleave_transfer(fr + i, fg + i, fb + i, static_cast<std::size_t>(t.x1 - t.x0), out.transfer.data() + i, out.luminance.data() + i);
    }
  });
}

}  // namespace

template <class Characteristic>
const TransferImage& transfer_ao(TransferBuffers& buffers, const GBuffer& g, const Characteristic& ch, const Image<Vec3>& indirect,
                                 const Falloff& falloff, const TransferParams& params, std::uint32_t seed) {
  constexpr bool kDepthBuffer = std::is_same_v<Characteristic, DepthBufferCharacteristic>;
  falloff.validate();
  params.validate();
  check_transfer_inputs(g, indirect, params);
  check_layers(ch, params.layers, falloff.radius, "transfer");
  const int w = g.width(), h = g.height();
  const bool radiance = params.reflectance == TransferReflectance::Radiance;
  const ContainmentSamples s = make_containment_samples(params.samples, falloff);
  const simd::Rotations16 rotations = simd_rotations(interleave_rotations(seed, params.interleave.interleave));
  const float far_limit = params.silhouette_elimination ? -falloff.radius : -kInfinity;  // AT 4.3
  const int m = params.ray_steps;
  const bool filter = params.interleave.interleave && params.interleave.filter;
  const ScreenProjection projection = ScreenProjection::from_camera(g.camera);
  // A view of the reflectance: RGB triples, read in place (Vec3 is three packed floats).
  static_assert(sizeof(Vec3) == 3 * sizeof(float));
  const float* albedo = &indirect.data()->x;
  const float* direct = radiance ? &g.direct.data()->x : nullptr;  // Ld~, radiance mode only
  // The depth-buffer kernel reads a~ through a palette packed into the G-buffer's depth plane when
  // it is the depth it reads (the radiance mode reads Ld~ at the occluder's pixel, which a palette
  // index does not give).
  alignas(64) std::array<float, 96> palette_rgb{};
  simd::TransferInputs in{nullptr, palette_rgb.data(), albedo, direct, params.albedo_scale};
  if constexpr (kDepthBuffer) {
    if (!radiance && ch.depth == ch.plane->data() && make_palette(indirect, *ch.plane, buffers.depth_and_palette, palette_rgb))
      in.packed = buffers.depth_and_palette.data();
  }
  // Unfiltered, the depth-buffer kernel writes the final images itself (W interleaved, its
  // luminance where R would go, O), and the interleave pass is skipped.
  const bool kernel_writes_final = !filter && kDepthBuffer;
  const RawPlanes raw = raw_planes(buffers, w, h, filter, kernel_writes_final);
  parallel_for_tiles(w, h, kTileWidth, kTileHeight, [&](const Tile& t) {
    thread_local simd::CoveredPixels row;  // its arrays kept between tiles: one allocation per thread, not 17 per tile
    for (int y = t.y0; y < t.y1; ++y) {
      const std::size_t base = static_cast<std::size_t>(y) * w;
      // Uncovered pixels, runs of id 0: W = O = 1 (the kernel writes every covered pixel). Writing
      // the final images, only those (raw.g, raw.b unused).
      const std::uint32_t* id = g.object_id.data() + base;
      for (int x = t.x0; x < t.x1;) {
        if (id[x] != 0) {
          ++x;
          continue;
        }
        int e = x + 1;
        while (e < t.x1 && id[e] == 0) ++e;
        const std::size_t first = base + x, end = base + e;
        if (raw.final_rgb) {
          std::fill(raw.final_rgb + first, raw.final_rgb + end, Vec3{1, 1, 1});
          std::fill(raw.r + first, raw.r + end, luminance(Vec3{1, 1, 1}));
          std::fill(raw.o + first, raw.o + end, 1.0f);
        } else {
          for (float* plane : {raw.r, raw.g, raw.b, raw.o}) std::fill(plane + first, plane + end, 1.0f);
        }
        x = e;
      }
      simd::load_covered_pixels(row, g, y, t.x0, t.x1, rotations, params.bias, true);
      const simd::TransferOutputs o{raw.r, raw.g, raw.b, raw.o, raw.final_rgb};
      if constexpr (kDepthBuffer)
        simd::transfer_rays(row, simd_depth_plane(ch, params.layers), simd_points(s), m, far_limit, in, base + t.x0, o);
      else
        transfer_rays(row, ch, projection, s, m, far_limit, albedo, direct, params.albedo_scale, base + t.x0, o);
    }
  });
  if (!kernel_writes_final)
    finish_transfer(buffers, raw, g, filter, effective_depth_limit(params.interleave, falloff.radius), carried_depth_plane(ch));
  return buffers.result;
}

template <class Characteristic>
TransferImage transfer_ao(const GBuffer& g, const Characteristic& ch, const Image<Vec3>& indirect, const Falloff& falloff,
                          const TransferParams& params, std::uint32_t seed) {
  TransferBuffers buffers;
  transfer_ao(buffers, g, ch, indirect, falloff, params, seed);
  return std::move(buffers.result);
}

TransferImage transfer_ao(const GBuffer& g, const Falloff& falloff, const TransferParams& params, std::uint32_t seed) {
  return transfer_ao(g, depth_characteristic(g, params.layers, falloff.radius, "transfer"), g.albedo, falloff, params, seed);
}

const TransferImage& transfer_ao(TransferBuffers& buffers, const GBuffer& g, const Falloff& falloff, const TransferParams& params,
                                 std::uint32_t seed) {
  depth_plane(g, *buffers.depth);  // in the buffers' own pages: no fresh 4 bytes a pixel to fault in each frame
  return transfer_ao(buffers, g, depth_characteristic(g, params.layers, falloff.radius, "transfer", buffers.depth), g.albedo, falloff, params,
                     seed);
}

MethodOutput run(const MethodInput& in, const TransferParams& params) {
  MethodOutput out;
  detail::with_characteristic(in, params.characteristic, params.layers, "transfer", params.silhouette_elimination, in.falloff.radius,
                              [&](const auto& ch, bool kernel_elimination) {
                                TransferParams q = params;
                                q.silhouette_elimination = kernel_elimination;
                                TransferImage img;
                                if (in.cache) {  // the scratch images of the last call, reused
                                  TransferBuffers& buffers = in.cache->get<TransferBuffers>([] { return std::make_unique<TransferBuffers>(); },
                                                                                           [](const TransferBuffers&) { return true; });
                                  transfer_ao(buffers, in.gbuffer, ch, in.gbuffer.albedo, in.falloff, q, in.seed);
                                  img = std::move(buffers.result);
                                } else {
                                  img = transfer_ao(in.gbuffer, ch, in.gbuffer.albedo, in.falloff, q, in.seed);
                                }
                                out.visibility = std::move(img.luminance);
                                out.color = std::move(img.transfer);
                                out.extras["obscurance"] = std::move(img.obscurance);
                              });
  detail::add_characteristic_stats(out, params.characteristic, params.silhouette_elimination);
  return out;
}

void check_gpu(const TransferParams& params) { detail::check_gpu_screen_space("transfer", params.characteristic, params.layers); }

#define AO_INSTANTIATE_TRANSFER(Characteristic)                                                                                       \
  template TransferImage transfer_ao(const GBuffer&, const Characteristic&, const Image<Vec3>&, const Falloff&, const TransferParams&, \
                                     std::uint32_t);                                                                                  \
  template const TransferImage& transfer_ao(TransferBuffers&, const GBuffer&, const Characteristic&, const Image<Vec3>&,             \
                                            const Falloff&, const TransferParams&, std::uint32_t);
AO_INSTANTIATE_TRANSFER(DepthBufferCharacteristic)
AO_INSTANTIATE_TRANSFER(ImplicitCharacteristic)
AO_INSTANTIATE_TRANSFER(HeightFieldCharacteristic)
AO_INSTANTIATE_TRANSFER(DepthTimesHeightField)
AO_INSTANTIATE_TRANSFER(EliminatedDepthTimesHeightField)
#undef AO_INSTANTIATE_TRANSFER

}  // namespace ao
