#include "vibid/shared/fixed/residual_cusum.hpp"

namespace vibid::fixed {

Status ValidateResidualCusum(const ResidualCusumParams& p) {
  if (p.window_samples == 0 || p.window_samples > kMaxWindowSamples) {
    return Status::kInvalidArgument;
  }
  constexpr std::int32_t kI32Min = -0x7FFFFFFF - 1;
  if (p.residual_gain == 0 || p.residual_gain == kI32Min || p.reference_gain == kI32Min) {
    return Status::kInvalidArgument;
  }
  if (p.sum_shift > kMaxSumShift || p.z_shift > kMaxZShift) {
    return Status::kInvalidArgument;
  }
  if (p.z_gain <= 0 || p.k < 0 || p.h <= 0 || p.h >= kMaxStatistic) {
    return Status::kInvalidArgument;
  }
  return Status::kOk;
}

Status ResidualCusum::Init(const ResidualCusumParams& params) {
  params_ = ResidualCusumParams{};
  residual_gain_ = 0;
  reference_gain_ = 0;
  left_ = 0;
  const Status s = ValidateResidualCusum(params);
  if (s != Status::kOk) return s;
  params_ = params;
  residual_gain_ = params.residual_gain;
  reference_gain_ = params.reference_gain;
  Reset();
  return Status::kOk;
}

void ResidualCusum::Reset() {
  sum_ = 0;
  left_ = params_.window_samples;
  windows_ = 0;
  g_ = 0;
  z_ = 0;
  tripped_ = false;
  trip_sample_ = 0;
  trip_statistic_ = 0;
  clamp_count_ = 0;
}

void ResidualCusum::EndWindow() {
  constexpr std::int64_t kI32Max = 0x7FFFFFFF;
  constexpr std::int64_t kI32Min = -kI32Max - 1;
  std::int64_t e = (sum_ >> params_.sum_shift) - params_.center;
  if (e > kI32Max || e < -kI32Max) {
    e = e > 0 ? kI32Max : -kI32Max;
    ++clamp_count_;
  }
  const std::int64_t round = params_.z_shift == 0 ? 0 : std::int64_t{1} << (params_.z_shift - 1);
  std::int64_t z = (e * params_.z_gain + round) >> params_.z_shift;
  if (z > kI32Max) z = kI32Max;
  if (z < kI32Min) z = kI32Min;
  z_ = static_cast<std::int32_t>(z);
  sum_ = 0;
  left_ = params_.window_samples;
  if (windows_ < params_.holdoff_windows) {
    // Within the hold-off: the observer's start transient, not judged (g stays 0); its clamps are
    // dropped at the hold-off's last window so clamp_count speaks of the judged windows only.
    ++windows_;
    if (windows_ == params_.holdoff_windows) clamp_count_ = 0;
    return;
  }
  std::int64_t g = std::int64_t{g_} + z - params_.k;
  if (g < 0) g = 0;
  if (g > kMaxStatistic) {
    g = kMaxStatistic;
    ++clamp_count_;
  }
  g_ = static_cast<std::int32_t>(g);
  ++windows_;
  if (!tripped_ && g_ > params_.h) {
    tripped_ = true;
    trip_sample_ = windows_ * params_.window_samples;
    trip_statistic_ = g_;
  }
}

}  // namespace vibid::fixed
