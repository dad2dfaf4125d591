// SPDX-License-Identifier: Apache-2.0
#include "ao/io/json_text.h"

#include <fstream>
#include <iterator>
#include <system_error>
#include <utility>
#include <vector>

#include "ao/core/error.h"
#include "ao/io/io_error_internal.h"

namespace ao {

namespace fs = std::filesystem;

namespace {


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

/// A SAX handler that builds the value as nlohmann's DOM parser does, one container per open
/// array or object on a stack, and counts the depth as it opens them.
class DepthLimitedBuilder : public nlohmann::json_sax<nlohmann::json> {
 public:
  DepthLimitedBuilder(nlohmann::json& root, int max_depth) : root_(root), max_depth_(max_depth) {}

  bool null() override { return put(nullptr); }
  bool boolean(bool v) override { return put(v); }
  bool number_integer(number_integer_t v) override { return put(v); }
  bool number_unsigned(number_unsigned_t v) override { return put(v); }
  bool number_float(number_float_t v, const string_t&) override { return put(v); }
  bool string(string_t& v) override { return put(std::move(v)); }
  bool binary(binary_t& v) override { return put(nlohmann::json::binary(std::move(v))); }
  bool start_object(std::size_t) override { return open(nlohmann::json::object()); }
  bool key(string_t& k) override {
    if (stack_.back()->contains(k)) throw JsonDuplicateKey(k.substr(0, 40));
    key_ = &(*stack_.back())[k];
    return true;
  }
  bool end_object() override { return close(); }
  bool start_array(std::size_t) override { return open(nlohmann::json::array()); }
  bool end_array() override { return close(); }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& e) override {
    // Rethrown as the type it is, so that callers see nlohmann's parse_error and its byte.
    if (const auto* p = dynamic_cast<const nlohmann::json::parse_error*>(&e)) throw *p;
    if (const auto* o = dynamic_cast<const nlohmann::json::out_of_range*>(&e)) throw *o;
    throw nlohmann::json::other_error::create(0, e.what(), nullptr);
  }

 private:
  // Where the next value goes: the root, the member named by the last key, or the end of an array.
  nlohmann::json* slot() {
    if (stack_.empty()) return &root_;
    if (stack_.back()->is_object()) return key_;
    stack_.back()->push_back(nullptr);
    return &stack_.back()->back();
  }
  template <class Value>
  bool put(Value&& v) {
    *slot() = nlohmann::json(std::forward<Value>(v));
    return true;
  }
  bool open(nlohmann::json container) {
    if (static_cast<int>(stack_.size()) >= max_depth_) throw JsonTooDeep();
    nlohmann::json* at = slot();
    *at = std::move(container);
    stack_.push_back(at);
    return true;
  }
  bool close() {
    stack_.pop_back();
    return true;
  }

  nlohmann::json& root_;
  int max_depth_;
  std::vector<nlohmann::json*> stack_;  ///< The open containers; a pointer stays valid while its container is open (values are added only to the innermost).
  nlohmann::json* key_ = nullptr;
};

nlohmann::json parse_or_throw(std::string_view text) { return parse_json_with_depth_limit(text, kMaxJsonDepth); }

[[noreturn]] void too_deep(const std::string& source);

void too_deep(const std::string& source) {
  throw InputError(source + ": JSON nests deeper than " + std::to_string(kMaxJsonDepth) + " levels");
}

}  // namespace

nlohmann::json parse_json_with_depth_limit(std::string_view text, int max_depth) {
  nlohmann::json root;
  DepthLimitedBuilder builder(root, max_depth);
  nlohmann::json::sax_parse(text.begin(), text.end(), &builder);
  return root;
}

std::optional<nlohmann::json> parse_json_limited(std::string_view text, const std::string& source) {
  try {
    return parse_or_throw(text);
  } catch (const JsonTooDeep&) {
    too_deep(source);
  } catch (const JsonDuplicateKey& e) {
    throw InputError(source + ": JSON has the key '" + io_detail::one_line(e.key) + "' twice in one object");
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
  } catch (const JsonTooDeep&) {
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
