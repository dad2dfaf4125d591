// SPDX-License-Identifier: Apache-2.0
// The parameter tables themselves (core/params.h says what they are for): Param, one parameter
// bound to its place in a struct; ParamTable, a struct's parameters by name, read and written as
// JSON; nested_params, one table's rows inside a larger struct; and ParamSchema's constructor. The
// files that define a table or read one through its struct include this header.
#pragma once

#include <cstdint>
#include <functional>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "ao/core/params.h"

namespace ao {

namespace params_detail {
/// The field `ref` names in `s`: a pointer to a member of S, or a function S& -> field&.
template <class S, class Ref>
decltype(auto) access(Ref ref, S& s) {
  if constexpr (std::is_member_object_pointer_v<Ref>) return (s.*ref);
  else return ref(s);
}
}  // namespace params_detail

/// One parameter bound to its place in a struct P.
template <class P>
struct Param {
  ParamSpec spec;
  std::function<nlohmann::json(const P&)> get;      ///< The value as JSON.
  std::function<void(P&, const nlohmann::json&)> set;  ///< Reads JSON of the right type (checked by the caller).

  /// `ref` is a pointer to a member of P, or a function that returns a reference into P (for a
  /// field of a nested struct: [](P& p) -> float& { return p.options.limit; }).
  template <class Ref>
  static Param integer(std::string name, Ref ref, Range range, std::string unit, std::string help) {
    return make<int>(std::move(name), ParamType::Int, ref, range, std::move(unit), std::move(help));
  }
  template <class Ref>
  static Param real(std::string name, Ref ref, Range range, std::string unit, std::string help) {
    return make<float>(std::move(name), ParamType::Float, ref, range, std::move(unit), std::move(help));
  }
  /// A std::uint32_t seed: any integer in [0, 2^32 - 1].
  template <class Ref>
  static Param seed(std::string name, Ref ref, std::string help) {
    return make<std::uint32_t>(std::move(name), ParamType::Int, ref, Range::closed(0, 4294967295.0), "", std::move(help));
  }
  template <class Ref>
  static Param boolean(std::string name, Ref ref, std::string help) {
    return make<bool>(std::move(name), ParamType::Bool, ref, Range{}, "", std::move(help));
  }
  /// std::optional<int>: JSON null = unset.
  template <class Ref>
  static Param optional_integer(std::string name, Ref ref, Range range, std::string unit, std::string help) {
    return make<std::optional<int>>(std::move(name), ParamType::OptionalInt, ref, range, std::move(unit), std::move(help));
  }
  /// std::optional<float>: JSON null = unset (e.g. "the preset's value").
  template <class Ref>
  static Param optional_real(std::string name, Ref ref, Range range, std::string unit, std::string help) {
    return make<std::optional<float>>(std::move(name), ParamType::OptionalFloat, ref, range, std::move(unit), std::move(help));
  }
  /// An enum, written by name; `names` pairs each name with its value, in the enum's order.
  template <class E, class Ref>
  static Param enumeration(std::string name, Ref ref, std::vector<std::pair<std::string, E>> names, std::string help) {
    Param p;
    p.spec.name = std::move(name);
    p.spec.type = ParamType::Enum;
    p.spec.help = std::move(help);
    for (const auto& n : names) p.spec.enum_names.push_back(n.first);
    p.get = [ref, names](const P& s) {
      const E v = access(ref, const_cast<P&>(s));
      for (const auto& [n, e] : names)
        if (e == v) return nlohmann::json(n);
      return nlohmann::json(nullptr);
    };
    p.set = [ref, names](P& s, const nlohmann::json& j) {
      const std::string n = j.get<std::string>();
      for (const auto& [name_k, e] : names)
        if (name_k == n) access(ref, s) = e;
    };
    p.spec.default_value = p.get(P{});
    return p;
  }

