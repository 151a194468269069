// One failing check: the image must exit nonzero so ctest marks the run failed (the test is
// registered with WILL_FAIL, so it passes only if the failure propagated).
#include <gtest/gtest.h>

namespace {

TEST(TargetRunner, ReportsAFailure) { EXPECT_EQ(1 + 1, 3); }

}  // namespace
