// The shaders as an engine takes them (src/ao/gpu/shaders/, installed to share/ao/shaders/): each
// file is the one the library embeds, says in its comments what it computes, and documents every
// uniform it declares; every one compiles on the device.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "ao/gpu/gl_internal.h"
#include "ao/gpu/resources_internal.h"
#include "gpu/gpu_support.h"

namespace ao {
namespace {

const std::filesystem::path kShaders = std::filesystem::path(AO_TESTS_DIR) / ".." / "src" / "ao" / "gpu" / "shaders";

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
    EXPECT_EQ(std::string(s.text), read(kShaders / s.name)) << s.name;
  }
  for (const auto& entry : std::filesystem::directory_iterator(kShaders))
    EXPECT_TRUE(embedded.contains(entry.path().filename().string())) << entry.path();
}

TEST(GpuShaders, EveryUniformIsDocumentedInItsFile) {
  const std::regex uniform(R"(^\s*uniform\s+\w+\s+(u_\w+))");
  for (const auto& entry : std::filesystem::directory_iterator(kShaders)) {
    const std::string text = read(entry.path());
    std::string comments;
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);)
      if (const std::size_t at = line.find("//"); at != std::string::npos) comments += line.substr(at) + "\n";
    EXPECT_NE(comments.find("//"), std::string::npos) << entry.path() << " has no comment";
    std::istringstream again(text);
    for (std::string line; std::getline(again, line);) {
      std::smatch m;
      if (!std::regex_search(line, m, uniform)) continue;
      // A uniform is documented when a comment names it (a family of them may be named together,
      // "u_basis_x/y/z").
      const std::string name = m[1];
      const std::string stem = name.substr(0, name.find_last_of('_'));
      EXPECT_TRUE(comments.find(name) != std::string::npos || comments.find(stem + "_x/y/z") != std::string::npos)
          << entry.path().filename() << ": uniform " << name << " is not documented in its comments";
    }
  }
}

TEST(GpuShaders, EveryShaderCompilesOnTheDevice) {
  // The loader's include expansion and defines, as the methods use them.
  gpu_detail::Context& c = gpu_detail::Access::context(test::gpu_device());
  c.make_current();
  for (const auto& entry : std::filesystem::directory_iterator(kShaders)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() != ".comp") continue;
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

}  // namespace
}  // namespace ao
