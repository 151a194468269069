#include "vibid/shared/wire/calibration_record.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <initializer_list>

#include "golden_vectors.hpp"
#include "test_filter.hpp"
#include "vibid/shared/wire/crc32.hpp"

namespace vibid::wire {
namespace {

using Bytes = std::array<std::uint8_t, kCalRecordBytes>;

using Matrix = std::array<float, kMaxDof * kMaxDof>;

// An n x n matrix in the record's kMaxDof x kMaxDof row-major block, zero beyond n.
Matrix Padded(std::initializer_list<std::initializer_list<float>> rows) {
  Matrix m{};
  std::size_t r = 0;
  for (const auto& row : rows) {
    std::size_t c = 0;
    for (const float v : row) m[r * kMaxDof + c++] = v;
    ++r;
  }
  return m;
}

// The values scripts/golden/wire_vectors.py packs into the golden record.
CalibrationRecord GoldenValues() {
  CalibrationRecord r;
  r.dof_count = 2;
  r.created_unix_s = 1700000000;
  r.host_major = 0;
  r.host_minor = 1;
  r.host_patch = 7;
  const char label[] = "rig-A two mass";
  std::memcpy(r.label.data(), label, sizeof(label) - 1);
  r.mass_kg = Padded({{0.57f, 0.0f}, {0.0f, 0.56f}});
  r.damping_ns_per_m = Padded({{1.25f, -0.5f}, {-0.5f, 0.75f}});
  r.stiffness_n_per_m = Padded({{30.0f, -15.0f}, {-15.0f, 15.0f}});
  r.channels[0] = {2048, 1 << 20, 0, Unit::kNewton, 0, 100.0f};
  r.channels[1] = {2047, 1 << 20, 0, Unit::kNewton, 1, 50.0f};
  r.channels[2] = {2050, 3 << 19, 1, Unit::kMeterPerSecond2, 0, 490.3325f};
  r.channels[3] = {2046, 3 << 19, 1, Unit::kMeterPerSecond2, 1, 490.3325f};
  r.channels[4] = {0, 1 << 17, 0, Unit::kMeter, 0, 0.5f};
  r.channels[5] = {-5, -(1 << 17), 0, Unit::kMeter, 1, 0.5f};
  return r;
}

Bytes GoldenBytes() {
  Bytes b{};
  EXPECT_EQ(testing::GoldenVector("calibration_record", b), kCalRecordBytes);
  return b;
}

// Re-seals bytes after a deliberate edit so the range checks, not the CRC, must catch it.
void Reseal(Bytes& b) {
  const std::uint32_t crc = ComputeCrc32(std::span<const std::uint8_t>(b).first(kCalOffCrc));
  for (std::size_t i = 0; i < 4; ++i) b[kCalOffCrc + i] = static_cast<std::uint8_t>(crc >> (8 * i));
}

TEST(CalibrationRecord, VersionMatchesGoldenFile) {
  EXPECT_EQ(testing::GoldenConstant("cal_record_version"), kCalRecordVersion);
}

TEST(CalibrationRecord, EncodesLikeGolden) {
  Bytes out{};
  EncodeCalibrationRecord(GoldenValues(), out);
  EXPECT_TRUE(out == GoldenBytes());
}

TEST(CalibrationRecord, DecodesGoldenByHand) {
  const Bytes b = GoldenBytes();
  // Hand-decoded header: "VCAL", version 3, length 1020 = 0x03FC, dof 2.
  EXPECT_EQ(b[0], 'V');
  EXPECT_EQ(b[3], 'L');
  EXPECT_EQ(b[4], 3);
  EXPECT_EQ(b[6], 0xFC);
  EXPECT_EQ(b[7], 0x03);
  EXPECT_EQ(b[8], 2);
  CalibrationRecord r;
  ASSERT_EQ(DecodeCalibrationRecord(b, r), Status::kOk);
  EXPECT_EQ(r.dof_count, 2);
  EXPECT_EQ(r.created_unix_s, 1700000000);
  EXPECT_EQ(r.host_patch, 7);
  EXPECT_EQ(r.label[0], 'r');
  EXPECT_EQ(r.label[14], '\0');
  EXPECT_EQ(r.mass_kg[0], 0.57f);
  EXPECT_EQ(r.mass_kg[1 * kMaxDof + 1], 0.56f);
  EXPECT_EQ(r.mass_kg[2 * kMaxDof + 2], 0.0f);
  EXPECT_EQ(r.stiffness_n_per_m[1], -15.0f);
  EXPECT_EQ(r.channels[2].gain, 3 << 19);
  EXPECT_EQ(r.channels[2].gain_shift, 1);
  EXPECT_EQ(r.channels[5].offset_counts, -5);
  EXPECT_EQ(r.channels[5].unit, Unit::kMeter);
  EXPECT_EQ(r.channels[3].full_scale, 490.3325f);
  EXPECT_EQ(r.dob_input_channel[0], kNoChannel);
  EXPECT_EQ(StoredRecordCrc(b), ComputeCrc32(std::span<const std::uint8_t>(b).first(kCalOffCrc)));
}

TEST(CalibrationRecord, EveryFlippedBitIsDataLossOrVersion) {
  const Bytes good = GoldenBytes();
  CalibrationRecord r;
  for (std::size_t i = 0; i < kCalRecordBytes; i += 7) {
    Bytes b = good;
    b[i] ^= 0x10;
    const Status s = DecodeCalibrationRecord(b, r);
    EXPECT_TRUE(s == Status::kDataLoss || s == Status::kVersionMismatch) << "byte " << i;
  }
}

TEST(CalibrationRecord, RefusesWrongVersionAndLength) {
  CalibrationRecord r;
  Bytes b = GoldenBytes();
  b[kCalOffVersion] = 1;  // the record before the residual test: refused, not misread
  Reseal(b);
  EXPECT_EQ(DecodeCalibrationRecord(b, r), Status::kVersionMismatch);
  b[kCalOffVersion] = 2;  // two masses at most: refused, not misread
  Reseal(b);
  EXPECT_EQ(DecodeCalibrationRecord(b, r), Status::kVersionMismatch);
  b[kCalOffVersion] = 4;
  Reseal(b);
  EXPECT_EQ(DecodeCalibrationRecord(b, r), Status::kVersionMismatch);
  // A version-2 record as a version-2 host built it (876 bytes, length 0x036C): named a version
  // mismatch, not a malformed buffer, so the host can say to rebuild it.
  b = GoldenBytes();
  b[kCalOffVersion] = 2;
  b[kCalOffLength] = 0x6C;
  EXPECT_EQ(DecodeCalibrationRecord(std::span<const std::uint8_t>(b).first(876), r),
            Status::kVersionMismatch);
  b = GoldenBytes();
  EXPECT_EQ(DecodeCalibrationRecord(std::span<const std::uint8_t>(b).first(100), r),
            Status::kInvalidArgument);
  EXPECT_EQ(DecodeCalibrationRecord(std::span<const std::uint8_t>(b).first(7), r),
            Status::kInvalidArgument);
}

TEST(CalibrationRecord, RefusesOutOfRangeFields) {
  struct Edit {
    std::size_t offset;
    std::uint8_t value;
  };
  // Each edit breaks one rule; the record is re-sealed so only the range checks can catch it.
  const Edit edits[] = {
      {kCalOffDofCount, 0},               // no masses
      {kCalOffDofCount, 5},               // more than kMaxDof
      {kCalOffDofCount, 3},               // a third mass whose mass entry is 0
      {kCalOffFlags, 0x80},               // unknown flag
      {kCalOffReserved, 1},               // reserved byte
      {kCalOffLabel + 20, 'x'},           // text after the label's NUL
      {kCalOffLabel + 1, 0x07},           // control character
      {kCalOffMass + 3, 0x80},            // m11 = -0.57: not positive definite
      {kCalOffStiffness + 4 + 3, 0x41},   // k12 != k21: asymmetric
      {kCalOffStiffness + 4 * 15, 1},     // k44 nonzero in a 2-mass record
      {kCalOffDamping + 3, 0x7F},         // c11 exponent all ones: not finite
      {kCalOffChannels + 8, 32},          // gain shift beyond 31
      {kCalOffChannels + 16 + 9, 9},      // unknown unit
      {kCalOffChannels + 32 + 10, 2},     // dof 2 of a 2-mass rig
      {kCalOffChannels + 48 + 11, 1},     // reserved channel byte
      {kCalOffChannels + 64 + 15, 0xBF},  // negative full scale
      {kCalOffDob + 100, 1},              // DOB bytes without the flag
      {kCalOffDobInputs + 1, 2},          // DOB input channel without the flag
      {kCalOffDobReserved, 1},            // reserved byte after the inputs
      {kCalOffCreated + 7, 0x80},         // negative creation time
  };
  CalibrationRecord r;
  for (const Edit& e : edits) {
    Bytes b = GoldenBytes();
    b[e.offset] = e.value;
    Reseal(b);
    EXPECT_EQ(DecodeCalibrationRecord(b, r), Status::kInvalidArgument) << "offset " << e.offset;
  }
}

TEST(CalibrationRecord, OneDofRecordRefusesSecondMassEntries) {
  CalibrationRecord v = GoldenValues();
  v.dof_count = 1;
  for (ChannelScaling& c : v.channels) c.dof = c.dof == 1 ? kNoDof : c.dof;
  v.mass_kg = Padded({{0.57f}});
  v.damping_ns_per_m = Padded({{1.25f}});
  v.stiffness_n_per_m = Padded({{15.0f}});
  Bytes b{};
  EncodeCalibrationRecord(v, b);
  CalibrationRecord r;
  EXPECT_EQ(DecodeCalibrationRecord(b, r), Status::kOk);
  v.stiffness_n_per_m[1 * kMaxDof + 1] = 15.0f;
  EncodeCalibrationRecord(v, b);
  EXPECT_EQ(DecodeCalibrationRecord(b, r), Status::kInvalidArgument);
}

// The four-mass chain scripts/golden/wire_vectors.py packs (calibration_record_chain4): masses
// 1.4, 1.2, 1.0, 0.8 kg, springs 4200, 3600, 3000, 2400 N/m from ground, dampers 3, 2.5, 2, 1.5
// N s/m; acc1 on mass 1, x1 on 2, acc2 on 3, x2 on 4, the hammer's load cell on mass 4.
CalibrationRecord Chain4Values() {
  CalibrationRecord r;
  r.dof_count = 4;
  r.created_unix_s = 1700000000;
  r.host_minor = 1;
  r.host_patch = 7;
  std::memcpy(r.label.data(), "chain4", 6);
  r.mass_kg = Padded({{1.4f, 0, 0, 0}, {0, 1.2f, 0, 0}, {0, 0, 1.0f, 0}, {0, 0, 0, 0.8f}});
  r.damping_ns_per_m = Padded(
      {{5.5f, -2.5f, 0, 0}, {-2.5f, 4.5f, -2.0f, 0}, {0, -2.0f, 3.5f, -1.5f}, {0, 0, -1.5f, 1.5f}});
  r.stiffness_n_per_m = Padded({{7800.0f, -3600.0f, 0, 0},
                                {-3600.0f, 6600.0f, -3000.0f, 0},
                                {0, -3000.0f, 5400.0f, -2400.0f},
                                {0, 0, -2400.0f, 2400.0f}});
  r.channels[0] = {2048, 1 << 20, 0, Unit::kNewton, 3, 100.0f};
  r.channels[1] = {2048, 1 << 20, 0, Unit::kNewton, kNoDof, 50.0f};
  r.channels[2] = {2048, 3 << 19, 1, Unit::kMeterPerSecond2, 0, 490.0f};
  r.channels[3] = {2048, 3 << 19, 1, Unit::kMeterPerSecond2, 2, 490.0f};
  r.channels[4] = {0, 1 << 17, 0, Unit::kMeter, 1, 0.5f};
  r.channels[5] = {0, 1 << 17, 0, Unit::kMeter, 3, 0.5f};
  return r;
}

TEST(CalibrationRecord, FourMassChainEncodesLikeGoldenAndDecodesBack) {
  Bytes golden{};
  ASSERT_EQ(testing::GoldenVector("calibration_record_chain4", golden), kCalRecordBytes);
  Bytes out{};
  EncodeCalibrationRecord(Chain4Values(), out);
  EXPECT_TRUE(out == golden);
  CalibrationRecord r;
  ASSERT_EQ(DecodeCalibrationRecord(golden, r), Status::kOk);
  EXPECT_EQ(r.dof_count, 4);
  // Hand-decoded: k34 = -2400 N/m is entry 11 of the stiffness block (offset 176 + 44); its
  // float32 is 0xC5160000, little-endian.
  EXPECT_EQ(golden[kCalOffStiffness + 44 + 2], 0x16);
  EXPECT_EQ(golden[kCalOffStiffness + 44 + 3], 0xC5);
  EXPECT_EQ(r.stiffness_n_per_m[2 * kMaxDof + 3], -2400.0f);
  EXPECT_EQ(r.mass_kg[3 * kMaxDof + 3], 0.8f);
  EXPECT_EQ(r.channels[5].dof, 3);
  // A channel on a fifth mass is refused.
  CalibrationRecord v = Chain4Values();
  v.channels[5].dof = 4;
  EncodeCalibrationRecord(v, out);
  EXPECT_EQ(DecodeCalibrationRecord(out, r), Status::kInvalidArgument);
}

// Positive definiteness beyond 2 x 2: every leading 2 x 2 minor and diagonal entry positive is
// not enough. [[1, 2, 0], [2, 5, 3], [0, 3, 1]] has leading minors 1, 1 and -8 (its pivots 1, 1,
// -8 by hand), so it is refused; [[2, 1, 0], [1, 2, 1], [0, 1, 2]] (minors 2, 3, 4) is accepted.
TEST(CalibrationRecord, ThreeMassMassMatrixMustBePositiveDefinite) {
  CalibrationRecord v = Chain4Values();
  v.dof_count = 3;
  v.channels[0].dof = 2;
  v.channels[5].dof = 2;
  v.damping_ns_per_m = Padded({{1, 0, 0}, {0, 1, 0}, {0, 0, 1}});
  v.stiffness_n_per_m = Padded({{2, -1, 0}, {-1, 2, -1}, {0, -1, 1}});
  Bytes b{};
  CalibrationRecord r;
  v.mass_kg = Padded({{2, 1, 0}, {1, 2, 1}, {0, 1, 2}});
  EncodeCalibrationRecord(v, b);
  EXPECT_EQ(DecodeCalibrationRecord(b, r), Status::kOk);
  v.mass_kg = Padded({{1, 2, 0}, {2, 5, 3}, {0, 3, 1}});
  EncodeCalibrationRecord(v, b);
  EXPECT_EQ(DecodeCalibrationRecord(b, r), Status::kInvalidArgument);
  // Singular (minor 3 exactly 0: [[1, 1, 0], [1, 2, 1], [0, 1, 1]]) is refused too.
  v.mass_kg = Padded({{1, 1, 0}, {1, 2, 1}, {0, 1, 1}});
  EncodeCalibrationRecord(v, b);
  EXPECT_EQ(DecodeCalibrationRecord(b, r), Status::kInvalidArgument);
}

// ScaleChannel against values worked out by hand from its formula.
TEST(ScaleChannel, ClosedForm) {
  std::uint32_t clips = 0;
  // 12-bit ADC centred at 2048, gain 2^20: one count is 2^20 of Q31 (full scale = 2048 counts).
  const ChannelScaling adc{2048, 1 << 20, 0, Unit::kNewton, 0, 100.0f};
  EXPECT_EQ(ScaleChannel(2048, adc, clips), 0);
  EXPECT_EQ(ScaleChannel(2049, adc, clips), 1 << 20);
  EXPECT_EQ(ScaleChannel(0, adc, clips), INT32_MIN);  // -2048 * 2^20 = -2^31 exactly
  EXPECT_EQ(clips, 0u);
  EXPECT_EQ(ScaleChannel(4096, adc, clips), INT32_MAX);  // +2^31 saturates
  EXPECT_EQ(clips, 1u);
  // Rounding half up: (3 * 3) / 2 = 4.5 -> 5; (-3 * 3) / 2 = -4.5 -> -4.
  const ChannelScaling half{0, 3, 1, Unit::kMeter, 0, 1.0f};
  EXPECT_EQ(ScaleChannel(3, half, clips), 5);
  EXPECT_EQ(ScaleChannel(-3, half, clips), -4);
  // Extremes: the widest difference times the most negative gain does not overflow int64.
  const ChannelScaling extreme{INT32_MIN, INT32_MIN, 31, Unit::kMeter, 0, 1.0f};
  EXPECT_EQ(ScaleChannel(INT32_MAX, extreme, clips), INT32_MIN);  // -(2^32 - 1) -> saturates
  EXPECT_EQ(clips, 2u);
  // The default scaling is the identity on counts.
  EXPECT_EQ(ScaleChannel(-123456, DefaultScaling(), clips), -123456);
}

// Half of Q31 full scale is half the full scale; the default scaling reads back counts.
TEST(ScaleChannel, CalibratedToSi) {
  const ChannelScaling force{2048, 1 << 20, 0, Unit::kNewton, 0, 100.0f};
  EXPECT_EQ(CalibratedToSi(1 << 30, force), 50.0);
  EXPECT_EQ(CalibratedToSi(INT32_MIN, force), -100.0);
  EXPECT_EQ(CalibratedToSi(-123456, DefaultScaling()), -123456.0);
}

}  // namespace
}  // namespace vibid::wire

