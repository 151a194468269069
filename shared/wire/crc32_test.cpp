#include "vibid/shared/wire/crc32.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>

#include "golden_vectors.hpp"

namespace vibid::wire {
namespace {

// Check value of CRC-32/ISO-HDLC from the Catalogue of parametrised CRC algorithms
// (reveng.sourceforge.io): CRC of the ASCII string "123456789".
TEST(Crc32, PublishedCheckValue) {
  const std::array<std::uint8_t, 9> input{'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  EXPECT_EQ(ComputeCrc32(input), 0xCBF43926u);
}

// The golden file's check value comes from Python's zlib.crc32 (scripts/golden/wire_vectors.py).
TEST(Crc32, MatchesZlibGolden) {
  std::array<std::uint8_t, testing::kMaxVectorBytes> input{};
  std::array<std::uint8_t, 4> expected{};
  const std::size_t n = testing::GoldenVector("crc_check_input", input);
  ASSERT_EQ(n, 9u);
  ASSERT_EQ(testing::GoldenVector("crc_check_value", expected), 4u);
  const std::uint32_t want =
      static_cast<std::uint32_t>(expected[0]) | static_cast<std::uint32_t>(expected[1]) << 8 |
      static_cast<std::uint32_t>(expected[2]) << 16 | static_cast<std::uint32_t>(expected[3]) << 24;
  EXPECT_EQ(ComputeCrc32(std::span<const std::uint8_t>(input).first(n)), want);
}

// Feeding in pieces gives the CRC of the concatenation.
TEST(Crc32, IncrementalEqualsOneShot) {
  std::array<std::uint8_t, 200> data{};
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::uint8_t>(i * 37 + 11);
  for (std::size_t split = 0; split <= data.size(); split += 13) {
    Crc32 crc;
    crc.Update(std::span<const std::uint8_t>(data).first(split));
    crc.Update(std::span<const std::uint8_t>(data).subspan(split));
    EXPECT_EQ(crc.value(), ComputeCrc32(data));
  }
}

// The empty message has CRC 0 (init and final XOR cancel).
TEST(Crc32, EmptyIsZero) { EXPECT_EQ(ComputeCrc32({}), 0u); }

}  // namespace
}  // namespace vibid::wire
