// SPDX-License-Identifier: Apache-2.0
// The ray-traced ground truth as a method of the registry (`ao render -m raytraced`): the
// reference of a kind (reference.h) rendered with its ray settings.
#pragma once

#include <nlohmann/json_fwd.hpp>

#include "ao/core/params.h"
#include "ao/methods/method.h"
#include "ao/reference/raytraced.h"
#include "ao/reference/reference.h"

namespace ao {

/// The parameter that chooses which reference the method renders: one of reference_kind_names().
inline constexpr const char* kReferenceParam = "reference";

/// The method's parameters: the rays (raytraced.h) and which reference they render.
struct RaytracedMethodParams {
  RaytracedParams rays;
  /// Obscurance of the requested membership (default), the tangent sphere's visible fraction, or
  /// ambient transfer W (reference.h).
  ReferenceKind reference = ReferenceKind::Obscurance;

  /// Throws InputError naming the bad field.
  void validate() const { rays.validate(); }
};
/// The parameter table: raytraced_param_table's rows, then "reference".
const ParamTable<RaytracedMethodParams>& raytraced_method_param_table();

/// The reference of kind params.reference with the requested falloff, rendered in in.rays:
/// visibility, its standard error, (transfer) W as color and O as the extra "obscurance", and
/// the rays and standard errors as stats. InputError without a scene (a G-buffer file).
MethodOutput run(const MethodInput& in, const RaytracedMethodParams& params);

}  // namespace ao
