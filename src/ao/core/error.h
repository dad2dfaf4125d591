// Errors. Library code never exits: bad input throws InputError with one line that names the
// file (or option) and the problem; only src/cli/main.cpp turns errors into exit codes.
#pragma once

#include <cassert>
#include <stdexcept>
#include <string>

namespace ao {

/// Bad input from the user: a file, an option value or a G-buffer. The message is one line,
/// starting with what was wrong ("cow.off: face 12 uses vertex 9001, the file has 2903").
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Failure of the environment rather than the input (disk full, cannot rename, library failure).
class SystemError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace ao

/// Internal invariant; compiled out of release builds.
#define AO_ASSERT(cond) assert(cond)
