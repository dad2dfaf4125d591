// SPDX-License-Identifier: Apache-2.0
// Errors. Library code never exits: bad input throws InputError with one line that names the
// file (or request field) and the problem; only src/cli/main.cpp turns errors into exit codes.
#pragma once

#include <cassert>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace ao {

/// A request field named in an error's text, marked so that each caller can show it in its own
/// words: `field("BakeRequest::padding") + " must be in [0, 1024] texels"` reads
/// "BakeRequest::padding must be ..." in what(), "--padding must be ..." on the command line and
/// "padding must be ..." in Python (InputError::message). The name is "Type::member" or
/// "Type::member.member" (letters, digits, '_', ':' and '.').
std::string field(std::string_view name);

/// `text` with each marked field named by `name(field)`, or by its library name where `name` is
/// empty or returns an empty string: for InputError::message, and for the warnings and notes a
/// job reports (jobs/reporter.h), which may mark fields too.
std::string name_fields(const std::string& text, const std::function<std::string(std::string_view field)>& name);

/// Bad input from the user: a file, a request field's value or a G-buffer. The message is one
/// line, starting with what was wrong ("cow.off: face 12 uses vertex 9001, the file has 2903").
class InputError : public std::runtime_error {
 public:
  /// `text` may mark request fields with field(); what() names them by their library names.
  explicit InputError(const std::string& text);
  explicit InputError(const char* text) : InputError(std::string(text)) {}

  /// The request fields the text names, in order of appearance (empty for most file errors).
  std::vector<std::string> fields() const;
  /// The text with each field named by `name(field)`: the command line's options, Python's
  /// keywords. `name` returns an empty string for a field it has no name for, which then keeps
  /// its library name.
  std::string message(const std::function<std::string(std::string_view field)>& name) const;
  /// The text with its marks, for an error that adds context and rethrows: InputError(context +
  /// e.marked()) keeps the fields nameable.
  const std::string& marked() const { return *text_; }

 private:
  std::shared_ptr<const std::string> text_;  ///< Shared: exceptions are copied as they propagate.
};

/// Failure of the environment rather than the input (disk full, cannot rename, library failure).
class SystemError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace ao

/// Internal invariant; compiled out of release builds.
#define AO_ASSERT(cond) assert(cond)
