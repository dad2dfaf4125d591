// SPDX-License-Identifier: Apache-2.0
#include "ao/reference/reference.h"

#include <array>
#include <charconv>

#include <nlohmann/json.hpp>

#include "ao/reference/tangent_sphere.h"
#include "ao/reference/transfer_reference.h"

namespace ao {

namespace {

constexpr std::array<std::string_view, 3> kKindNames{"obscurance", "tangent-sphere", "transfer"};

// Shortest text that reads back as the same float (fixed notation unless the exponent is below -4 or large).
std::string shortest(float v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general);
  return std::string(buf, r.ptr);
}

}  // namespace

std::string_view to_string(ReferenceKind kind) { return kKindNames[static_cast<std::size_t>(kind)]; }

std::optional<ReferenceKind> parse_reference_kind(std::string_view name) {
  for (std::size_t k = 0; k < kKindNames.size(); ++k)
    if (kKindNames[k] == name) return static_cast<ReferenceKind>(k);
  return std::nullopt;
}

std::string reference_kind_names() {
  std::string s;
  for (std::string_view n : kKindNames) s += (s.empty() ? "" : ", ") + std::string(n);
  return s;
}

std::string ReferenceSpec::label() const {
  switch (kind) {
    case ReferenceKind::TangentSphere: return "tangent sphere";
    case ReferenceKind::Transfer:
      return std::string("transfer (").append(to_string(falloff.membership)).append(albedo == TransferAlbedo::Receiver ? ", receiver albedo)" : ")");
    default: return std::string(to_string(falloff.membership)).append(" obscurance");
  }
}

std::string ReferenceSpec::key() const {
  // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "literal" + std::string&&.
  std::string k(to_string(kind));
  k.append(" R=").append(shortest(falloff.radius));
  if (kind == ReferenceKind::TangentSphere) return k;
  k.append(" ").append(to_string(falloff.membership));
  if (falloff.membership == Membership::Exp) k.append(" tau=").append(shortest(falloff.effective_tau()));
  if (falloff.membership == Membership::Alchemy) k.append(" u=").append(shortest(falloff.effective_alchemy_u()));
  if (kind == ReferenceKind::Transfer) k.append(" albedo_scale=").append(shortest(albedo_scale));
  if (kind == ReferenceKind::Transfer && albedo == TransferAlbedo::Receiver) k.append(" albedo=receiver");
  return k;
}

void to_json(nlohmann::json& j, const ReferenceSpec& r) {
  j = {{"kind", to_string(r.kind)}};
  if (r.kind != ReferenceKind::TangentSphere) j["membership"] = to_string(r.falloff.membership);
  j["radius"] = r.falloff.radius;
  if (r.kind != ReferenceKind::TangentSphere) {
    if (r.falloff.membership == Membership::Exp) j["tau"] = r.falloff.effective_tau();
    if (r.falloff.membership == Membership::Alchemy) j["u"] = r.falloff.effective_alchemy_u();
  }
  if (r.kind == ReferenceKind::Transfer && r.albedo_scale != 1.0f) j["albedo_scale"] = r.albedo_scale;
  if (r.kind == ReferenceKind::Transfer && r.albedo == TransferAlbedo::Receiver) j["albedo"] = "receiver";
}

ReferenceSpec obscurance_reference(Falloff f) {
  if (f.membership == Membership::Alchemy && f.effective_alchemy_u() >= f.radius) f = Falloff{Membership::Step, f.radius};
  return {ReferenceKind::Obscurance, f};
}

ReferenceImage render_reference(const RayScene& scene, const GBuffer& g, const ReferenceSpec& spec, const RaytracedParams& params,
                                std::uint32_t seed, const ProgressFn& progress) {
  ReferenceImage out;
  switch (spec.kind) {
    case ReferenceKind::TangentSphere:
      out.scalar = render_tangent_sphere(scene, g, spec.falloff.radius, params, seed, progress);
      break;
    case ReferenceKind::Transfer: {
      TransferReferenceImage t = render_transfer_reference(scene, g, spec.falloff, spec.albedo_scale, params, seed, progress, spec.albedo);
      out.scalar = std::move(t.scalar);
      out.color = std::move(t.transfer);
      out.obscurance = std::move(t.obscurance);
      break;
    }
    default: out.scalar = render_raytraced(scene, g, spec.falloff, params, seed, progress);
  }
  return out;
}

}  // namespace ao
