#include "vibid/shared/fixed/filter_description.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>

namespace vibid::fixed {
namespace {

constexpr std::int32_t kOneQ30 = 1 << 30;  // 1.0 with shift 1

// A valid two-input description: one section per path, poles at 0.5 and 0.25 (a1 = -0.75,
// a2 = 0.125), unit numerator.
FilterDescription ValidDescription() {
  FilterDescription d;
  d.input_count = 2;
  d.output_dof = 1;
  d.sample_rate_hz = 5000;
  d.input_kind = {InputKind::kDisplacement, InputKind::kForce, InputKind::kUnused};
  d.input_dof = {1, 1, 0};
  d.input_full_scale_bits = {FullScaleBits(0.05f), FullScaleBits(100.0f), 0};
  d.output_full_scale_bits = FullScaleBits(200.0f);
  for (std::size_t i = 0; i < 2; ++i) {
    Path& p = d.paths[i];
    p.section_count = 1;
    p.output_gain = 1 << 30;
    p.output_shift = 1;
    p.sections[0] = Section{.b0 = kOneQ30 / 4,
                            .b1 = 0,
                            .b2 = 0,
                            .a1 = -3 * (kOneQ30 / 4),
                            .a2 = kOneQ30 / 8,
                            .shift = 1,
                            .feedback = ErrorFeedback::kSecondOrder};
  }
  Seal(d);
  return d;
}

TEST(FilterDescription, ValidDescriptionPasses) {
  EXPECT_EQ(ValidateDescription(ValidDescription()), Status::kOk);
}

TEST(FilterDescription, EncodeDecodeRoundTripsEveryByte) {
  const FilterDescription d = ValidDescription();
  std::array<std::uint8_t, kDescriptionBytes> bytes{};
  EncodeDescription(d, bytes);
  // Spot-check the documented offsets (little-endian).
  EXPECT_EQ(bytes[0], 'V');
  EXPECT_EQ(bytes[1], 'D');
  EXPECT_EQ(bytes[2], 'O');
  EXPECT_EQ(bytes[3], 'B');
  EXPECT_EQ(bytes[4], kDescriptionVersion);
  EXPECT_EQ(bytes[6], 2);
  EXPECT_EQ(bytes[8], 5000 & 0xFF);
  EXPECT_EQ(bytes[9], 5000 >> 8);
  EXPECT_EQ(bytes[12], static_cast<std::uint8_t>(InputKind::kDisplacement));
  EXPECT_EQ(bytes[36], 1);           // paths[0].section_count
  EXPECT_EQ(bytes[36 + 8 + 20], 1);  // paths[0].sections[0].shift
  EXPECT_EQ(bytes[36 + 8 + 21], 1);  // paths[0].sections[0].feedback
  EXPECT_EQ(bytes[636], d.checksum & 0xFFu);
  FilterDescription back{};
  ASSERT_EQ(DecodeDescription(bytes, back), Status::kOk);
  std::array<std::uint8_t, kDescriptionBytes> again{};
  EncodeDescription(back, again);
  EXPECT_TRUE(bytes == again);
  EXPECT_EQ(ValidateDescription(back), Status::kOk);
}

// Check value of CRC-32/ISO-HDLC over "123456789" is 0xCBF43926 (Greg Cook's CRC catalogue).
TEST(FilterDescription, CrcMatchesCatalogueCheckValue) {
  const std::array<std::uint8_t, 9> digits = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  EXPECT_EQ(Crc32IsoHdlc(digits), 0xCBF43926u);
}

TEST(FilterDescription, ChecksumChangesWithEveryField) {
  const FilterDescription d = ValidDescription();
  FilterDescription e = d;
  e.paths[1].sections[0].b0 += 1;
  EXPECT_NE(ComputeChecksum(d), ComputeChecksum(e));
  e = d;
  e.output_dof = 0;
  EXPECT_NE(ComputeChecksum(d), ComputeChecksum(e));
}

TEST(FilterDescription, RefusesEachBrokenRule) {
  const auto check = [](auto mutate, Status expected) {
    FilterDescription d = ValidDescription();
    mutate(d);
    Seal(d);
    return ValidateDescription(d) == expected;
  };
  EXPECT_TRUE(check([](FilterDescription& d) { d.magic = 0; }, Status::kVersionMismatch));
  EXPECT_TRUE(check([](FilterDescription& d) { d.version = 2; }, Status::kVersionMismatch));
  EXPECT_TRUE(check([](FilterDescription& d) { d.input_count = 0; }, Status::kOutOfRange));
  EXPECT_TRUE(check([](FilterDescription& d) { d.input_count = 4; }, Status::kOutOfRange));
  EXPECT_TRUE(
      check([](FilterDescription& d) { d.paths[0].section_count = 9; }, Status::kOutOfRange));
  EXPECT_TRUE(check([](FilterDescription& d) { d.sample_rate_hz = 0; }, Status::kInvalidArgument));
  EXPECT_TRUE(check([](FilterDescription& d) { d.reserved0 = 1; }, Status::kInvalidArgument));
  EXPECT_TRUE(check([](FilterDescription& d) { d.paths[0].sections[0].shift = 16; },
                    Status::kInvalidArgument));
  EXPECT_TRUE(
      check([](FilterDescription& d) { d.paths[0].output_shift = 31; }, Status::kInvalidArgument));
  EXPECT_TRUE(check([](FilterDescription& d) { d.paths[1].sections[0].reserved[1] = 1; },
                    Status::kInvalidArgument));
  EXPECT_TRUE(check(
      [](FilterDescription& d) { d.paths[1].sections[0].feedback = static_cast<ErrorFeedback>(2); },
      Status::kInvalidArgument));
  EXPECT_TRUE(check([](FilterDescription& d) { d.input_kind[1] = InputKind::kUnused; },
                    Status::kInvalidArgument));
  EXPECT_TRUE(check([](FilterDescription& d) { d.input_kind[0] = static_cast<InputKind>(9); },
                    Status::kInvalidArgument));
  // An unused slot must be all zero so the checksum covers no stale data.
  EXPECT_TRUE(
      check([](FilterDescription& d) { d.paths[2].output_gain = 1; }, Status::kInvalidArgument));
  EXPECT_TRUE(check([](FilterDescription& d) { d.input_full_scale_bits[2] = FullScaleBits(1.0f); },
                    Status::kInvalidArgument));
  // A section beyond section_count must be zero.
  EXPECT_TRUE(
      check([](FilterDescription& d) { d.paths[0].sections[1].a2 = 5; }, Status::kInvalidArgument));
  EXPECT_TRUE(check([](FilterDescription& d) { d.input_full_scale_bits[0] = FullScaleBits(-1.0f); },
                    Status::kInvalidArgument));
  EXPECT_TRUE(check([](FilterDescription& d) { d.output_full_scale_bits = 0x7FC00000u; },  // NaN
                    Status::kInvalidArgument));
  // Coefficient sum above kMaxCoefficientSum: the accumulator bound.
  EXPECT_TRUE(check(
      [](FilterDescription& d) {
        Section& s = d.paths[0].sections[0];
        s.b0 = INT32_MAX;
        s.b1 = INT32_MAX;
        s.b2 = -3;  // sum 2^32 - 1 > kMaxCoefficientSum
        s.a1 = 0;
        s.a2 = 0;
      },
      Status::kInvalidArgument));
  // Unstable: a pole at z = 1 (a1 = -1.5, a2 = 0.5 -> roots 1 and 0.5) and one outside.
  EXPECT_TRUE(check(
      [](FilterDescription& d) {
        d.paths[1].sections[0].a1 = -3 * (kOneQ30 / 2);
        d.paths[1].sections[0].a2 = kOneQ30 / 2;
      },
      Status::kUnstable));
  EXPECT_TRUE(
      check([](FilterDescription& d) { d.paths[1].sections[0].a2 = kOneQ30; }, Status::kUnstable));
  // Checksum: a flipped byte after sealing.
  FilterDescription d = ValidDescription();
  d.paths[0].sections[0].b2 ^= 1;
  EXPECT_EQ(ValidateDescription(d), Status::kDataLoss);
}

// Jury's conditions on the integers are exact at the boundary (shift 1, so 1.0 = 2^30): one LSB
// inside the unit circle is stable, a pole on it is not.
TEST(FilterDescription, StabilityIsExactAtTheBoundary) {
  Section s{.b0 = 0, .b1 = 0, .b2 = 0, .a1 = 0, .a2 = kOneQ30 - 1, .shift = 1};
  EXPECT_TRUE(SectionIsStable(s));
  s.a2 = kOneQ30;  // |a2| = 1: complex poles on the unit circle
  EXPECT_FALSE(SectionIsStable(s));
  s.a2 = 0;
  s.a1 = -(kOneQ30 - 1);  // single pole at z = 1 - 2^-30
  EXPECT_TRUE(SectionIsStable(s));
  s.a1 = -kOneQ30;  // pole at z = 1
  EXPECT_FALSE(SectionIsStable(s));
  s.a1 = kOneQ30;  // pole at z = -1
  EXPECT_FALSE(SectionIsStable(s));
}

}  // namespace
}  // namespace vibid::fixed
