// SPDX-License-Identifier: Apache-2.0
// The headers C++ and GLSL both read (*_shared.h: core/shared.h says how): a compute shader built
// from them on the device writes each constant's bits and each shared function's results into a
// buffer, and every one equals what the C++ compiler made of the same text. The check would fail
// if a constant were typed again in a shader with another value, or a header stopped compiling as
// GLSL.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "ao/core/color_shared.h"
#include "ao/core/hash_shared.h"
#include "ao/gpu/gl_internal.h"
#include "ao/gpu/resources_internal.h"
#include "ao/methods/alchemy/alchemy_shared.h"
#include "ao/methods/cone/cone_shared.h"
#include "ao/methods/gtao/gtao_shared.h"
#include "ao/methods/screen_space_shared.h"
#include "gpu/gpu_support.h"

namespace ao {
namespace {

// One line per value: its name, the GLSL expression of its bits, and the C++ value's bits.
struct Row {
  std::string name, glsl;
  std::uint32_t cpu;
};

std::uint32_t bits(float f) { return std::bit_cast<std::uint32_t>(f); }

std::vector<Row> rows() {
  using namespace shared;
  const auto f = [](const char* name, const char* glsl, float v) { return Row{name, std::string("floatBitsToUint(") + glsl + ")", bits(v)}; };
  const auto u = [](const char* name, const char* glsl, std::uint32_t v) { return Row{name, glsl, v}; };
  return {
      u("kHashMultiplier1", "kHashMultiplier1", kHashMultiplier1),
      u("kHashMultiplier2", "kHashMultiplier2", kHashMultiplier2),
      u("kHashGolden", "kHashGolden", kHashGolden),
      u("hash32", "hash32(123456789u)", hash32(123456789u)),
      u("hash_combine", "hash_combine(0xdeadbeefu, 42u)", hash_combine(0xdeadbeefu, 42u)),
      u("pixel_seed", "pixel_seed(7u, 1919, 1079)", pixel_seed(7u, 1919, 1079)),
      f("to_unit_float", "to_unit_float(0xfedcba98u)", to_unit_float(0xfedcba98u)),
      f("kLuminanceR", "kLuminanceR", kLuminanceR),
      f("kLuminanceG", "kLuminanceG", kLuminanceG),
      f("kLuminanceB", "kLuminanceB", kLuminanceB),
      f("kMinViewCosine", "kMinViewCosine", kMinViewCosine),
      f("kAlchemyMaxPixelRadius", "kAlchemyMaxPixelRadius", kAlchemyMaxPixelRadius),
      f("kAlchemyCoordOffset", "kAlchemyCoordOffset", kAlchemyCoordOffset),
      u("kInvSqrtMagic", "kInvSqrtMagic", kInvSqrtMagic),
      f("kAcosFit0", "kAcosFit0", kAcosFit0),
      f("kAcosFit1", "kAcosFit1", kAcosFit1),
      f("kAcosFit2", "kAcosFit2", kAcosFit2),
      f("kAcosFit3", "kAcosFit3", kAcosFit3),
      f("kAcosFit4", "kAcosFit4", kAcosFit4),
      f("kAcosFit5", "kAcosFit5", kAcosFit5),
      f("kAcosFit6", "kAcosFit6", kAcosFit6),
      f("kAcosFit7", "kAcosFit7", kAcosFit7),
      f("kConeOpaque", "kConeOpaque", kConeOpaque),
  };
}

// The shared functions of floats: the GPU may fuse a multiply and an add the C++ kernels keep
// apart, so these are compared within a few float spacings instead of bit for bit.
struct FloatRow {
  std::string name, glsl;
  float cpu;
};

std::vector<FloatRow> float_rows() {
  using namespace shared;
  return {{"luminance", "luminance(0.25f, 0.5f, 0.125f)", luminance(0.25f, 0.5f, 0.125f)},
          {"multi_bounce_fit", "multi_bounce_fit(0.5f, 0.8f)", multi_bounce_fit(0.5f, 0.8f)},
          {"multi_bounce_fit (V above the fit)", "multi_bounce_fit(0.9f, 0.0f)", multi_bounce_fit(0.9f, 0.0f)}};
}

std::vector<std::uint32_t> run_on_device(const std::string& body, std::size_t n) {
  gpu_detail::Context& c = gpu_detail::Access::context(test::gpu_device());
  c.make_current();
  const std::string source = gpu_detail::expand_includes(
      "#version 430\n"
      "#include \"ao/core/hash_shared.h\"\n"
      "#include \"ao/core/color_shared.h\"\n"
      "#include \"ao/methods/screen_space_shared.h\"\n"
      "#include \"ao/methods/alchemy/alchemy_shared.h\"\n"
      "#include \"ao/methods/gtao/gtao_shared.h\"\n"
      "#include \"ao/methods/cone/cone_shared.h\"\n"
      "layout(local_size_x = 1) in;\n"
      "layout(std430, binding = 0) writeonly buffer Out { uint o[]; };\n"
      "void main() {\n" +
      body + "}\n");
  const GLuint shader = c.gl.CreateShader(GL_COMPUTE_SHADER);
  const char* text = source.c_str();
  c.gl.ShaderSource(shader, 1, &text, nullptr);
  c.gl.CompileShader(shader);
  GLint ok = 0;
  c.gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    std::string log(4096, '\0');
    c.gl.GetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), nullptr, log.data());
    c.gl.DeleteShader(shader);
    ADD_FAILURE() << "the shared headers do not compile as GLSL: " << log.c_str() << "\n" << source;
    return {};
  }
  const GLuint program = c.gl.CreateProgram();
  c.gl.AttachShader(program, shader);
  c.gl.LinkProgram(program);
  c.gl.DeleteShader(shader);
  const gpu_detail::Buffer out = gpu_detail::make_buffer(c, n * sizeof(std::uint32_t), nullptr);
  c.gl.UseProgram(program);
  c.gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, out.id());
  c.gl.DispatchCompute(1, 1, 1);
  c.gl.MemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<std::uint32_t> values(n);
  c.gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, out.id());
  c.gl.GetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(n * sizeof(std::uint32_t)), values.data());
  c.gl.DeleteProgram(program);
  c.check("reading the shared values back");
  return values;
}

TEST(SharedHeaders, TheShadersReadTheSameConstantsAndFunctionsAsTheCpu) {
  const std::vector<Row> exact = rows();
  const std::vector<FloatRow> close = float_rows();
  std::string body;
  std::size_t i = 0;
  for (const Row& r : exact) body += "  o[" + std::to_string(i++) + "] = " + r.glsl + ";\n";
  for (const FloatRow& r : close) body += "  o[" + std::to_string(i++) + "] = floatBitsToUint(" + r.glsl + ");\n";
  const std::vector<std::uint32_t> gpu = run_on_device(body, i);
  ASSERT_EQ(gpu.size(), i);
  for (std::size_t k = 0; k < exact.size(); ++k) EXPECT_EQ(gpu[k], exact[k].cpu) << exact[k].name << " differs between the GPU and the CPU";
  for (std::size_t k = 0; k < close.size(); ++k) {
    const float g = std::bit_cast<float>(gpu[exact.size() + k]);
    // Two float spacings of the value: one rounding more or less where the GPU fuses a multiply-add.
    EXPECT_NEAR(g, close[k].cpu, 2.4e-7f * std::max(1.0f, std::abs(close[k].cpu))) << close[k].name;
  }
}

}  // namespace
}  // namespace ao
