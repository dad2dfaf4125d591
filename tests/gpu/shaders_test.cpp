// SPDX-License-Identifier: Apache-2.0
// The shaders as an engine takes them (src/ao/gpu/shaders/ and each method's folder, installed to
// share/ao/shaders/): each
// file is the one the library embeds, says in its comments what it computes, and documents every
// uniform it declares; every one compiles on the device.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "ao/gpu/gl_internal.h"
#include "ao/gpu/resources_internal.h"
#include "gpu/gpu_support.h"

namespace ao {
namespace {

const std::filesystem::path kSources = std::filesystem::path(AO_TESTS_DIR) / ".." / "src" / "ao";

// Every shader file under src/ao (the files the build embeds: the extensions of shader stages and
// GLSL, and the headers C++ and GLSL share), by file name (names are unique).
std::map<std::string, std::filesystem::path> shader_files() {
  static const std::set<std::string> kExtensions{".comp", ".glsl", ".vert", ".geom", ".frag"};
  const auto embedded = [](const std::filesystem::path& p) {
    const std::string name = p.filename().string();
    return kExtensions.contains(p.extension().string()) || name == "shared.h" || name.ends_with("_shared.h");
  };
  std::map<std::string, std::filesystem::path> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(kSources))
    if (embedded(entry.path())) {
      const bool unique = files.emplace(entry.path().filename().string(), entry.path()).second;
      EXPECT_TRUE(unique) << entry.path() << ": a second shader of this name (the loader finds shaders by name)";
    }
  return files;
}

std::string read(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(GpuShaders, EveryFileIsEmbeddedAsItIs) {
  std::set<std::string> embedded;
  for (const gpu_detail::EmbeddedShader& s : gpu_detail::embedded_shaders()) {
    embedded.insert(s.name);
    const auto files = shader_files();
    ASSERT_TRUE(files.contains(s.name)) << s.name << " is embedded and not in the sources";
    EXPECT_EQ(std::string(s.text), read(files.at(s.name))) << s.name;
  }
  for (const auto& [name, path] : shader_files()) EXPECT_TRUE(embedded.contains(name)) << path;
}

TEST(GpuShaders, EveryUniformIsDocumentedInItsFile) {
  const std::regex uniform(R"(^\s*uniform\s+\w+\s+(u_\w+))");
  for (const auto& [name, path] : shader_files()) {
    const std::string text = read(path);
    std::string comments;
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);)
      if (const std::size_t at = line.find("//"); at != std::string::npos) comments += line.substr(at) + "\n";
    EXPECT_NE(comments.find("//"), std::string::npos) << path << " has no comment";
    std::istringstream again(text);
    for (std::string line; std::getline(again, line);) {
      std::smatch m;
      if (!std::regex_search(line, m, uniform)) continue;
      // A uniform is documented when a comment names it (a family of them may be named together,
      // "u_basis_x/y/z").
      const std::string uniform_name = m[1];
      const std::string stem = uniform_name.substr(0, uniform_name.find_last_of('_'));
      EXPECT_TRUE(comments.find(uniform_name) != std::string::npos || comments.find(stem + "_x/y/z") != std::string::npos)
          << name << ": uniform " << uniform_name << " is not documented in its comments";
    }
  }
}

TEST(GpuShaders, EveryShaderCompilesOnTheDevice) {
  // The loader's include expansion and defines, as the methods use them.
  gpu_detail::Context& c = gpu_detail::Access::context(test::gpu_device());
  c.make_current();
  for (const auto& [name, path] : shader_files()) {
    if (path.extension() != ".comp") continue;
    if (name == "box_filter.comp") {
      EXPECT_NO_THROW(c.program({name}, "#define CHANNELS 1\n")) << name;
      EXPECT_NO_THROW(c.program({name}, "#define CHANNELS 4\n")) << name;
    } else {
      EXPECT_NO_THROW(c.program({name})) << name;
    }
  }
  EXPECT_NO_THROW(c.program({"gbuffer.vert", "gbuffer.geom", "gbuffer.frag"}));
  EXPECT_NO_THROW(c.program({"cone_voxelize.vert", "cone_voxelize.geom", "cone_voxelize.frag"}));
}

// A constant the shared headers define (AO_CONST name = literal, core/shared.h) is read from them:
// no shader types its value again (outside comments), where it could drift from the C++ kernels'.
TEST(GpuShaders, NoShaderTypesASharedConstantAgain) {
  const std::regex constant(R"(AO_CONST\s+\w+\s+(\w+)\s*=\s*([^;]+);)");
  std::vector<std::pair<std::string, std::string>> literals;  // name, literal without its suffix
  for (const auto& [name, path] : shader_files()) {
    if (!name.ends_with("_shared.h")) continue;
    const std::string text = read(path);
    for (auto it = std::sregex_iterator(text.begin(), text.end(), constant); it != std::sregex_iterator(); ++it) {
      std::string literal = (*it)[2];
      if (!literal.empty() && (literal.back() == 'f' || literal.back() == 'u')) literal.pop_back();
      literals.emplace_back((*it)[1], literal);
    }
  }
  ASSERT_GT(literals.size(), 10u) << "the shared headers' constants were not found";
  for (const auto& [name, path] : shader_files()) {
    if (name.ends_with(".h")) continue;
    std::istringstream lines(read(path));
    for (std::string line; std::getline(lines, line);) {
      const std::string code = line.substr(0, line.find("//"));
      for (const auto& [constant_name, literal] : literals)
        EXPECT_EQ(code.find(literal), std::string::npos) << name << " types " << constant_name << " (" << literal << ") again: " << line;
    }
  }
}

}  // namespace
}  // namespace ao
