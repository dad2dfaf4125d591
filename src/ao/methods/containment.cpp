#include "ao/methods/containment.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>

#include "ao/core/error.h"
#include "ao/core/parallel.h"
#include "ao/methods/characteristic.h"
#include "ao/methods/samples.h"
#include "ao/methods/screen_space_internal.h"

namespace ao {

namespace {
constexpr float kInfinityLike = 1e30f;  // below this a distance stands for -infinity (characteristic.h)
// Tiles of 128 x 16 pixels: a row segment of eight 16-lane vectors per sample loop, and few rows
// per tile; faster than 64 x 64 tiles in bench containment/0.
constexpr int kTileWidth = 128, kTileHeight = 16;
constexpr int kMaxRaySteps = 8;
}

const ParamTable<ContainmentParams>& containment_param_table() {
  using P = Param<ContainmentParams>;
  static const ParamTable<ContainmentParams> table{
      "containment",
      {{P::integer("samples", &ContainmentParams::samples, Range::closed(1, kMaxScreenSpaceSamples), "", "n in eq. 5: test points per pixel"),
        P::integer("ray_steps", &ContainmentParams::ray_steps, Range::closed(1, kMaxRaySteps), "",
                   "m: tests along each ray at (j/m) r, j = 1..m (AT sec. 4); 1 = eq. 5's end point only"),
        P::boolean("silhouette_elimination", &ContainmentParams::silhouette_elimination,
                   "AT 4.3: a point is occluded only if the surface in front of it is less than R in front"),
        P::real("bias", &ContainmentParams::bias, Range::at_least(0), "world units",
                "depth-test bias; 0 = auto (one pixel footprint x (1 + tan theta_v))")},
       interleave_params(&ContainmentParams::interleave)}};
  return table;
}

void ContainmentParams::validate() const { containment_param_table().validate(*this); }
void to_json(nlohmann::json& j, const ContainmentParams& p) { j = containment_param_table().to_json(p); }
void from_json(const nlohmann::json& j, ContainmentParams& p) { containment_param_table().from_json(j, p); }

void load_pixel_row_simd(PixelRow& row, std::vector<int>& index, const GBuffer& g, int y, int first, int last,
                         const std::array<Rotation, 16>& rotations, float bias_world, bool frame) {
  row.y = y;
  row.x0 = first;
  const auto n = static_cast<std::size_t>(last - first);
  for (std::vector<float>* v : {&row.px, &row.py, &row.pz, &row.nx, &row.ny, &row.nz, &row.rc, &row.rs, &row.bias}) v->resize(n);
  if (frame)
    for (std::vector<float>* v : {&row.tx, &row.ty, &row.tz, &row.bx, &row.by, &row.bz}) v->resize(n);
  row.covered.assign(n, 1);
  index.resize(n);
  // One pixel's footprint at unit depth: the image plane spans 2 tan(fov/2) over `height` pixels.
  const float footprint = 2.0f * g.camera.tan_half_fov() / static_cast<float>(g.height());
  float *px = row.px.data(), *py = row.py.data(), *pz = row.pz.data();
  float *nx = row.nx.data(), *ny = row.ny.data(), *nz = row.nz.data();
  float *rc = row.rc.data(), *rs = row.rs.data(), *bias = row.bias.data();
  int* idx = index.data();
  const Vec3* pos = &g.position(first, y);
  const Vec3* nrm = &g.normal(first, y);
  const std::uint32_t* id = &g.object_id(first, y);
  // Compaction: the covered pixels' offsets (scalar, branch-free), then their data gathered
  // across entries (vectorised). The row's rotations repeat every 4 pixels.
  int m = 0;
  for (int j = 0; j < last - first; ++j) {
    idx[m] = j;
    m += id[j] != 0 ? 1 : 0;
  }
  const Rotation* rot = rotations.data();
#pragma GCC ivdep
  for (int k = 0; k < m; ++k) {
    const int j = idx[k];
    const Vec3 p = pos[j], nn = nrm[j];
    const Rotation r = rot[(y & 3) * 4 + ((first + j) & 3)];
    px[k] = p.x, py[k] = p.y, pz[k] = p.z;
    nx[k] = nn.x, ny[k] = nn.y, nz[k] = nn.z;
    rc[k] = r.c, rs[k] = r.s;
  }
  row.count = m;
  // The auto bias, as PixelRow::load: tan theta_v from the normal and the unit view direction
  // (clamped to 8). Lane k reads and writes only entry k (GCC 12 ignores __restrict on locals and
  // would need too many run-time alias checks, hence ivdep).
  if (bias_world > 0) {
    std::fill(bias, bias + m, bias_world);
  } else {
#pragma GCC ivdep
    for (int k = 0; k < m; ++k) {
      const Vec3 p{px[k], py[k], pz[k]}, nn{nx[k], ny[k], nz[k]};
      const float len = std::sqrt(dot(p, p));
      const Vec3 u = len > 0 ? p / len : p;
      const float cos_v = std::max(std::abs(dot(nn, u)), 0.124f);
      const float tan_v = std::sqrt(1.0f - cos_v * cos_v) / cos_v;
      bias[k] = footprint * (-p.z) * (1.0f + tan_v);
    }
  }
  if (!frame) return;
  float *tx = row.tx.data(), *ty = row.ty.data(), *tz = row.tz.data();
  float *bx = row.bx.data(), *by = row.by.data(), *bz = row.bz.data();
#pragma GCC ivdep
  for (int k = 0; k < m; ++k) {
    const Frame f = Frame::from_normal({nx[k], ny[k], nz[k]});
    // Rotation by alpha about N (sec. 4.2): T' = cos a T + sin a B, B' = -sin a T + cos a B.
    const float rck = rc[k], rsk = rs[k];
    const Vec3 t = f.t * rck + f.b * rsk, b = f.b * rck - f.t * rsk;
    tx[k] = t.x, ty[k] = t.y, tz[k] = t.z;
    bx[k] = b.x, by[k] = b.y, bz[k] = b.z;
  }
}

template <class Characteristic>
Image<float> containment_ao(const GBuffer& g, const Characteristic& ch, const Falloff& falloff, const ContainmentParams& params,
                            std::uint32_t seed) {
  falloff.validate();
  params.validate();
  const int w = g.width(), h = g.height();
  const ContainmentSamples s = make_containment_samples(params.samples, falloff);
  const std::array<Rotation, 16> rotations = interleave_rotations(seed, params.interleave.interleave);
  // AT 4.3: a test point is occluded only if R > z - z* > 0, i.e. distance in (-R, -bias).
  const float far_limit = params.silhouette_elimination ? -falloff.radius : -kInfinity;
  const float inv_n = 1.0f / static_cast<float>(params.samples);
  const int m = params.ray_steps;
  const float inv_m = 1.0f / static_cast<float>(m);
  Image<float> v(w, h, 1.0f);
  parallel_for_tiles(w, h, kTileWidth, kTileHeight, [&](const Tile& t) {
    // A local copy: its members are then known not to alias the accumulators, so the loop vectorises.
    const Characteristic local_ch = ch;
    PixelRow row;
    std::vector<int> index;
    std::vector<float> open(static_cast<std::size_t>(t.x1 - t.x0)), blocked(static_cast<std::size_t>(t.x1 - t.x0));
    for (int y = t.y0; y < t.y1; ++y) {
      load_pixel_row_simd(row, index, g, y, t.x0, t.x1, rotations, params.bias, true);
      const int count = row.count;
      std::fill(open.begin(), open.end(), 0.0f);
      float* __restrict o = open.data();
      const float *px = row.px.data(), *py = row.py.data(), *pz = row.pz.data();
      const float *tx = row.tx.data(), *ty = row.ty.data(), *tz = row.tz.data();
      const float *bx = row.bx.data(), *by = row.by.data(), *bz = row.bz.data();
      const float *nx = row.nx.data(), *ny = row.ny.data(), *nz = row.nz.data();
      const float* bias = row.bias.data();
      for (int i = 0; i < s.size(); ++i) {
        const float X = s.x[static_cast<std::size_t>(i)], Y = s.y[static_cast<std::size_t>(i)], Z = s.z[static_cast<std::size_t>(i)];
        if (m == 1) {
          // Across the pixels of the row: SIMD lanes, one gather of the depth buffer per vector.
// Lane k writes only its own accumulator; the gathers read the (read-only) G-buffer.
#pragma GCC ivdep
          for (int k = 0; k < count; ++k) {
            // VAO eq. 5: p_i = x + X_i T + Y_i B + Z_i N.
            const float qx = px[k] + X * tx[k] + Y * bx[k] + Z * nx[k];
            const float qy = py[k] + X * ty[k] + Y * by[k] + Z * ny[k];
            const float qz = pz[k] + X * tz[k] + Y * bz[k] + Z * nz[k];
            const float d = local_ch.distance(qx, qy, qz);
            // AT 4.3; an analytic surface's -FLT_MAX ("inner along the whole line") is never a distant
            // foreground object, as in volumetric.cpp and transfer.cpp. The depth buffer never gives
            // it, and its loop keeps the plain form: with the extra test GCC 12 no longer vectorises
            // it (several times slower, bench containment/0).
            bool near = d > far_limit;
            if constexpr (!std::is_same_v<Characteristic, DepthBufferCharacteristic>) near = near | (d < -kInfinityLike);
            const bool occluded = (d < -bias[k]) & near;
            o[k] += occluded ? 0.0f : 1.0f;
          }
          continue;
        }
        // AT sec. 4: I = prod_j I0(x + w r j/m), the ray is free only if all m test points are.
        std::fill(blocked.begin(), blocked.end(), 0.0f);
        float* __restrict b = blocked.data();
        for (int j = 1; j <= m; ++j) {
          const float f = static_cast<float>(j) * inv_m;
          const float fX = f * X, fY = f * Y, fZ = f * Z;
#pragma GCC ivdep
          for (int k = 0; k < count; ++k) {
            const float qx = px[k] + fX * tx[k] + fY * bx[k] + fZ * nx[k];
            const float qy = py[k] + fX * ty[k] + fY * by[k] + fZ * ny[k];
            const float qz = pz[k] + fX * tz[k] + fY * bz[k] + fZ * nz[k];
            const float d = local_ch.distance(qx, qy, qz);
            bool near = d > far_limit;
            if constexpr (!std::is_same_v<Characteristic, DepthBufferCharacteristic>) near = near | (d < -kInfinityLike);
            const bool occluded = (d < -bias[k]) & near;
            b[k] = occluded ? 1.0f : b[k];
          }
        }
        for (int k = 0; k < count; ++k) o[k] += 1.0f - b[k];
      }
      for (int k = 0; k < count; ++k) v(t.x0 + index[static_cast<std::size_t>(k)], y) = o[k] * inv_n;
    }
  });
  if (params.interleave.interleave && params.interleave.filter)
    v = depth_aware_box_filter(v, g, effective_depth_limit(params.interleave, falloff.radius), carried_depth_plane(ch));
  return v;
}

Image<float> containment_ao(const GBuffer& g, const Falloff& falloff, const ContainmentParams& params, std::uint32_t seed) {
  return containment_ao(g, DepthBufferCharacteristic(g), falloff, params, seed);
}

template Image<float> containment_ao(const GBuffer&, const DepthBufferCharacteristic&, const Falloff&, const ContainmentParams&, std::uint32_t);
template Image<float> containment_ao(const GBuffer&, const ImplicitCharacteristic&, const Falloff&, const ContainmentParams&, std::uint32_t);
template Image<float> containment_ao(const GBuffer&, const HeightFieldCharacteristic&, const Falloff&, const ContainmentParams&, std::uint32_t);
template Image<float> containment_ao(const GBuffer&, const DepthTimesHeightField&, const Falloff&, const ContainmentParams&, std::uint32_t);
template Image<float> containment_ao(const GBuffer&, const EliminatedDepthTimesHeightField&, const Falloff&, const ContainmentParams&,
                                     std::uint32_t);

}  // namespace ao
