// SPDX-License-Identifier: Apache-2.0
// The field marks of InputError's text (error.h): each field is written between two unit
// separators (0x1F), a character no message, option or file name of ao's uses.
#include "ao/core/error.h"

#include <algorithm>
#include <cctype>

namespace ao {

namespace {

constexpr char kMark = '\x1f';

bool is_field_name(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isalnum(c) || c == '_' || c == ':' || c == '.'; });
}

// Calls `text_part` for each stretch of plain text and `field_part` for each marked field. A mark
// without its pair, or around something that is not a field name, is text.
template <class Text, class Field>
void split_marks(const std::string& text, Text text_part, Field field_part) {
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t open = text.find(kMark, at);
    const std::size_t close = open == std::string::npos ? std::string::npos : text.find(kMark, open + 1);
    if (close == std::string::npos) break;
    const std::string_view name(text.data() + open + 1, close - open - 1);
    if (!is_field_name(name)) {
      text_part(std::string_view(text.data() + at, close - at));
      at = close;
      continue;
    }
    text_part(std::string_view(text.data() + at, open - at));
    field_part(name);
    at = close + 1;
  }
  text_part(std::string_view(text.data() + at, text.size() - at));
}

}  // namespace

std::string name_fields(const std::string& text, const std::function<std::string(std::string_view)>& name) {
  std::string out;
  split_marks(
      text, [&](std::string_view t) { out += t; },
      [&](std::string_view f) {
        std::string own = name ? name(f) : std::string();
        out += own.empty() ? std::string(f) : own;
      });
  return out;
}

std::string field(std::string_view name) { return kMark + std::string(name) + kMark; }

InputError::InputError(const std::string& text) : std::runtime_error(name_fields(text, {})), text_(std::make_shared<const std::string>(text)) {}

std::vector<std::string> InputError::fields() const {
  std::vector<std::string> out;
  split_marks(*text_, [](std::string_view) {}, [&](std::string_view f) { out.emplace_back(f); });
  return out;
}

std::string InputError::message(const std::function<std::string(std::string_view field)>& name) const { return name_fields(*text_, name); }

}  // namespace ao
