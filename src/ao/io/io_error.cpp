// SPDX-License-Identifier: Apache-2.0
#include "ao/io/io_error_internal.h"

#include <cctype>

#include "ao/core/error.h"

namespace ao::io_detail {

void fail(const std::filesystem::path& path, const std::string& problem) { throw InputError(path.string() + ": " + problem); }

std::string one_line(std::string_view text, std::size_t max_chars) {
  const std::string_view kept = text.substr(0, max_chars);
  std::string out;
  out.reserve(kept.size());
  bool line_break = false;
  const auto drop_trailing = [&out] {
    while (!out.empty() && (out.back() == ' ' || out.back() == '.' || out.back() == ';')) out.pop_back();
  };
  for (const char c : kept) {
    if (c == '\n' || c == '\r') {
      line_break = !out.empty();
      continue;
    }
    const bool blank = c == ' ' || c == '\t' || c == '\v' || c == '\f';
    if (line_break) {
      // A new line of the message: "first line; second line" (a sentence's own dot stays).
      while (!out.empty() && out.back() == ' ') out.pop_back();
      if (!out.empty() && out.back() != '.' && out.back() != ';' && out.back() != ':') out += ';';
      out += ' ';
      line_break = false;
      if (blank) continue;
    }
    if (blank) {
      if (!out.empty() && out.back() != ' ') out += ' ';
      continue;
    }
    out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  }
  drop_trailing();
  return text.size() > max_chars ? out + "..." : out;
}

std::string printable(std::string_view token, std::size_t max_chars) {
  std::string out;
  for (const char c : token.substr(0, max_chars)) out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  return token.size() > max_chars ? out + "..." : out;
}

std::string quote(std::string_view token) {
  std::string out(1, '\'');  // appended piecewise: "'" + string trips GCC 12's false -Wrestrict
  out += printable(token);
  out += '\'';
  return out;
}

}  // namespace ao::io_detail
