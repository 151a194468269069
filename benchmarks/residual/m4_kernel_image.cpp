// Cortex-M4 image for benchmarks/residual/m4_instructions.py: steps the residual CUSUM over
// kWindows windows of kWindow samples with a reference force (the costlier case: one more
// multiply), so the script can count the instructions of every sample in QEMU (the average, the
// plain sample and the window's last, where the statistic updates). Built by the firmware preset
// (shared/fixed/CMakeLists.txt); not a test.
#include <gtest/gtest.h>

#include <cstdint>

#include "vibid/shared/fixed/residual_cusum.hpp"

namespace vibid::fixed {
namespace {

// Must match WINDOW and WINDOWS in m4_instructions.py.
constexpr std::uint32_t kWindow = 64;
constexpr std::uint32_t kWindows = 8;

// What the sampling interrupt does per frame: one Step. Not inlined, so the script counts from
// its entry until control is back in Drive (the call and return are counted too).
[[gnu::noinline]] bool Sample(ResidualCusum& test, std::int32_t d_hat, std::int32_t reference) {
  return test.Step(d_hat, reference);
}

[[gnu::noinline]] std::uint32_t Drive(ResidualCusum& test, std::uint32_t samples) {
  std::uint32_t windows = 0;
  for (std::uint32_t n = 0; n < samples; ++n) {
    // Observer-like values well inside the range (no clamp, so no data-dependent path).
    auto d_hat = static_cast<std::int32_t>((n * 2654435761u) >> 12) - (1 << 19);
    auto reference = static_cast<std::int32_t>((n * 40503u) & 0xFFFFFu) - (1 << 19);
    // Opaque to the optimiser: knowing these ranges, it would drop the clamp the board runs.
    asm volatile("" : "+r"(d_hat), "+r"(reference));
    windows += Sample(test, d_hat, reference) ? 1u : 0u;
  }
  return windows;
}

TEST(ResidualCusumM4, StepsWindowsWithAReference) {
  static ResidualCusum test;
  ResidualCusumParams p;
  p.window_samples = kWindow;
  p.residual_gain = 1 << 28;      // 1/16 in Q32
  p.reference_gain = -(1 << 27);  // a reference at half d_hat's full scale
  p.sum_shift = 10;
  p.center = 1 << 24;
  p.z_shift = 40;
  p.z_gain = 1 << 30;
  p.k = 1 << 15;
  p.h = 10 << 16;
  ASSERT_EQ(test.Init(p), Status::kOk);
  EXPECT_EQ(Drive(test, kWindow * kWindows), kWindows);
  EXPECT_EQ(test.clamp_count(), 0u);
}

}  // namespace
}  // namespace vibid::fixed
