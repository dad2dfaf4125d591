// SPDX-License-Identifier: Apache-2.0
#include "ao/core/membership.h"

#include <array>
#include <cmath>
#include <utility>

#include "ao/core/error.h"
#include "ao/core/math.h"

namespace ao {

namespace {
constexpr std::array<std::pair<Membership, std::string_view>, 6> kNames{{
    {Membership::Step, "step"},
    {Membership::Linear, "linear"},
    {Membership::Sqrt, "sqrt"},
    {Membership::Cubic, "cubic"},
    {Membership::Exp, "exp"},
    {Membership::Alchemy, "alchemy"},
}};
}

void Falloff::validate() const {
  if (!(radius > 0.0f) || !std::isfinite(radius)) throw InputError("falloff: radius R must be a positive finite number of world units");
  if (!(tau >= 0.0f) || !std::isfinite(tau)) throw InputError("falloff: tau must be >= 0 (0 selects 3/R)");
  if (!(alchemy_u >= 0.0f) || !std::isfinite(alchemy_u)) throw InputError("falloff: alchemy u must be >= 0 world units (0 selects 2R)");
}

float Falloff::reach() const { return membership == Membership::Exp ? kInfinity : radius; }

float Falloff::mu(float d) const {
  if (membership == Membership::Exp) return d == kInfinity ? 1.0f : 1.0f - std::exp(-effective_tau() * d);
  const float t = std::min(d / radius, 1.0f);
  switch (membership) {
    case Membership::Step: return d < radius ? 0.0f : 1.0f;
    case Membership::Linear: return t;
    case Membership::Sqrt: return std::sqrt(t);
    case Membership::Cubic: return t * t * t;
    // 1 - g(d) with g(d) = u/d (eq. 10; eq. 7 for d >= u; eq. 10's epsilon only matters for d < epsilon/u, see
    // docs/methods/alchemy.md), clipped to g <= 1 because a direction cannot be more than fully occluded
    // (eq. 4: 0 <= g <= 1). u/0 = inf gives mu(0) = 0.
    case Membership::Alchemy: return d < radius ? std::max(0.0f, 1.0f - effective_alchemy_u() / d) : 1.0f;
    case Membership::Exp: break;
  }
  return 1.0f;
}

float Falloff::inverse(float xi) const {
  switch (membership) {
    case Membership::Step: return radius;
    case Membership::Linear: return xi * radius;
    case Membership::Sqrt: return xi * xi * radius;
    case Membership::Cubic: return std::cbrt(xi) * radius;
    case Membership::Exp: return -std::log1p(-xi) / effective_tau();
    case Membership::Alchemy: {
      // CDF max(0, 1 - u/d) on [0, R) with an atom of mass u/R at R (all of it when u >= R).
      const float u = effective_alchemy_u();
      return xi < 1.0f - u / radius ? std::min(radius, u / (1.0f - xi)) : radius;
    }
  }
  return radius;
}

std::string_view to_string(Membership m) {
  for (const auto& [value, name] : kNames)
    if (value == m) return name;
  return "?";
}

std::optional<Membership> parse_membership(std::string_view name) {
  for (const auto& [value, n] : kNames)
    if (n == name) return value;
  return std::nullopt;
}

std::string membership_names() {
  std::string s;
  for (const auto& [value, n] : kNames) {
    if (!s.empty()) s += ", ";
    s += n;
  }
  return s;
}

}  // namespace ao
