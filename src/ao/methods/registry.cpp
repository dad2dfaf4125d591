#include "ao/methods/registry.h"

#include <array>

#include "ao/core/error.h"
#include "ao/methods/alchemy.h"
#include "ao/methods/cone.h"
#include "ao/methods/containment.h"
#include "ao/methods/transfer.h"
#include "ao/methods/volumetric.h"
#include "ao/reference/raytraced.h"

namespace ao {

namespace {

MethodOutput run_raytraced(const MethodInput& in, const nlohmann::json& j) {
  if (!in.scene)
    throw InputError("method raytraced traces rays in the scene, and a G-buffer file has none: give a scene instead of --gbuffer-in");
  RaytracedParams p = j.get<RaytracedParams>();
  p.validate();
  RaytracedImage img = render_raytraced(*in.scene, in.gbuffer, in.falloff, p, in.seed, in.progress);
  MethodOutput out;
  out.visibility = std::move(img.visibility);
  out.stats = {{"rays", img.rays}, {"mean_std_error", img.mean_std_error}, {"max_std_error", img.max_std_error}};
  return out;
}

MethodOutput run_containment(const MethodInput& in, const nlohmann::json& j) {
  const ContainmentParams p = j.get<ContainmentParams>();
  MethodOutput out;
  out.visibility = containment_ao(in.gbuffer, in.falloff, p, in.seed);
  return out;
}

MethodOutput run_volumetric(const MethodInput& in, const nlohmann::json& j) {
  const VolumetricParams p = j.get<VolumetricParams>();
  MethodOutput out;
  out.visibility = volumetric_ao(in.gbuffer, in.falloff.radius, p, in.seed);
  return out;
}

MethodOutput run_transfer(const MethodInput& in, const nlohmann::json& j) {
  const TransferParams p = j.get<TransferParams>();
  TransferImage img = transfer_ao(in.gbuffer, in.falloff, p, in.seed);
  MethodOutput out;
  out.visibility = std::move(img.luminance);
  out.color = std::move(img.transfer);
  out.extras["obscurance"] = std::move(img.obscurance);
  return out;
}

MethodOutput run_cone(const MethodInput& in, const nlohmann::json& j) {
  if (!in.scene) throw InputError("method cone voxelizes the scene, and a G-buffer file has none: give a scene instead of --gbuffer-in");
  const ConeParams p = j.get<ConeParams>();
  const std::vector<MeshClosure> closure = analyze_closure(in.scene->scene());
  ConeResult r = render_cone(in.scene->scene(), closure, in.gbuffer, in.falloff.radius, p, in.seed, in.progress);
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

const std::array kMethods{
    MethodInfo{"raytraced", "ground truth: Monte Carlo obscurance with Embree rays, any membership", true,
               [] { return nlohmann::json(RaytracedParams{}); }, run_raytraced,
               [](const Falloff& requested, const nlohmann::json&) { return requested; }},
    MethodInfo{"containment", "containment tests against the depth buffer, r = mu^-1(xi) (volumetric AO eq. 5), any membership", false,
               [] { return nlohmann::json(ContainmentParams{}); }, run_containment,
               [](const Falloff& requested, const nlohmann::json&) { return requested; }},
    // Volumetric AO implies mu = (r/R)^3 with the same R (tangent sphere of radius R/2: distances up to R).
    MethodInfo{"volumetric", "free volume of the tangent sphere by pipes along z (volumetric AO eq. 6-7); implies cubic membership", false,
               [] { return nlohmann::json(VolumetricParams{}); }, run_volumetric,
               [](const Falloff& requested, const nlohmann::json&) { return Falloff{Membership::Cubic, requested.radius}; }},
    // W approaches the obscurance of the same membership as the albedo goes to 0.
    MethodInfo{"transfer",
               "ambient transfer W: obscurance plus nearby bounces, RGB (ambient transfer eq. 9); extra: obscurance; "
               "-p reflectance=radiance adds the light of sunlit occluders (needs --sun)",
               false,
               [] { return nlohmann::json(TransferParams{}); }, run_transfer,
               [](const Falloff& requested, const nlohmann::json&) { return requested; }},
    // Cone tracing estimates classical AO with R = R_max (sec. III-C): step membership, the user's R.
    MethodInfo{"cone", "voxel cone tracing: parity voxelization in bit columns, cones of spheres, prisms by popcount (Dalla Favera & Celes)", true,
               [] { return nlohmann::json(ConeParams{}); }, run_cone,
               [](const Falloff& requested, const nlohmann::json&) { return Falloff{Membership::Step, requested.radius}; }},
    // Alchemy approximates obscurance with its own falloff u/t (u = sigma in world units), radius r.
    MethodInfo{"alchemy", "Alchemy AO: screen-space disk samples, eq. 10 (sigma, k, beta, epsilon, r, s) + 13-tap cross-bilateral filter", false,
               [] { return nlohmann::json(AlchemyParams{}); }, run_alchemy,
               [](const Falloff& requested, const nlohmann::json& params) {
                 return alchemy_reference_falloff(params.get<AlchemyParams>(), requested.radius);
               }},
};

}  // namespace

std::span<const MethodInfo> all_methods() { return kMethods; }

const MethodInfo& find_method(std::string_view name) {
  std::string names;
  for (const MethodInfo& m : kMethods) {
    if (m.name == name) return m;
    names += (names.empty() ? "" : ", ") + std::string(m.name);
  }
  throw InputError("unknown method '" + std::string(name) + "' (known: " + names + ")");
}

}  // namespace ao
