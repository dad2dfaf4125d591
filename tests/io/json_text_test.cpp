// SPDX-License-Identifier: Apache-2.0
// JSON from users' files and options (json_text.h): the depth limit found while parsing, the size
// limit of files, and messages that never quote the value.
#include "ao/io/json_text.h"

#include <gtest/gtest.h>

#include <string>

#include "ao/core/error.h"
#include "ao/io/mesh_io.h"
#include "support/run.h"

namespace ao {
namespace {

// `fn` throws InputError, one line containing `needle`.
template <class Fn>
void expect_input_error(Fn&& fn, const std::string& needle) {
  try {
    fn();
    ADD_FAILURE() << "no error, expected " << needle;
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

std::string nested(int depth) { return std::string(static_cast<std::size_t>(depth), '[') + std::string(static_cast<std::size_t>(depth), ']'); }

TEST(JsonText, DepthUpToTheLimitParsesAndBeyondIsOneLine) {
  const std::optional<nlohmann::json> ok = parse_json_limited(nested(kMaxJsonDepth), "x");
  ASSERT_TRUE(ok.has_value());
  EXPECT_TRUE(ok->is_array());
  for (int depth : {kMaxJsonDepth + 1, 1000, 200000}) {
    SCOPED_TRACE(depth);
    try {
      (void)parse_json_limited(nested(depth), "--param x");
      FAIL() << "accepted";
    } catch (const InputError& e) {
      EXPECT_STREQ(e.what(), "--param x: JSON nests deeper than 64 levels");
    }
  }
}

// Found by scripts/mutate on glTF: a key written twice ("nodes") passed ao's check with one value
// while assimp's reader used the other. An object with a key twice is refused, wherever JSON comes from.
TEST(JsonText, AKeyTwiceInOneObjectIsRefused) {
  expect_input_error([] { (void)parse_json_limited(R"({"fov": 40, "eye": [0, 0, 1], "fov": 60})", "cam.json"); },
                     "cam.json: JSON has the key 'fov' twice in one object");
  EXPECT_TRUE(parse_json_limited(R"({"a": {"fov": 1}, "b": {"fov": 2}})", "x").has_value()) << "the same key in two objects is fine";
  test::TempDir dir;
  const std::string gltf = R"({"asset": {"version": "2.0"}, "nodes": [], "nodes": [{"mesh": 0}]})";
  try {
    (void)load_scene_file(dir.write("twice.gltf", gltf));
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("twice.gltf: glTF JSON has the key 'nodes' twice in one object"), std::string::npos) << e.what();
  }
}

TEST(JsonText, NotJsonIsNoValueAndNotAnError) {
  EXPECT_FALSE(parse_json_limited("gtao", "x").has_value());
  EXPECT_FALSE(parse_json_limited("[1, 2", "x").has_value());
  EXPECT_FALSE(parse_json_limited("1 2", "x").has_value());
  EXPECT_EQ(parse_json_limited("0.5", "x").value(), nlohmann::json(0.5));
}

TEST(JsonText, FileErrorsNameTheFileAndThePlaceNotTheValue) {
  test::TempDir dir;
  expect_input_error([&] { (void)read_json_file(dir.write("bad.json", "{\n  \"eye\": [1, 2,\n  oops]\n}"), "a camera"); }, "bad.json: is not valid JSON (line 3, column 3; expected a camera)");
  expect_input_error([&] { (void)read_json_file(dir.write("empty.json", " \n"), "a camera"); }, "empty.json: is empty (expected a camera)");
  expect_input_error([&] { (void)read_json_file(dir / "missing.json", "a camera"); }, "missing.json: cannot open the file");
  expect_input_error([&] { (void)read_json_file(dir.path(), "a camera"); }, "is a directory, not a JSON file");
  expect_input_error([&] { (void)read_json_file(dir.write("deep.json", "{\"a\": " + nested(100000) + "}"), "a camera"); }, "deep.json: JSON nests deeper than 64 levels");
  // Larger than 16 MiB: refused by its size, before it is parsed.
  expect_input_error([&] { (void)read_json_file(dir.write("big.json", "[" + std::string(kMaxJsonFileBytes, ' ') + "]"), "a camera"); }, "larger than the 16 MiB");
  EXPECT_EQ(read_json_file(dir.write("ok.json", "{\"fov\": 40}"), "a camera").at("fov"), 40);
}

TEST(JsonText, ExcerptIsShortAndOneLine) {
  EXPECT_EQ(json_excerpt(nlohmann::json({1, 2, 3})), "[1,2,3]");
  nlohmann::json many = nlohmann::json::array();
  for (int k = 0; k < 1000; ++k) many.push_back(k);
  const std::string e = json_excerpt(many);
  EXPECT_EQ(e.size(), 43u);
  EXPECT_TRUE(e.ends_with("..."));
  EXPECT_EQ(json_excerpt(nlohmann::json("a\nb")), "\"a\\nb\"");  // JSON escapes line breaks itself
}

}  // namespace
}  // namespace ao
