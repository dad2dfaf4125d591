// SPDX-License-Identifier: Apache-2.0
// Every source file of the repository names its licence in an SPDX line (Apache-2.0, LICENSE), as
// Debian's and other distributions' licence checkers read it: C++, GLSL, Python, shell, CMake and
// the scripts, in the first line or right after a #! or #version line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

const fs::path kRoot = fs::path(AO_TESTS_DIR) / "..";

// The comment a file of this name carries its SPDX line in ("" = not a source file).
std::string comment_of(const fs::path& p, const fs::path& relative) {
  const std::string ext = p.extension().string(), name = p.filename().string();
  for (const char* e : {".cpp", ".h", ".comp", ".vert", ".frag", ".geom", ".glsl", ".js"})
    if (ext == e) return "//";
  for (const char* e : {".py", ".pyi", ".sh", ".cmake"})
    if (ext == e) return "#";
  if (name == "CMakeLists.txt" || relative.begin()->string() == "scripts" || relative == fs::path(".ci/run")) return "#";
  return "";
}

TEST(Licence, EverySourceFileHasAnSpdxLine) {
  std::vector<std::string> missing;
  std::size_t checked = 0;
  for (const char* dir : {"src", "python", "tests", "bench", "examples", "fuzz", "scripts", "cmake", ".ci"}) {
    if (!fs::is_directory(kRoot / dir)) continue;
    for (const auto& entry : fs::recursive_directory_iterator(kRoot / dir)) {
      if (!entry.is_regular_file()) continue;
      const fs::path relative = fs::relative(entry.path(), kRoot);
      const std::string rel = relative.generic_string();
      if (rel.starts_with("tests/data/") || rel.starts_with("fuzz/seeds/") || rel.find("__pycache__") != std::string::npos) continue;
      const std::string comment = comment_of(entry.path(), relative);
      if (comment.empty()) continue;
      std::ifstream in(entry.path());
      std::string first, second;
      std::getline(in, first);
      std::getline(in, second);
      const std::string want = comment + " SPDX-License-Identifier: Apache-2.0";
      const bool after_header = first.starts_with("#!") || first.starts_with("#version");
      if ((after_header ? second : first) != want) missing.push_back(rel);
      ++checked;
    }
  }
  const std::string top = (kRoot / "CMakeLists.txt").string();
  std::ifstream in(top);
  std::string first;
  std::getline(in, first);
  if (first != "# SPDX-License-Identifier: Apache-2.0") missing.push_back("CMakeLists.txt");
  EXPECT_GT(checked, 500u);  // the walk found the tree
  std::string list;
  for (const std::string& m : missing) list += "\n  " + m;
  EXPECT_TRUE(missing.empty()) << missing.size() << " source files without the SPDX line (first line, or the second after #! or #version):" << list;
}

}  // namespace