 private:
  template <class Ref>
  static decltype(auto) access(Ref ref, P& s) {
    return params_detail::access(ref, s);
  }
  template <class T, class Ref>
  static Param make(std::string name, ParamType type, Ref ref, Range range, std::string unit, std::string help) {
    Param p;
    p.spec = {std::move(name), type, std::move(unit), range, {}, std::move(help), {}};
    p.get = [ref](const P& s) -> nlohmann::json {
      const T& v = access(ref, const_cast<P&>(s));
      if constexpr (std::is_same_v<T, float>) return float_json(v);
      else if constexpr (std::is_same_v<T, std::optional<int>>) return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
      else if constexpr (std::is_same_v<T, std::optional<float>>) return v ? float_json(*v) : nlohmann::json(nullptr);
      else return nlohmann::json(v);
    };
    p.set = [ref](P& s, const nlohmann::json& j) {
      T& v = access(ref, s);
      if constexpr (std::is_same_v<T, std::optional<int>>) v = j.is_null() ? std::nullopt : std::optional<int>(j.get<int>());
      else if constexpr (std::is_same_v<T, std::optional<float>>) v = j.is_null() ? std::nullopt : std::optional<float>(j.get<float>());
      else v = j.get<T>();
    };
    p.spec.default_value = p.get(P{});
    return p;
  }
};

namespace params_detail {
/// InputError "<owner>: <name> must be <valid text>, got <value>".
[[noreturn]] void throw_bad_value(std::string_view owner, const ParamSpec& spec, const nlohmann::json& got);
/// InputError "<owner>: unknown parameter '<key>' (known: a, b, c)".
[[noreturn]] void throw_unknown_key(std::string_view owner, std::string_view key, const std::vector<const ParamSpec*>& specs);
/// InputError "<owner>: parameters must be a JSON object, got ...".
[[noreturn]] void throw_not_object(std::string_view owner, const nlohmann::json& got);
/// Whether `j` has the JSON type `spec` asks for and, for enums, a known name (ranges aside).
bool type_matches(const ParamSpec& spec, const nlohmann::json& j);
/// Whether a number (int or float JSON) lies in the range of `spec`; true for other types.
bool in_range(const ParamSpec& spec, const nlohmann::json& j);
}  // namespace params_detail

/// The parameters of one Params struct P, by name.
template <class P>
class ParamTable {
 public:
  using Struct = P;  ///< The Params struct the table describes.
  ParamTable(std::string owner, std::vector<Param<P>> params) : owner_(std::move(owner)), params_(std::move(params)) {}
  /// Appends the rows of another table over the same struct (shared option groups).
  ParamTable(std::string owner, std::initializer_list<std::vector<Param<P>>> groups) : owner_(std::move(owner)) {
    for (const auto& g : groups) params_.insert(params_.end(), g.begin(), g.end());
  }

  const std::string& owner() const { return owner_; }
  const std::vector<Param<P>>& params() const { return params_; }
  std::vector<ParamSpec> specs() const {
    std::vector<ParamSpec> s;
    for (const Param<P>& p : params_) s.push_back(p.spec);
    return s;
  }

  /// Every parameter as JSON, keyed by name.
  nlohmann::json to_json(const P& s) const {
    nlohmann::json j = nlohmann::json::object();
    for (const Param<P>& p : params_) j[p.spec.name] = p.get(s);
    return j;
  }
  /// Sets the parameters present in `j` (absent ones keep their value in `s`). InputError, one
  /// line, for a non-object, an unknown key, a value of the wrong type or out of its range.
  void from_json(const nlohmann::json& j, P& s) const {
    if (!j.is_object()) params_detail::throw_not_object(owner_, j);
    for (const auto& [key, value] : j.items()) {
      const Param<P>* p = find(key);
      if (!p) {
        std::vector<const ParamSpec*> specs;
        for (const Param<P>& q : params_) specs.push_back(&q.spec);
        params_detail::throw_unknown_key(owner_, key, specs);
      }
      if (!params_detail::type_matches(p->spec, value) || !params_detail::in_range(p->spec, value))
        params_detail::throw_bad_value(owner_, p->spec, value);
      p->set(s, value);
    }
  }
  /// InputError naming the first parameter of `s` outside its range.
  void validate(const P& s) const {
    for (const Param<P>& p : params_) {
      const nlohmann::json v = p.get(s);
      if (!params_detail::in_range(p.spec, v)) params_detail::throw_bad_value(owner_, p.spec, v);
    }
  }
  const Param<P>* find(std::string_view name) const {
    for (const Param<P>& p : params_)
      if (p.spec.name == name) return &p;
    return nullptr;
  }

 private:
  std::string owner_;
  std::vector<Param<P>> params_;
};

/// The rows of `table` as rows of a struct W that holds its P where `part` says (a pointer to a
/// member of W, or a function W& -> P&): a parameter object that extends another one keeps the
/// other's rows, names, ranges and help, declared once.
template <class W, class P, class Part>
std::vector<Param<W>> nested_params(const ParamTable<P>& table, Part part) {
  std::vector<Param<W>> rows;
  for (const Param<P>& p : table.params()) {
    Param<W> q;
    q.spec = p.spec;
    q.get = [get = p.get, part](const W& w) { return get(params_detail::access(part, const_cast<W&>(w))); };
    q.set = [set = p.set, part](W& w, const nlohmann::json& j) { set(params_detail::access(part, w), j); };
    rows.push_back(std::move(q));
  }
  return rows;
}

template <class P>
ParamSchema::ParamSchema(const ParamTable<P>& table)
    : owner_(table.owner()), specs_(table.specs()), canonical_([&table](const nlohmann::json& j) {
        P p{};
        table.from_json(j, p);
        if constexpr (requires { p.validate(); }) p.validate();
        else table.validate(p);
        return table.to_json(p);
      }) {}

}  // namespace ao
