#include "vibid/shared/wire/calibration_record.hpp"

#include <bit>

#include "vibid/shared/fixed/filter_description.hpp"
#include "vibid/shared/wire/byte_order.hpp"
#include "vibid/shared/wire/crc32.hpp"

namespace vibid::wire {

static_assert(kDobDescriptionBytes == fixed::kDescriptionBytes, "the record embeds the filter");
static_assert(kMaxDobInputs == fixed::kMaxInputs);

namespace {

constexpr std::size_t kN = kMaxDof;

// Bit-level test: no libm on the board, and -ffast-math must not fold it away.
bool IsFinite(float v) { return (std::bit_cast<std::uint32_t>(v) & 0x7F800000u) != 0x7F800000u; }

void StoreF32(std::span<std::uint8_t> out, std::size_t offset, float v) {
  StoreU32(out, offset, std::bit_cast<std::uint32_t>(v));
}
float LoadF32(std::span<const std::uint8_t> in, std::size_t offset) {
  return std::bit_cast<float>(LoadU32(in, offset));
}

void StoreMatrix(std::span<std::uint8_t> out, std::size_t offset,
                 const std::array<float, kN * kN>& m) {
  for (std::size_t i = 0; i < m.size(); ++i) StoreF32(out, offset + 4 * i, m[i]);
}
void LoadMatrix(std::span<const std::uint8_t> in, std::size_t offset,
                std::array<float, kN * kN>& m) {
  for (std::size_t i = 0; i < m.size(); ++i) m[i] = LoadF32(in, offset + 4 * i);
}

// Finite, symmetric, zero outside the leading dof_count x dof_count block.
bool MatrixShapeOk(const std::array<float, kN * kN>& m, std::size_t dof_count) {
  for (std::size_t r = 0; r < kN; ++r) {
    for (std::size_t c = 0; c < kN; ++c) {
      const float v = m[r * kN + c];
      if (!IsFinite(v)) return false;
      if ((r >= dof_count || c >= dof_count) && v != 0.0f) return false;
      if (v != m[c * kN + r]) return false;
    }
  }
  return true;
}

// A symmetric matrix is positive definite exactly when every pivot of its Gaussian elimination
// (without row exchanges) is positive: the pivots are the ratios of successive leading minors
// (Sylvester's criterion), and elimination forms them without square roots (the board has a
// single-precision FPU and no libm). An overflow to infinity or NaN compares false and refuses
// the record, as it should.
bool MassPositiveDefinite(const std::array<float, kN * kN>& m, std::size_t dof_count) {
  std::array<float, kN* kN> a = m;
  for (std::size_t p = 0; p < dof_count; ++p) {
    const float pivot = a[p * kN + p];
    if (!(pivot > 0.0f) || !IsFinite(pivot)) return false;
    for (std::size_t r = p + 1; r < dof_count; ++r) {
      const float f = a[r * kN + p] / pivot;
      for (std::size_t c = p; c < dof_count; ++c) a[r * kN + c] -= f * a[p * kN + c];
    }
  }
  return true;
}

bool LabelOk(const std::array<char, kCalLabelBytes>& label) {
  bool ended = false;
  for (const char ch : label) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == 0) {
      ended = true;
    } else if (ended || c < 0x20 || c > 0x7E) {
      return false;
    }
  }
  return true;
}

bool ChannelOk(const ChannelScaling& s, std::size_t dof_count) {
  return s.gain_shift <= kMaxGainShift &&
         static_cast<std::uint8_t>(s.unit) <= static_cast<std::uint8_t>(Unit::kMeterPerSecond) &&
         (s.dof == kNoDof || s.dof < dof_count) && IsFinite(s.full_scale) && s.full_scale > 0.0f;
}

Unit UnitOf(fixed::InputKind kind) {
  switch (kind) {
    case fixed::InputKind::kForce: return Unit::kNewton;
    case fixed::InputKind::kDisplacement: return Unit::kMeter;
    case fixed::InputKind::kVelocity: return Unit::kMeterPerSecond;
    case fixed::InputKind::kAcceleration: return Unit::kMeterPerSecond2;
    case fixed::InputKind::kUnused: break;
  }
  return Unit::kCounts;
}

