// Cortex-M4 image for benchmarks/decimator/m4_instructions.py: pushes 7 channels through the
// decimator for PERIODS whole output periods at each factor, so the script can count the
// instructions of every Push in QEMU (average per input frame, and the worst tick, where every
// stage computes). Built by the firmware preset (shared/fixed/CMakeLists.txt); not a test.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>

#include "vibid/shared/fixed/decimator.hpp"

namespace vibid::fixed {
namespace {

// Must match FACTORS and PERIODS in m4_instructions.py.
constexpr std::uint32_t kFactors[] = {2, 5, 10, 50, 625, 1000};
constexpr std::uint32_t kPeriods = 2;
constexpr std::size_t kChannels = kDecimatorMaxChannels;

// Not inlined: the script counts from each entry into Decimator::Push until control is back in
// this function, so the input generation here is not counted.
[[gnu::noinline]] std::uint32_t Drive(Decimator& dec, std::uint32_t pushes) {
  std::int32_t in[kChannels];
  std::int32_t out[kChannels];
  std::uint32_t outputs = 0;
  for (std::uint32_t n = 0; n < pushes; ++n) {
    // Sensor-like values well inside the range (no saturation, so no data-dependent path).
    for (std::size_t ch = 0; ch < kChannels; ++ch) {
      in[ch] = static_cast<std::int32_t>(((n * 2654435761u) >> 12) + 1000u * ch) - (1 << 19);
    }
    outputs += dec.Push(in, out) ? 1u : 0u;
  }
  return outputs;
}

TEST(DecimatorM4, PushesSevenChannelsAtEachFactor) {
  static Decimator dec;
  for (const std::uint32_t factor : kFactors) {
    ASSERT_EQ(dec.Init(factor, kChannels), Status::kOk);
    EXPECT_EQ(Drive(dec, kPeriods * factor), kPeriods);
    EXPECT_EQ(dec.saturation_count(), 0u);
  }
}

}  // namespace
}  // namespace vibid::fixed