namespace vibid::wire {
namespace {

// GoldenValues() with the test filter fed by force 2 (channel 1) and accelerometer 2
// (channel 3), both on mass 1, with the filter's full scales.
CalibrationRecord WithFilter() {
  CalibrationRecord r = GoldenValues();
  r.channels[1].full_scale = testing::kForceFullScaleN;
  r.channels[3].full_scale = testing::kAccelFullScaleMs2;
  testing::AttachFilter(r, testing::TestFilter(), 1, 3);
  return r;
}

Status EncodeDecode(const CalibrationRecord& r) {
  Bytes b{};
  EncodeCalibrationRecord(r, b);
  CalibrationRecord back;
  return DecodeCalibrationRecord(b, back);
}

TEST(CalibrationRecordDob, ValidFilterAndRouting) {
  const CalibrationRecord r = WithFilter();
  Bytes b{};
  EncodeCalibrationRecord(r, b);
  CalibrationRecord back;
  ASSERT_EQ(DecodeCalibrationRecord(b, back), Status::kOk);
  EXPECT_EQ(back.flags, kCalFlagHasDob);
  EXPECT_EQ(back.dob_input_channel[1], 3);
  EXPECT_TRUE(back.dob == r.dob);
  // The filter's magic sits at the documented record offset 340.
  EXPECT_EQ(b[kCalOffDob], 'V');
  EXPECT_EQ(b[kCalOffDob + 3], 'B');
}

// The same record packed by scripts/golden/wire_vectors.py, filter description included.
TEST(CalibrationRecordDob, EncodesLikeGolden) {
  Bytes golden{};
  ASSERT_EQ(testing::GoldenVector("calibration_record_dob", golden), kCalRecordBytes);
  Bytes out{};
  EncodeCalibrationRecord(WithFilter(), out);
  EXPECT_TRUE(out == golden);
  CalibrationRecord back;
  EXPECT_EQ(DecodeCalibrationRecord(golden, back), Status::kOk);
  EXPECT_EQ(golden[kCalOffDobInputs], 1);
  EXPECT_EQ(golden[kCalOffDobInputs + 1], 3);
}

TEST(CalibrationRecordDob, RefusesRoutingThatDisagreesWithTheFilter) {
  CalibrationRecord r = WithFilter();
  r.dob_input_channel[0] = 2;  // an accelerometer feeding the force input
  EXPECT_EQ(EncodeDecode(r), Status::kInvalidArgument);
  r = WithFilter();
  r.channels[1].full_scale = 50.0f;  // the filter expects 100 N full scale
  EXPECT_EQ(EncodeDecode(r), Status::kInvalidArgument);
  r = WithFilter();
  r.channels[3].dof = 0;  // accelerometer on the other mass
  EXPECT_EQ(EncodeDecode(r), Status::kInvalidArgument);
  r = WithFilter();
  r.dob_input_channel[2] = 4;  // the filter has two inputs
  EXPECT_EQ(EncodeDecode(r), Status::kInvalidArgument);
  r = WithFilter();
  r.dob_input_channel[1] = 6;
  EXPECT_EQ(EncodeDecode(r), Status::kInvalidArgument);
  r = WithFilter();
  r.dof_count = 1;  // output on mass 1 of a one-mass rig (and channels on mass 1)
  EXPECT_EQ(EncodeDecode(r), Status::kInvalidArgument);
}

TEST(CalibrationRecordDob, FilterVerdictsPassThrough) {
  CalibrationRecord r = WithFilter();
  fixed::FilterDescription unstable = testing::TestFilter();
  unstable.paths[0].sections[0].a2 = 1 << 30;  // a2 = 1: poles on the unit circle
  fixed::Seal(unstable);
  testing::AttachFilter(r, unstable, 1, 3);
  EXPECT_EQ(EncodeDecode(r), Status::kUnstable);

  r = WithFilter();
  r.dob[100] ^= 1;  // filter bytes changed after sealing: its own checksum fails
  EXPECT_EQ(EncodeDecode(r), Status::kDataLoss);

  r = WithFilter();
  r.flags = 0;  // filter bytes present without the flag
  EXPECT_EQ(EncodeDecode(r), Status::kInvalidArgument);
}

}  // namespace
}  // namespace vibid::wire