// The filter must be valid on its own, and each input must be fed by a channel that measures
// what the filter expects, on the same mass, with the same Q31 full scale (otherwise the
// integers would mean something else than the host designed for).
Status CheckDob(const CalibrationRecord& r) {
  fixed::FilterDescription d;
  (void)fixed::DecodeDescription(r.dob, d);
  const Status valid = fixed::ValidateDescription(d);
  if (valid != Status::kOk) return valid;
  if (d.output_dof >= r.dof_count) return Status::kInvalidArgument;
  for (std::size_t i = 0; i < kMaxDobInputs; ++i) {
    const std::uint8_t c = r.dob_input_channel[i];
    if (i >= d.input_count) {
      if (c != kNoChannel) return Status::kInvalidArgument;
      continue;
    }
    if (c >= kChannelCount) return Status::kInvalidArgument;
    const ChannelScaling& ch = r.channels[c];
    if (ch.unit != UnitOf(d.input_kind[i]) || ch.dof != d.input_dof[i] ||
        std::bit_cast<std::uint32_t>(ch.full_scale) != d.input_full_scale_bits[i]) {
      return Status::kInvalidArgument;
    }
  }
  return Status::kOk;
}

// The residual test needs the observer, a force channel to subtract (or none) and parameters the
// kernel accepts.
Status CheckWatch(const CalibrationRecord& r) {
  if ((r.flags & kCalFlagHasDob) == 0) return Status::kInvalidArgument;
  const Status valid = fixed::ValidateResidualCusum(r.watch);
  if (valid != Status::kOk) return Status::kInvalidArgument;
  const std::uint8_t c = r.watch_reference_channel;
  if (c == kNoChannel) {
    if (r.watch.reference_gain != 0) return Status::kInvalidArgument;
  } else if (c >= kChannelCount || r.channels[c].unit != Unit::kNewton ||
             r.watch.reference_gain == 0) {
    return Status::kInvalidArgument;
  }
  if (!IsFinite(r.watch_in_control_arl_windows) || !(r.watch_in_control_arl_windows > 0.0f)) {
    return Status::kInvalidArgument;
  }
  return Status::kOk;
}

}  // namespace

