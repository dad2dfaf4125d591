#include "ao/registry/registry.h"

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "ao/bake/high_to_low.h"
#include "ao/bake/histogram.h"
#include "ao/bake/raytraced_bake.h"
#include "ao/core/error.h"
#include "ao/core/memory.h"
#include "ao/gbuffer/render_gbuffer.h"
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

MethodCache::MethodCache() = default;
MethodCache::~MethodCache() = default;
MethodCache::MethodCache(MethodCache&&) noexcept = default;
MethodCache& MethodCache::operator=(MethodCache&&) noexcept = default;

ConeContext& MethodCache::cone(const Scene& scene) {
  if (!cone_ || &cone_->scene() != &scene) cone_ = std::make_unique<ConeContext>(scene);
  return *cone_;
}

TransferBuffers& MethodCache::transfer() {
  if (!transfer_) transfer_ = std::make_unique<TransferBuffers>();
  return *transfer_;
}

bool MethodInfo::has_extra(std::string_view extra) const {
  for (std::string_view e : extras)
    if (e == extra) return true;
  return false;
}

namespace {

constexpr std::array<std::string_view, 4> kCharacteristicNames{"depth", "implicit", "height-field", "depth*height-field"};

// ---- Parameter objects that extend a method's Params with the registry's own choice ----

// Containment, volumetric and transfer: their Params plus the characteristic function.
template <class P>
struct ScreenSpaceParams {
  P method;
  CharacteristicKind characteristic = CharacteristicKind::Depth;
  void validate() const { method.validate(); }
};

template <class P>
std::vector<Param<ScreenSpaceParams<P>>> characteristic_row() {
  std::vector<std::pair<std::string, CharacteristicKind>> names;
  for (std::size_t k = 0; k < kCharacteristicNames.size(); ++k) names.emplace_back(kCharacteristicNames[k], static_cast<CharacteristicKind>(k));
  return {Param<ScreenSpaceParams<P>>::enumeration(
      kCharacteristicParam, &ScreenSpaceParams<P>::characteristic, std::move(names),
      "the characteristic function I(p): depth buffer, the scene's implicit surface or height field, or depth x height field")};
}

// The method's table, then the characteristic.
template <auto Table>
const auto& screen_space_table() {
  using P = typename std::decay_t<decltype(Table())>::Struct;
  using W = ScreenSpaceParams<P>;
  static const ParamTable<W> table{Table().owner(), {nested_params<W>(Table(), &W::method), characteristic_row<P>()}};
  return table;
}

// raytraced: its RaytracedParams plus the kind of reference it renders.
struct RaytracedMethodParams {
  RaytracedParams rays;
  ReferenceKind reference = ReferenceKind::Obscurance;
  void validate() const { rays.validate(); }
};

const ParamTable<RaytracedMethodParams>& raytraced_method_table() {
  using W = RaytracedMethodParams;
  std::vector<std::pair<std::string, ReferenceKind>> kinds;
  for (ReferenceKind k : {ReferenceKind::Obscurance, ReferenceKind::TangentSphere, ReferenceKind::Transfer}) kinds.emplace_back(to_string(k), k);
  static const ParamTable<W> table{
      raytraced_param_table().owner(),
      {nested_params<W>(raytraced_param_table(), &W::rays),
       {Param<W>::enumeration(kReferenceParam, &W::reference, std::move(kinds),
                              "which reference to render: obscurance, the tangent sphere's visible fraction, or ambient transfer W")}}};
  return table;
}

// The struct a table describes, read from canonical (or any accepted) JSON.
template <class P>
P parse(const ParamTable<P>& table, const nlohmann::json& j) {
  P p{};
  table.from_json(j, p);
  p.validate();
  return p;
}

template <auto Table>
const ParamSchema& schema() {
  static const ParamSchema s(Table());
  return s;
}

// ---- Characteristic functions ----

std::string joined_names(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

// The second depth layer a method run with `layers` = 2 reads: the G-buffer's own when it has one
// at the separation in effect, else rendered from the scene for this run.
std::shared_ptr<const Image<float>> second_layer_for(const MethodInput& in, float separation, std::string_view method) {
  const GBuffer& g = in.gbuffer;
  if (has_second_layer(g, separation)) return {std::shared_ptr<void>(), &g.second_depth};  // not owned: g outlives the run
  if (!in.scene)
    throw InputError(std::string(method) + ": layers=2 traces the second depth layer in the scene, and this G-buffer came without " +
                     "a scene (a G-buffer file or arrays hold one layer): give the scene, or use layers=1");
  return std::make_shared<const Image<float>>(render_second_layer_depth(*in.scene, g, separation));
}

// Builds the characteristic function of `kind` in the G-buffer's camera space and calls
// fn(ch, kernel_elimination): whether the kernel's own silhouette elimination (AT 4.3) is to run.
// `elimination` is the user's silhouette_elimination; `limit` the distance in front of a sample
// point beyond which the depth-buffer factor of the product counts as a distant foreground object.
template <class Fn>
void with_characteristic(const MethodInput& in, CharacteristicKind kind, const DepthLayers& layers, std::string_view method, bool elimination,
                         float limit, Fn&& fn) {
  const GBuffer& g = in.gbuffer;
  if (kind == CharacteristicKind::Depth && layers.layers < 2) return fn(DepthBufferCharacteristic(g), elimination);
  if (kind == CharacteristicKind::Depth) {
    const float separation = effective_separation(layers, in.falloff.radius);
    return fn(DepthBufferCharacteristic(g, second_layer_for(in, separation, method), separation), elimination);
  }
  if (layers.layers == 2)
    throw InputError(std::string(method) + ": layers=2 is a second layer of the depth buffer, and characteristic " +
                     std::string(kCharacteristicNames[static_cast<std::size_t>(kind)]) + " is analytic: use layers=1 with it");
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

// ---- Run functions ----

MethodOutput run_raytraced(const MethodInput& in, const nlohmann::json& j) {
  if (!in.scene)
    throw InputError("method raytraced traces rays in the scene, and a G-buffer file has none: give a scene instead of --gbuffer-in");
  const RaytracedMethodParams p = parse(raytraced_method_table(), j);
  ReferenceImage img = render_reference(*in.scene, in.gbuffer, {p.reference, in.falloff}, p.rays, in.seed, in.progress);
  MethodOutput out;
  out.visibility = std::move(img.scalar.visibility);
  if (!img.color.empty()) out.color = std::move(img.color);
  if (!img.obscurance.empty()) out.extras["obscurance"] = std::move(img.obscurance);
  out.std_error = std::move(img.scalar.std_error);
  out.stats = {{"rays", img.scalar.rays}, {"mean_std_error", img.scalar.mean_std_error}, {"max_std_error", img.scalar.max_std_error}};
  return out;
}

MethodOutput run_containment(const MethodInput& in, const nlohmann::json& j) {
  const auto w = parse(screen_space_table<containment_param_table>(), j);
  MethodOutput out;
  // AT 4.3 tests the sample point itself: a surface more than R in front of it is distant.
  with_characteristic(in, w.characteristic, w.method.layers, "containment", w.method.silhouette_elimination, in.falloff.radius,
                      [&](const auto& ch, bool kernel_elimination) {
                        ContainmentParams q = w.method;
                        q.silhouette_elimination = kernel_elimination;
                        out.visibility = containment_ao(in.gbuffer, ch, in.falloff, q, in.seed);
                      });
  add_characteristic_stats(out, w.characteristic, w.method.silhouette_elimination);
  return out;
}

MethodOutput run_volumetric(const MethodInput& in, const nlohmann::json& j) {
  const auto w = parse(screen_space_table<volumetric_param_table>(), j);
  MethodOutput out;
  // The kernel eliminates a surface more than R in front of a pipe's entry, which lies up to R/2 in
  // front of the sphere's centre, where the characteristic is read: a depth-buffer surface more than
  // 1.5 R in front of the centre is distant for every pipe, so the wrapped factor never drops a
  // surface the kernel's per-pipe test would keep.
  with_characteristic(in, w.characteristic, w.method.layers, "volumetric", w.method.silhouette_elimination, 1.5f * in.falloff.radius,
                      [&](const auto& ch, bool kernel_elimination) {
                        VolumetricParams q = w.method;
                        q.silhouette_elimination = kernel_elimination;
                        out.visibility = volumetric_ao(in.gbuffer, ch, in.falloff.radius, q, in.seed);
                      });
  add_characteristic_stats(out, w.characteristic, w.method.silhouette_elimination);
  return out;
}

MethodOutput run_transfer(const MethodInput& in, const nlohmann::json& j) {
  const auto w = parse(screen_space_table<transfer_param_table>(), j);
  MethodOutput out;
  with_characteristic(in, w.characteristic, w.method.layers, "transfer", w.method.silhouette_elimination, in.falloff.radius,
                      [&](const auto& ch, bool kernel_elimination) {
                        TransferParams q = w.method;
                        q.silhouette_elimination = kernel_elimination;
                        TransferImage img;
                        if (in.cache) {  // the scratch images of the last call, reused
                          TransferBuffers& buffers = in.cache->transfer();
                          transfer_ao(buffers, in.gbuffer, ch, in.gbuffer.albedo, in.falloff, q, in.seed);
                          img = std::move(buffers.result);
                        } else {
                          img = transfer_ao(in.gbuffer, ch, in.gbuffer.albedo, in.falloff, q, in.seed);
                        }
                        out.visibility = std::move(img.luminance);
                        out.color = std::move(img.transfer);
                        out.extras["obscurance"] = std::move(img.obscurance);
                      });
  add_characteristic_stats(out, w.characteristic, w.method.silhouette_elimination);
  return out;
}

MethodOutput run_cone(const MethodInput& in, const nlohmann::json& j) {
  if (!in.scene) throw InputError("method cone voxelizes the scene, and a G-buffer file has none: give a scene instead of --gbuffer-in");
  const ConeParams p = parse(cone_param_table(), j);
  ConeResult r;
  if (in.cache) {
    r = in.cache->cone(in.scene->scene()).render(in.gbuffer, in.falloff.radius, p, in.seed, in.progress);
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
  const AlchemyParams p = parse(alchemy_param_table(), j);
  // Two layers: the G-buffer's second layer, or one traced for this run (the separation scales with r).
  std::shared_ptr<const Image<float>> second;
  if (p.layers.layers == 2) second = second_layer_for(in, effective_separation(p.layers, alchemy_constants(p, in.falloff.radius).radius), "alchemy");
  AlchemyImage img = render_alchemy(in.gbuffer, second.get(), p, in.falloff.radius, in.seed, in.progress);
  MethodOutput out;
  out.visibility = std::move(img.visibility);
  if (!img.unfiltered.empty()) out.extras["unfiltered"] = std::move(img.unfiltered);
  out.stats = {{"estimator_ms", img.estimator_ms}, {"filter_ms", img.filter_ms}};
  return out;
}

MethodOutput run_gtao(const MethodInput& in, const nlohmann::json& j) {
  const GtaoParams p = parse(gtao_param_table(), j);
  GtaoImage img = gtao_ao(in.gbuffer, in.falloff.radius, p, in.seed);
  MethodOutput out;
  out.visibility = std::move(img.visibility);
  out.color = std::move(img.color);
  return out;
}

// ---- References and other capabilities ----

Falloff requested_falloff(const Falloff& requested, const nlohmann::json&) { return requested; }
Falloff step_falloff(const Falloff& requested, const nlohmann::json&) { return {Membership::Step, requested.radius}; }
ReferenceSpec step_reference(const Falloff& requested, const nlohmann::json&) { return obscurance_reference({Membership::Step, requested.radius}); }

bool transfer_reads_direct_light(const nlohmann::json& j) {
  return parse(screen_space_table<transfer_param_table>(), j).method.reflectance == TransferReflectance::Radiance;
}

MethodMemory cone_memory(const nlohmann::json& j) {
  const ConeParams p = parse(cone_param_table(), j);
  return {estimate_cone_grid_memory(p.columns, p.depth_bits),
          "a " + std::to_string(p.columns) + "^2 x " + std::to_string(p.depth_bits) + " voxel grid"};
}

nlohmann::json cone_resolved(const nlohmann::json& j) { return cone_param_table().to_json(parse(cone_param_table(), j).resolved()); }

nlohmann::json alchemy_resolved(const nlohmann::json& j) {
  AlchemyParams p = parse(alchemy_param_table(), j);
  p.intensity = p.effective_intensity();
  return alchemy_param_table().to_json(p);
}

// GTAO without the multi-bounce fit estimates the cosine-weighted visibility within R: step
// obscurance with the user's R (the membership asked for does not change what it computes). With
// the fit it estimates the ambient light after interreflections among surfaces of the albedo
// around the point (Jimenez et al. 2016, sec. 5), which the ray-traced ambient transfer W with the
// occluders' albedo computes (reference/transfer_reference.h), scored on its luminance.
ReferenceSpec gtao_reference(const Falloff& requested, const nlohmann::json& j) {
  const Falloff step{Membership::Step, requested.radius};
  if (parse(gtao_param_table(), j).multi_bounce) return ReferenceSpec{ReferenceKind::Transfer, step};
  return obscurance_reference(step);
}

constexpr std::array<std::string_view, 1> kReferenceQuantity{kReferenceParam};
constexpr std::array<std::string_view, 1> kAlbedoScaleQuantity{"albedo_scale"};
constexpr std::array<std::string_view, 1> kMultiBounceQuantity{"multi_bounce"};
constexpr std::array<std::string_view, 1> kRadiusQuantity{"radius"};  // Alchemy's r is the R it integrates within
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
               .params = schema<raytraced_method_table>,
               .run = run_raytraced,
               .reference = [](const Falloff& requested,
                               const nlohmann::json& j) { return ReferenceSpec{parse(raytraced_method_table(), j).reference, requested}; },
               .obscurance_falloff = requested_falloff},
    // Containment estimates the obscurance of the requested membership directly (eq. 5).
    MethodInfo{.name = "containment",
               .summary = "containment tests against the depth buffer, r = mu^-1(xi) (volumetric AO eq. 5), any membership",
               .takes_characteristic = true,
               .samples_param = "samples",
               .params = schema<screen_space_table<containment_param_table>>,
               .run = run_containment,
               .reference = [](const Falloff& requested, const nlohmann::json&) { return obscurance_reference(requested); },
               .obscurance_falloff = requested_falloff},
    // Volumetric AO's V is the free fraction of the tangent sphere of radius R/2 (eq. 6-7), whose
    // ray-traced form is tangent_sphere.h. As an obscurance it implies mu = (r/R)^3 with the same R.
    MethodInfo{.name = "volumetric",
               .summary = "free volume of the tangent sphere by pipes along z (volumetric AO eq. 6-7); implies cubic membership",
               .takes_characteristic = true,
               .samples_param = "samples",
               .params = schema<screen_space_table<volumetric_param_table>>,
               .run = run_volumetric,
               .reference =
                   [](const Falloff& requested, const nlohmann::json&) {
                     return ReferenceSpec{ReferenceKind::TangentSphere, {Membership::Cubic, requested.radius}};
                   },
               .obscurance_falloff = [](const Falloff& requested, const nlohmann::json&) { return Falloff{Membership::Cubic, requested.radius}; }},
    // W of eq. 9 estimates eq. 6 (transfer_reference.h) with the same membership and albedo scale;
    // it approaches the obscurance of that membership as the albedo goes to 0. (Radiance mode's
    // direct term is not in the reference: it would need the sun, which MethodInput does not carry.)
    MethodInfo{.name = "transfer",
               .summary = "ambient transfer W: obscurance plus nearby bounces, RGB (ambient transfer eq. 9); extra: obscurance; "
                          "-p reflectance=radiance adds the light of sunlit occluders (needs --sun)",
               .takes_characteristic = true,
               .cached = true,
               .extras = kObscuranceExtra,
               .quantity_params = kAlbedoScaleQuantity,
               .samples_param = "samples",
               .params = schema<screen_space_table<transfer_param_table>>,
               .run = run_transfer,
               .reference =
                   [](const Falloff& requested, const nlohmann::json& j) {
                     return ReferenceSpec{ReferenceKind::Transfer, requested,
                                          parse(screen_space_table<transfer_param_table>(), j).method.albedo_scale};
                   },
               .obscurance_falloff = requested_falloff,
               .reads_direct_light = transfer_reads_direct_light},
    // Cone tracing estimates classical AO with R = R_max (sec. III-C): step membership, the user's R.
    MethodInfo{.name = "cone",
               .summary = "voxel cone tracing: parity voxelization in bit columns, cones of spheres, prisms by popcount (Dalla Favera & Celes)",
               .needs_scene = true,
               .cached = true,
               .params = schema<cone_param_table>,
               .run = run_cone,
               .reference = step_reference,
               .obscurance_falloff = step_falloff,
               .resolve_presets = cone_resolved,
               .memory = cone_memory},
    // Alchemy approximates classical obscurance within its radius r (step, R = r): at the paper's
    // preset eq. 7's falloff is exactly that, and the reference never moves with sigma, the
    // estimator's aesthetic knob (docs/methods/alchemy.md).
    MethodInfo{.name = "alchemy",
               .summary = "Alchemy AO: screen-space disk samples, eq. 10 (sigma, k, beta, epsilon, r, s) + 13-tap cross-bilateral filter",
               .extras = kUnfilteredExtra,
               .quantity_params = kRadiusQuantity,
               .samples_param = "samples",
               .params = schema<alchemy_param_table>,
               .run = run_alchemy,
               .reference =
                   [](const Falloff& requested, const nlohmann::json& j) {
                     return obscurance_reference(alchemy_reference_falloff(parse(alchemy_param_table(), j), requested.radius));
                   },
               .obscurance_falloff = [](const Falloff& requested,
                                        const nlohmann::json& j) { return alchemy_reference_falloff(parse(alchemy_param_table(), j), requested.radius); },
               .resolve_presets = alchemy_resolved},
    MethodInfo{.name = "gtao",
               .summary = "GTAO (Jimenez et al. 2016): horizons in screen-space slices, analytic cosine-weighted inner integral, 4x4 denoise; "
                          "-p multi_bounce=true adds its multi-bounce fit",
               .quantity_params = kMultiBounceQuantity,
               .params = schema<gtao_param_table>,
               .run = run_gtao,
               .reference = gtao_reference,
               .obscurance_falloff = step_falloff},
};

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
  throw InputError("no parameter table '" + std::string(name) + "' (known: " + names + ")");
}

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
    case ReferenceKind::Transfer: {
      // The occluders' albedo scale of a method whose own reference is ambient transfer, else 1.
      const ReferenceSpec matched = m.reference(requested, params);
      return {ReferenceKind::Transfer, f, matched.kind == ReferenceKind::Transfer ? matched.albedo_scale : 1.0f};
    }
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

const MethodInfo& ground_truth_method() {
  for (const MethodInfo& m : kMethods)
    if (m.ground_truth) return m;
  throw std::logic_error("the registry has no ground-truth method");
}

}  // namespace ao
