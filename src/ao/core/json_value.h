// SPDX-License-Identifier: Apache-2.0
// A JSON value held through a pointer, so that a header can carry one by value (a job's request and
// result, a method's output) without including <nlohmann/json.hpp>, which alone takes about 1.9 s
// to parse. Holding, copying, moving and assigning one needs only this header; looking inside
// needs <nlohmann/json.hpp> where it is done:
//
//   ao::RenderRequest r;                          // no nlohmann/json.hpp needed
//   r.params = nlohmann::json{{"samples", 16}};   // this line needs it
//   r.params["samples"] = 32;                     // so does this one
//   const nlohmann::json& p = r.params;           // the value itself, for any nlohmann call
//
// A JsonValue is made from a nlohmann::json only, never from a braced list: `r.params =
// {{"samples", 16}}` would give its outer braces to JsonValue and make the array ["samples", 16],
// where nlohmann::json makes the object {"samples": 16}, so it does not compile; name the type.
#pragma once

#include <concepts>
#include <memory>
#include <type_traits>
#include <utility>

#include <nlohmann/json_fwd.hpp>

namespace ao {

class JsonValue {
 public:
  JsonValue() noexcept = default;  ///< JSON null.
  /// Holds `value`, copied or moved. Implicit: a JsonValue stands for the JSON it holds.
  template <class J>
    requires std::same_as<std::remove_cvref_t<J>, nlohmann::json>
  JsonValue(J&& value) : value_(hold(std::forward<J>(value))) {}  // NOLINT(google-explicit-constructor)
  JsonValue(const JsonValue& other);
  JsonValue(JsonValue&& other) noexcept;
  JsonValue& operator=(const JsonValue& other);
  JsonValue& operator=(JsonValue&& other) noexcept;
  ~JsonValue();

  /// An empty JSON object (`{}`).
  static JsonValue object();

  /// The value (null for a default-constructed or moved-from JsonValue).
  const nlohmann::json& get() const;
  nlohmann::json& get();
  operator const nlohmann::json&() const { return get(); }  // NOLINT(google-explicit-constructor)
  const nlohmann::json& operator*() const { return get(); }
  nlohmann::json& operator*() { return get(); }
  const nlohmann::json* operator->() const { return &get(); }
  nlohmann::json* operator->() { return &get(); }

  /// The value's element `key`, as nlohmann::json's operator[] gives it (J only delays the lookup to
  /// where the caller has included <nlohmann/json.hpp>).
  template <class Key, class J = nlohmann::json>
  J& operator[](const Key& key) {
    return static_cast<J&>(get())[key];
  }
  template <class Key, class J = nlohmann::json>
  const J& operator[](const Key& key) const {
    return static_cast<const J&>(get())[key];
  }

 private:
  static std::unique_ptr<nlohmann::json> hold(const nlohmann::json& value);
  static std::unique_ptr<nlohmann::json> hold(nlohmann::json&& value);

  std::unique_ptr<nlohmann::json> value_;  ///< Null stands for JSON null.
};

}  // namespace ao
