// The quantized disturbance-observer filter as the host designs it and the board runs it.
//
// One description travels inside the calibration record, so it is a plain aggregate of
// fixed-width integers with a fixed maximum size (no heap, no pointers) and an explicit
// little-endian byte layout (EncodeDescription / DecodeDescription). The board calls
// ValidateDescription before it runs an uploaded filter.
//
// Structure: d_hat = sum over inputs i of  g_i * H_i(z) u_i, where u_i is input i as a Q31
// fraction of its full-scale value, H_i is a cascade of up to kMaxSections second-order sections
// (each path scaled so no section output can leave Q31 for any full-scale input) and g_i the
// path's output gain. The host realizes Q(s) G_A^-1(s) on the sensor paths and -Q(s) on the
// force path, so the sum is methods Eq. 13 (or the multi-input form Q[M x'' + C x' + K x - F]).
//
// Byte layout (little-endian, offsets in bytes, total kDescriptionBytes = 640):
//
//   0   u32  magic                    kDescriptionMagic ("VDOB" in memory order)
//   4   u16  version                  kDescriptionVersion
//   6   u8   input_count              1..kMaxInputs; paths at index >= input_count are all zero
//   7   u8   output_dof               0-based mass index the estimate d_hat acts on
//   8   u32  sample_rate_hz           rate the filter was discretized at (> 0)
//   12  u8   input_kind[3]            InputKind per input (kUnused beyond input_count)
//   15  u8   reserved0                0
//   16  u8   input_dof[3]             0-based mass index each input is measured on
//   19  u8   reserved1                0
//   20  u32  input_full_scale_bits[3] IEEE-754 binary32 bit pattern: SI value of Q31 full scale
//                                     (N for force, m, m/s, m/s^2) of input i
//   32  u32  output_full_scale_bits   binary32 bit pattern: N that d_hat's Q31 full scale stands
//   for 36  Path paths[3]                 3 x 200 bytes, layout below 636 u32  checksum CRC-32
//   (ISO-HDLC, poly 0xEDB88320 reflected, init and
//                                     xorout 0xFFFFFFFF) of encoded bytes [0, 636)
//
//   Path (200 bytes):
//   0   u8   section_count            0..kMaxSections; a path with 0 sections is a pure gain
//   1   u8   output_shift             0..kMaxOutputShift
//   2   u8   reserved[2]              0
//   4   i32  output_gain              contribution = round(y * output_gain / 2^(31 - output_shift))
//   8   Section sections[8]           8 x 24 bytes; sections >= section_count are all zero
//
//   Section (24 bytes), coefficients in Q(31 - shift), i.e. real value = raw / 2^(31 - shift):
//   0   i32  b0, b1, b2, a1, a2       y[n] = b0 x[n] + b1 x[n-1] + b2 x[n-2] - a1 y[n-1] - a2
//   y[n-2]
//                                     (scipy.signal sos convention, a0 = 1 implied)
//   20  u8   shift                    0..kMaxSectionShift
//   21  u8   feedback                 ErrorFeedback: 0 none, 1 second-order (1 - z^-1)^2
//   22  u8   reserved[2]              0
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/shared/status.hpp"

