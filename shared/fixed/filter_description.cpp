#include "vibid/shared/fixed/filter_description.hpp"

#include "vibid/shared/crc32.hpp"

#include <cstdint>

namespace vibid::fixed {
namespace {

// Explicit little-endian cursor: the wire form must not depend on the compiler's struct layout
// or the machine's byte order.
class Writer {
 public:
  explicit Writer(std::span<std::uint8_t, kDescriptionBytes> out) : out_(out) {}
  void U8(std::uint8_t v) { out_[pos_++] = v; }
  void U16(std::uint16_t v) {
    U8(static_cast<std::uint8_t>(v & 0xFFu));
    U8(static_cast<std::uint8_t>(v >> 8));
  }
  void U32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) U8(static_cast<std::uint8_t>((v >> (8 * i)) & 0xFFu));
  }
  void I32(std::int32_t v) { U32(static_cast<std::uint32_t>(v)); }

 private:
  std::span<std::uint8_t, kDescriptionBytes> out_;
  std::size_t pos_ = 0;
};

class Reader {
 public:
  explicit Reader(std::span<const std::uint8_t, kDescriptionBytes> in) : in_(in) {}
  std::uint8_t U8() { return in_[pos_++]; }
  std::uint16_t U16() {
    const auto lo = U8();
    const auto hi = U8();
    return static_cast<std::uint16_t>(lo | (hi << 8));
  }
  std::uint32_t U32() {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(U8()) << (8 * i);
    return v;
  }
  std::int32_t I32() { return static_cast<std::int32_t>(U32()); }

 private:
  std::span<const std::uint8_t, kDescriptionBytes> in_;
  std::size_t pos_ = 0;
};

std::int64_t Abs64(std::int32_t v) { return v < 0 ? -static_cast<std::int64_t>(v) : v; }

bool SectionIsZero(const Section& s) {
  return s.b0 == 0 && s.b1 == 0 && s.b2 == 0 && s.a1 == 0 && s.a2 == 0 && s.shift == 0 &&
         s.feedback == ErrorFeedback::kNone && s.reserved[0] == 0 && s.reserved[1] == 0;
}

bool PathIsZero(const Path& p) {
  if (p.section_count != 0 || p.output_shift != 0 || p.output_gain != 0 || p.reserved[0] != 0 ||
      p.reserved[1] != 0) {
    return false;
  }
  for (const Section& s : p.sections) {
    if (!SectionIsZero(s)) return false;
  }
  return true;
}

bool FullScaleIsValid(std::uint32_t bits) {
  const float v = FullScaleValue(bits);
  // NaN fails both comparisons; +inf fails the upper bound.
  return v > 0.0f && v <= 3.4e38f;
}

Status ValidateSection(const Section& s) {
  if (s.shift > kMaxSectionShift) return Status::kInvalidArgument;
  if (s.reserved[0] != 0 || s.reserved[1] != 0) return Status::kInvalidArgument;
  if (s.feedback != ErrorFeedback::kNone && s.feedback != ErrorFeedback::kSecondOrder) {
    return Status::kInvalidArgument;
  }
  const std::int64_t abs_sum = Abs64(s.b0) + Abs64(s.b1) + Abs64(s.b2) + Abs64(s.a1) + Abs64(s.a2);
  if (abs_sum > kMaxCoefficientSum) return Status::kInvalidArgument;
  if (!SectionIsStable(s)) return Status::kUnstable;
  return Status::kOk;
}

Status ValidatePath(const Path& p) {
  if (p.section_count > kMaxSections) return Status::kOutOfRange;
  if (p.output_shift > kMaxOutputShift) return Status::kInvalidArgument;
  if (p.reserved[0] != 0 || p.reserved[1] != 0) return Status::kInvalidArgument;
  for (std::size_t k = 0; k < kMaxSections; ++k) {
    const Section& s = p.sections[k];
    if (k >= p.section_count) {
      if (!SectionIsZero(s)) return Status::kInvalidArgument;
      continue;
    }
    if (const Status st = ValidateSection(s); st != Status::kOk) return st;
  }
  return Status::kOk;
}

}  // namespace

std::uint32_t Crc32IsoHdlc(std::span<const std::uint8_t> bytes) { return ComputeCrc32(bytes); }

