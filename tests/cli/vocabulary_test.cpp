// SPDX-License-Identifier: Apache-2.0
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

// The line of `ao COMMAND --help` that describes `option` ("--membership"), with its
// continuation lines; empty when the command has no such option.
std::string help_line(const std::string& command, const std::string& option) {
  const test::RunResult r = test::run_ao(command + " --help");
  std::istringstream lines(r.out);
  std::string found;
  const std::regex names(R"(^  ((?:-[A-Za-z],)?--[a-z-]+(?:,--[a-z-]+)*))");
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (std::regex_search(line, m, names)) {
      if (!found.empty()) break;
      std::istringstream parts(m[1].str());
      for (std::string p; std::getline(parts, p, ',');)
        if (p == option) found = line;
    } else if (!found.empty() && line.rfind("   ", 0) == 0) {
      found.append(1, ' ').append(line, line.find_first_not_of(' '));
    } else if (!found.empty()) {
      break;
    }
  }
  return found;
}

// The default a help line shows ("--seed UINT=1" -> "1"), or "".
std::string help_default(const std::string& line) {
  std::smatch m;
  static const std::regex with_default(R"(^  \S+ \S*?=(\S+))");
  return std::regex_search(line, m, with_default) ? m[1].str() : "";
}

// The values a help line lists: "[one of a, b]", a type "a|b", or a description ending ": a, b, c"
// (single words, perhaps before a remark in parentheses); empty when it lists none.
std::set<std::string> help_values(const std::string& line) {
  std::smatch m;
  std::string list;
  if (std::regex_search(line, m, std::regex(R"(\[one of ([^\]]+)\])"))) list = m[1].str();
  else if (std::regex_search(line, m, std::regex(R"(^  \S+ ([a-z-]+(?:\|[a-z-]+)+))"))) list = std::regex_replace(m[1].str(), std::regex("\\|"), ", ");
  else if (std::regex_search(line, m, std::regex(R"(: ([a-z-]+(?:, [a-z-]+)+)(?: \(|$))"))) list = m[1].str();
  std::set<std::string> values;
  const std::regex word("[a-z-]+");
  for (auto it = std::sregex_iterator(list.begin(), list.end(), word); it != std::sregex_iterator(); ++it) values.insert(it->str());
  return values;
}

