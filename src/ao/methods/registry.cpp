#include "ao/methods/registry.h"

#include <algorithm>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "ao/core/error.h"
#include "ao/methods/alchemy.h"
#include "ao/methods/characteristic.h"
#include "ao/methods/cone.h"
#include "ao/methods/containment.h"
#include "ao/methods/gtao.h"
#include "ao/methods/transfer.h"
#include "ao/methods/transfer_internal.h"
#include "ao/methods/volumetric.h"
#include "ao/reference/raytraced.h"
#include "ao/reference/reference.h"
#include "ao/scene/procedural.h"

namespace ao {

namespace {

// The reference kind raytraced renders (kReferenceParam), taken off `j` so that the rest goes to
// RaytracedParams' from_json, which rejects unknown keys; absent means obscurance.
ReferenceKind take_reference_kind(nlohmann::json& j) {
  if (!j.is_object() || !j.contains(kReferenceParam)) return ReferenceKind::Obscurance;
  const nlohmann::json value = j.at(kReferenceParam);
  j.erase(kReferenceParam);
  if (value.is_string())
    if (const auto kind = parse_reference_kind(value.get<std::string>())) return *kind;
  throw InputError("raytraced: reference must be one of " + reference_kind_names() + ", got " + value.dump());
}

MethodOutput run_raytraced(const MethodInput& in, const nlohmann::json& j) {
  if (!in.scene)
    throw InputError("method raytraced traces rays in the scene, and a G-buffer file has none: give a scene instead of --gbuffer-in");
  nlohmann::json rest = j;
  const ReferenceKind kind = take_reference_kind(rest);
  RaytracedParams p = rest.get<RaytracedParams>();
  p.validate();
  ReferenceImage img = render_reference(*in.scene, in.gbuffer, {kind, in.falloff}, p, in.seed, in.progress);
  MethodOutput out;
  out.visibility = std::move(img.scalar.visibility);
  if (!img.color.empty()) out.color = std::move(img.color);
  if (!img.obscurance.empty()) out.extras["obscurance"] = std::move(img.obscurance);
  out.stats = {{"rays", img.scalar.rays}, {"mean_std_error", img.scalar.mean_std_error}, {"max_std_error", img.scalar.max_std_error}};
  return out;
}

nlohmann::json raytraced_defaults() {
  nlohmann::json j = RaytracedParams{};
  j[kReferenceParam] = to_string(ReferenceKind::Obscurance);
  return j;
}

// The occluders' albedo scale a method's parameters carry (transfer's albedo_scale), else 1.
float albedo_scale_of(const nlohmann::json& params) {
  return params.is_object() && params.contains("albedo_scale") && params.at("albedo_scale").is_number() ? params.at("albedo_scale").get<float>()
                                                                                                       : 1.0f;
}

Falloff requested_falloff(const Falloff& requested, const nlohmann::json&) { return requested; }

// The characteristic functions a screen-space method can run with (registry.h,
// kCharacteristicParam), in the order of characteristic_names().
enum class CharacteristicKind { Depth, Implicit, HeightField, DepthTimesHeightField };
constexpr std::array<std::string_view, 4> kCharacteristicNames{"depth", "implicit", "height-field", "depth*height-field"};

std::string joined_names(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

// A screen-space method's default parameters: its Params plus the registry's characteristic choice.
template <class Params>
nlohmann::json screen_space_defaults() {
  nlohmann::json j = Params{};
  j[kCharacteristicParam] = kCharacteristicNames[0];
  return j;
}

// A screen-space method's parameters: its table's, then the registry's characteristic choice.
template <auto Table>
std::vector<ParamSpec> screen_space_specs() {
  std::vector<ParamSpec> s = Table().specs();
  ParamSpec c;
  c.name = kCharacteristicParam;
  c.type = ParamType::Enum;
  for (std::string_view n : kCharacteristicNames) c.enum_names.emplace_back(n);
  c.help = "the characteristic function I(p): depth buffer, the scene's implicit surface or height field, or depth x height field";
  c.default_value = kCharacteristicNames[0];
  s.push_back(c);
  return s;
}
template <auto Table>
std::vector<ParamSpec> table_specs() {
  return Table().specs();
}

// Splits the characteristic choice off `j` (what remains goes to the method's from_json, which
// rejects unknown keys) and returns it; absent means the depth buffer.
CharacteristicKind take_characteristic(nlohmann::json& j, std::string_view method) {
  if (!j.is_object() || !j.contains(kCharacteristicParam)) return CharacteristicKind::Depth;
  const nlohmann::json value = j.at(kCharacteristicParam);
  j.erase(kCharacteristicParam);
  std::string names;
  for (std::string_view n : kCharacteristicNames) names += (names.empty() ? "" : ", ") + std::string(n);
  if (value.is_string())
    for (std::size_t k = 0; k < kCharacteristicNames.size(); ++k)
      if (value.get<std::string>() == kCharacteristicNames[k]) return static_cast<CharacteristicKind>(k);
  throw InputError(std::string(method) + ": characteristic must be one of " + names + ", got " + value.dump());
}

// The registry-level key a method's parameter object carries besides its table's.
enum class Extra { None, Characteristic, Reference };

// `j` read into Params, validated and written back; the registry-level key (characteristic of the
// screen-space methods, reference of raytraced) is checked and kept.
template <auto Table, Extra kExtra>
nlohmann::json canonical(const nlohmann::json& j) {
  using Params = typename std::decay_t<decltype(Table())>::Struct;
  nlohmann::json rest = j;
  nlohmann::json extra;
  if (kExtra == Extra::Characteristic) {
    extra = j.is_object() && j.contains(kCharacteristicParam) ? j.at(kCharacteristicParam) : nlohmann::json(kCharacteristicNames[0]);
    take_characteristic(rest, Table().owner());  // refuses an unknown name, and removes the key
  }
  if (kExtra == Extra::Reference) extra = to_string(take_reference_kind(rest));
  Params p = rest.get<Params>();
  p.validate();
  nlohmann::json out = p;
  if (kExtra == Extra::Characteristic) out[kCharacteristicParam] = extra;
  if (kExtra == Extra::Reference) out[kReferenceParam] = extra;
  return out;
}

// raytraced's parameters: its table's, then the registry's reference choice.
std::vector<ParamSpec> raytraced_specs() {
  std::vector<ParamSpec> s = raytraced_param_table().specs();
  ParamSpec r;
  r.name = kReferenceParam;
  r.type = ParamType::Enum;
  const std::string names = reference_kind_names();
  for (std::size_t start = 0; start <= names.size();) {
    const std::size_t end = std::min(names.find(", ", start), names.size());
    r.enum_names.push_back(names.substr(start, end - start));
    start = end + 2;
  }
  r.help = "which reference to render: obscurance, the tangent sphere's visible fraction, or ambient transfer W";
  r.default_value = to_string(ReferenceKind::Obscurance);
  s.push_back(r);
  return s;
}

// Builds the characteristic function of `kind` in the G-buffer's camera space and calls
// fn(ch, kernel_elimination): whether the kernel's own silhouette elimination (AT 4.3) is to run.
// `elimination` is the user's silhouette_elimination; `limit` the distance in front of a sample
// point beyond which the depth-buffer factor of the product counts as a distant foreground object.
template <class Fn>
void with_characteristic(const MethodInput& in, CharacteristicKind kind, std::string_view method, bool elimination, float limit, Fn&& fn) {
  const GBuffer& g = in.gbuffer;
  if (kind == CharacteristicKind::Depth) return fn(DepthBufferCharacteristic(g), elimination);
  const bool implicit = kind == CharacteristicKind::Implicit;
  const std::string name(kCharacteristicNames[static_cast<std::size_t>(kind)]);
  const std::string builtins = joined_names(implicit ? builtin_scenes_with_implicit_surface() : builtin_scenes_with_height_field());
  const std::string what = implicit ? "implicit surface" : "height field";
  if (!in.surfaces)
    throw InputError(std::string(method) + ": characteristic " + name + " reads the scene's " + what +
                     ", and a G-buffer file has none: give a built-in scene that has one (" + builtins + ") instead of --gbuffer-in");
  if (implicit ? !in.surfaces->implicit : !in.surfaces->height_field)
    throw InputError(std::string(method) + ": characteristic " + name + " needs a scene with an analytic " + what + ", and " +
                     (in.scene ? "'" + in.scene->scene().name + "'" : std::string("this scene")) + " has none (built-in scenes with one: " +
                     builtins + ")");
  // Analytic factors: their inner regions are solid, so the kernels' elimination stays off for them.
  switch (kind) {
    case CharacteristicKind::Implicit: return fn(implicit_characteristic(*in.surfaces->implicit, g.camera), false);
    case CharacteristicKind::HeightField: return fn(height_field_characteristic(*in.surfaces->height_field, g.camera), false);
    default: {
      const EliminatedDepthTimesHeightField product{{DepthBufferCharacteristic(g), elimination ? limit : kInfinity},
                                                    height_field_characteristic(*in.surfaces->height_field, g.camera)};
      return fn(product, false);
    }
  }
}

// What --json reports about the characteristic function a method ran with (nothing for the default).
void add_characteristic_stats(MethodOutput& out, CharacteristicKind kind, bool elimination) {
  if (kind == CharacteristicKind::Depth) return;
  out.stats[kCharacteristicParam] = kCharacteristicNames[static_cast<std::size_t>(kind)];
  out.stats["silhouette_elimination"] = kind == CharacteristicKind::DepthTimesHeightField && elimination ? "depth-buffer factor only" : "off";
}

MethodOutput run_containment(const MethodInput& in, const nlohmann::json& j) {
  nlohmann::json rest = j;
  const CharacteristicKind kind = take_characteristic(rest, "containment");
  const ContainmentParams p = rest.get<ContainmentParams>();
  MethodOutput out;
  // AT 4.3 tests the sample point itself: a surface more than R in front of it is distant.
  with_characteristic(in, kind, "containment", p.silhouette_elimination, in.falloff.radius, [&](const auto& ch, bool kernel_elimination) {
    ContainmentParams q = p;
    q.silhouette_elimination = kernel_elimination;
    out.visibility = containment_ao(in.gbuffer, ch, in.falloff, q, in.seed);
  });
  add_characteristic_stats(out, kind, p.silhouette_elimination);
  return out;
}

MethodOutput run_volumetric(const MethodInput& in, const nlohmann::json& j) {
  nlohmann::json rest = j;
  const CharacteristicKind kind = take_characteristic(rest, "volumetric");
  const VolumetricParams p = rest.get<VolumetricParams>();
  MethodOutput out;
  // The kernel eliminates a surface more than R in front of a pipe's entry, which lies up to R/2 in
  // front of the sphere's centre, where the characteristic is read: a depth-buffer surface more than
  // 1.5 R in front of the centre is distant for every pipe, so the wrapped factor never drops a
  // surface the kernel's per-pipe test would keep.
  with_characteristic(in, kind, "volumetric", p.silhouette_elimination, 1.5f * in.falloff.radius, [&](const auto& ch, bool kernel_elimination) {
    VolumetricParams q = p;
    q.silhouette_elimination = kernel_elimination;
    out.visibility = volumetric_ao(in.gbuffer, ch, in.falloff.radius, q, in.seed);
  });
  add_characteristic_stats(out, kind, p.silhouette_elimination);
  return out;
}

MethodOutput run_transfer(const MethodInput& in, const nlohmann::json& j) {
  nlohmann::json rest = j;
  const CharacteristicKind kind = take_characteristic(rest, "transfer");
  const TransferParams p = rest.get<TransferParams>();
  MethodOutput out;
  with_characteristic(in, kind, "transfer", p.silhouette_elimination, in.falloff.radius, [&](const auto& ch, bool kernel_elimination) {
    TransferParams q = p;
    q.silhouette_elimination = kernel_elimination;
    TransferImage img;
    if (in.cache) {  // the scratch images of the last call, reused
      TransferBuffers& buffers = in.cache->entry<TransferBuffers>("transfer");
      transfer_ao(buffers, in.gbuffer, ch, in.gbuffer.albedo, in.falloff, q, in.seed);
      img = std::move(buffers.result);
    } else {
      img = transfer_ao(in.gbuffer, ch, in.gbuffer.albedo, in.falloff, q, in.seed);
    }
    out.visibility = std::move(img.luminance);
    out.color = std::move(img.transfer);
    out.extras["obscurance"] = std::move(img.obscurance);
  });
  add_characteristic_stats(out, kind, p.silhouette_elimination);
  return out;
}

MethodOutput run_cone(const MethodInput& in, const nlohmann::json& j) {
  if (!in.scene) throw InputError("method cone voxelizes the scene, and a G-buffer file has none: give a scene instead of --gbuffer-in");
  const ConeParams p = j.get<ConeParams>();
  ConeResult r;
  if (in.cache) {
    const Scene& scene = in.scene->scene();
    ConeContext* context = &in.cache->entry<ConeContext>("cone", scene);
    if (&context->scene() != &scene) context = &in.cache->replace<ConeContext>("cone", scene);
    r = context->render(in.gbuffer, in.falloff.radius, p, in.seed, in.progress);
  } else {
    const std::vector<MeshClosure> closure = analyze_closure(in.scene->scene());
    r = render_cone(in.scene->scene(), closure, in.gbuffer, in.falloff.radius, p, in.seed, in.progress);
  }
  MethodOutput out;
  out.stats = cone_stats(r);
  out.visibility = std::move(r.visibility);
  return out;
}

MethodOutput run_alchemy(const MethodInput& in, const nlohmann::json& j) {
  const AlchemyParams p = j.get<AlchemyParams>();
  AlchemyImage img = render_alchemy(in.gbuffer, p, in.falloff.radius, in.seed, in.progress);
  MethodOutput out;
  out.visibility = std::move(img.visibility);
  if (!img.unfiltered.empty()) out.extras["unfiltered"] = std::move(img.unfiltered);
  out.stats = {{"estimator_ms", img.estimator_ms}, {"filter_ms", img.filter_ms}};
  return out;
}

MethodOutput run_gtao(const MethodInput& in, const nlohmann::json& j) {
  const GtaoParams p = j.get<GtaoParams>();
  GtaoImage img = gtao_ao(in.gbuffer, in.falloff.radius, p, in.seed);
  MethodOutput out;
  out.visibility = std::move(img.visibility);
  out.color = std::move(img.color);
  return out;
}

const std::array kMethods{
    MethodInfo{"raytraced",
               "ground truth with Embree rays: obscurance of any membership (-p reference=obscurance), the tangent sphere's visible "
               "fraction (tangent-sphere) or ambient transfer W (transfer)",
               true, raytraced_defaults, run_raytraced,
               [](const Falloff& requested, const nlohmann::json& params) {
                 nlohmann::json rest = params;
                 return ReferenceSpec{take_reference_kind(rest), requested};
               },
               requested_falloff, raytraced_specs, canonical<raytraced_param_table, Extra::Reference>},
    // Containment estimates the obscurance of the requested membership directly (eq. 5).
    MethodInfo{"containment", "containment tests against the depth buffer, r = mu^-1(xi) (volumetric AO eq. 5), any membership", false,
               screen_space_defaults<ContainmentParams>, run_containment,
               [](const Falloff& requested, const nlohmann::json&) { return obscurance_reference(requested); }, requested_falloff,
               screen_space_specs<containment_param_table>, canonical<containment_param_table, Extra::Characteristic>},
    // Volumetric AO's V is the free fraction of the tangent sphere of radius R/2 (eq. 6-7), whose
    // ray-traced form is tangent_sphere.h. As an obscurance it implies mu = (r/R)^3 with the same R.
    MethodInfo{"volumetric", "free volume of the tangent sphere by pipes along z (volumetric AO eq. 6-7); implies cubic membership", false,
               screen_space_defaults<VolumetricParams>, run_volumetric,
               [](const Falloff& requested, const nlohmann::json&) {
                 return ReferenceSpec{ReferenceKind::TangentSphere, {Membership::Cubic, requested.radius}};
               },
               [](const Falloff& requested, const nlohmann::json&) { return Falloff{Membership::Cubic, requested.radius}; },
               screen_space_specs<volumetric_param_table>, canonical<volumetric_param_table, Extra::Characteristic>},
    // W of eq. 9 estimates eq. 6 (transfer_reference.h) with the same membership and albedo scale;
    // it approaches the obscurance of that membership as the albedo goes to 0. (Radiance mode's
    // direct term is not in the reference: it would need the sun, which MethodInput does not carry.)
    MethodInfo{"transfer",
               "ambient transfer W: obscurance plus nearby bounces, RGB (ambient transfer eq. 9); extra: obscurance; "
               "-p reflectance=radiance adds the light of sunlit occluders (needs --sun)",
               false, screen_space_defaults<TransferParams>, run_transfer,
               [](const Falloff& requested, const nlohmann::json& params) {
                 return ReferenceSpec{ReferenceKind::Transfer, requested, albedo_scale_of(params)};
               },
               requested_falloff, screen_space_specs<transfer_param_table>, canonical<transfer_param_table, Extra::Characteristic>},
    // Cone tracing estimates classical AO with R = R_max (sec. III-C): step membership, the user's R.
    MethodInfo{"cone", "voxel cone tracing: parity voxelization in bit columns, cones of spheres, prisms by popcount (Dalla Favera & Celes)", true,
               [] { return nlohmann::json(ConeParams{}); }, run_cone,
               [](const Falloff& requested, const nlohmann::json&) { return obscurance_reference({Membership::Step, requested.radius}); },
               [](const Falloff& requested, const nlohmann::json&) { return Falloff{Membership::Step, requested.radius}; },
               table_specs<cone_param_table>, canonical<cone_param_table, Extra::None>},
    // Alchemy approximates obscurance with its own falloff u/t (u = sigma in world units), radius r;
    // with preset=paper (u = 2r >= r) that falloff is exactly step AO; at the fitted default sigma
    // (u = 0.8 r) it is not, and obscurance_reference labels it as Alchemy's own (docs/methods/alchemy.md).
    MethodInfo{"alchemy", "Alchemy AO: screen-space disk samples, eq. 10 (sigma, k, beta, epsilon, r, s) + 13-tap cross-bilateral filter", false,
               [] { return nlohmann::json(AlchemyParams{}); }, run_alchemy,
               [](const Falloff& requested, const nlohmann::json& params) {
                 return obscurance_reference(alchemy_reference_falloff(params.get<AlchemyParams>(), requested.radius));
               },
               [](const Falloff& requested, const nlohmann::json& params) {
                 return alchemy_reference_falloff(params.get<AlchemyParams>(), requested.radius);
               },
               table_specs<alchemy_param_table>, canonical<alchemy_param_table, Extra::None>},
    // GTAO with a radius cut estimates the cosine-weighted visibility within R: step obscurance with
    // the user's R (the membership asked for does not change what it computes).
    MethodInfo{"gtao",
               "GTAO (Jimenez et al. 2016): horizons in screen-space slices, analytic cosine-weighted inner integral, 4x4 denoise; "
               "-p multi_bounce=true adds its multi-bounce fit",
               false, [] { return nlohmann::json(GtaoParams{}); }, run_gtao,
               [](const Falloff& requested, const nlohmann::json&) { return obscurance_reference({Membership::Step, requested.radius}); },
               [](const Falloff& requested, const nlohmann::json&) { return Falloff{Membership::Step, requested.radius}; },
               table_specs<gtao_param_table>, canonical<gtao_param_table, Extra::None>},
};

}  // namespace

std::span<const MethodInfo> all_methods() { return kMethods; }

std::span<const std::string_view> characteristic_names() { return kCharacteristicNames; }

ReferenceSpec choose_reference(const MethodInfo& m, std::string_view name, const Falloff& requested, const nlohmann::json& params) {
  if (name == kMatchedReference) return m.reference(requested, params);
  const Falloff f = m.obscurance_falloff(requested, params);
  const std::optional<ReferenceKind> kind = parse_reference_kind(name);
  if (!kind)
    throw InputError("unknown reference '" + std::string(name) + "' for " + std::string(m.name) + " (known: " + kMatchedReference + ", " +
                     reference_kind_names() + ")");
  switch (*kind) {
    case ReferenceKind::TangentSphere: return {ReferenceKind::TangentSphere, {Membership::Cubic, f.radius}};
    case ReferenceKind::Transfer: return {ReferenceKind::Transfer, f, albedo_scale_of(params)};
    default: return obscurance_reference(f);
  }
}

const MethodInfo& find_method(std::string_view name) {
  std::string names;
  for (const MethodInfo& m : kMethods) {
    if (m.name == name) return m;
    names += (names.empty() ? "" : ", ") + std::string(m.name);
  }
  throw InputError("unknown method '" + std::string(name) + "' (known: " + names + ")");
}

}  // namespace ao
