// SPDX-License-Identifier: Apache-2.0
#include "ao/core/json_value.h"

#include <utility>

#include <nlohmann/json.hpp>

namespace ao {

std::unique_ptr<nlohmann::json> JsonValue::hold(const nlohmann::json& value) { return std::make_unique<nlohmann::json>(value); }
std::unique_ptr<nlohmann::json> JsonValue::hold(nlohmann::json&& value) { return std::make_unique<nlohmann::json>(std::move(value)); }
JsonValue::JsonValue(const JsonValue& other) : value_(other.value_ ? std::make_unique<nlohmann::json>(*other.value_) : nullptr) {}
JsonValue::JsonValue(JsonValue&& other) noexcept = default;
JsonValue& JsonValue::operator=(const JsonValue& other) {
  if (this != &other) value_ = other.value_ ? std::make_unique<nlohmann::json>(*other.value_) : nullptr;
  return *this;
}
JsonValue& JsonValue::operator=(JsonValue&& other) noexcept = default;
JsonValue::~JsonValue() = default;

JsonValue JsonValue::object() { return JsonValue(nlohmann::json::object()); }

const nlohmann::json& JsonValue::get() const {
  static const nlohmann::json null;
  return value_ ? *value_ : null;
}

nlohmann::json& JsonValue::get() {
  if (!value_) value_ = std::make_unique<nlohmann::json>();
  return *value_;
}

}  // namespace ao