namespace vibid::fixed {

inline constexpr std::size_t kMaxInputs = 3;
inline constexpr std::size_t kMaxSections = 8;
inline constexpr std::uint8_t kMaxSectionShift = 15;
inline constexpr std::uint8_t kMaxOutputShift = 30;
/// Bound on |b0| + |b1| + |b2| + |a1| + |a2| of a section's raw integers: with int32 states every
/// product sum stays below 2^63 - 2^33, leaving room for the error feedback and the rounding.
inline constexpr std::int64_t kMaxCoefficientSum = (std::int64_t{1} << 32) - 4;
inline constexpr std::uint32_t kDescriptionMagic = 0x424F4456u;  // bytes 'V','D','O','B'
inline constexpr std::uint16_t kDescriptionVersion = 1;
inline constexpr std::size_t kDescriptionBytes = 640;
inline constexpr std::size_t kChecksumOffset = kDescriptionBytes - 4;

/// What an input channel measures; the board routes its calibrated channel by this.
enum class InputKind : std::uint8_t {
  kUnused = 0,
  kForce = 1,         ///< Measured excitation F (N).
  kDisplacement = 2,  ///< m.
  kVelocity = 3,      ///< m/s.
  kAcceleration = 4,  ///< m/s^2.
};

/// Rounding-error feedback of a section (see dob_filter.hpp). Poles near z = 1 amplify the
/// output rounding by up to 1 / ((1 - r)^2 ...); feeding the two previous rounding remainders back
/// with weights (2, -1) shapes that noise by (1 - z^-1)^2, which cancels the amplification at low
/// frequencies for the price of at most 4x (12 dB) near Nyquist.
enum class ErrorFeedback : std::uint8_t {
  kNone = 0,
  kSecondOrder = 1,
};

/// One second-order section, coefficients in Q(31 - shift).
struct Section {
  std::int32_t b0 = 0;
  std::int32_t b1 = 0;
  std::int32_t b2 = 0;
  std::int32_t a1 = 0;
  std::int32_t a2 = 0;
  std::uint8_t shift = 0;
  ErrorFeedback feedback = ErrorFeedback::kNone;
  std::uint8_t reserved[2] = {0, 0};
};

/// The cascade applied to one input, and the gain its output enters d_hat with.
struct Path {
  std::uint8_t section_count = 0;
  std::uint8_t output_shift = 0;
  std::uint8_t reserved[2] = {0, 0};
  std::int32_t output_gain = 0;
  std::array<Section, kMaxSections> sections{};
};

/// The whole quantized observer. Field order and widths are the wire layout (see file comment).
struct FilterDescription {
  std::uint32_t magic = kDescriptionMagic;
  std::uint16_t version = kDescriptionVersion;
  std::uint8_t input_count = 0;
  std::uint8_t output_dof = 0;
  std::uint32_t sample_rate_hz = 0;
  std::array<InputKind, kMaxInputs> input_kind{};
  std::uint8_t reserved0 = 0;
  std::array<std::uint8_t, kMaxInputs> input_dof{};
  std::uint8_t reserved1 = 0;
  std::array<std::uint32_t, kMaxInputs> input_full_scale_bits{};
  std::uint32_t output_full_scale_bits = 0;
  std::array<Path, kMaxInputs> paths{};
  std::uint32_t checksum = 0;
};

static_assert(sizeof(Section) == 24);
static_assert(offsetof(Section, shift) == 20);
static_assert(offsetof(Section, feedback) == 21);
static_assert(sizeof(Path) == 200);
static_assert(offsetof(Path, output_gain) == 4);
static_assert(offsetof(Path, sections) == 8);
static_assert(offsetof(FilterDescription, sample_rate_hz) == 8);
static_assert(offsetof(FilterDescription, input_kind) == 12);
static_assert(offsetof(FilterDescription, input_dof) == 16);
static_assert(offsetof(FilterDescription, input_full_scale_bits) == 20);
static_assert(offsetof(FilterDescription, output_full_scale_bits) == 32);
static_assert(offsetof(FilterDescription, paths) == 36);
static_assert(offsetof(FilterDescription, checksum) == kChecksumOffset);
static_assert(sizeof(FilterDescription) == kDescriptionBytes);

/// binary32 bit pattern <-> value, for the full-scale fields (metadata; the kernel is
/// integer-only).
constexpr std::uint32_t FullScaleBits(float value) { return std::bit_cast<std::uint32_t>(value); }
constexpr float FullScaleValue(std::uint32_t bits) { return std::bit_cast<float>(bits); }

/// Writes the little-endian wire form (the checksum field is written as stored, not recomputed).
void EncodeDescription(const FilterDescription& description,
                       std::span<std::uint8_t, kDescriptionBytes> out);

/// Reads the wire form. Does not validate; call ValidateDescription on the result.
/// @returns kOk always for a full-size buffer (kept a Status for symmetry with the record codecs).
Status DecodeDescription(std::span<const std::uint8_t, kDescriptionBytes> in,
                         FilterDescription& description);

/// CRC-32/ISO-HDLC (reflected poly 0xEDB88320, init and xorout 0xFFFFFFFF) of `bytes`.
std::uint32_t Crc32IsoHdlc(std::span<const std::uint8_t> bytes);

/// CRC-32 (ISO-HDLC) of the encoded bytes [0, kChecksumOffset).
std::uint32_t ComputeChecksum(const FilterDescription& description);

/// Stores ComputeChecksum(description) in description.checksum.
void Seal(FilterDescription& description);

/// Checks an uploaded description before the board runs it.
/// @returns kOk if it may run;
///          kVersionMismatch for a wrong magic or version (checked first);
///          kDataLoss if the checksum does not match (checked next: corrupted bytes say nothing);
///          kOutOfRange for input_count outside 1..kMaxInputs or section_count > kMaxSections;
///          kInvalidArgument for a shift or feedback mode out of range, a nonzero reserved byte, a
///          used input of
///            kind kUnused or an unused slot carrying data, a zero sample rate, a non-finite or
///            non-positive full scale, or a section whose absolute coefficient sum exceeds
///            kMaxCoefficientSum (the bound that keeps the 64-bit accumulator from overflowing);
///          kUnstable if a section's integer denominator 1 + a1 z^-1 + a2 z^-2 has a root on or
///            outside the unit circle (Jury: |a2| < 1 and |a1| < 1 + a2, evaluated exactly on the
///            integers).
Status ValidateDescription(const FilterDescription& description);

/// True if the integer section's poles lie strictly inside the unit circle (exact Jury test).
bool SectionIsStable(const Section& section);

}  // namespace vibid::fixed
