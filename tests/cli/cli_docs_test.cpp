// SPDX-License-Identifier: Apache-2.0
// The man pages and shell completions scripts/cli-docs makes from ao's --help (as the build does
// into build/cli-docs/): the sections help2man cannot take from --help, and completion of values.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "support/run.h"

namespace ao {
namespace {

namespace fs = std::filesystem;

// Runs `command` under bash; returns its stdout.
std::string shell(const std::string& command, const fs::path& dir) {
  const fs::path script = dir / "cmd.sh", out = dir / "cmd.out";
  test::write_text(script, command + "\n");
  std::string run = "bash ";
  run.append(script.string()).append(" > ").append(out.string()).append(" 2>&1");
  EXPECT_EQ(std::system(run.c_str()), 0) << test::read_text(out);
  return test::read_text(out);
}

struct CliDocs : ::testing::Test {
  test::TempDir dir;
  void SetUp() override {
    std::string command = "bash '" AO_TESTS_DIR "/../scripts/cli-docs' '" AO_CLI_PATH "' '";
    command.append((dir / "docs").string()).append("' 0.0.0");
    shell(command, dir.path());
  }
  // What bash completion offers for `words` (the last one being completed), in an empty folder.
  std::string complete(const std::string& words) {
    fs::create_directories(dir / "empty");
    std::string command = "source '";
    command.append((dir / "docs/bash-completion/ao").string()).append("'; cd '").append((dir / "empty").string()).append("'; COMP_WORDS=(");
    command.append(words).append("); COMP_CWORD=$((${#COMP_WORDS[@]} - 1)); _ao; echo \"${COMPREPLY[*]}\"");
    return shell(command, dir.path());
  }
};

TEST_F(CliDocs, BashCompletesTheValuesTheHelpLists) {
  EXPECT_EQ(complete("ao render -m gt"), "gtao\n");
  EXPECT_EQ(complete("ao render -m ra"), "raytraced\n");
  EXPECT_EQ(complete("ao render --membership s"), "step sqrt\n");
  EXPECT_EQ(complete("ao render we"), "wedge\n");  // a built-in scene (no file of that name here)
  EXPECT_EQ(complete("ao params bake-h"), "bake-histogram bake-high-to-low\n");
  EXPECT_EQ(complete("ao compare --device g"), "gpu\n");
  EXPECT_EQ(complete("ao ren"), "render\n");
  EXPECT_EQ(complete("ao bake --memb"), "--membership\n");
}

TEST_F(CliDocs, ZshCompletionHasTheSameValues) {
  const std::string zsh = test::read_text(dir / "docs/zsh-completion/_ao");
  EXPECT_EQ(zsh.rfind("#compdef ao\n", 0), 0u);
  EXPECT_NE(zsh.find("values=\"raytraced containment volumetric transfer cone alchemy gtao\""), std::string::npos);
  EXPECT_NE(zsh.find("positional=\"default plane wedge sphere-on-plane box-room displaced\""), std::string::npos);
}

TEST_F(CliDocs, ManPagesHaveExamplesExitStatusEnvironmentAndFiles) {
  if (!fs::exists(dir / "docs/man1/ao-render.1")) GTEST_SKIP() << "help2man is not installed: no man pages";
  const std::string render = test::read_text(dir / "docs/man1/ao-render.1");
  for (const char* section : {".SH EXAMPLES", ".SH \"EXIT STATUS\"", ".SH ENVIRONMENT", "AO_PROGRESS_SECONDS", ".SH \"SEE ALSO\""})
    EXPECT_NE(render.find(section), std::string::npos) << section;
  EXPECT_NE(render.find("\nao render "), std::string::npos) << "no example of ao render";
  const std::string see_also = render.substr(render.find(".SH \"SEE ALSO\""));
  EXPECT_EQ(see_also.find("ao\\-render(1)"), std::string::npos) << "SEE ALSO names the page itself: " << see_also;
  EXPECT_EQ(see_also.find("ao-render(1)"), std::string::npos) << "SEE ALSO names the page itself: " << see_also;
  EXPECT_NE(see_also.find("ao(1)"), std::string::npos) << see_also;
  const std::string compare = test::read_text(dir / "docs/man1/ao-compare.1");
  for (const char* section : {".SH FILES", "AO_FONT", "DejaVuSans.ttf"}) EXPECT_NE(compare.find(section), std::string::npos) << section;
}

}  // namespace
}  // namespace ao