namespace vibid::wire {
namespace {

// WithFilter() with the residual test packed as WATCH in scripts/golden/wire_vectors.py: force 1
// (channel 0, newtons) as the reference.
CalibrationRecord WithWatch() {
  CalibrationRecord r = WithFilter();
  r.flags = static_cast<std::uint8_t>(r.flags | kCalFlagHasWatch);
  r.watch_reference_channel = 0;
  r.watch = {.window_samples = 1000,
             .residual_gain = 1 << 28,
             .reference_gain = -(1 << 27),
             .sum_shift = 14,
             .z_shift = 40,
             .center = 1 << 24,
             .z_gain = 1 << 30,
             .k = 1 << 15,
             .h = 8 * 65536 + 16384};
  r.watch_in_control_arl_windows = 5000.0f;
  return r;
}

TEST(CalibrationRecordWatch, EncodesLikeGoldenAndDecodesBack) {
  Bytes golden{};
  ASSERT_EQ(testing::GoldenVector("calibration_record_watch", golden), kCalRecordBytes);
  Bytes out{};
  EncodeCalibrationRecord(WithWatch(), out);
  EXPECT_TRUE(out == golden);
  // Hand-decoded: the flags byte holds both bits, the block starts at 980 with the channel, W
  // (1000 = 0x03E8) at 984.
  EXPECT_EQ(golden[kCalOffFlags], 3);
  EXPECT_EQ(golden[980], 0);
  EXPECT_EQ(golden[981], 14);
  EXPECT_EQ(golden[984], 0xE8);
  EXPECT_EQ(golden[985], 0x03);
  CalibrationRecord back;
  ASSERT_EQ(DecodeCalibrationRecord(golden, back), Status::kOk);
  EXPECT_EQ(back.watch_reference_channel, 0);
  EXPECT_EQ(back.watch.window_samples, 1000u);
  EXPECT_EQ(back.watch.reference_gain, -(1 << 27));
  EXPECT_EQ(back.watch.h, 8 * 65536 + 16384);
  EXPECT_EQ(back.watch_in_control_arl_windows, 5000.0f);
}

TEST(CalibrationRecordWatch, WithoutTheFlagTheBlockIsZero) {
  Bytes b{};
  EncodeCalibrationRecord(WithFilter(), b);
  for (std::size_t i = 0; i < kCalWatchBytes; ++i) EXPECT_EQ(b[kCalOffWatch + i], 0) << i;
  CalibrationRecord back;
  ASSERT_EQ(DecodeCalibrationRecord(b, back), Status::kOk);
  EXPECT_EQ(back.watch_reference_channel, kNoChannel);
  b[kCalOffWatch + 4] = 1;  // a window without the flag
  Reseal(b);
  EXPECT_EQ(DecodeCalibrationRecord(b, back), Status::kInvalidArgument);
}

TEST(CalibrationRecordWatch, RefusesWhatTheBoardCouldNotRun) {
  EXPECT_EQ(EncodeDecode(WithWatch()), Status::kOk);
  auto refused = [](auto change) {
    CalibrationRecord r = WithWatch();
    change(r);
    return EncodeDecode(r);
  };
  // No observer to watch.
  EXPECT_EQ(refused([](CalibrationRecord& r) {
              r = GoldenValues();
              r.flags = kCalFlagHasWatch;
              r.watch = WithWatch().watch;
              r.watch_reference_channel = kNoChannel;
              r.watch.reference_gain = 0;
              r.watch_in_control_arl_windows = 1.0f;
            }),
            Status::kInvalidArgument);
  // Parameters the kernel refuses.
  EXPECT_EQ(refused([](CalibrationRecord& r) { r.watch.window_samples = 0; }),
            Status::kInvalidArgument);
  EXPECT_EQ(refused([](CalibrationRecord& r) { r.watch.h = 0; }), Status::kInvalidArgument);
  // A reference that is not a force, or beyond the channels; a gain without a reference.
  EXPECT_EQ(refused([](CalibrationRecord& r) { r.watch_reference_channel = 2; }),
            Status::kInvalidArgument);
  EXPECT_EQ(refused([](CalibrationRecord& r) { r.watch_reference_channel = 6; }),
            Status::kInvalidArgument);
  EXPECT_EQ(refused([](CalibrationRecord& r) { r.watch_reference_channel = kNoChannel; }),
            Status::kInvalidArgument);
  EXPECT_EQ(refused([](CalibrationRecord& r) { r.watch.reference_gain = 0; }),
            Status::kInvalidArgument);
  // r = d_hat alone is fine.
  EXPECT_EQ(refused([](CalibrationRecord& r) {
              r.watch_reference_channel = kNoChannel;
              r.watch.reference_gain = 0;
            }),
            Status::kOk);
  EXPECT_EQ(refused([](CalibrationRecord& r) { r.watch_in_control_arl_windows = 0.0f; }),
            Status::kInvalidArgument);
}

TEST(CalibrationRecordWatch, CarriesTheHoldOffInByteThree) {
  // The golden record was packed with byte 3 = 0, as every record written before the hold-off:
  // it loads, with no hold-off (the kernel judges from the first window, as before).
  Bytes golden{};
  ASSERT_EQ(testing::GoldenVector("calibration_record_watch", golden), kCalRecordBytes);
  EXPECT_EQ(golden[kCalOffWatch + 3], 0);
  CalibrationRecord back;
  ASSERT_EQ(DecodeCalibrationRecord(golden, back), Status::kOk);
  EXPECT_EQ(back.watch.holdoff_windows, 0);
  // Any u8 travels: 9 and 255 at byte 983, the rest of the record unchanged.
  for (const std::uint8_t holdoff : {std::uint8_t{9}, std::uint8_t{255}}) {
    CalibrationRecord r = WithWatch();
    r.watch.holdoff_windows = holdoff;
    Bytes b{};
    EncodeCalibrationRecord(r, b);
    EXPECT_EQ(b[983], holdoff);
    for (std::size_t i = 0; i < kCalOffCrc; ++i) {
      if (i != 983) {
        EXPECT_EQ(b[i], golden[i]) << i;
      }
    }
    ASSERT_EQ(DecodeCalibrationRecord(b, back), Status::kOk);
    EXPECT_EQ(back.watch.holdoff_windows, holdoff);
    EXPECT_EQ(back.watch.window_samples, 1000u);
  }
  // Without the flag the whole block, byte 3 included, stays zero.
  Bytes b{};
  EncodeCalibrationRecord(WithFilter(), b);
  b[kCalOffWatch + 3] = 1;
  Reseal(b);
  EXPECT_EQ(DecodeCalibrationRecord(b, back), Status::kInvalidArgument);
}

}  // namespace
}  // namespace vibid::wire
