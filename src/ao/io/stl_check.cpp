// SPDX-License-Identifier: Apache-2.0
// ASCII STL structure check (stl_check.h). The grammar is fixed and small, so a token scan with the
// line number for messages is all it takes; the numbers are read the way ao reads them in every
// text format (number_text.h), so a value that does not parse is named here, not misread later.
#include "ao/io/stl_check.h"

#include <cctype>
#include <cstdint>
#include <cstring>
#include <string>

#include "ao/core/error.h"
#include "ao/io/io_error_internal.h"
#include "ao/io/number_text.h"

namespace ao {
namespace {

namespace fs = std::filesystem;

using io_detail::printable;

class Tokens {
 public:
  explicit Tokens(std::string_view text) : text_(text) {}
  /// The next token, empty at the end of the text; line() is then the line it is on.
  std::string_view next() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    return text_.substr(start, pos_ - start);
  }
  /// Skips the rest of the current line (a solid's name may hold spaces).
  void skip_line() {
    while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
  }
  long long line() const { return line_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  long long line_ = 1;
};

bool equals_ci(std::string_view a, const char* b) {
  if (a.size() != std::strlen(b)) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) != b[i]) return false;
  return true;
}

}  // namespace

bool is_ascii_stl(std::string_view data) {
  const std::size_t start = data.find_first_not_of(" \t\r\n");
  if (start == std::string_view::npos || data.size() - start < 5) return false;
  for (std::size_t i = 0; i < 5; ++i)
    if (std::tolower(static_cast<unsigned char>(data[start + i])) != "solid"[i]) return false;
  if (data.size() >= 84) {
    std::uint32_t n = 0;
    std::memcpy(&n, data.data() + 80, 4);  // little-endian, as the test machines
    if (84 + 50 * static_cast<std::uint64_t>(n) == data.size()) return false;
  }
  return true;
}

void check_binary_stl(const fs::path& path, std::string_view data) {
  if (data.size() < 84)
    throw InputError(path.string() + ": truncated binary STL: " + std::to_string(data.size()) + " bytes, its header alone takes 84");
  std::uint32_t n = 0;
  std::memcpy(&n, data.data() + 80, 4);  // little-endian, as the test machines
  const std::uint64_t expected = 84 + 50 * static_cast<std::uint64_t>(n);
  if (expected != data.size())
    throw InputError(path.string() + ": binary STL header says " + std::to_string(n) + " triangles, which take 84 + 50 x " + std::to_string(n) + " = " +
                     std::to_string(expected) + " bytes; the file has " + std::to_string(data.size()) + " (or an ASCII STL that does not start with 'solid')");
}

void check_ascii_stl(const fs::path& path, std::string_view data) {
  Tokens t(data);
  long long facet = 0;
  const auto fail = [&](const std::string& problem) -> void {
    throw InputError(path.string() + ": line " + std::to_string(t.line()) + ": " + problem);
  };
  const auto expect = [&](const char* word, const char* inside) {
    const std::string_view token = t.next();
    if (token.empty()) fail(std::string("truncated ") + inside + ": expected '" + word + "', the file ends");
    if (!equals_ci(token, word)) fail(std::string("expected '") + word + "' " + inside + ", found '" + printable(token) + "'");
  };
  const auto numbers = [&](const char* what, const std::string& inside) {
    for (int k = 0; k < 3; ++k) {
      const std::string_view token = t.next();
      if (token.empty()) fail("truncated " + inside + ": " + what + " has " + std::to_string(k) + " of its 3 numbers");
      float value = 0;
      if (!parse_real(token, value)) fail(std::string(what) + " " + inside + ": '" + printable(token) + "' is not a number");
    }
  };
  int solids = 0;
  for (std::string_view token = t.next(); !token.empty(); token = t.next()) {
    if (!equals_ci(token, "solid")) fail("expected 'solid', found '" + printable(token) + "'");
    ++solids;
    t.skip_line();
    for (;;) {
      token = t.next();
      if (token.empty()) fail("truncated: the solid has no 'endsolid' after facet " + std::to_string(facet));
      if (equals_ci(token, "endsolid")) {
        t.skip_line();
        break;
      }
      const std::string inside = "inside facet " + std::to_string(facet);
      if (!equals_ci(token, "facet")) fail("expected 'facet' or 'endsolid', found '" + printable(token) + "'");
      expect("normal", inside.c_str());
      numbers("its normal", inside);
      expect("outer", inside.c_str());
      expect("loop", inside.c_str());
      for (int v = 0; v < 3; ++v) {
        expect("vertex", inside.c_str());
        numbers("a vertex", inside);
      }
      expect("endloop", inside.c_str());
      expect("endfacet", inside.c_str());
      ++facet;
    }
  }
  if (solids == 0) fail("no 'solid' in the file");
}

}  // namespace ao
