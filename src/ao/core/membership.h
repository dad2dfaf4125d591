// SPDX-License-Identifier: Apache-2.0
// Fuzzy membership (falloff) functions mu(d) of the obscurance integral
//   V(x) = (1/pi) * integral over the hemisphere of mu(D(w)) cos(theta) dw        (volumetric AO, eq. 2)
// where D(w) is the distance to the first surface in direction w (infinite when nothing is hit).
// mu(0) = 0 and mu grows to 1: a direction whose occluder is far counts as open. With mu = 1 for
// every direction V = 1 (the 1/pi normalises the cosine-weighted hemisphere to one).
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace ao {

enum class Membership {
  Step,    ///< Classical AO: mu = 0 if d < R, else 1.
  Linear,  ///< mu = min(d/R, 1).
  Sqrt,    ///< Localised square root: mu = sqrt(min(d/R, 1)).
  Cubic,   ///< mu = min(d/R, 1)^3, the falloff implied by volumetric AO (its Figure 3e).
  Exp,     ///< mu = 1 - exp(-tau d), not localised: needs the distance of far occluders too.
  Alchemy, ///< mu = 1 - min(1, u/d) for d < R, else 1: the falloff g(t) = u/t that Alchemy AO's eq. 10
           ///< integrates (eq. 7's u t / max(u, t)^2 for t >= u; eq. 10 replaces eq. 9's max(u^2, v.v) by
           ///< v.v + epsilon and folds u into sigma), clipped to g <= 1 as its eq. 4 requires; u >= R makes it Step.
           ///< Derivation: docs/methods/alchemy.md.
};

/// A membership function with its parameters. Distances are in world units.
struct Falloff {
  Membership membership = Membership::Step;
  float radius = 1.0f;  ///< R, world units, > 0. Unused by Exp except for its default tau.
  float tau = 0.0f;     ///< Absorption coefficient of Exp, 1/world units; 0 selects 3/R (mu(R) = 0.95).
  float alchemy_u = 0.0f;  ///< u of Alchemy's falloff (= its sigma in world units), world units, >= 0;
                           ///< 0 selects 2R (the paper's sigma = 1 m at r = 0.5 m), where Alchemy equals Step.

  /// Throws InputError naming the bad field.
  void validate() const;
  /// The tau Exp actually uses.
  float effective_tau() const { return tau > 0 ? tau : 3.0f / radius; }
  /// The u Alchemy actually uses.
  float effective_alchemy_u() const { return alchemy_u > 0 ? alchemy_u : 2.0f * radius; }
  /// Distance beyond which mu = 1, so rays need not look further: R, or infinity for Exp.
  float reach() const;
  /// mu(d) for d >= 0; d = +infinity (nothing hit) gives 1.
  float mu(float d) const;
  /// mu^-1(xi) for xi in [0,1): a distance distributed with density dmu/dr (volumetric AO, sec. on
  /// containment tests). Step's derivative is a Dirac delta at R, so every xi maps to R.
  float inverse(float xi) const;
};

std::string_view to_string(Membership m);
/// Parses "step", "linear", "sqrt", "cubic", "exp", "alchemy"; nullopt for anything else.
std::optional<Membership> parse_membership(std::string_view name);
/// Comma-separated list of valid names, for error messages and --help.
std::string membership_names();

}  // namespace ao
