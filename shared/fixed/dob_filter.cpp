// What every backend shares: validation, the uninitialised filter, the block checks and the
// saturation count. The arithmetic is the build's DobKernel (dob_filter.hpp, "Backends").
#include "vibid/shared/fixed/dob_filter.hpp"

#include <cstddef>
#include <cstdint>
#include <span>

namespace vibid::fixed {

Status DobFilter::Init(const FilterDescription& description) {
  const Status st = ValidateDescription(description);
  description_ = st == Status::kOk ? description : FilterDescription{.input_count = 0};
  // An uninitialised filter never runs its kernel (Step returns 0, StepBlock refuses).
  if (st == Status::kOk) kernel_.Load(description_);
  saturation_count_ = 0;
  return st;
}

void DobFilter::Reset() {
  kernel_.Reset(description_);
  saturation_count_ = 0;
}

std::int32_t DobFilter::Step(const InputFrame& inputs) {
  if (!initialised()) return 0;
  std::int32_t out = 0;
  saturation_count_ += kernel_.Run(inputs.data(), &out, 1);
  return out;
}

Status DobFilter::StepBlock(std::span<const std::int32_t> interleaved,
                            std::span<std::int32_t> output) {
  const std::size_t n_in = description_.input_count;
  if (n_in == 0 || interleaved.size() != output.size() * n_in) return Status::kInvalidArgument;
  if (!output.empty()) {
    saturation_count_ += kernel_.Run(interleaved.data(), output.data(), output.size());
  }
  return Status::kOk;
}

}  // namespace vibid::fixed
