// SPDX-License-Identifier: Apache-2.0
// Library errors in library words: the job layer names the request's fields (jobs/fields.h), the
// command line its options (src/cli/field_names.cpp), each from one table that covers every field.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "ao/core/error.h"
#include "ao/jobs/bake.h"
#include "ao/jobs/fields.h"
#include "ao/jobs/render.h"
#include "field_names.h"
#include "support/run.h"

namespace ao {
namespace {

namespace fs = std::filesystem;

TEST(FieldNames, EveryRequestFieldHasAnOption) {
  for (std::string_view f : fields::kAll) {
    EXPECT_FALSE(cli::option_name(f).empty()) << f << " has no option in src/cli/field_names.cpp";
    EXPECT_TRUE(InputError(field(f)).fields() == std::vector<std::string>{std::string(f)}) << f << " is not a field name (error.h)";
  }
}

TEST(FieldNames, MarksReadAsTheLibrarysNamesAndAsEachCallersOwn) {
  const InputError e(field("BakeRequest::padding") + " must be in [0, 1024] texels, got " + field("X::y") + " or \x1f" + "a b\x1f" + " end\x1f");
  // Marks around something that is not a field name, and a mark without its pair, stay text.
  EXPECT_EQ(std::string(e.what()), "BakeRequest::padding must be in [0, 1024] texels, got X::y or \x1f" "a b\x1f end\x1f");
  EXPECT_EQ((e.fields()), (std::vector<std::string>{"BakeRequest::padding", "X::y"}));
  const std::string named = e.message([](std::string_view f) { return f == "X::y" ? std::string() : "--" + std::string(f.substr(f.find(':') + 2)); });
  EXPECT_EQ(named, "--padding must be in [0, 1024] texels, got X::y or \x1f" "a b\x1f end\x1f");
  // Rethrown with context, the marks go along.
  const InputError wrapped("mesh.obj: " + e.marked());
  EXPECT_EQ(wrapped.message(cli::option_name), "mesh.obj: --padding must be in [0, 1024] texels, got X::y or \x1f" "a b\x1f end\x1f");
}

TEST(FieldNames, JobErrorsNameRequestFields) {
  BakeRequest b;
  b.inputs = {"unused.obj"};
  b.padding = 2000;
  try {
    run_bake(b);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "BakeRequest::padding must be in [0, 1024] texels, got 2000");
  }
  RenderRequest r;
  r.scene.args = {"wedge"};
  r.camera.width = 0;
  try {
    check_render_request(r);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "CameraRequest::width must be in [1, 32768] pixels, got 0");
  }
}

TEST(FieldNames, TheCommandLineNamesItsOptions) {
  test::expect_one_line_error(test::run_ao("bake wedge --padding 2000 -o x.png"), "ao: error: --padding must be in [0, 1024] texels, got 2000");
  test::expect_one_line_error(test::run_ao("render wedge --width 0 -o x.png"), "ao: error: --width must be in [1, 32768] pixels, got 0");
  test::expect_one_line_error(test::run_ao("bake wedge --cage-extrusion 0.1 -o x.png"),
                              "ao: error: --cage, --cage-extrusion, --max-front, --max-back and --miss-mask need --high");
}

// The job layer's sources name no command-line option in a string: every message names fields.
TEST(FieldNames, TheJobLayerNamesNoOption) {
  const std::regex option(R"re("[^"]*(^|[ (/,])--?[a-z][a-z-]*[ ":,.)])re");
  for (const auto& entry : fs::directory_iterator(fs::path(AO_TESTS_DIR) / ".." / "src" / "ao" / "jobs")) {
    std::ifstream in(entry.path());
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
      const std::string code = line.substr(0, line.find("//"));
      std::smatch m;
      if (std::regex_search(code, m, option)) ADD_FAILURE() << entry.path().filename().string() << ":" << number << ": " << line;
    }
  }
}

}  // namespace
}  // namespace ao
