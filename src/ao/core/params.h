// SPDX-License-Identifier: Apache-2.0
// One parameter table per method: each parameter of a Params struct is declared once, with its
// name, where it lives in the struct, type, unit, valid range, one-line help and enum names. JSON in
// and out (from_json / to_json), the range checks of validate(), `ao render -p key=value`, the
// `--json` echo and the docs' parameter tables (`ao params --markdown METHOD`) all come from it.
//
//   const ParamTable<ContainmentParams>& table() {
//     static const ParamTable<ContainmentParams> t{"containment", {
//         Param<ContainmentParams>::integer("samples", &ContainmentParams::samples, {1, 256}, "", "n in eq. 5: test points per pixel"),
//         Param<ContainmentParams>::real("bias", &ContainmentParams::bias, Range::at_least(0), "world units", "depth-test bias; 0 = auto"),
//     }};
//     return t;
//   }
//
// Defaults are the struct's own member initialisers (a default-constructed P), so they too are
// written once. Floats are written to JSON as the shortest decimal that reads back to the same
// float (0.0001f is 0.0001, not 9.999999747378752e-05).
//
// This header holds what code that treats every table alike reads (ParamSpec, ParamSchema) and
// needs no <nlohmann/json.hpp>; the tables themselves (Param, ParamTable, nested_params, and
// ParamSchema's constructor) are in core/params_table.h, which the files that define or read a
// table include.
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "ao/core/json_value.h"

namespace ao {

/// The JSON type of a parameter.
enum class ParamType { Int, Float, Bool, Enum, OptionalInt, OptionalFloat };

/// A closed or open interval of valid values (Int, Float, OptionalInt).
struct Range {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false;  ///< True: min itself is not valid.
  bool max_open = false;  ///< True: max itself is not valid.

  static Range closed(double lo, double hi) { return {lo, hi, false, false}; }
  static Range at_least(double lo) { return {lo, std::numeric_limits<double>::infinity(), false, true}; }
  static Range above(double lo) { return {lo, std::numeric_limits<double>::infinity(), true, true}; }
  static Range open_closed(double lo, double hi) { return {lo, hi, true, false}; }
  static Range open(double lo, double hi) { return {lo, hi, true, true}; }

  bool contains(double v) const;
  /// "[1, 256]", "(0, 90)", ">= 0", "> 0".
  std::string text() const;
};

/// What a parameter is, independent of the struct that holds it: what docs, --help and a UI show.
struct ParamSpec {
  std::string name;
  ParamType type = ParamType::Float;
  std::string unit;                     ///< "world units", "pixels", "degrees"; empty when a pure number.
  Range range;                          ///< Int, Float, OptionalInt, OptionalFloat.
  std::vector<std::string> enum_names;  ///< Enum: the accepted names, in the enum's order.
  std::string help;                     ///< One line.
  JsonValue default_value;              ///< As JSON (null: OptionalInt unset).

  /// "integer in [1, 256]", "number >= 0 (world units)", "true or false", "one of wis, analytic", ...
  std::string valid_text() const;
};

/// A float as the shortest decimal that reads back to the same float, as a JSON number.
nlohmann::json float_json(float v);
/// A float as that decimal, for messages.
std::string float_text(float v);
/// `j` in one line for a message; strings unquoted.
std::string json_text(const nlohmann::json& j);

template <class P>
struct Param;
template <class P>
class ParamTable;

/// A parameter table seen without its struct: what code that treats every method's (and baker's)
/// parameters alike works with (the registry, `ao params`, `ao tune`, the docs, a UI).
class ParamSchema {
 public:
  /// The schema of `table`, which must outlive it (tables are function-local statics); defined in
  /// core/params_table.h.
  template <class P>
  explicit ParamSchema(const ParamTable<P>& table);

  const std::string& owner() const { return owner_; }
  /// The parameters in table order.
  const std::vector<ParamSpec>& specs() const { return specs_; }
  /// The parameter called `name`, or null.
  const ParamSpec* find(std::string_view name) const {
    for (const ParamSpec& s : specs_)
      if (s.name == name) return &s;
    return nullptr;
  }
  /// Every parameter at its default (the struct's member initialisers), as JSON.
  nlohmann::json defaults() const;
  /// `j` read over the defaults, checked (InputError, one line, naming the parameter: an unknown
  /// key, a wrong type, a value out of its range, or a combination the struct's validate()
  /// refuses) and written back complete.
  nlohmann::json canonical(const nlohmann::json& j) const;

 private:
  std::string owner_;
  std::vector<ParamSpec> specs_;
  std::function<nlohmann::json(const nlohmann::json&)> canonical_;
};

/// The Markdown table of `specs` (parameter, type and valid values, default, unit, meaning): what
/// the docs' parameter sections are generated from.
std::string params_markdown(const std::vector<ParamSpec>& specs);

}  // namespace ao
