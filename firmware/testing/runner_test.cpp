// The runner's own behaviour on the target: fixtures, fatal vs non-fatal checks, value printing.
#include <gtest/gtest.h>

#include <cstdint>

namespace {

class Counter : public ::testing::Test {
 protected:
  void SetUp() override { value = 41; }
  int value = 0;
};

TEST_F(Counter, SetUpRunsBeforeTheBody) {
  ++value;
  EXPECT_EQ(value, 42);
}

TEST(TargetRunner, ComparisonsHoldForMixedTypes) {
  const std::int64_t big = INT64_C(1) << 40;
  EXPECT_GT(big, 1);
  EXPECT_LE(-1, 0);
  EXPECT_NE(big, 0);
  EXPECT_NEAR(0.1 + 0.2, 0.3, 1e-15);
  EXPECT_DOUBLE_EQ(0.1 + 0.2, 0.30000000000000004);
  EXPECT_FLOAT_EQ(1.0f / 3.0f, 0.33333334f);
  EXPECT_STREQ("abc", "abc");
  EXPECT_STRNE("abc", "abd");
  EXPECT_TRUE(big > 0) << "streamed messages compile";
  ASSERT_FALSE(big < 0);
}

// Floating-point arithmetic runs on the FPU the startup code enabled (hard-float ABI).
TEST(TargetRunner, FloatingPointWorks) {
  volatile float a = 1.5f;
  volatile double b = 2.25;
  EXPECT_EQ(a * a, 2.25f);
  EXPECT_EQ(b * b, 5.0625);
}

}  // namespace

namespace {

int g_calls = 0;
int Next() { return ++g_calls; }

// GoogleTest evaluates each operand once; a check with a side effect must not run it twice.
TEST(TargetRunner, OperandsAreEvaluatedOnce) {
  g_calls = 0;
  EXPECT_EQ(Next(), 1);
  ASSERT_GE(Next(), 2);
  EXPECT_TRUE(Next() == 3);
  EXPECT_EQ(g_calls, 3);
}

}  // namespace
