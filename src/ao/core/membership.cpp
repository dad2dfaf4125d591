#include "ao/core/membership.h"

#include <array>
#include <cmath>
#include <utility>

#include "ao/core/error.h"
#include "ao/core/math.h"

namespace ao {

namespace {
constexpr std::array<std::pair<Membership, std::string_view>, 5> kNames{{
    {Membership::Step, "step"},
    {Membership::Linear, "linear"},
    {Membership::Sqrt, "sqrt"},
    {Membership::Cubic, "cubic"},
    {Membership::Exp, "exp"},
}};
}

void Falloff::validate() const {
  if (!(radius > 0.0f) || !std::isfinite(radius)) throw InputError("falloff: radius R must be a positive finite number of world units");
  if (!(tau >= 0.0f) || !std::isfinite(tau)) throw InputError("falloff: tau must be >= 0 (0 selects 3/R)");
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