void EncodeCalibrationRecord(const CalibrationRecord& record,
                             std::span<std::uint8_t, kCalRecordBytes> out) {
  StoreU32(out, kCalOffMagic, kCalMagic);
  StoreU16(out, kCalOffVersion, kCalRecordVersion);
  StoreU16(out, kCalOffLength, static_cast<std::uint16_t>(kCalRecordBytes));
  StoreU8(out, kCalOffDofCount, record.dof_count);
  StoreU8(out, kCalOffFlags, record.flags);
  StoreU16(out, kCalOffReserved, 0);
  StoreI64(out, kCalOffCreated, record.created_unix_s);
  StoreU8(out, kCalOffHostVersion, record.host_major);
  StoreU8(out, kCalOffHostVersion + 1, record.host_minor);
  StoreU16(out, kCalOffHostVersion + 2, record.host_patch);
  for (std::size_t i = 0; i < kCalLabelBytes; ++i) {
    StoreU8(out, kCalOffLabel + i, static_cast<std::uint8_t>(record.label[i]));
  }
  StoreMatrix(out, kCalOffMass, record.mass_kg);
  StoreMatrix(out, kCalOffDamping, record.damping_ns_per_m);
  StoreMatrix(out, kCalOffStiffness, record.stiffness_n_per_m);
  for (std::size_t c = 0; c < kChannelCount; ++c) {
    const ChannelScaling& s = record.channels[c];
    const std::size_t base = kCalOffChannels + c * kChannelScalingBytes;
    StoreI32(out, base + 0, s.offset_counts);
    StoreI32(out, base + 4, s.gain);
    StoreU8(out, base + 8, s.gain_shift);
    StoreU8(out, base + 9, static_cast<std::uint8_t>(s.unit));
    StoreU8(out, base + 10, s.dof);
    StoreU8(out, base + 11, 0);
    StoreF32(out, base + 12, s.full_scale);
  }
  for (std::size_t i = 0; i < kMaxDobInputs; ++i) {
    StoreU8(out, kCalOffDobInputs + i, record.dob_input_channel[i]);
  }
  StoreU8(out, kCalOffDobReserved, 0);
  for (std::size_t i = 0; i < kDobDescriptionBytes; ++i) out[kCalOffDob + i] = record.dob[i];
  // Without the test the block is all zero (the reference channel too), as the decoder demands.
  const bool watch = (record.flags & kCalFlagHasWatch) != 0;
  const fixed::ResidualCusumParams w = watch ? record.watch : fixed::ResidualCusumParams{};
  StoreU8(out, kCalOffWatch + 0, watch ? record.watch_reference_channel : 0);
  StoreU8(out, kCalOffWatch + 1, w.sum_shift);
  StoreU8(out, kCalOffWatch + 2, w.z_shift);
  StoreU8(out, kCalOffWatch + 3, w.holdoff_windows);
  StoreU32(out, kCalOffWatch + 4, w.window_samples);
  StoreI32(out, kCalOffWatch + 8, w.residual_gain);
  StoreI32(out, kCalOffWatch + 12, w.reference_gain);
  StoreI32(out, kCalOffWatch + 16, w.center);
  StoreI32(out, kCalOffWatch + 20, w.z_gain);
  StoreI32(out, kCalOffWatch + 24, w.k);
  StoreI32(out, kCalOffWatch + 28, w.h);
  StoreF32(out, kCalOffWatch + 32, watch ? record.watch_in_control_arl_windows : 0.0f);
  StoreU32(out, kCalOffCrc, ComputeCrc32(std::span<const std::uint8_t>(out).first(kCalOffCrc)));
}

std::uint32_t StoredRecordCrc(std::span<const std::uint8_t, kCalRecordBytes> bytes) {
  return LoadU32(bytes, kCalOffCrc);
}

