// Cortex-M4 image for benchmarks/dob/m4_instructions.py: runs the observer kernel over the
// committed vector's first frames once, so the instructions executed inside the kernel can be
// counted in QEMU and divided by the frame count. Built by the firmware preset (firmware/testing).
#include <gtest/gtest.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/shared/fixed/dob_filter.hpp"

namespace vibid::fixed {
namespace {

#include "testdata/dob_kernel_vectors.inc"

// Must match FRAMES in m4_instructions.py.
constexpr std::size_t kFrames = 1000;

TEST(DobKernelM4, RunsTheVectorOnce) {
  FilterDescription d{};
  static_cast<void>(
      DecodeDescription(std::span<const std::uint8_t, kDescriptionBytes>(kVectorDescription), d));
  DobFilter filter;
  ASSERT_EQ(filter.Init(d), Status::kOk);
  static std::int32_t out[kFrames];
  ASSERT_EQ(filter.StepBlock(std::span<const std::int32_t>(kVectorInput, 2 * kFrames), out),
            Status::kOk);
  EXPECT_EQ(out[kFrames - 1], kVectorOutput[kFrames - 1]);
}

}  // namespace
}  // namespace vibid::fixed
