#include "vibid/shared/fixed/dob_filter.hpp"

#include <cstdint>
#include <limits>

namespace vibid::fixed {
namespace {

constexpr std::int64_t kInt32Max = std::numeric_limits<std::int32_t>::max();
constexpr std::int64_t kInt32Min = std::numeric_limits<std::int32_t>::min();

}  // namespace

Status DobFilter::Init(const FilterDescription& description) {
  const Status st = ValidateDescription(description);
  if (st != Status::kOk) {
    description_ = FilterDescription{.input_count = 0};
    Reset();
    return st;
  }
  description_ = description;
  Reset();
  return Status::kOk;
}

void DobFilter::Reset() {
  state_ = {};
  saturation_count_ = 0;
}

std::int32_t DobFilter::StepPath(std::size_t path, std::int32_t input) {
  const Path& p = description_.paths[path];
  std::int32_t x = input;
  for (std::size_t k = 0; k < p.section_count; ++k) {
    const Section& s = p.sections[k];
    auto& st = state_[path][k];
    // Exact: ValidateDescription bounds the raw coefficient sum (see the header).
    std::int64_t acc = std::int64_t{s.b0} * x + std::int64_t{s.b1} * st[0] +
                       std::int64_t{s.b2} * st[1] - std::int64_t{s.a1} * st[2] -
                       std::int64_t{s.a2} * st[3];
    if (s.feedback == ErrorFeedback::kSecondOrder) acc += 2 * std::int64_t{st[4]} - st[5];
    const int q = 31 - s.shift;
    std::int64_t y = (acc + (std::int64_t{1} << (q - 1))) >> q;
    std::int32_t remainder = 0;
    if (y > kInt32Max) {
      y = kInt32Max;
      ++saturation_count_;
    } else if (y < kInt32Min) {
      y = kInt32Min;
      ++saturation_count_;
    } else {
      // In [-2^(q-1), 2^(q-1)): fits an int32 for q <= 31.
      remainder = static_cast<std::int32_t>(acc - y * (std::int64_t{1} << q));
    }
    st[1] = st[0];
    st[0] = x;
    st[3] = st[2];
    st[2] = static_cast<std::int32_t>(y);
    st[5] = st[4];
    st[4] = remainder;
    x = static_cast<std::int32_t>(y);
  }
  return x;
}

std::int32_t DobFilter::Step(const InputFrame& inputs) {
  std::int64_t sum = 0;
  for (std::size_t i = 0; i < description_.input_count; ++i) {
    const Path& p = description_.paths[i];
    const std::int32_t y = StepPath(i, inputs[i]);
    const int q = 31 - p.output_shift;
    sum += (std::int64_t{y} * p.output_gain + (std::int64_t{1} << (q - 1))) >> q;
  }
  if (sum > kInt32Max) {
    ++saturation_count_;
    return static_cast<std::int32_t>(kInt32Max);
  }
  if (sum < kInt32Min) {
    ++saturation_count_;
    return static_cast<std::int32_t>(kInt32Min);
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
