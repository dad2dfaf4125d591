// SPDX-License-Identifier: Apache-2.0
// A library built without the GPU backend (AO_GPU=OFF) keeps its API and says so when asked for a
// device (the rest of tests/gpu/ needs the backend).
#include <gtest/gtest.h>

#include <string>

#include "ao/core/error.h"
#include "ao/gpu/device.h"

namespace ao {
namespace {

TEST(GpuUnavailable, OpeningADeviceIsAOneLineSystemErrorNamingTheBuild) {
  try {
    GpuDevice::open();
    ADD_FAILURE() << "opened a device without the backend";
  } catch (const SystemError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_NE(what.find("AO_GPU=OFF"), std::string::npos) << what;
  }
  EXPECT_THROW(GpuDevice::from_current_context(nullptr), SystemError);
}

}  // namespace
}  // namespace ao
