#include "vibid/shared/fixed/dob_filter.hpp"

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
  return static_cast<std::int64_t>((static_cast<std::uint64_t>(static_cast<std::uint32_t>(hi >> n)) << 32) | out_lo);
}

}  // namespace

Status DobFilter::Init(const FilterDescription& description) {
  const Status st = ValidateDescription(description);
  paths_ = {};
  records_ = {};
  if (st != Status::kOk) {
    description_ = FilterDescription{.input_count = 0};
    Reset();
    return st;
  }
  description_ = description;
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
  Reset();
  return Status::kOk;
}

void DobFilter::Reset() {
  // At rest: x = y = 0 (so ~y = -1) and remainders 0 (so r' = half).
  for (auto& path : records_) {
    for (SectionRecord& r : path) {
      r.x1 = r.x2 = 0;
      r.ny1 = r.ny2 = -1;
      r.r1 = r.r2 = r.half;
    }
  }
  saturation_count_ = 0;
}

#if defined(__ARM_ARCH_7EM__) && defined(__thumb2__)

// Cortex-M4: the sections of one path in one loop of 28 instructions per section, no branch but
// the loop's own. Arguments as the AAPCS passes them: r0 carries x (then y) from section to
// section, r1 walks the records, r2 holds (sections left - 1) << 16 in its high half and the
// saturations in its low half. Per section r6..r11 hold the state, r4:r5 the accumulator, r3, r12
// and lr the coefficients as loaded.
__attribute__((naked, noinline)) std::uint64_t DobFilter::StepPath(std::int32_t, SectionRecord*, std::uint32_t) {
  static_assert(sizeof(SectionRecord) == 76 && offsetof(SectionRecord, b0) == 24 &&
                offsetof(SectionRecord, a1) == 44 && offsetof(SectionRecord, f2) == 56);
  asm volatile(
      "push {r4-r11, lr}\n\t"
      "1:\n\t"
      "ldmia r1!, {r6-r11}\n\t"              // x1 x2 ~y1 ~y2 r1' r2'
      "ldmia r1!, {r3, r4, r5, r12, lr}\n\t" // b0, start (r4:r5), b1, b2
      "smlal r4, r5, r3, r0\n\t"
      "smlal r4, r5, r12, r6\n\t"
      "smlal r4, r5, lr, r7\n\t"
      "ldmia r1!, {r3, r12, lr}\n\t"         // a1 a2 f1
      "smlal r4, r5, r3, r8\n\t"
      "smlal r4, r5, r12, r9\n\t"
      "smlal r4, r5, lr, r10\n\t"
      "ldmia r1!, {r3, r7, r9, r12, lr}\n\t" // f2, q, 32 - q, mask, half
      "smlal r4, r5, r3, r11\n\t"
      "lsr r11, r4, r7\n\t"                  // y = lo >> q | hi << (32 - q)
      "lsl r9, r5, r9\n\t"
      "orr r11, r11, r9\n\t"
      "and r9, r4, r12\n\t"                  // r' = lo & mask
      "add r12, r5, lr\n\t"                  // saturated: (hi + half) >> q != 0
      "lsrs r12, r12, r7\n\t"
      "itttt ne\n\t"
      "mvnne r11, #0x80000000\n\t"           // y = hi < 0 ? INT32_MIN : INT32_MAX
      "eorne r11, r11, r5, asr #31\n\t"
      "movne r9, lr\n\t"                     // r' = half
      "addne r2, r2, #1\n\t"
      "mvn r7, r11\n\t"                      // ~y
      "sub r3, r1, #76\n\t"
      "stm r3, {r0, r6, r7, r8, r9, r10}\n\t"  // x, x1, ~y, ~y1, r', r1'
      "mov r0, r11\n\t"
      "subs r2, r2, #0x10000\n\t"
      "bcs 1b\n\t"
      "mov r1, r2\n\t"                       // result: y in r0, the count in r1
      "pop {r4-r11, pc}\n\t");
}

#else

std::uint64_t DobFilter::StepPath(std::int32_t x, SectionRecord* r, std::uint32_t count) {
  SectionRecord* const end = r + (count >> 16) + 1;
  for (; r != end; ++r) {
    // Exact: ValidateDescription bounds the raw coefficient sum (see the header).
    std::int64_t acc = static_cast<std::int64_t>((std::uint64_t{static_cast<std::uint32_t>(r->start_hi)} << 32) | r->start_lo);
    acc += std::int64_t{r->b0} * x;
    acc += std::int64_t{r->b1} * r->x1;
    acc += std::int64_t{r->b2} * r->x2;
    acc += std::int64_t{r->a1} * r->ny1;
    acc += std::int64_t{r->a2} * r->ny2;
    acc += std::int64_t{r->f1} * r->r1;
    acc += std::int64_t{r->f2} * r->r2;
    const auto lo = static_cast<std::uint32_t>(acc);
    const auto hi = static_cast<std::int32_t>(acc >> 32);
    std::int32_t y = static_cast<std::int32_t>((lo >> r->q) | (static_cast<std::uint32_t>(hi) << r->left));
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

#endif

// Inlined into Step and StepBlock: the per-frame work is counted in the functions the board calls.
__attribute__((always_inline)) inline std::int32_t DobFilter::StepFrame(const std::int32_t* inputs) {
  std::int64_t sum = 0;
  std::uint32_t saturations = 0;
  const std::size_t n_in = description_.input_count;
  for (std::size_t i = 0; i < n_in; ++i) {
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
  std::int32_t out = lo;
  if (hi != (lo >> 31)) {
    out = (hi >> 31) ^ kInt32Max;
    ++saturations;
  }
  saturation_count_ += saturations;
  return out;
}

std::int32_t DobFilter::Step(const InputFrame& inputs) { return StepFrame(inputs.data()); }

Status DobFilter::StepBlock(std::span<const std::int32_t> interleaved,
                            std::span<std::int32_t> output) {
  const std::size_t n_in = description_.input_count;
  if (n_in == 0 || interleaved.size() != output.size() * n_in) return Status::kInvalidArgument;
  const std::int32_t* in = interleaved.data();
  for (std::int32_t& out : output) {
    out = StepFrame(in);
    in += n_in;
  }
  return Status::kOk;
}

}  // namespace vibid::fixed
