// SPDX-License-Identifier: Apache-2.0
#include "ao/registry/registry.h"

#include <array>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "ao/bake/high_to_low.h"
#include "ao/bake/histogram.h"
#include "ao/bake/raytraced_bake.h"
#include "ao/core/closest_name.h"
#include "ao/core/error.h"
#include "ao/core/params_table.h"
#include "ao/gbuffer/render_gbuffer.h"
#include "ao/reference/ray_scene.h"

namespace ao {

nlohmann::json MethodInfo::default_params() const { return params().defaults(); }

nlohmann::json MethodInfo::canonical_params(const nlohmann::json& overrides) const { return params().canonical(overrides); }

bool MethodInfo::has_extra(std::string_view extra) const {
  for (std::string_view e : extras)
    if (e == extra) return true;
  return false;
}

namespace {

template <auto Table>
const ParamSchema& schema() {
  static const ParamSchema s(Table());
  return s;
}

// A row's decode: `j` over the defaults through the table, checked, as the method's struct.
template <auto Table>
MethodParams decode(const nlohmann::json& j) {
  typename std::decay_t<decltype(Table())>::Struct p{};
  Table().from_json(j, p);
  p.validate();
  return p;
}

// ---- What judges each method, by its parameter struct ----

// Containment estimates the obscurance of the requested membership directly (eq. 5).
ReferenceSpec matched(const Falloff& requested, const ContainmentParams&) { return obscurance_reference(requested); }
// Volumetric AO's V is the free fraction of the tangent sphere of radius R/2 (eq. 6-7), whose
// ray-traced form is tangent_sphere.h; as an obscurance it implies mu = (r/R)^3 with the same R.
ReferenceSpec matched(const Falloff& requested, const VolumetricParams&) {
  return ReferenceSpec{ReferenceKind::TangentSphere, {Membership::Cubic, requested.radius}};
}
// W of eq. 9 estimates eq. 6 (transfer_reference.h) with the same membership and albedo scale; it
// approaches the obscurance of that membership as the albedo goes to 0. (Radiance mode's direct
// term is not in the reference: it would need the sun, which MethodInput does not carry.)
ReferenceSpec matched(const Falloff& requested, const TransferParams& p) { return ReferenceSpec{ReferenceKind::Transfer, requested, p.albedo_scale}; }
// Cone tracing estimates classical AO with R = R_max (sec. III-C): step membership, the user's R.
ReferenceSpec matched(const Falloff& requested, const ConeParams&) { return obscurance_reference({Membership::Step, requested.radius}); }
// Alchemy estimates classical obscurance, the paper's eq. 3 (A*_r: cosine-weighted visibility
// within r), judged at the scene's R like every other method: its own radius r (0 = R), like sigma,
// is a knob of the estimator, scored against the fixed reference, never moving it
// (docs/methods/alchemy.md).
ReferenceSpec matched(const Falloff& requested, const AlchemyParams&) { return obscurance_reference({Membership::Step, requested.radius}); }
// GTAO without the multi-bounce fit estimates the cosine-weighted visibility within R: step
// obscurance with the user's R (the membership asked for does not change what it computes). With
// the fit it estimates the ambient light after interreflections with a neighbourhood of the
// receiver's own albedo (Jimenez et al. 2016, sec. 5: the fit's ground truth gives the occluders
// the albedo of the point they surround), which the ray-traced ambient transfer W with the
// receiver's albedo computes (reference/transfer_reference.h, TransferAlbedo::Receiver), scored on
// its luminance. W with the occluders' own albedo stays available as `--reference transfer`.
ReferenceSpec matched(const Falloff& requested, const GtaoParams& p) {
  const Falloff step{Membership::Step, requested.radius};
  return p.multi_bounce ? ReferenceSpec{.kind = ReferenceKind::Transfer, .falloff = step, .albedo = TransferAlbedo::Receiver} : obscurance_reference(step);
}
ReferenceSpec matched(const Falloff& requested, const RaytracedMethodParams& p) { return ReferenceSpec{p.reference, requested}; }

Falloff obscurance_of(const Falloff& requested, const VolumetricParams&) { return {Membership::Cubic, requested.radius}; }
Falloff obscurance_of(const Falloff& requested, const ConeParams&) { return {Membership::Step, requested.radius}; }
Falloff obscurance_of(const Falloff& requested, const GtaoParams&) { return {Membership::Step, requested.radius}; }
Falloff obscurance_of(const Falloff& requested, const AlchemyParams&) { return {Membership::Step, requested.radius}; }
// Containment, transfer and the ray-traced reference: the requested obscurance.
template <class P>
Falloff obscurance_of(const Falloff& requested, const P&) {
  return requested;
}

// Each method's table, by its parameter struct.
const ParamTable<RaytracedMethodParams>& table_of(const RaytracedMethodParams&) { return raytraced_method_param_table(); }
const ParamTable<ContainmentParams>& table_of(const ContainmentParams&) { return containment_param_table(); }
const ParamTable<VolumetricParams>& table_of(const VolumetricParams&) { return volumetric_param_table(); }
const ParamTable<TransferParams>& table_of(const TransferParams&) { return transfer_param_table(); }
const ParamTable<ConeParams>& table_of(const ConeParams&) { return cone_param_table(); }
const ParamTable<AlchemyParams>& table_of(const AlchemyParams&) { return alchemy_param_table(); }
const ParamTable<GtaoParams>& table_of(const GtaoParams&) { return gtao_param_table(); }

ConeParams resolved(const ConeParams& p) { return p.resolved(); }
AlchemyParams resolved(AlchemyParams p) {
  p.intensity = p.effective_intensity();
  return p;
}
template <class P>
P resolved(const P& p) {
  return p;
}

constexpr std::array<std::string_view, 1> kReferenceQuantity{kReferenceParam};
constexpr std::array<std::string_view, 1> kAlbedoScaleQuantity{"albedo_scale"};
constexpr std::array<std::string_view, 1> kMultiBounceQuantity{"multi_bounce"};
constexpr std::array<std::string_view, 1> kObscuranceExtra{"obscurance"};
constexpr std::array<std::string_view, 1> kUnfilteredExtra{"unfiltered"};

const std::array kMethods{
    MethodInfo{.name = "raytraced",
               .summary = "ground truth with Embree rays: obscurance of any membership (-p reference=obscurance), the tangent sphere's visible "
                          "fraction (tangent-sphere) or ambient transfer W (transfer)",
               .ground_truth = true,
               .needs_scene = true,
               .extras = kObscuranceExtra,  // with reference=transfer: O from the same rays
               .quantity_params = kReferenceQuantity,
               .samples_param = "samples",
               .target_error_param = "target_error",
               .params = schema<raytraced_method_param_table>,
               .decode = decode<raytraced_method_param_table>},
    MethodInfo{.name = "containment",
               .summary = "containment tests against the depth buffer, r = mu^-1(xi) (volumetric AO eq. 5), any membership",
               .takes_characteristic = true,
               .gpu = true,
               .samples_param = "samples",
               .params = schema<containment_param_table>,
               .decode = decode<containment_param_table>},
    MethodInfo{.name = "volumetric",
               .summary = "free volume of the tangent sphere by pipes along z (volumetric AO eq. 6-7); implies cubic membership",
               .takes_characteristic = true,
               .gpu = true,
               .samples_param = "samples",
               .params = schema<volumetric_param_table>,
               .decode = decode<volumetric_param_table>},
    MethodInfo{.name = "transfer",
               .summary = "ambient transfer W: obscurance plus nearby bounces, RGB (ambient transfer eq. 9); extra: obscurance; "
                          "-p reflectance=radiance adds the light of sunlit occluders (needs --sun)",
               .takes_characteristic = true,
               .cached = true,
               .gpu = true,
               .extras = kObscuranceExtra,
               .quantity_params = kAlbedoScaleQuantity,
               .samples_param = "samples",
               .params = schema<transfer_param_table>,
               .decode = decode<transfer_param_table>},
    MethodInfo{.name = "cone",
               .summary = "voxel cone tracing: parity voxelization in bit columns, cones of spheres, prisms by popcount (Dalla Favera & Celes)",
               .needs_scene = true,
               .cached = true,
               .gpu = true,
               .params = schema<cone_param_table>,
               .decode = decode<cone_param_table>},
    MethodInfo{.name = "alchemy",
               .summary = "Alchemy AO: screen-space disk samples, eq. 10 (sigma, k, beta, epsilon, r, s) + 13-tap cross-bilateral filter",
               .gpu = true,
               .extras = kUnfilteredExtra,
               .samples_param = "samples",
               .params = schema<alchemy_param_table>,
               .decode = decode<alchemy_param_table>},
    MethodInfo{.name = "gtao",
               .summary = "GTAO (Jimenez et al. 2016): horizons in screen-space slices, analytic cosine-weighted inner integral, 4x4 denoise; "
                          "-p multi_bounce=true adds its multi-bounce fit",
               .gpu = true,
               .quantity_params = kMultiBounceQuantity,
               .params = schema<gtao_param_table>,
               .decode = decode<gtao_param_table>},
};
static_assert(kMethods.size() == std::variant_size_v<MethodParams>, "a row per alternative of MethodParams, in its order");

constexpr std::array kBakerTables{
    ParamTableInfo{"bake-raytraced", schema<raytraced_bake_param_table>},
    ParamTableInfo{"bake-histogram", schema<histogram_param_table>},
    ParamTableInfo{"bake-high-to-low", schema<high_to_low_param_table>},
};

}  // namespace

std::span<const ParamTableInfo> all_param_tables() {
  static const std::vector<ParamTableInfo> tables = [] {
    std::vector<ParamTableInfo> t;
    for (const MethodInfo& m : kMethods) t.push_back({m.name, m.params});
    t.insert(t.end(), kBakerTables.begin(), kBakerTables.end());
    return t;
  }();
  return tables;
}

const ParamSchema& find_param_table(std::string_view name) {
  std::string names;
  for (const ParamTableInfo& t : all_param_tables()) {
    if (t.name == name) return t.schema();
    names += (names.empty() ? "" : ", ") + std::string(t.name);
  }
  throw InputError("no parameter table '" + std::string(name) + "' (known: " + names + ")" + did_you_mean(name, names));
}

std::span<const MethodInfo> all_methods() { return kMethods; }


ReferenceSpec choose_reference(std::string_view name, const Falloff& requested, const MethodParams& params) {
  if (name == kMatchedReference) return matched_reference(requested, params);
  const Falloff f = obscurance_falloff(requested, params);
  const std::optional<ReferenceKind> kind = parse_reference_kind(name);
  if (!kind)
    throw InputError("unknown reference '" + std::string(name) + "' for " + std::string(method_of(params).name) + " (known: " + kMatchedReference +
                     ", " + reference_kind_names() + ")" + did_you_mean(name, std::string(kMatchedReference) + ", " + reference_kind_names()));
  switch (*kind) {
    case ReferenceKind::TangentSphere: return {ReferenceKind::TangentSphere, {Membership::Cubic, f.radius}};
    case ReferenceKind::Transfer: {
      // The occluders' albedo scale of a method whose own reference is ambient transfer, else 1.
      const ReferenceSpec m = matched_reference(requested, params);
      return {ReferenceKind::Transfer, f, m.kind == ReferenceKind::Transfer ? m.albedo_scale : 1.0f};
    }
    default: return obscurance_reference(f);
  }
}

const MethodInfo& method_of(const MethodParams& params) { return kMethods[params.index()]; }

nlohmann::json params_json(const MethodParams& params) {
  return std::visit([](const auto& p) { return table_of(p).to_json(p); }, params);
}

MethodOutput run_method(const MethodInput& in, const MethodParams& params) {
  MethodInput full = in;
  if (in.rays && !full.scene) full.scene = &in.rays->scene();
  if (in.rays && !full.trace_second_layer)
    full.trace_second_layer = [&in](float separation) { return render_second_layer_depth(*in.rays, in.gbuffer, separation); };
  return std::visit([&](const auto& p) { return run(full, p); }, params);
}

ReferenceSpec matched_reference(const Falloff& requested, const MethodParams& params) {
  return std::visit([&](const auto& p) { return matched(requested, p); }, params);
}

Falloff obscurance_falloff(const Falloff& requested, const MethodParams& params) {
  return std::visit([&](const auto& p) { return obscurance_of(requested, p); }, params);
}

bool reads_direct_light(const MethodParams& params) {
  const auto* t = std::get_if<TransferParams>(&params);
  return t && t->reflectance == TransferReflectance::Radiance;
}

MethodParams with_presets_resolved(const MethodParams& params) {
  return std::visit([](const auto& p) { return MethodParams(resolved(p)); }, params);
}

MethodMemory extra_memory(const MethodParams& params) {
  const auto* c = std::get_if<ConeParams>(&params);
  return c ? memory(*c) : MethodMemory{};
}

void check_gpu_method(const MethodParams& params) {
  const MethodInfo& m = method_of(params);
  if (!m.gpu) {
    std::string names;
    for (const MethodInfo& g : kMethods)
      if (g.gpu) names += (names.empty() ? "" : ", ") + std::string(g.name);
    throw InputError("method " + std::string(m.name) + " runs on the CPU only (--device cpu); the GPU runs " + names);
  }
  std::visit([](const auto& p) {
    if constexpr (requires { ao::check_gpu(p); }) ao::check_gpu(p);
  }, params);
}

const MethodInfo& find_method(std::string_view name) {
  std::string names;
  for (const MethodInfo& m : kMethods) {
    if (m.name == name) return m;
    names += (names.empty() ? "" : ", ") + std::string(m.name);
  }
  throw InputError("unknown method '" + std::string(name) + "' (known: " + names + ")" + did_you_mean(name, names));
}

const MethodInfo& ground_truth_method() {
  for (const MethodInfo& m : kMethods)
    if (m.ground_truth) return m;
  throw std::logic_error("the registry has no ground-truth method");
}

}  // namespace ao