TEST(Vocabulary, TheDocumentedDefaultsAndValuesAreWhatHelpSays) {
  // Each row's meaning is segments separated by "; ", a segment that starts "bake: " (or
  // "bake, view: ") about those commands, the others about the rest. A segment's default is written
  // "default `X`", "`X` (default)" or "(default X)"; its values are its words in backticks.
  std::ifstream in(std::string(AO_TESTS_DIR) + "/../docs/cli.md");
  const std::regex row(R"(^\| (`-[^|]*) \| ([a-z, ]+) \| (.*) \|$)");
  int checked = 0;
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (!std::regex_search(line, m, row)) continue;
    const std::string cell = m[1].str(), meaning = m[3].str();
    const std::string option = cell.substr(1, cell.find('`', 1) - 1);
    std::set<std::string> rest;
    std::istringstream cs(m[2].str());
    for (std::string c; std::getline(cs, c, ',');) rest.insert(c.substr(c.find_first_not_of(' ')));
    std::vector<std::pair<std::set<std::string>, std::string>> segments;  // commands -> text
    std::string general;
    std::size_t at = 0;
    while (at <= meaning.size()) {
      const std::size_t end = std::min(meaning.find("; ", at), meaning.size());
      const std::string seg = meaning.substr(at, end - at);
      std::smatch p;
      std::set<std::string> named;
      if (std::regex_search(seg, p, std::regex(R"(^([a-z]+(?:, [a-z]+)*)(?: \([^)]*\))?: )"))) {
        std::istringstream ns(p[1].str());
        for (std::string c; std::getline(ns, c, ',');) named.insert(c.substr(c.find_first_not_of(' ')));
      }
      bool all_known = !named.empty();
      for (const std::string& c : named) all_known = all_known && rest.count(c);
      if (all_known) {
        segments.emplace_back(named, seg);
        for (const std::string& c : named) rest.erase(c);
      } else {
        general += seg + " ";
      }
      at = end + 2;
    }
    segments.emplace_back(rest, general);
    for (const auto& [commands, text] : segments) {
      std::smatch d;
      std::string documented_default;
      if (std::regex_search(text, d, std::regex(R"(default `([^`]+)`|`([^`]+)` \(default\)|\(default ([^) ]+)\))")))
        documented_default = d[1].matched ? d[1].str() : d[2].matched ? d[2].str() : d[3].str();
      std::set<std::string> documented_values;
      const std::regex quoted("`([a-z][a-z-]*)`");
      for (auto it = std::sregex_iterator(text.begin(), text.end(), quoted); it != std::sregex_iterator(); ++it)
        documented_values.insert((*it)[1].str());
      for (const std::string& c : commands) {
        const std::string help = help_line(c, option);
        ASSERT_FALSE(help.empty()) << option << ": no line in ao " << c << " --help";
        if (!documented_default.empty()) {
          EXPECT_EQ(help_default(help), documented_default) << option << " of " << c << ": docs/cli.md says default " << documented_default << ", --help: " << help;
          ++checked;
        }
        const std::set<std::string> values = help_values(help);
        if (!values.empty()) {
          EXPECT_EQ(documented_values, values) << option << " of " << c << ": the values docs/cli.md lists differ from --help: " << help;
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 10) << "docs/cli.md's defaults and values were not found";
}

TEST(Vocabulary, AMistypedCommandOrOptionGetsTheClosestName) {
  test::expect_one_line_error(test::run_ao("rendr"), "unknown command 'rendr'; did you mean 'render'?", 2);
  test::expect_one_line_error(test::run_ao(""), "name a command: render, bake", 2);
  test::expect_one_line_error(test::run_ao("render --widht 4"), "render: unknown option '--widht'; did you mean '--width'?", 2);
  test::expect_one_line_error(test::run_ao("bake --sampels 3"), "bake: unknown option '--sampels'; did you mean '--samples'?", 2);
  test::expect_one_line_error(test::run_ao("render --zzzzzzzz"), "render: unknown option '--zzzzzzzz' (ao render --help", 2);
  test::expect_one_line_error(test::run_ao("tune -m alchemy"), "tune: --fit is required", 2);
}

TEST(Vocabulary, AMistypedValueGetsTheClosestName) {
  test::TempDir dir;
  test::expect_one_line_error(test::run_ao("render -m gtoa"), "unknown method 'gtoa' (known: ", 1);
  test::expect_one_line_error(test::run_ao("render -m gtoa"), "; did you mean 'gtao'?", 1);
  test::expect_one_line_error(test::run_ao("render -m raytrace"), "; did you mean 'raytraced'?", 1);
  test::expect_one_line_error(test::run_ao("render wedge -m gtao -p slcies=4"), "has no parameter 'slcies' (it has: ", 1);
  test::expect_one_line_error(test::run_ao("render wedge -m gtao -p slcies=4"), "; did you mean 'slices'?", 1);
  test::expect_one_line_error(test::run_ao("render wedge -m gtao -p gtao.slcies=4"), "; did you mean 'slices'?", 1);
  test::expect_one_line_error(test::run_ao("compare wedge --methods gtao -p gtao.slcies=4"), "; did you mean 'slices'?", 1);
  test::expect_one_line_error(test::run_ao("compare wedge --methods alchemy,gtao -p slcies=4"), "; did you mean 'slices'?", 1);
  test::expect_one_line_error(test::run_ao("render wedge -m cone -p preset=hihg"), "preset must be one of low, medium, high, got \"hihg\"; did you mean 'high'?", 1);
  test::expect_one_line_error(test::run_ao("render wdge"), "not a built-in scene (default, plane, wedge", 1);
  test::expect_one_line_error(test::run_ao("render wdge"), "; did you mean 'wedge'?", 1);
  test::expect_one_line_error(test::run_ao("render wedge -o x.pgn", dir.path()), "; did you mean '.png'?", 1);
  test::expect_one_line_error(test::run_ao("render wedge --membership stpe"), "; did you mean 'step'?", 1);
  test::expect_one_line_error(test::run_ao("render wedge --device gpuu"), "; did you mean 'gpu'?", 1);
  test::expect_one_line_error(test::run_ao("render wedge --normal shadng"), "; did you mean 'shading'?", 1);
  test::expect_one_line_error(test::run_ao("compare wedge --reference obscurnce"), "; did you mean 'obscurance'?", 1);
  test::expect_one_line_error(test::run_ao("tune -m gtoa --fit slices"), "; did you mean 'gtao'?", 1);
  test::expect_one_line_error(test::run_ao("params gtoa"), "; did you mean 'gtao'?", 1);
  test::expect_one_line_error(test::run_ao("bake x.obj -m histogrm", dir.path()), "; did you mean 'histogram'?", 1);
  // Nothing close: no suggestion.
  const test::RunResult far = test::run_ao("render -m sphere");
  EXPECT_EQ(far.err.find("did you mean"), std::string::npos) << far.err;
}

TEST(Vocabulary, AnOptionWithoutItsValueSaysWhatItExpects) {
  test::expect_one_line_error(test::run_ao("render -p"), "render: --param needs a value: KEY=VALUE", 2);
  test::expect_one_line_error(test::run_ao("render wedge --seed"), "render: --seed needs a value: a whole number >= 0", 2);
  test::expect_one_line_error(test::run_ao("render wedge --width"), "render: --width needs a value: a whole number", 2);
  // bake takes no -p (its settings are options of their own): said so, and no single-letter guess.
  const test::RunResult bake = test::run_ao("bake x.obj -p");
  test::expect_one_line_error(bake, "bake: unknown option '-p': an option of render, compare, view, tune, not of bake", 2);
  EXPECT_EQ(bake.err.find("did you mean"), std::string::npos) << bake.err;
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
  // -m, as render, view, tune and bake spell the method: the same option as --methods.
  const test::RunResult m = test::run_ao("compare -m gtao --width 32 --height 18 --reference-samples 4 --json -q --out-dir out3", dir.path());
  ASSERT_EQ(m.exit_code, 0) << m.err;
  EXPECT_NE(m.out.find("\"method\": \"gtao\""), std::string::npos);
  EXPECT_EQ(m.out.find("\"method\": \"alchemy\""), std::string::npos);
}

}  // namespace
}  // namespace ao
