// The DOB kernel's portable backend (layout and overflow notes in dob_kernel.hpp).
#include "dob_kernel.hpp"

#include <cstddef>
#include <cstdint>
#include <limits>

namespace vibid::fixed {

namespace {

constexpr std::int32_t kInt32Max = std::numeric_limits<std::int32_t>::max();

// Arithmetic right shift of a 64-bit value by n in [1, 31] (left = 32 - n), written on the two
// 32-bit halves so a 32-bit core needs no case for shifts of 32 or more.
inline std::int64_t ShiftRight(std::int64_t v, std::int32_t n, std::int32_t left) {
  const auto lo = static_cast<std::uint32_t>(v);
  const auto hi = static_cast<std::int32_t>(v >> 32);
  const std::uint32_t out_lo = (lo >> n) | (static_cast<std::uint32_t>(hi) << left);
  return static_cast<std::int64_t>(
      (static_cast<std::uint64_t>(static_cast<std::uint32_t>(hi >> n)) << 32) | out_lo);
}

}  // namespace

void DobKernel::Load(const FilterDescription& description) {
  input_count_ = description.input_count;
  paths_ = {};
  records_ = {};
  for (std::size_t i = 0; i < description.input_count; ++i) {
    const Path& p = description.paths[i];
    KernelPath& kp = paths_[i];
    kp.sections = p.section_count;
    kp.count = p.section_count > 0 ? static_cast<std::uint32_t>(p.section_count - 1) << 16 : 0u;
    kp.gain = p.output_gain;
    kp.p = 31 - p.output_shift;
    kp.left = 32 - kp.p;
    kp.half = std::int64_t{1} << (kp.p - 1);
    for (std::size_t k = 0; k < p.section_count; ++k) {
      const Section& s = p.sections[k];
      SectionRecord& r = records_[i][k];
      const bool feedback = s.feedback == ErrorFeedback::kSecondOrder;
      r.b0 = s.b0;
      r.b1 = s.b1;
      r.b2 = s.b2;
      r.a1 = s.a1;
      r.a2 = s.a2;
      r.f1 = feedback ? 2 : 0;
      r.f2 = feedback ? -1 : 0;
      r.q = 31 - s.shift;
      r.left = 32 - r.q;
      r.mask = (std::uint32_t{1} << r.q) - 1u;
      r.half = std::int32_t{1} << (r.q - 1);
      // -a y = a ~y + a, and 2 r1 - r2 = 2 r1' - r2' - half (r' = r + half): see the header.
      const std::int64_t start = std::int64_t{r.half} + s.a1 + s.a2 - (feedback ? r.half : 0);
      r.start_lo = static_cast<std::uint32_t>(start);
      r.start_hi = static_cast<std::int32_t>(start >> 32);
    }
  }
  Reset(description);
}

void DobKernel::Reset(const FilterDescription& /*description*/) {
  // At rest: x = y = 0 (so ~y = -1) and remainders 0 (so r' = half).
  for (auto& path : records_) {
    for (SectionRecord& r : path) {
      r.x1 = r.x2 = 0;
      r.ny1 = r.ny2 = -1;
      r.r1 = r.r2 = r.half;
    }
  }
}

std::uint64_t DobKernel::StepPath(std::int32_t x, SectionRecord* r, std::uint32_t count) {
  SectionRecord* const end = r + (count >> 16) + 1;
  for (; r != end; ++r) {
    // Exact: ValidateDescription bounds the raw coefficient sum (see the header).
    std::int64_t acc = static_cast<std::int64_t>(
        (std::uint64_t{static_cast<std::uint32_t>(r->start_hi)} << 32) | r->start_lo);
    acc += std::int64_t{r->b0} * x;
    acc += std::int64_t{r->b1} * r->x1;
    acc += std::int64_t{r->b2} * r->x2;
    acc += std::int64_t{r->a1} * r->ny1;
    acc += std::int64_t{r->a2} * r->ny2;
    acc += std::int64_t{r->f1} * r->r1;
    acc += std::int64_t{r->f2} * r->r2;
    const auto lo = static_cast<std::uint32_t>(acc);
    const auto hi = static_cast<std::int32_t>(acc >> 32);
    std::int32_t y =
        static_cast<std::int32_t>((lo >> r->q) | (static_cast<std::uint32_t>(hi) << r->left));
    std::int32_t rem = static_cast<std::int32_t>(lo & r->mask);
    // y fits an int32 exactly when hi lies in [-2^(q-1), 2^(q-1)).
    if (((static_cast<std::uint32_t>(hi) + static_cast<std::uint32_t>(r->half)) >> r->q) != 0) {
      y = (hi >> 31) ^ kInt32Max;
      rem = r->half;
      ++count;
    }
    r->x2 = r->x1;
    r->x1 = x;
    r->ny2 = r->ny1;
    r->ny1 = ~y;
    r->r2 = r->r1;
    r->r1 = rem;
    x = y;
  }
  return (std::uint64_t{count} << 32) | static_cast<std::uint32_t>(x);
}

// Inlined into Run: the per-frame work is counted in the function the board calls.
__attribute__((always_inline)) inline std::int32_t DobKernel::StepFrame(
    const std::int32_t* inputs, std::uint32_t& saturations) {
  std::int64_t sum = 0;
  for (std::size_t i = 0; i < input_count_; ++i) {
    const KernelPath& p = paths_[i];
    std::int32_t y = inputs[i];
    if (p.sections > 0) {
      const std::uint64_t r = StepPath(y, records_[i].data(), p.count);
      y = static_cast<std::int32_t>(static_cast<std::uint32_t>(r));
      saturations += static_cast<std::uint32_t>(r >> 32) & 0xFFFFu;
    }
    sum += ShiftRight(p.half + std::int64_t{y} * p.gain, p.p, p.left);
  }
  // The sum fits an int32 exactly when its high word is the sign extension of its low word.
  const auto lo = static_cast<std::int32_t>(static_cast<std::uint32_t>(sum));
  const auto hi = static_cast<std::int32_t>(sum >> 32);
  if (hi == (lo >> 31)) return lo;
  ++saturations;
  return (hi >> 31) ^ kInt32Max;
}

std::uint32_t DobKernel::Run(const std::int32_t* inputs, std::int32_t* output, std::size_t frames) {
  std::uint32_t saturations = 0;
  for (std::size_t n = 0; n < frames; ++n) {
    output[n] = StepFrame(inputs, saturations);
    inputs += input_count_;
  }
  return saturations;
}

}  // namespace vibid::fixed
