// One option vocabulary (docs/cli.md): the table of shared options agrees with every command's
// --help both ways, and a wrong command line gets one line in ao's words with a suggestion.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "support/run.h"

namespace ao {
namespace {

const std::vector<std::string> kCommands = {"render", "bake", "compare", "tune", "view", "params"};

// Every option name in `ao COMMAND --help` ("--width", "-o").
std::set<std::string> help_options(const std::string& command) {
  const test::RunResult r = test::run_ao(command + " --help");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  std::set<std::string> names;
  std::istringstream lines(r.out);
  const std::regex option(R"(^  ((?:-[A-Za-z],)?--[a-z-]+(?:,--[a-z-]+)*))");
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (!std::regex_search(line, m, option)) continue;
    std::istringstream parts(m[1].str());
    for (std::string p; std::getline(parts, p, ',');) names.insert(p);
  }
  return names;
}

// docs/cli.md's table: option name -> the commands it lists.
std::map<std::string, std::set<std::string>> documented() {
  std::ifstream in(std::string(AO_TESTS_DIR) + "/../docs/cli.md");
  std::map<std::string, std::set<std::string>> table;
  const std::regex row(R"(^\| (`-[^|]*) \| ([a-z, ]+) \|)");
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (!std::regex_search(line, m, row)) continue;
    std::set<std::string> commands;
    std::istringstream cs(m[2].str());
    for (std::string c; std::getline(cs, c, ',');) commands.insert(c.substr(c.find_first_not_of(' ')));
    const std::string names = m[1].str();
    const std::regex name("`(-[^`]+)`");
    for (auto it = std::sregex_iterator(names.begin(), names.end(), name); it != std::sregex_iterator(); ++it) table[(*it)[1]] = commands;
  }
  return table;
}

TEST(Vocabulary, TheDocumentedTableIsWhatEachCommandTakes) {
  std::map<std::string, std::set<std::string>> seen;  // option -> commands whose help has it
  for (const std::string& c : kCommands)
    for (const std::string& o : help_options(c)) seen[o].insert(c);
  const auto table = documented();
  ASSERT_GT(table.size(), 15u) << "docs/cli.md's table was not found";
  for (const auto& [option, commands] : table) EXPECT_EQ(seen[option], commands) << option << " in docs/cli.md";
  for (const auto& [option, commands] : seen) {
    if (commands.size() > 1) {
      EXPECT_TRUE(table.count(option)) << option << " is taken by several commands but not in docs/cli.md";
    }
  }
}

TEST(Vocabulary, AMistypedCommandOrOptionGetsTheClosestName) {
  test::expect_one_line_error(test::run_ao("rendr"), "unknown command 'rendr'; did you mean 'render'?", 2);
  test::expect_one_line_error(test::run_ao(""), "name a command: render, bake", 2);
  test::expect_one_line_error(test::run_ao("render --widht 4"), "render: unknown option '--widht'; did you mean '--width'?", 2);
  test::expect_one_line_error(test::run_ao("bake --sampels 3"), "bake: unknown option '--sampels'; did you mean '--samples'?", 2);
  test::expect_one_line_error(test::run_ao("render --zzzzzzzz"), "render: unknown option '--zzzzzzzz' (ao render --help", 2);
  test::expect_one_line_error(test::run_ao("tune -m alchemy"), "tune: --fit is required", 2);
}

TEST(Vocabulary, AValueOfTheWrongTypeIsNamedInAosWords) {
  test::expect_one_line_error(test::run_ao("render --width abc"), "--width: expected a whole number, got 'abc'");
  test::expect_one_line_error(test::run_ao("--threads two render"), "--threads: expected a whole number, got 'two'");
  test::expect_one_line_error(test::run_ao("render --seed -1"), "--seed: expected a whole number >= 0, got '-1'");
}

TEST(Vocabulary, CompareTakesKeyValueForEveryChosenMethodThatHasIt) {
  test::TempDir dir;
  const test::RunResult r = test::run_ao("compare --methods alchemy,gtao -p intensity=0.3 -p gtao.slices=3 --width 32 --height 18 "
                                         "--reference-samples 4 --json -q --out-dir out",
                                         dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"intensity\": 0.3"), std::string::npos);
  EXPECT_NE(r.out.find("\"slices\": 3"), std::string::npos);
  test::expect_one_line_error(test::run_ao("compare --methods gtao -p intensity=0.3", dir.path()), "no chosen method has a parameter 'intensity'");
  // -p @FILE as in the other commands: a parameter file's keys for every chosen method that has them.
  std::ofstream(dir / "p.json") << R"({"parameters": {"intensity": 0.25}})";
  const test::RunResult f = test::run_ao("compare --methods alchemy,gtao -p @p.json --width 32 --height 18 --reference-samples 4 --json -q --out-dir out2",
                                         dir.path());
  ASSERT_EQ(f.exit_code, 0) << f.err;
  EXPECT_NE(f.out.find("\"intensity\": 0.25"), std::string::npos);
}

}  // namespace
}  // namespace ao
