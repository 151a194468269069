#include "vibid/fw/version.hpp"

#include <gtest/gtest.h>

namespace vibid::fw {
namespace {

// The CMake project version is 0.1.0; get-info must report what the build was configured with.
TEST(FirmwareVersion, MatchesProjectVersion) {
  const FirmwareVersion v = CurrentFirmwareVersion();
  EXPECT_EQ(v.major, VIBID_TEST_EXPECTED_MAJOR);
  EXPECT_EQ(v.minor, VIBID_TEST_EXPECTED_MINOR);
}

}  // namespace
}  // namespace vibid::fw
