// SPDX-License-Identifier: Apache-2.0
// The parameter tables in docs/ are generated from the code's tables (scripts/update-docs): these
// tests fail while a doc is stale, and while a table has no doc.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "ao/core/params.h"
#include "ao/registry/registry.h"

namespace {

namespace fs = std::filesystem;

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const fs::path kDocs = fs::path(AO_TESTS_DIR) / ".." / "docs";

TEST(DocsParams, EveryGeneratedBlockMatchesItsParameterTable) {
  const std::regex block(R"(<!-- params ([\w-]+) -->\n([\s\S]*?)<!-- /params -->)");
  int blocks = 0;
  for (const auto& entry : fs::recursive_directory_iterator(kDocs)) {
    if (entry.path().extension() != ".md") continue;
    const std::string text = read(entry.path());
    for (std::sregex_iterator it(text.begin(), text.end(), block), end; it != end; ++it) {
      ++blocks;
      const std::string name = (*it)[1];
      EXPECT_EQ((*it)[2].str(), ao::params_markdown(ao::find_param_table(name).specs()))
          << entry.path() << ": the table of " << name << " is stale; run scripts/update-docs";
    }
  }
  EXPECT_GT(blocks, 0);
}

TEST(DocsParams, EveryParameterTableIsInTheDocs) {
  std::set<std::string> documented;
  const std::regex marker(R"(<!-- params ([\w-]+) -->)");
  for (const auto& entry : fs::recursive_directory_iterator(kDocs)) {
    if (entry.path().extension() != ".md") continue;
    const std::string text = read(entry.path());
    for (std::sregex_iterator it(text.begin(), text.end(), marker), end; it != end; ++it) documented.insert((*it)[1]);
  }
  for (const ao::ParamTableInfo& t : ao::all_param_tables()) EXPECT_TRUE(documented.count(std::string(t.name))) << t.name << " has no generated table in docs/";
}

}  // namespace
