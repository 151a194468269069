// The disturbance observer as the sampling pipeline runs it: the fixed-point kernel
// (vibid::fixed::DobFilter) fed from the calibrated channels the record routes to its inputs, and
// beside it the residual test that says when the observer's model has gone stale
// (vibid::fixed::ResidualCusum on d_hat minus the record's reference force, when the record
// carries one).
// The host replays exactly this: wire::ScaleChannel on the logged raw values, the same routing,
// the same kernel, frame by frame, and gets the same d_hat bit for bit.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include "vibid/shared/fixed/dob_filter.hpp"
#include "vibid/shared/fixed/residual_cusum.hpp"
#include "vibid/shared/status.hpp"
#include "vibid/shared/wire/calibration_record.hpp"
#include "vibid/shared/wire/device.hpp"
#include "vibid/shared/wire/log_record.hpp"
#include "vibid/shared/wire/watch_info.hpp"

namespace vibid::fw {

class DobStage {
 public:
  /// Takes the filter (and the residual test, kCalFlagHasWatch) of a record that passed
  /// wire::DecodeCalibrationRecord; a record without a filter unloads both. Main loop, sampling
  /// stopped.
  /// @returns kOk; the kernel's Init status if it refuses the description (then unloaded), or
  ///          the test's if it refuses its parameters (then the filter stays, the test unloaded).
  Status Load(const wire::CalibrationRecord& record);

  bool loaded() const { return filter_.initialised(); }
  /// The rate the filter was discretized at; 0 when unloaded.
  std::uint32_t sample_rate_hz() const {
    return loaded() ? filter_.description().sample_rate_hz : 0;
  }

  /// Clears the filter state and the residual test, its flag included (a new run starts from
  /// rest).
  void Reset() {
    filter_.Reset();
    watch_.Reset();
    trip_tick_ = 0;
    watch_windows_.store(0, std::memory_order_release);
  }

  /// One frame: routes the calibrated channels to the inputs and steps the kernel.
  /// @returns d_hat, a Q31 fraction of the description's output full scale (0 when unloaded).
  std::int32_t Step(const std::array<std::int32_t, wire::kChannelCount>& calibrated);

  /// The residual test on this frame's d_hat (after Step, in the sampling context); `tick` is the
  /// acquisition tick the trip time is told in.
  void StepWatch(std::int32_t d_hat,
                 const std::array<std::int32_t, wire::kChannelCount>& calibrated,
                 std::uint32_t tick) {
    const std::int32_t reference =
        watch_channel_ < wire::kChannelCount ? calibrated[watch_channel_] : 0;
    if (!watch_.Step(d_hat, reference)) return;
    if (watch_.tripped() && trip_tick_ == 0 && watch_.trip_sample() == watch_.samples()) {
      trip_tick_ = tick;
    }
    watch_windows_.store(watch_.windows(), std::memory_order_release);
  }

  bool watch_loaded() const { return watch_.initialised(); }

  /// The test's state as a log record carries it (wire::kAcqFlagLogWatch): g, which the kernel
  /// keeps within 0..2^30, below the flag bit. Sampling context, after StepWatch.
  std::uint32_t WatchWord() const {
    return static_cast<std::uint32_t>(watch_.statistic()) |
           (watch_.tripped() ? wire::kLogWatchStaleBit : 0u);
  }

  /// The test's state for get-info's watch page, consistent even while windows end (main loop).
  wire::WatchInfoResponse WatchInfo(bool observer_running) const;

  std::uint32_t saturations() const { return filter_.saturation_count(); }

 private:
  fixed::DobFilter filter_;
  std::array<std::uint8_t, wire::kMaxDobInputs> channels_{};
  fixed::ResidualCusum watch_;
  std::uint8_t watch_channel_ = wire::kNoChannel;
  std::uint32_t trip_tick_ = 0;  // written in the sampling context with the window's end
  // The windows completed, published after each window's figures: a reader that sees the same
  // count before and after copying them copied one window's state.
  std::atomic<std::uint32_t> watch_windows_{0};
};

}  // namespace vibid::fw
