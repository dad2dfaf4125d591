// SPDX-License-Identifier: Apache-2.0
#include "ao/core/params.h"

#include <charconv>
#include <cmath>
#include <cstdlib>

#include <nlohmann/json.hpp>

#include "ao/core/closest_name.h"
#include "ao/core/error.h"

namespace ao {

namespace {

// A bound of a range as the shortest decimal (ranges are written as float or int literals).
std::string number_text(double v) {
  if (v == std::floor(v) && std::abs(v) < 1e15) return std::to_string(static_cast<long long>(v));
  return float_text(static_cast<float>(v));
}

const char* type_name(ParamType t) {
  switch (t) {
    case ParamType::Int: return "an integer";
    case ParamType::Float: return "a number";
    case ParamType::Bool: return "true or false";
    case ParamType::Enum: return "one of";
    case ParamType::OptionalInt: return "null or an integer";
    case ParamType::OptionalFloat: return "null or a number";
  }
  return "";
}

}  // namespace

bool Range::contains(double v) const {
  // NaN fails every comparison, so it is never in range; infinities only where the bound is closed.
  const bool lo = min_open ? v > min : v >= min;
  const bool hi = max_open ? v < max : v <= max;
  return lo && hi && !std::isnan(v);
}

std::string Range::text() const {
  const bool no_min = std::isinf(min), no_max = std::isinf(max);
  if (no_min && no_max) return "";
  if (no_max) return std::string(min_open ? "> " : ">= ") + number_text(min);
  if (no_min) return std::string(max_open ? "< " : "<= ") + number_text(max);
  return std::string(min_open ? "(" : "[") + number_text(min) + ", " + number_text(max) + (max_open ? ")" : "]");
}

std::string ParamSpec::valid_text() const {
  std::string s = type_name(type);
  if (type == ParamType::Enum) {
    std::string names;
    for (const std::string& n : enum_names) {
      if (!names.empty()) names += ", ";
      names += n;
    }
    return s + " " + names;
  }
  const std::string r = range.text();
  if (!r.empty()) s += (r[0] == '[' || r[0] == '(' ? " in " : " ") + r;
  if (!unit.empty()) s += " (" + unit + ")";
  return s;
}

std::string float_text(float v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return ec == std::errc() ? std::string(buf, end) : std::to_string(v);
}

nlohmann::json float_json(float v) {
  if (!std::isfinite(v)) return static_cast<double>(v);
  // The shortest decimal that reads back to v, as the double nearest to it: JSON then prints it
  // with the digits it was given.
  return std::strtod(float_text(v).c_str(), nullptr);
}

std::string json_text(const nlohmann::json& j) { return j.is_string() ? j.get<std::string>() : j.dump(); }

namespace {

/// A value for a message: its JSON text, at most 40 characters (a value may be any JSON, as large
/// as the file or the option that gave it).
std::string excerpt(const nlohmann::json& j) {
  std::string text = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (text.size() > 40) text = text.substr(0, 40) + "...";
  for (char& c : text)
    if (static_cast<unsigned char>(c) < 0x20) c = ' ';
  return text;
}

}  // namespace

namespace params_detail {

void throw_bad_value(std::string_view owner, const ParamSpec& spec, const nlohmann::json& got) {
  std::string value = excerpt(got);
  if (got.is_number_float()) value = float_text(got.get<float>());
  // A mistyped enum name gets the closest of the names.
  const std::string near = spec.type == ParamType::Enum && got.is_string() ? did_you_mean(got.get<std::string>(), spec.enum_names) : "";
  throw InputError(std::string(owner) + ": " + spec.name + " must be " + spec.valid_text() + ", got " + value + near);
}

void throw_unknown_key(std::string_view owner, std::string_view key, const std::vector<const ParamSpec*>& specs) {
  std::string known;
  for (const ParamSpec* s : specs) {
    if (!known.empty()) known += ", ";
    known += s->name;
  }
  throw InputError(std::string(owner) + ": unknown parameter '" + std::string(key) + "' (known: " + known + ")" + did_you_mean(key, known));
}

void throw_not_object(std::string_view owner, const nlohmann::json& got) {
  throw InputError(std::string(owner) + ": parameters must be a JSON object, got " + excerpt(got));
}

bool type_matches(const ParamSpec& spec, const nlohmann::json& j) {
  switch (spec.type) {
    case ParamType::Int: return j.is_number_integer();
    case ParamType::OptionalInt: return j.is_null() || j.is_number_integer();
    case ParamType::OptionalFloat: return j.is_null() || j.is_number();
    case ParamType::Float: return j.is_number();
    case ParamType::Bool: return j.is_boolean();
    case ParamType::Enum:
      if (!j.is_string()) return false;
      for (const std::string& n : spec.enum_names)
        if (n == j.get<std::string>()) return true;
      return false;
  }
  return false;
}

bool in_range(const ParamSpec& spec, const nlohmann::json& j) {
  const bool optional = spec.type == ParamType::OptionalInt || spec.type == ParamType::OptionalFloat;
  const bool is_float = spec.type == ParamType::Float || spec.type == ParamType::OptionalFloat;
  if (spec.type != ParamType::Int && spec.type != ParamType::Float && !optional) return true;
  if (j.is_null()) return optional;
  if (!j.is_number()) return false;
  // Integers beyond int's range are out of every int range; floats are checked as the float they become.
  if (j.is_number_integer()) {
    const double v = j.get<double>();
    if (!is_float && (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())) return false;
    return spec.range.contains(is_float ? static_cast<double>(static_cast<float>(v)) : v);
  }
  return spec.range.contains(static_cast<double>(j.get<float>()));
}

}  // namespace params_detail

std::string params_markdown(const std::vector<ParamSpec>& specs) {
  std::string s = "| parameter | valid values | default | meaning |\n|---|---|---|---|\n";
  for (const ParamSpec& p : specs) {
    std::string def = p.default_value->is_null() ? "null" : json_text(p.default_value);
    s += "| `" + p.name + "` | " + p.valid_text() + " | " + def + " | " + p.help + " |\n";
  }
  return s;
}

nlohmann::json ParamSchema::defaults() const { return canonical_(nlohmann::json::object()); }

nlohmann::json ParamSchema::canonical(const nlohmann::json& j) const { return canonical_(j); }

}  // namespace ao
