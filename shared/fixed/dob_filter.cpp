#include "vibid/shared/fixed/dob_filter.hpp"

#include <cstdint>
#include <limits>

namespace vibid::fixed {
namespace {

constexpr std::int32_t kInt32Max = std::numeric_limits<std::int32_t>::max();
constexpr std::int32_t kInt32Min = std::numeric_limits<std::int32_t>::min();

// Arithmetic right shift of a 64-bit value by n in [1, 31], written on the two 32-bit halves so a
// 32-bit core needs no case for shifts of 32 or more.
inline std::int64_t ShiftRight(std::int64_t v, std::int32_t n) {
  const auto lo = static_cast<std::uint32_t>(v);
  const auto hi = static_cast<std::int32_t>(v >> 32);
  const std::uint32_t out_lo = (lo >> n) | (static_cast<std::uint32_t>(hi) << (32 - n));
  return static_cast<std::int64_t>((static_cast<std::uint64_t>(static_cast<std::uint32_t>(hi >> n)) << 32) | out_lo);
}

}  // namespace

Status DobFilter::Init(const FilterDescription& description) {
  const Status st = ValidateDescription(description);
  if (st != Status::kOk) {
    description_ = FilterDescription{.input_count = 0};
    paths_ = {};
    sections_ = {};
    Reset();
    return st;
  }
  description_ = description;
  paths_ = {};
  sections_ = {};
  for (std::size_t i = 0; i < description.input_count; ++i) {
    const Path& p = description.paths[i];
    KernelPath& kp = paths_[i];
    kp.sections = p.section_count;
    kp.gain = p.output_gain;
    kp.p = 31 - p.output_shift;
    kp.half = std::int64_t{1} << (kp.p - 1);
    for (std::size_t k = 0; k < p.section_count; ++k) {
      const Section& s = p.sections[k];
      KernelSection& ks = sections_[i][k];
      const bool feedback = s.feedback == ErrorFeedback::kSecondOrder;
      ks.b0 = s.b0;
      ks.b1 = s.b1;
      ks.b2 = s.b2;
      ks.a1 = s.a1;
      ks.a2 = s.a2;
      ks.f1 = feedback ? 2 : 0;
      ks.f2 = feedback ? -1 : 0;
      ks.q = 31 - s.shift;
      ks.half = std::int32_t{1} << (ks.q - 1);
      // -a y = a ~y + a, and 2 r1 - r2 = 2 r1' - r2' - half (r' = r + half): see the header.
      ks.start = std::int64_t{ks.half} + s.a1 + s.a2 - (feedback ? ks.half : 0);
    }
  }
  Reset();
  return Status::kOk;
}

void DobFilter::Reset() {
  // At rest: x = y = 0 (so ~y = -1) and remainders 0 (so r' = half).
  for (std::size_t i = 0; i < kMaxInputs; ++i) {
    for (std::size_t k = 0; k < kMaxSections; ++k) {
      state_[i][k] = SectionState{0, 0, -1, -1, sections_[i][k].half, sections_[i][k].half};
    }
  }
  saturation_count_ = 0;
}

std::int32_t DobFilter::StepPath(std::size_t path, std::int32_t input) {
  const KernelSection* s = sections_[path].data();
  const KernelSection* const end = s + paths_[path].sections;
  SectionState* st = state_[path].data();
  std::int32_t x = input;
  std::uint32_t saturations = 0;
  for (; s != end; ++s, ++st) {
    // Exact: ValidateDescription bounds the raw coefficient sum (see the header).
    std::int64_t acc = s->start;
    acc += std::int64_t{s->b0} * x;
    acc += std::int64_t{s->b1} * st->x1;
    acc += std::int64_t{s->b2} * st->x2;
    acc += std::int64_t{s->a1} * st->ny1;
    acc += std::int64_t{s->a2} * st->ny2;
    acc += std::int64_t{s->f1} * st->r1;
    acc += std::int64_t{s->f2} * st->r2;
    const auto lo = static_cast<std::uint32_t>(acc);
    const auto hi = static_cast<std::int32_t>(acc >> 32);
    // y = acc >> q fits an int32 exactly when hi lies in [-2^(q-1), 2^(q-1)).
    const bool saturated = ((static_cast<std::uint32_t>(hi) + static_cast<std::uint32_t>(s->half)) >> s->q) != 0;
    std::int32_t y = static_cast<std::int32_t>((lo >> s->q) | (static_cast<std::uint32_t>(hi) << (32 - s->q)));
    std::int32_t r = static_cast<std::int32_t>(lo - (static_cast<std::uint32_t>(y) << s->q));
    if (saturated) {
      y = (hi >> 31) ^ kInt32Max;
      r = s->half;
      ++saturations;
    }
    st->x2 = st->x1;
    st->x1 = x;
    st->ny2 = st->ny1;
    st->ny1 = ~y;
    st->r2 = st->r1;
    st->r1 = r;
    x = y;
  }
  saturation_count_ += saturations;
  return x;
}

std::int32_t DobFilter::Step(const InputFrame& inputs) {
  std::int64_t sum = 0;
  for (std::size_t i = 0; i < description_.input_count; ++i) {
    const KernelPath& p = paths_[i];
    const std::int32_t y = StepPath(i, inputs[i]);
    sum += ShiftRight(p.half + std::int64_t{y} * p.gain, p.p);
  }
  if (sum > kInt32Max) {
    ++saturation_count_;
    return kInt32Max;
  }
  if (sum < kInt32Min) {
    ++saturation_count_;
    return kInt32Min;
  }
  return static_cast<std::int32_t>(sum);
}

Status DobFilter::StepBlock(std::span<const std::int32_t> interleaved,
                            std::span<std::int32_t> output) {
  const std::size_t n_in = description_.input_count;
  if (n_in == 0 || interleaved.size() != output.size() * n_in) return Status::kInvalidArgument;
  InputFrame frame{};
  for (std::size_t n = 0; n < output.size(); ++n) {
    for (std::size_t i = 0; i < n_in; ++i) frame[i] = interleaved[n * n_in + i];
    output[n] = Step(frame);
  }
  return Status::kOk;
}

}  // namespace vibid::fixed
