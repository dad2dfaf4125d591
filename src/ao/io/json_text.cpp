#include "ao/io/json_text.h"

#include <fstream>
#include <iterator>
#include <system_error>

#include "ao/core/error.h"
#include "ao/io/io_error_internal.h"

namespace ao {

namespace fs = std::filesystem;

namespace {

struct TooDeep {};

/// "line L, column C" of byte `byte` (1-based, as nlohmann counts it) in `text`.
std::string place(std::string_view text, std::size_t byte) {
  const std::size_t at = std::min(byte > 0 ? byte - 1 : 0, text.size());
  std::size_t line = 1, column = 1;
  for (std::size_t i = 0; i < at; ++i) {
    if (text[i] == '\n') ++line, column = 1;
    else ++column;
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

/// Parses `text`; an invalid text throws nlohmann's parse_error, a deep one TooDeep.
nlohmann::json parse_or_throw(std::string_view text) {
  // The callback sees each value's depth (0 at the top level) before the parser descends into it.
  return nlohmann::json::parse(text.begin(), text.end(), [](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
    if (depth >= kMaxJsonDepth) throw TooDeep{};  // depth counts from 0 at the top level
    return true;
  });
}

[[noreturn]] void too_deep(const std::string& source) {
  throw InputError(source + ": JSON nests deeper than " + std::to_string(kMaxJsonDepth) + " levels");
}

}  // namespace

std::optional<nlohmann::json> parse_json_limited(std::string_view text, const std::string& source) {
  try {
    return parse_or_throw(text);
  } catch (const TooDeep&) {
    too_deep(source);
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

nlohmann::json read_json_file(const fs::path& path, std::string_view expected) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) io_detail::fail(path, "is a directory, not a JSON file");
  std::ifstream in(path, std::ios::binary);
  if (!in) io_detail::fail(path, "cannot open the file");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (!ec && size > kMaxJsonFileBytes)
    io_detail::fail(path, "is " + std::to_string(size) + " bytes, larger than the 16 MiB a JSON file of ao may have (expected " + std::string(expected) + ")");
  std::string text;
  text.reserve(static_cast<std::size_t>(ec ? 0 : size));
  // Read at most one byte past the limit: a file that grows (or a FIFO) cannot make us read more.
  std::istreambuf_iterator<char> it(in), end;
  for (; it != end && text.size() <= kMaxJsonFileBytes; ++it) text.push_back(*it);
  if (in.bad()) io_detail::fail(path, "cannot read the file");
  if (text.size() > kMaxJsonFileBytes) io_detail::fail(path, "is larger than the 16 MiB a JSON file of ao may have (expected " + std::string(expected) + ")");
  try {
    return parse_or_throw(text);
  } catch (const TooDeep&) {
    too_deep(path.string());
  } catch (const nlohmann::json::parse_error& e) {
    if (text.find_first_not_of(" \t\r\n") == std::string::npos) io_detail::fail(path, "is empty (expected " + std::string(expected) + ")");
    io_detail::fail(path, "is not valid JSON (" + place(text, e.byte) + "; expected " + std::string(expected) + ")");
  } catch (const nlohmann::json::exception&) {
    io_detail::fail(path, "is not valid JSON (expected " + std::string(expected) + ")");
  }
}

std::string json_excerpt(const nlohmann::json& value, std::size_t max_chars) {
  // Non-ASCII text is replaced rather than failing on invalid UTF-8 (the value may be a file's).
  const std::string text = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return io_detail::one_line(text, max_chars);
}

}  // namespace ao
