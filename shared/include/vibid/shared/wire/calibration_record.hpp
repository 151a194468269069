// The calibration record: what the host uploads and the board keeps in flash. It carries the
// physical model (for the host to read back and for range checks), the per-channel scaling the
// board applies to every sample, and the quantized disturbance-observer filter the board runs.
//
// Byte layout (little-endian, offsets in bytes, total kCalRecordBytes = 1020):
//
//   0    u32  magic              kCalMagic: bytes 'V','C','A','L'
//   4    u16  version            kCalRecordVersion (3: models of up to four masses; version 2
//                                held two, in 876 bytes, and is refused with kVersionMismatch)
//   6    u16  length             kCalRecordBytes (a reader of another length refuses the record)
//   8    u8   dof_count          1..kMaxDof
//   9    u8   flags              kCalFlagHasDob, kCalFlagHasWatch (only with kCalFlagHasDob)
//   10   u16  reserved           0
//   12   i64  created_unix_s     when the host built the record (seconds since 1970, UTC)
//   20   u8   host_major  21 u8 host_minor  22 u16 host_patch   version of the host that built it
//   24   char label[24]          printable ASCII, NUL-padded (the rig's name)
//   48   f32  mass_kg[4][4]      row-major; entries beyond dof_count are 0
//   112  f32  damping_ns_per_m[4][4]
//   176  f32  stiffness_n_per_m[4][4]
//   240  ChannelScaling[6]       16 bytes each, in wire::Channel order, layout below
//   336  u8   dob_input_channel[3]  the wire::Channel feeding each DOB input (its scaling's unit
//                                must match the input's kind and its full scale the input's);
//                                kNoChannel for unused inputs and when there is no filter
//   339  u8   reserved           0
//   340  u8   dob[640]           the quantized DOB (vibid::fixed description encoding), all
//                                zero when kCalFlagHasDob is clear
//   980  Watch (36 bytes)        the observer's residual test (vibid::fixed::ResidualCusum), all
//                                zero when kCalFlagHasWatch is clear; layout below
//   1016 u32  crc32              CRC-32 of bytes [0, 1016)
//
//   Watch (36 bytes; the kernel's parameters, see residual_cusum.hpp):
//   0   u8   reference_channel   the wire::Channel of the load cell whose force r = d_hat - F
//                                subtracts (a kNewton channel), kNoChannel for r = d_hat
//   1   u8   sum_shift  2 u8 z_shift
//   3   u8   holdoff_windows     windows after the observer's start that are not judged (its start
//                                transient); 0 = none. This byte was reserved (0) before, so
//                                records written then still load and judge from the first window
//   4   u32  window_samples      W
//   8   i32  residual_gain       Q32
//   12  i32  reference_gain      Q32; 0 exactly when reference_channel is kNoChannel
//   16  i32  center  20 i32 z_gain  24 i32 k (Q16)  28 i32 h (Q16)
//   32  f32  in_control_arl_windows  the windows between false alarms the host designed for
//                                (metadata for the host to show; the board does not use it)
//
//   ChannelScaling (16 bytes):
//   0   i32  offset_counts       raw value that reads as zero
//   4   i32  gain                calibrated = sat32(round(((raw - offset) * gain) / 2^gain_shift))
//   8   u8   gain_shift          0..kMaxGainShift
//   9   u8   unit                Unit of full_scale
//   10  u8   dof                 mass the sensor sits on (0-based), kNoDof if none
//   11  u8   reserved            0
//   12  f32  full_scale          SI value (in `unit`) that calibrated = 2^31 stands for
//
// Why the model is float32: the board never computes with M, C, K (the filter arrives already
// quantized); they travel for the host to show and to check, and float32's 24-bit mantissa is far
// finer than identification accuracy (about 1 %) across grams to tonnes without a per-quantity
// fixed-point scale. The per-sample scaling, which the board does run, is integer (gain and
// shift), so the host replays it bit for bit (ScaleChannel below).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/shared/fixed/residual_cusum.hpp"
#include "vibid/shared/status.hpp"
#include "vibid/shared/wire/device.hpp"

