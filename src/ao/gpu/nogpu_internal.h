// SPDX-License-Identifier: Apache-2.0
// What the *_nogpu.cpp files of a library built without the GPU backend (CMake AO_GPU=OFF) throw.
#pragma once

#include "ao/core/error.h"

namespace ao::gpu_detail {

[[noreturn]] inline void unavailable() {
  throw SystemError("--device gpu: this ao was built without the GPU backend (CMake AO_GPU=OFF: the EGL and OpenGL headers were not found)");
}

}  // namespace ao::gpu_detail