void EncodeDescription(const FilterDescription& d, std::span<std::uint8_t, kDescriptionBytes> out) {
  Writer w(out);
  w.U32(d.magic);
  w.U16(d.version);
  w.U8(d.input_count);
  w.U8(d.output_dof);
  w.U32(d.sample_rate_hz);
  for (const InputKind k : d.input_kind) w.U8(static_cast<std::uint8_t>(k));
  w.U8(d.reserved0);
  for (const std::uint8_t dof : d.input_dof) w.U8(dof);
  w.U8(d.reserved1);
  for (const std::uint32_t b : d.input_full_scale_bits) w.U32(b);
  w.U32(d.output_full_scale_bits);
  for (const Path& p : d.paths) {
    w.U8(p.section_count);
    w.U8(p.output_shift);
    w.U8(p.reserved[0]);
    w.U8(p.reserved[1]);
    w.I32(p.output_gain);
    for (const Section& s : p.sections) {
      w.I32(s.b0);
      w.I32(s.b1);
      w.I32(s.b2);
      w.I32(s.a1);
      w.I32(s.a2);
      w.U8(s.shift);
      w.U8(static_cast<std::uint8_t>(s.feedback));
      for (const std::uint8_t r : s.reserved) w.U8(r);
    }
  }
  w.U32(d.checksum);
}

Status DecodeDescription(std::span<const std::uint8_t, kDescriptionBytes> in,
                         FilterDescription& d) {
  Reader r(in);
  d.magic = r.U32();
  d.version = r.U16();
  d.input_count = r.U8();
  d.output_dof = r.U8();
  d.sample_rate_hz = r.U32();
  for (InputKind& k : d.input_kind) k = static_cast<InputKind>(r.U8());
  d.reserved0 = r.U8();
  for (std::uint8_t& dof : d.input_dof) dof = r.U8();
  d.reserved1 = r.U8();
  for (std::uint32_t& b : d.input_full_scale_bits) b = r.U32();
  d.output_full_scale_bits = r.U32();
  for (Path& p : d.paths) {
    p.section_count = r.U8();
    p.output_shift = r.U8();
    p.reserved[0] = r.U8();
    p.reserved[1] = r.U8();
    p.output_gain = r.I32();
    for (Section& s : p.sections) {
      s.b0 = r.I32();
      s.b1 = r.I32();
      s.b2 = r.I32();
      s.a1 = r.I32();
      s.a2 = r.I32();
      s.shift = r.U8();
      s.feedback = static_cast<ErrorFeedback>(r.U8());
      for (std::uint8_t& res : s.reserved) res = r.U8();
    }
  }
  d.checksum = r.U32();
  return Status::kOk;
}

std::uint32_t ComputeChecksum(const FilterDescription& d) {
  std::array<std::uint8_t, kDescriptionBytes> bytes{};
  EncodeDescription(d, bytes);
  return Crc32IsoHdlc(std::span<const std::uint8_t>(bytes.data(), kChecksumOffset));
}

void Seal(FilterDescription& d) { d.checksum = ComputeChecksum(d); }

bool SectionIsStable(const Section& s) {
  if (s.shift > kMaxSectionShift) return false;
  // With one = 2^(31 - shift): |a2| < one and |a1| < one + a2 (Jury, second order), exact in int64.
  const std::int64_t one = std::int64_t{1} << (31 - s.shift);
  const std::int64_t a1 = s.a1;
  const std::int64_t a2 = s.a2;
  const std::int64_t abs_a1 = a1 < 0 ? -a1 : a1;
  const std::int64_t abs_a2 = a2 < 0 ? -a2 : a2;
  return abs_a2 < one && abs_a1 < one + a2;
}

Status ValidateDescription(const FilterDescription& d) {
  if (d.magic != kDescriptionMagic || d.version != kDescriptionVersion) {
    return Status::kVersionMismatch;
  }
  if (ComputeChecksum(d) != d.checksum) return Status::kDataLoss;
  if (d.input_count == 0 || d.input_count > kMaxInputs) return Status::kOutOfRange;
  if (d.sample_rate_hz == 0 || d.reserved0 != 0 || d.reserved1 != 0) {
    return Status::kInvalidArgument;
  }
  if (!FullScaleIsValid(d.output_full_scale_bits)) return Status::kInvalidArgument;
  for (std::size_t i = 0; i < kMaxInputs; ++i) {
    const bool used = i < d.input_count;
    if (!used) {
      if (d.input_kind[i] != InputKind::kUnused || d.input_dof[i] != 0 ||
          d.input_full_scale_bits[i] != 0 || !PathIsZero(d.paths[i])) {
        return Status::kInvalidArgument;
      }
      continue;
    }
    const auto kind = static_cast<std::uint8_t>(d.input_kind[i]);
    if (kind == 0 || kind > static_cast<std::uint8_t>(InputKind::kAcceleration)) {
      return Status::kInvalidArgument;
    }
    if (!FullScaleIsValid(d.input_full_scale_bits[i])) return Status::kInvalidArgument;
    if (const Status st = ValidatePath(d.paths[i]); st != Status::kOk) return st;
  }
  return Status::kOk;
}

}  // namespace vibid::fixed