namespace vibid::wire {

inline constexpr std::uint32_t kCalMagic = 0x4C414356u;  // bytes 'V','C','A','L'
inline constexpr std::uint16_t kCalRecordVersion = 3;
/// The board's four response inputs (acc1, acc2, x1, x2) measure a chain of up to four masses.
inline constexpr std::size_t kMaxDof = 4;
inline constexpr std::size_t kDobDescriptionBytes = 640;
inline constexpr std::size_t kCalLabelBytes = 24;
inline constexpr std::uint8_t kCalFlagHasDob = 1u << 0;
inline constexpr std::uint8_t kCalFlagHasWatch = 1u << 1;
inline constexpr std::uint8_t kNoDof = 0xFF;
inline constexpr std::uint8_t kMaxGainShift = 31;

inline constexpr std::size_t kCalOffMagic = 0;
inline constexpr std::size_t kCalOffVersion = 4;
inline constexpr std::size_t kCalOffLength = 6;
inline constexpr std::size_t kCalOffDofCount = 8;
inline constexpr std::size_t kCalOffFlags = 9;
inline constexpr std::size_t kCalOffReserved = 10;
inline constexpr std::size_t kCalOffCreated = 12;
inline constexpr std::size_t kCalOffHostVersion = 20;
inline constexpr std::size_t kCalOffLabel = 24;
inline constexpr std::size_t kCalOffMass = kCalOffLabel + kCalLabelBytes;
inline constexpr std::size_t kCalOffDamping = kCalOffMass + 4 * kMaxDof * kMaxDof;
inline constexpr std::size_t kCalOffStiffness = kCalOffDamping + 4 * kMaxDof * kMaxDof;
inline constexpr std::size_t kCalOffChannels = kCalOffStiffness + 4 * kMaxDof * kMaxDof;
inline constexpr std::size_t kChannelScalingBytes = 16;
inline constexpr std::size_t kMaxDobInputs = 3;
inline constexpr std::uint8_t kNoChannel = 0xFF;
inline constexpr std::size_t kCalOffDobInputs =
    kCalOffChannels + kChannelCount * kChannelScalingBytes;
inline constexpr std::size_t kCalOffDobReserved = kCalOffDobInputs + kMaxDobInputs;
inline constexpr std::size_t kCalOffDob = kCalOffDobReserved + 1;
inline constexpr std::size_t kCalOffWatch = kCalOffDob + kDobDescriptionBytes;
inline constexpr std::size_t kCalWatchBytes = 36;
inline constexpr std::size_t kCalOffCrc = kCalOffWatch + kCalWatchBytes;
inline constexpr std::size_t kCalRecordBytes = kCalOffCrc + 4;

static_assert(kCalOffMass == 48 && kCalOffDamping == 112 && kCalOffStiffness == 176);
static_assert(kCalOffChannels == 240 && kCalOffDobInputs == 336 && kCalOffDob == 340);
static_assert(kCalOffWatch == 980 && kCalOffCrc == 1016 && kCalRecordBytes == 1020);
static_assert(kCalRecordBytes <= 0xFFFF, "length travels in a u16");

/// What a channel's full scale is measured in.
enum class Unit : std::uint8_t {
  kCounts = 0,  ///< Uncalibrated: the value is the raw count.
  kNewton = 1,
  kMeterPerSecond2 = 2,
  kMeter = 3,
  kMeterPerSecond = 4,
};

struct ChannelScaling {
  std::int32_t offset_counts = 0;
  std::int32_t gain = 1;
  std::uint8_t gain_shift = 0;
  Unit unit = Unit::kCounts;
  std::uint8_t dof = kNoDof;
  float full_scale = 2147483648.0f;  ///< Default: one calibrated unit per count.
};

struct CalibrationRecord {
  std::uint8_t dof_count = 1;
  std::uint8_t flags = 0;
  std::int64_t created_unix_s = 0;
  std::uint8_t host_major = 0;
  std::uint8_t host_minor = 0;
  std::uint16_t host_patch = 0;
  std::array<char, kCalLabelBytes> label{};
  std::array<float, kMaxDof * kMaxDof> mass_kg{};            ///< Row-major.
  std::array<float, kMaxDof * kMaxDof> damping_ns_per_m{};   ///< Row-major.
  std::array<float, kMaxDof * kMaxDof> stiffness_n_per_m{};  ///< Row-major.
  std::array<ChannelScaling, kChannelCount> channels{};
  std::array<std::uint8_t, kMaxDobInputs> dob_input_channel{kNoChannel, kNoChannel, kNoChannel};
  std::array<std::uint8_t, kDobDescriptionBytes> dob{};
  /// The residual test (kCalFlagHasWatch): its load cell channel and its parameters.
  std::uint8_t watch_reference_channel = kNoChannel;
  fixed::ResidualCusumParams watch{};
  float watch_in_control_arl_windows = 0.0f;
};

/// Writes the record and its CRC-32 into exactly kCalRecordBytes.
void EncodeCalibrationRecord(const CalibrationRecord& record,
                             std::span<std::uint8_t, kCalRecordBytes> out);

/// Reads and checks a record, the filter included.
/// @returns kOk;
///          kInvalidArgument if bytes hold less than the header (8 bytes);
///          kVersionMismatch for a wrong magic, version or length field (checked first: a record
///            of version 1 or 2 is named so whatever its length);
///          kInvalidArgument if bytes.size() != kCalRecordBytes (checked next);
///          kDataLoss if the CRC-32 does not match (checked next);
///          kInvalidArgument for any field out of range: dof_count, flags, reserved bytes, label,
///            a non-finite or asymmetric matrix, a mass matrix that is not positive definite (every
///            pivot of its Gaussian elimination positive),
///            nonzero entries beyond dof_count, a gain shift > kMaxGainShift, an unknown unit,
///            a dof index beyond dof_count, a full scale that is not finite and positive, a
///            negative creation time, DOB bytes or input channels present without the flag, an
///            input channel beyond the six channels;
///          with a filter (kCalFlagHasDob): fixed::ValidateDescription's verdict (kVersionMismatch,
///            kDataLoss, kOutOfRange, kInvalidArgument, kUnstable), then kInvalidArgument for an
///            output mass beyond dof_count or an input whose channel differs from the filter's
///            expectation in unit, mass or full scale, or an unused input given a channel.
///          with a residual test (kCalFlagHasWatch): kInvalidArgument without a filter, for
///            parameters fixed::ValidateResidualCusum refuses, a nonzero reserved byte, a
///            reference channel beyond the six or not in newtons, a reference gain without a
///            reference channel (or none with one), or a non-finite or non-positive run length;
///            without it, kInvalidArgument for any nonzero byte of the block.
Status DecodeCalibrationRecord(std::span<const std::uint8_t> bytes, CalibrationRecord& record);

/// The record's CRC-32 field as stored in encoded bytes (no check).
std::uint32_t StoredRecordCrc(std::span<const std::uint8_t, kCalRecordBytes> bytes);

/// The scaling every channel gets when the board is uncalibrated: the raw count.
constexpr ChannelScaling DefaultScaling() { return ChannelScaling{}; }

/// One sample through its channel's calibration.
///
/// Scaling and overflow: raw and offset are int32, so their difference needs 33 bits and is
/// formed in int64; |raw - offset| <= 2^32 - 1 and |gain| <= 2^31 keep the product within
/// (2^32 - 1) * 2^31 < 2^63 - 2^31, and the rounding constant 2^(gain_shift - 1) <= 2^30 cannot
/// carry it past 2^63 (the reason gain_shift stops at 31). The shift is arithmetic (round half
/// up). The result is saturated to int32 and each saturation counted in `clip_count`, never
/// wrapped.
constexpr std::int32_t ScaleChannel(std::int32_t raw, const ChannelScaling& s,
                                    std::uint32_t& clip_count) {
  const std::int64_t diff = static_cast<std::int64_t>(raw) - s.offset_counts;
  std::int64_t acc = diff * s.gain;
  if (s.gain_shift > 0) {
    acc = (acc + (std::int64_t{1} << (s.gain_shift - 1))) >> s.gain_shift;
  }
  if (acc > INT32_MAX) {
    ++clip_count;
    return INT32_MAX;
  }
  if (acc < INT32_MIN) {
    ++clip_count;
    return INT32_MIN;
  }
  return static_cast<std::int32_t>(acc);
}

/// The SI value (in s.unit) a calibrated integer stands for: calibrated / 2^31 * full_scale.
/// For the host (recordings, live values); the board stays in integers.
constexpr double CalibratedToSi(std::int32_t calibrated, const ChannelScaling& s) {
  return static_cast<double>(calibrated) / 2147483648.0 * static_cast<double>(s.full_scale);
}

}  // namespace vibid::wire
