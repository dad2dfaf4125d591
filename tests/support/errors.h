// SPDX-License-Identifier: Apache-2.0
// Checks for the bad-input rule of SPEC: a library call throws the expected error type with one
// line that names the file and the problem.
#pragma once

#include <gtest/gtest.h>

#include <exception>
#include <filesystem>
#include <string>

namespace ao::test {

/// Runs fn, which must throw E with a one-line message containing path's file name and `problem`.
template <class E, class Fn>
void expect_one_line_error(Fn&& fn, const std::filesystem::path& path, const std::string& problem) {
  try {
    fn();
    ADD_FAILURE() << "no exception for " << path;
  } catch (const E& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_NE(what.find(path.filename().string()), std::string::npos) << what;
    EXPECT_NE(what.find(problem), std::string::npos) << what;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type for " << path << ": " << e.what();
  }
}

}  // namespace ao::test