Status DecodeCalibrationRecord(std::span<const std::uint8_t> bytes, CalibrationRecord& record) {
  // The header first, so a record of another version (another length: version 2 held 876
  // bytes) is named a version mismatch, not a malformed buffer.
  if (bytes.size() < kCalOffDofCount) return Status::kInvalidArgument;
  if (LoadU32(bytes, kCalOffMagic) != kCalMagic ||
      LoadU16(bytes, kCalOffVersion) != kCalRecordVersion ||
      LoadU16(bytes, kCalOffLength) != kCalRecordBytes) {
    return Status::kVersionMismatch;
  }
  if (bytes.size() != kCalRecordBytes) return Status::kInvalidArgument;
  if (ComputeCrc32(bytes.first(kCalOffCrc)) != LoadU32(bytes, kCalOffCrc)) {
    return Status::kDataLoss;
  }
  CalibrationRecord r;
  r.dof_count = LoadU8(bytes, kCalOffDofCount);
  r.flags = LoadU8(bytes, kCalOffFlags);
  r.created_unix_s = LoadI64(bytes, kCalOffCreated);
  r.host_major = LoadU8(bytes, kCalOffHostVersion);
  r.host_minor = LoadU8(bytes, kCalOffHostVersion + 1);
  r.host_patch = LoadU16(bytes, kCalOffHostVersion + 2);
  for (std::size_t i = 0; i < kCalLabelBytes; ++i) {
    r.label[i] = static_cast<char>(LoadU8(bytes, kCalOffLabel + i));
  }
  LoadMatrix(bytes, kCalOffMass, r.mass_kg);
  LoadMatrix(bytes, kCalOffDamping, r.damping_ns_per_m);
  LoadMatrix(bytes, kCalOffStiffness, r.stiffness_n_per_m);
  bool channels_ok = true;
  for (std::size_t c = 0; c < kChannelCount; ++c) {
    ChannelScaling& s = r.channels[c];
    const std::size_t base = kCalOffChannels + c * kChannelScalingBytes;
    s.offset_counts = LoadI32(bytes, base + 0);
    s.gain = LoadI32(bytes, base + 4);
    s.gain_shift = LoadU8(bytes, base + 8);
    s.unit = static_cast<Unit>(LoadU8(bytes, base + 9));
    s.dof = LoadU8(bytes, base + 10);
    s.full_scale = LoadF32(bytes, base + 12);
    channels_ok = channels_ok && LoadU8(bytes, base + 11) == 0;
  }
  bool inputs_ok = LoadU8(bytes, kCalOffDobReserved) == 0;
  bool inputs_unused = true;
  for (std::size_t i = 0; i < kMaxDobInputs; ++i) {
    const std::uint8_t c = LoadU8(bytes, kCalOffDobInputs + i);
    r.dob_input_channel[i] = c;
    inputs_ok = inputs_ok && (c == kNoChannel || c < kChannelCount);
    inputs_unused = inputs_unused && c == kNoChannel;
  }
  bool dob_zero = true;
  for (std::size_t i = 0; i < kDobDescriptionBytes; ++i) {
    r.dob[i] = bytes[kCalOffDob + i];
    dob_zero = dob_zero && r.dob[i] == 0;
  }

  bool watch_zero = true;
  for (std::size_t i = 0; i < kCalWatchBytes; ++i) {
    watch_zero = watch_zero && bytes[kCalOffWatch + i] == 0;
  }
  r.watch_reference_channel = LoadU8(bytes, kCalOffWatch + 0);
  r.watch.sum_shift = LoadU8(bytes, kCalOffWatch + 1);
  r.watch.z_shift = LoadU8(bytes, kCalOffWatch + 2);
  r.watch.holdoff_windows = LoadU8(bytes, kCalOffWatch + 3);
  r.watch.window_samples = LoadU32(bytes, kCalOffWatch + 4);
  r.watch.residual_gain = LoadI32(bytes, kCalOffWatch + 8);
  r.watch.reference_gain = LoadI32(bytes, kCalOffWatch + 12);
  r.watch.center = LoadI32(bytes, kCalOffWatch + 16);
  r.watch.z_gain = LoadI32(bytes, kCalOffWatch + 20);
  r.watch.k = LoadI32(bytes, kCalOffWatch + 24);
  r.watch.h = LoadI32(bytes, kCalOffWatch + 28);
  r.watch_in_control_arl_windows = LoadF32(bytes, kCalOffWatch + 32);

  if (r.dof_count < 1 || r.dof_count > kMaxDof) return Status::kInvalidArgument;
  if ((r.flags & ~(kCalFlagHasDob | kCalFlagHasWatch)) != 0 ||
      LoadU16(bytes, kCalOffReserved) != 0) {
    return Status::kInvalidArgument;
  }
  if (r.created_unix_s < 0 || !LabelOk(r.label)) return Status::kInvalidArgument;
  if (!MatrixShapeOk(r.mass_kg, r.dof_count) || !MatrixShapeOk(r.damping_ns_per_m, r.dof_count) ||
      !MatrixShapeOk(r.stiffness_n_per_m, r.dof_count) ||
      !MassPositiveDefinite(r.mass_kg, r.dof_count)) {
    return Status::kInvalidArgument;
  }
  for (const ChannelScaling& s : r.channels) channels_ok = channels_ok && ChannelOk(s, r.dof_count);
  if (!channels_ok) return Status::kInvalidArgument;
  if (!inputs_ok) return Status::kInvalidArgument;
  if ((r.flags & kCalFlagHasDob) == 0) {
    if (!dob_zero || !inputs_unused) return Status::kInvalidArgument;
  } else if (const Status dob = CheckDob(r); dob != Status::kOk) {
    return dob;
  }
  if ((r.flags & kCalFlagHasWatch) == 0) {
    if (!watch_zero) return Status::kInvalidArgument;
    r.watch_reference_channel = kNoChannel;
  } else if (CheckWatch(r) != Status::kOk) {
    return Status::kInvalidArgument;
  }
  record = r;
  return Status::kOk;
}

}  // namespace vibid::wire
