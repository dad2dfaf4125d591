// SPDX-License-Identifier: Apache-2.0
#include "ao/core/json_value.h"

#include <gtest/gtest.h>

#include <initializer_list>
#include <type_traits>
#include <utility>

#include <nlohmann/json.hpp>

namespace ao {
namespace {

TEST(JsonValue, DefaultIsNullAndObjectIsEmpty) {
  const JsonValue v;
  EXPECT_TRUE(v->is_null());
  EXPECT_EQ(*JsonValue::object(), nlohmann::json::object());
}

TEST(JsonValue, CopiesAreDeepAndAssignmentsReplaceTheValue) {
  JsonValue a = nlohmann::json{{"samples", 16}, {"filter", true}};
  JsonValue b = a;
  b["samples"] = 32;
  EXPECT_EQ(a->at("samples"), 16);  // the copy does not share the original's value
  EXPECT_EQ(b->at("samples"), 32);
  EXPECT_EQ(b->at("filter"), true);
  a = b;
  EXPECT_EQ(a->at("samples"), 32);
  a = JsonValue();
  EXPECT_TRUE(a->is_null());
  EXPECT_EQ(b->size(), 2u);
}

TEST(JsonValue, AMovedFromValueIsNullAndStillUsable) {
  JsonValue a = nlohmann::json{{"rays", 7}};
  JsonValue b = std::move(a);
  EXPECT_EQ(b->at("rays"), 7);
  EXPECT_TRUE(std::as_const(a)->is_null());  // NOLINT(bugprone-use-after-move): moved-from is defined as null
  a["rays"] = 9;                              // writing makes it an object again
  EXPECT_EQ(a->at("rays"), 9);
}

TEST(JsonValue, ReadsAndWritesAsTheJsonItHolds) {
  JsonValue stats;
  stats["rays"] = 12;  // null becomes an object, as nlohmann::json's operator[] makes it
  ASSERT_TRUE(stats->is_object());
  const nlohmann::json& view = stats;  // the implicit view
  EXPECT_EQ(view.at("rays"), 12);
  const JsonValue& c = stats;
  EXPECT_EQ(c["rays"], 12);
  EXPECT_EQ(stats, (nlohmann::json{{"rays", 12}}));
  EXPECT_NE(stats, (nlohmann::json{{"rays", 13}}));
  stats = nlohmann::json{{"estimator_ms", 1.5}};
  EXPECT_EQ(stats->at("estimator_ms"), 1.5);
  // A braced list does not convert: nlohmann::json would read {{"k", v}} as an object, a
  // JsonValue would take the outer braces and hold the array ["k", v].
  static_assert(!std::is_assignable_v<JsonValue&, std::initializer_list<nlohmann::json>>);
  static_assert(std::is_convertible_v<const nlohmann::json&, JsonValue>);
  static_assert(std::is_convertible_v<nlohmann::json&&, JsonValue>);
  EXPECT_FALSE(stats->contains("rays"));
}

}  // namespace
}  // namespace ao
