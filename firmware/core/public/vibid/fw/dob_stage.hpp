// The disturbance observer as the sampling pipeline runs it: the fixed-point kernel
// (vibid::fixed::DobFilter) fed from the calibrated channels the record routes to its inputs.
// The host replays exactly this: wire::ScaleChannel on the logged raw values, the same routing,
// the same kernel, frame by frame, and gets the same d_hat bit for bit.
#pragma once

#include <array>
#include <cstdint>

#include "vibid/shared/fixed/dob_filter.hpp"
#include "vibid/shared/status.hpp"
#include "vibid/shared/wire/calibration_record.hpp"
#include "vibid/shared/wire/device.hpp"

namespace vibid::fw {

class DobStage {
 public:
  /// Takes the filter of a record that passed wire::DecodeCalibrationRecord; a record without a
  /// filter unloads it. Main loop, sampling stopped.
  /// @returns kOk; the kernel's Init status if it refuses the description (then unloaded).
  Status Load(const wire::CalibrationRecord& record);

  bool loaded() const { return filter_.initialised(); }
  /// The rate the filter was discretized at; 0 when unloaded.
  std::uint32_t sample_rate_hz() const {
    return loaded() ? filter_.description().sample_rate_hz : 0;
  }

  /// Clears the filter state (a new run starts from rest).
  void Reset() { filter_.Reset(); }

  /// One frame: routes the calibrated channels to the inputs and steps the kernel.
  /// @returns d_hat, a Q31 fraction of the description's output full scale (0 when unloaded).
  std::int32_t Step(const std::array<std::int32_t, wire::kChannelCount>& calibrated);

  std::uint32_t saturations() const { return filter_.saturation_count(); }

 private:
  fixed::DobFilter filter_;
  std::array<std::uint8_t, wire::kMaxDobInputs> channels_{};
};

}  // namespace vibid::fw
