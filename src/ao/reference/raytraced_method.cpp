// SPDX-License-Identifier: Apache-2.0
#include "ao/reference/raytraced_method.h"

#include <string>
#include <utility>
#include <vector>

#include "ao/core/error.h"
#include "ao/core/params_table.h"

namespace ao {

const ParamTable<RaytracedMethodParams>& raytraced_method_param_table() {
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

MethodOutput run(const MethodInput& in, const RaytracedMethodParams& params) {
  if (!in.rays) throw InputError("method raytraced traces rays in the scene, and a G-buffer file has none: give a scene instead of --gbuffer-in");
  params.validate();
  ReferenceImage img = render_reference(*in.rays, in.gbuffer, {params.reference, in.falloff}, params.rays, in.seed, in.progress);
  MethodOutput out;
  out.visibility = std::move(img.scalar.visibility);
  if (!img.color.empty()) out.color = std::move(img.color);
  if (!img.obscurance.empty()) out.extras["obscurance"] = std::move(img.obscurance);
  out.std_error = std::move(img.scalar.std_error);
  out.stats = nlohmann::json{{"rays", img.scalar.rays}, {"mean_std_error", img.scalar.mean_std_error}, {"max_std_error", img.scalar.max_std_error}};
  return out;
}

}  // namespace ao
