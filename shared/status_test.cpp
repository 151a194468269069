#include "vibid/shared/status.hpp"

#include <gtest/gtest.h>

namespace vibid {
namespace {

// The numeric values travel on the wire; a renumbering breaks old hosts silently.
TEST(Status, WireValuesArePinned) {
  EXPECT_EQ(static_cast<int>(Status::kOk), 0);
  EXPECT_EQ(static_cast<int>(Status::kDataLoss), 4);
  EXPECT_EQ(static_cast<int>(Status::kUnstable), 10);
}

TEST(Status, NamesAreDistinct) {
  for (int a = 0; a <= 10; ++a) {
    for (int b = a + 1; b <= 10; ++b) {
      EXPECT_STRNE(StatusName(static_cast<Status>(a)), StatusName(static_cast<Status>(b)));
    }
  }
}

}  // namespace
}  // namespace vibid
