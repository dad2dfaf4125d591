// SPDX-License-Identifier: Apache-2.0
// Opens a GPU device and says what happened: run by GpuDevice.NoUsableGlIsAOneLineSystemError
// (tests/gpu/device_test.cpp) in an environment without a usable GL, as a process of its own
// (the test binary's own EGL state is set up by then). Prints "opened RENDERER" or
// "SystemError[MESSAGE]"; exits 0 either way.
#include <cstdio>

#include "ao/core/error.h"
#include "ao/gpu/device.h"

int main() {
  try {
    const ao::GpuDevice device = ao::GpuDevice::open();
    std::printf("opened %s\n", device.renderer().c_str());
  } catch (const ao::SystemError& e) {
    std::printf("SystemError[%s]\n", e.what());
  }
  return 0;
}
