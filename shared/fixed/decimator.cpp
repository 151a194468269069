#include "vibid/shared/fixed/decimator.hpp"

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <limits>

namespace vibid::fixed {
namespace {

constexpr std::int64_t kInt32Max = std::numeric_limits<std::int32_t>::max();
constexpr std::int64_t kInt32Min = std::numeric_limits<std::int32_t>::min();
constexpr int kTapShift = 30;  // taps are Q30

// One FIR design: odd length, symmetric, the centre tap and one tap per pair at distance
// 1 + i * stride from the centre (innermost first).
struct DecimatorStageDesign {
  std::uint32_t factor;
  std::uint32_t length;
  std::uint32_t stride;
  std::uint32_t pair_count;
  std::int32_t center;
  const std::int32_t* pairs;
};

// The stages of one factor, first (highest rate) to last; indices into kStageDesigns.
struct DecimatorPlan {
  std::uint32_t factor;
  std::uint32_t stage_count;
  std::array<std::uint8_t, kDecimatorMaxStages> stages;
};

#include "decimator_coefficients.inc"

// ---- compile-time checks of the generated tables (a regenerated table that breaks an
// assumption of the kernel fails the build, not the board).

constexpr bool DesignsAreSound() {
  for (const DecimatorStageDesign& d : kStageDesigns) {
    if (d.length % 2 != 1 || d.pair_count == 0) return false;
    if (1 + (d.pair_count - 1) * d.stride != (d.length - 1) / 2) return false;  // outermost pair
    if (d.length > 0xFFFF || (d.factor != 2 && d.factor != 5)) return false;
    std::int64_t sum = d.center;
    std::int64_t l1 = d.center < 0 ? -std::int64_t{d.center} : d.center;
    for (std::uint32_t i = 0; i < d.pair_count; ++i) {
      sum += 2 * std::int64_t{d.pairs[i]};
      l1 += 2 * (d.pairs[i] < 0 ? -std::int64_t{d.pairs[i]} : d.pairs[i]);
    }
    // Unit DC gain exactly, and the accumulator bound of the header.
    if (sum != (std::int64_t{1} << kTapShift) || l1 > (std::int64_t{1} << 32) - 1) return false;
  }
  return true;
}
static_assert(DesignsAreSound(), "decimator_coefficients.inc breaks the kernel's assumptions");

constexpr const DecimatorPlan* FindPlan(std::uint32_t factor) {
  for (const DecimatorPlan& p : kPlans) {
    if (p.factor == factor) return &p;
  }
  return nullptr;
}

constexpr bool PlansAreSound() {
  // The header's sizes are exact, so a regenerated table that needs less shrinks them too.
  if (kPlanMaxStages != kDecimatorMaxStages || kPlanMaxStateWords != kDecimatorStateWordsPerChannel)
    return false;
  for (std::uint32_t f = 1; f <= kDecimatorMaxFactor; ++f) {
    const DecimatorPlan* p = FindPlan(f);
    if ((p != nullptr) != IsSupportedDecimation(f)) return false;
    if (p == nullptr) continue;
    std::uint32_t product = 1;
    std::size_t words = 0;
    if (p->stage_count > kDecimatorMaxStages) return false;
    for (std::uint32_t s = 0; s < p->stage_count; ++s) {
      if (p->stages[s] >= std::size(kStageDesigns)) return false;
      product *= kStageDesigns[p->stages[s]].factor;
      words += 2 * std::size_t{kStageDesigns[p->stages[s]].length};
    }
    if (product != f || words > kDecimatorStateWordsPerChannel) return false;
  }
  return true;
}
static_assert(PlansAreSound(), "decimator plans do not cover exactly the supported factors");

std::int32_t Saturate(std::int64_t y, std::uint32_t& saturations) {
  if (y > kInt32Max) {
    ++saturations;
    return static_cast<std::int32_t>(kInt32Max);
  }
  if (y < kInt32Min) {
    ++saturations;
    return static_cast<std::int32_t>(kInt32Min);
  }
  return static_cast<std::int32_t>(y);
}

// One stage output from the window of its last L inputs (oldest first). The pairs are walked
// from the outside in so both pointers stay inside the window; the stride is a template
// argument so the pointer steps are immediate post-increments (no index arithmetic, no branch).
template <std::uint32_t kStride>
std::int32_t Convolve(const std::int32_t* window, const DecimatorStageDesign& d,
                      std::uint32_t& saturations) {
  const std::int32_t* lo = window;
  const std::int32_t* hi = window + (d.length - 1);
  const std::int32_t* tap = d.pairs + d.pair_count;
  std::int64_t acc =
      (std::int64_t{1} << (kTapShift - 1)) + std::int64_t{d.center} * window[(d.length - 1) / 2];
  for (std::uint32_t n = d.pair_count; n != 0; --n) {
    const std::int64_t h = *--tap;
    acc += h * *lo;  // two SMLALs with one tap load; see the header for why not pre-added
    acc += h * *hi;
    lo += kStride;
    hi -= kStride;
  }
  return Saturate(acc >> kTapShift, saturations);
}

}  // namespace

std::uint32_t DecimatorDelayTicks(std::uint32_t factor) {
  const DecimatorPlan* p = IsSupportedDecimation(factor) ? FindPlan(factor) : nullptr;
  if (p == nullptr) return 0;
  std::uint32_t rate = 1;
  std::uint32_t delay = 0;
  for (std::uint32_t s = 0; s < p->stage_count; ++s) {
    const DecimatorStageDesign& d = kStageDesigns[p->stages[s]];
    delay += (d.length - 1) / 2 * rate;
    rate *= d.factor;
  }
  return delay;
}

Status Decimator::Init(std::uint32_t factor, std::size_t channel_count) {
  const DecimatorPlan* p = IsSupportedDecimation(factor) ? FindPlan(factor) : nullptr;
  if (p == nullptr || channel_count == 0 || channel_count > kDecimatorMaxChannels) {
    factor_ = 0;
    channel_count_ = 0;
    stage_count_ = 0;
    Reset();
    return Status::kInvalidArgument;
  }
  factor_ = factor;
  channel_count_ = channel_count;
  stage_count_ = p->stage_count;
  std::size_t offset = 0;
  for (std::size_t s = 0; s < stage_count_; ++s) {
    stages_[s].design = p->stages[s];
    stages_[s].offset = static_cast<std::uint16_t>(offset);  // < kDecimatorStateWordsPerChannel
    offset += 2 * std::size_t{kStageDesigns[p->stages[s]].length};
  }
  Reset();
  return Status::kOk;
}

void Decimator::Reset() {
  tick_ = 0;
  for (Stage& s : stages_) {
    s.write = 0;
    s.phase = 0;
  }
  state_ = {};
  saturation_count_ = 0;
}

bool Decimator::Push(const std::int32_t* in, std::int32_t* out) {
  const std::size_t channels = channel_count_;
  if (channels == 0) return false;
  tick_ = tick_ + 1 == factor_ ? 0 : tick_ + 1;
  // Stage s reads src (the frame, then the previous stage's outputs) and writes x.
  const std::int32_t* src = in;
  std::array<std::int32_t, kDecimatorMaxChannels> x;
  for (std::size_t s = 0; s < stage_count_; ++s) {
    Stage& st = stages_[s];
    const DecimatorStageDesign& d = kStageDesigns[st.design];
    const std::uint32_t w = st.write;
    for (std::size_t ch = 0; ch < channels; ++ch) {
      std::int32_t* buf = state_[ch].data() + st.offset;
      buf[w] = src[ch];
      buf[w + d.length] = src[ch];
    }
    st.write = static_cast<std::uint16_t>(w + 1 == d.length ? 0 : w + 1);
    const bool emit = st.phase == 0;
    st.phase = static_cast<std::uint16_t>(st.phase + 1u == d.factor ? 0 : st.phase + 1u);
    if (!emit) return false;
    // The last L inputs are buf[w + 1 .. w + L] (the newest just written at w + L).
    if (d.stride == 2) {
      for (std::size_t ch = 0; ch < channels; ++ch) {
        x[ch] = Convolve<2>(state_[ch].data() + st.offset + w + 1, d, saturation_count_);
      }
    } else {
      for (std::size_t ch = 0; ch < channels; ++ch) {
        x[ch] = Convolve<1>(state_[ch].data() + st.offset + w + 1, d, saturation_count_);
      }
    }
    src = x.data();
  }
  for (std::size_t ch = 0; ch < channels; ++ch) out[ch] = src[ch];  // factor 1: the frame itself
  return true;
}

std::size_t Decimator::OutputFrames(std::size_t frames) const {
  if (factor_ == 0) return 0;
  const std::size_t first = (factor_ - tick_) % factor_;  // inputs before the next output
  return first < frames ? (frames - 1 - first) / factor_ + 1 : 0;
}

Status Decimator::PushBlock(std::span<const std::int32_t> interleaved, std::span<std::int32_t> out,
                            std::size_t& out_frames) {
  out_frames = 0;
  const std::size_t channels = channel_count_;
  if (channels == 0 || interleaved.size() % channels != 0) return Status::kInvalidArgument;
  const std::size_t frames = interleaved.size() / channels;
  if (out.size() < OutputFrames(frames) * channels) return Status::kInvalidArgument;
  for (std::size_t n = 0; n < frames; ++n) {
    if (Push(interleaved.data() + n * channels, out.data() + out_frames * channels)) ++out_frames;
  }
  return Status::kOk;
}

}  // namespace vibid::fixed
