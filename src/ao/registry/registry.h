// SPDX-License-Identifier: Apache-2.0
// The one table of AO methods. `ao render --method`, `ao compare`, `ao tune`, `ao view`, the
// Python module and the parametrised tests are driven by it, so a new method is one folder
// (methods/<name>/, with its parameter struct and its `run` overloads: methods/method.h) plus one
// row here and one alternative of MethodParams. What a method can do (which input it reads, which
// references it has, whether it runs on the GPU, its extra outputs, whether it keeps state between
// frames) is a typed field of its row or an overload on its parameter struct, never a parameter
// name or a method name recognised by the caller.
//
// A caller decodes the user's parameters (JSON, `-p`, Python keywords) once into MethodParams,
// the method's own struct, and hands that to run_method and the other functions below:
//
//   const ao::MethodInfo& m = ao::find_method("volumetric");
//   const ao::MethodParams p = m.decode({{"samples", 16}});      // InputError for a bad one
//   const ao::MethodOutput out = ao::run_method({g, &rays, falloff, seed}, p);
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <variant>

#include <nlohmann/json_fwd.hpp>

#include "ao/core/gbuffer.h"
#include "ao/core/membership.h"
#include "ao/core/params.h"
#include "ao/methods/alchemy/alchemy.h"
#include "ao/methods/cone/cone.h"
#include "ao/methods/containment/containment.h"
#include "ao/methods/gtao/gtao.h"
#include "ao/methods/method.h"
#include "ao/methods/transfer/transfer.h"
#include "ao/methods/volumetric/volumetric.h"
#include "ao/reference/raytraced_method.h"
#include "ao/reference/reference.h"

namespace ao {

/// A method's parameters as its own struct, decoded by its table: the alternative says which
/// method (the registry's rows are in this order).
using MethodParams =
    std::variant<RaytracedMethodParams, ContainmentParams, VolumetricParams, TransferParams, ConeParams, AlchemyParams, GtaoParams>;

/// One row of the registry.
struct MethodInfo {
  std::string_view name;
  std::string_view summary;  ///< One line for --help.
  /// The ray-traced ground truth itself: `ao compare` judges the other methods against its kinds
  /// and does not list it by default; the viewer accumulates it progressively.
  bool ground_truth = false;
  /// Reads the scene itself (rays, voxels), not only the G-buffer: needs a scene, not a G-buffer file.
  bool needs_scene = false;
  /// Takes the parameter `characteristic` (containment, volumetric, transfer: characteristic.h).
  bool takes_characteristic = false;
  /// Keeps state between calls on one scene in a MethodCache (cone: its voxel grid; transfer: its
  /// scratch images).
  bool cached = false;
  /// Runs on the GPU backend too (run_gpu_method; its folder's <name>_gpu.cpp and shaders).
  bool gpu = false;
  /// The names MethodOutput::extras may carry, written by `ao render --extras` as
  /// <output-stem>-<name><ext>.
  std::span<const std::string_view> extras;
  /// The parameters that choose which quantity is estimated, and so which reference judges it
  /// (raytraced's reference, transfer's albedo_scale, GTAO's multi_bounce). Every other parameter is
  /// a knob of the estimator, which the reference never follows: a reference depends on the scene,
  /// the camera, R, the membership and its own ray settings only (tests/registry).
  std::span<const std::string_view> quantity_params;
  /// The parameter `--samples` sets; empty when the method has no sample count.
  std::string_view samples_param;
  /// The parameter `--target-error` sets; empty when the method does not stop adaptively.
  std::string_view target_error_param;
  /// The parameter table (defaults, ranges, help).
  const ParamSchema& (*params)();
  /// `overrides` read over the defaults through the table and checked (InputError naming the
  /// parameter: an unknown key, a wrong type, a value out of range): the method's own struct.
  MethodParams (*decode)(const nlohmann::json& overrides);

  /// Every parameter at its default.
  nlohmann::json default_params() const;
  /// `overrides` read over the defaults through the table, checked and written back complete:
  /// what --json echoes.
  nlohmann::json canonical_params(const nlohmann::json& overrides) const;
  /// Whether `extra` is one of `extras`.
  bool has_extra(std::string_view extra) const;
};

/// The row of the method whose parameters `params` are.
const MethodInfo& method_of(const MethodParams& params);
/// `params` complete, as JSON (the table's canonical form): what --json echoes.
nlohmann::json params_json(const MethodParams& params);

/// Runs the method of `params` (its `run` overload, methods/method.h). When in.rays is set and
/// in.scene or in.trace_second_layer are not, they are taken from it (the scene it traces, and its
/// second depth layer behind the G-buffer's first).
MethodOutput run_method(const MethodInput& in, const MethodParams& params);

/// The reference that computes exactly the quantity the method estimates (same integral, normal
/// and R; derived in docs/methods/<name>.md), from the falloff the user asked for and the method's
/// parameters: what `ao compare` judges it against by default ("matched").
ReferenceSpec matched_reference(const Falloff& requested, const MethodParams& params);
/// The obscurance (VAO eq. 2) membership and R the method approximates or implies (volumetric
/// AO: cubic; cone tracing: step with R = R_max): `ao compare --reference obscurance`.
Falloff obscurance_falloff(const Falloff& requested, const MethodParams& params);
/// Whether these parameters read the G-buffer's direct-light pass (transfer's radiance mode).
bool reads_direct_light(const MethodParams& params);
/// `params` with every value a preset leaves unset filled in as the method uses it (cone's counts,
/// Alchemy's intensity), for a caller that starts from the values in effect (ao tune).
MethodParams with_presets_resolved(const MethodParams& params);
/// Memory beyond the images (cone's voxel grid); zero bytes when none.
MethodMemory extra_memory(const MethodParams& params);

/// InputError (one line, naming the way out) when the method of `params` has no GPU path, or when
/// `params` ask for what its GPU path does not implement (a characteristic function other than the
/// depth buffer, a second depth layer, cone's eye grid): the checks of run_gpu_method that need no
/// device, for a caller that refuses a run before loading anything.
void check_gpu_method(const MethodParams& params);

/// The names `ao compare --reference` accepts, besides the kinds of reference.h: "matched" (the
/// method's own, MethodInfo::reference; the default) and "obscurance" (MethodInfo::obscurance_falloff).
inline constexpr const char* kMatchedReference = "matched";

/// The reference called `name` for the method of `params`: "matched", "obscurance",
/// "tangent-sphere" (R of the method's obscurance falloff) or "transfer" (its membership and R; the
/// method's albedo_scale when it has one). InputError naming the valid names otherwise.
ReferenceSpec choose_reference(std::string_view name, const Falloff& requested, const MethodParams& params);

/// A parameter table by name: each method's (its name) and the bakers' ("bake-raytraced",
/// "bake-histogram", "bake-high-to-low"): what `ao params`, the generated docs and the Python
/// module list.
struct ParamTableInfo {
  std::string_view name;
  const ParamSchema& (*schema)();
};
std::span<const ParamTableInfo> all_param_tables();
/// The table called `name`; InputError listing the valid names otherwise.
const ParamSchema& find_param_table(std::string_view name);

/// All methods, in the order --help lists them.
std::span<const MethodInfo> all_methods();
/// The method called `name`; InputError listing the valid names otherwise.
const MethodInfo& find_method(std::string_view name);
/// The ground-truth method (MethodInfo::ground_truth).
const MethodInfo& ground_truth_method();

}  // namespace ao
