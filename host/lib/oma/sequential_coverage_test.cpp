// The sequential test's false alarms at the watch's defaults over 40 000 h of the residuals' law
// (400 references × 100 h), two-sided: about 40 s, hence the coverage label.
#include <gtest/gtest.h>

#include "sequential_test_support.hpp"

namespace vibid::oma {
namespace {

TEST(SequentialTest, TheDefaultRateOverFortyThousandHoursTwoSided) {
  testing::CountTwoSided(0.01, 400, 100.0, 42);
}

}  // namespace
}  // namespace vibid::oma
