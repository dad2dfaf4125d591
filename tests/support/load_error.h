// SPDX-License-Identifier: Apache-2.0
// The bad-input rule of SPEC for the mesh loaders: load_scene_file refuses a file with one
// InputError line that names the file.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "ao/core/error.h"
#include "ao/io/mesh_io.h"

namespace ao::test {

/// The message of the InputError loading `path` must throw, after checking that it is one line and
/// names the file (a failure, and an empty string, when the file loads).
inline std::string load_error(const std::filesystem::path& path) {
  try {
    load_scene_file(path);
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path.filename().string()), std::string::npos) << "message does not name the file: " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "message is not one line: " << msg;
    return msg;
  }
  ADD_FAILURE() << path << " loaded, expected an InputError";
  return {};
}

}  // namespace ao::test

/// load_error(path) holds and its message contains `fragment`.
#define EXPECT_LOAD_ERROR(path, fragment)                                                                \
  do {                                                                                                   \
    const std::string msg_ = ::ao::test::load_error(path);                                               \
    EXPECT_NE(msg_.find(fragment), std::string::npos) << "expected '" << (fragment) << "' in: " << msg_; \
  } while (0)
