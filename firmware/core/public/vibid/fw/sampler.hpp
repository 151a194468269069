// The sampling pipeline, run once per frame in the sampling context:
//
//   raw frame -> per-channel calibration (wire::ScaleChannel) -> DOB (when running)
//             -> trigger (immediate, or a load cell crossing a threshold)
//             -> the logged channels and d_hat through the anti-aliasing decimator
//             -> every `decimation`-th frame: a log record (its tick, the channels in their log
//                format, d_hat), the same filter on every value so ratios between channels keep
//                their passband values; a decimated log starts once the filter has settled
//
// Nothing is lost silently: a frame tick that skips ahead counts the missing ticks as overruns,
// a record that finds the log full after the trigger counts as dropped, and a sample that clips
// counts on its channel: a converter code at either end of the ADC's range (the signal is beyond
// the sensor's span) or a calibration that saturates (beyond the channel's calibrated full scale).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include "vibid/fw/dob_stage.hpp"
#include "vibid/fw/log_ring.hpp"
#include "vibid/fw/port.hpp"
#include "vibid/shared/fixed/decimator.hpp"
#include "vibid/shared/status.hpp"
#include "vibid/shared/wire/calibration_record.hpp"
#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/log_record.hpp"

namespace vibid::fw {

class Sampler final : public FrameSink {
 public:
  /// The most decimator outputs a record's residual-test word lags its frame by: ceil(delay / D)
  /// over every supported factor D (core_watch_test checks it).
  static constexpr std::uint32_t kMaxWatchLag = 16;

  Sampler(LogRing& ring, DobStage& dob) : ring_(ring), dob_(dob) { SetScaling(scaling_); }

  /// Calibration applied from the next frame on, with each channel's clip limits. Main loop,
  /// sampling stopped.
  void SetScaling(const std::array<wire::ChannelScaling, wire::kChannelCount>& scaling);

  /// Prepares an acquisition with an already validated configuration: resets the log, the
  /// counters and the DOB state; an immediate trigger fires at once. The DOB runs in this
  /// acquisition if it is loaded, discretized for this sample rate, and either logged
  /// (kAcqFlagLogDob) or switched on by SetDobRunning. Main loop, sampling stopped.
  /// @returns the log's Reset status (kOutOfRange if the pre-trigger does not fit);
  ///          kInvalidArgument for a decimation the decimator does not support.
  Status Arm(const wire::AcqConfigureRequest& config);

  /// Ends the acquisition (after the port stopped delivering frames); the log is kept.
  void Disarm();

  /// Runs the DOB in acquisitions that do not log it too (dob-control; live d_hat).
  void SetDobRunning(bool running) { dob_requested_.store(running, std::memory_order_release); }
  /// The observer is on (dob-control run): it runs whenever the board samples at its rate.
  bool dob_requested() const { return dob_requested_.load(std::memory_order_acquire); }

  void OnFrame(const SampleFrame& frame) override;

  wire::AcqState state() const { return state_.load(std::memory_order_acquire); }
  bool dob_running() const;
  std::uint32_t ticks() const { return ticks_.load(std::memory_order_relaxed); }
  std::uint32_t overruns() const { return overruns_.load(std::memory_order_relaxed); }
  std::uint32_t dropped() const { return dropped_.load(std::memory_order_relaxed); }
  /// Clipped samples of all channels plus DOB saturations since acq-start.
  std::uint32_t saturations() const {
    return clips_.load(std::memory_order_relaxed) + dob_.saturations();
  }
  /// Clipped samples per channel since acq-start, and the ticks they are out of (get-clips).
  wire::ClipResponse Clips() const;
  const wire::AcqConfigureRequest& config() const { return config_; }
  wire::LogLayout layout() const { return layout_; }

  /// The newest frame of the current or last acquisition after calibration, and its d_hat,
  /// consistent even while frames arrive. @returns false if no acquisition sampled a frame since
  /// boot.
  bool Latest(wire::LatestResponse& out) const;

 private:
  bool TriggerFires(const std::array<std::int32_t, wire::kChannelCount>& calibrated) const;
  enum class Logged : std::uint8_t { kNoRecord, kKept, kRefused };
  /// Feeds the logged values of one frame to the decimator; on an output tick pushes a record.
  /// kRefused: the log was full (after the trigger: a dropped record).
  Logged LogFrame(const SampleFrame& frame, std::int32_t d_hat);
  void PublishLatest(const SampleFrame& frame,
                     const std::array<std::int32_t, wire::kChannelCount>& calibrated,
                     std::int32_t d_hat);

  LogRing& ring_;
  DobStage& dob_;
  std::array<wire::ChannelScaling, wire::kChannelCount> scaling_{};
  // The codes a sample may take without counting as a clip, per channel, from SetScaling: a
  // decision per calibration, one pair of compares per sample.
  std::array<std::int32_t, wire::kChannelCount> lowest_unclipped_{};
  std::array<std::int32_t, wire::kChannelCount> highest_unclipped_{};
  wire::AcqConfigureRequest config_{};
  wire::LogLayout layout_{};
  fixed::Decimator decimator_;
  // A decimated log starts once the decimator has settled: its first record is the first output
  // whose filter span lies wholly inside the acquisition (tick >= twice the group delay).
  std::uint32_t settle_ticks_ = 0;
  // The residual test's word as a record carries it (wire::kAcqFlagLogWatch): the state at the
  // record's time as the host writes it, its tick less the decimator's delay. The state moves at
  // the frame rate and skips the filter, so each output keeps its word here and a record takes
  // the one `watch_lag_` outputs back (the delay in outputs, rounded up: the latest state at or
  // before the record's time, to within one output); kMaxWatchLag bounds it.
  std::array<std::uint32_t, kMaxWatchLag + 1> watch_words_{};
  std::uint32_t watch_lag_ = 0;
  std::uint32_t watch_head_ = 0;
  std::uint32_t expected_tick_ = 0;
  std::uint32_t post_trigger_records_ = 0;
  bool dob_in_acquisition_ = false;  // logged, or requested, at a matching rate
  bool dob_rate_ok_ = false;
  bool dob_was_running_ = false;

  std::atomic<wire::AcqState> state_{wire::AcqState::kIdle};
  std::atomic<bool> dob_requested_{false};
  std::atomic<std::uint32_t> ticks_{0};
  std::atomic<std::uint32_t> overruns_{0};
  std::atomic<std::uint32_t> dropped_{0};
  std::atomic<std::uint32_t> clips_{0};  // the sum of channel_clips_
  std::array<std::atomic<std::uint32_t>, wire::kChannelCount> channel_clips_{};

  // Latest frame, published with a sequence counter (odd while being written).
  std::atomic<std::uint32_t> latest_version_{0};
  std::uint32_t latest_tick_ = 0;
  std::array<std::int32_t, wire::kChannelCount> latest_calibrated_{};
  std::int32_t latest_d_hat_ = 0;
};

}  // namespace vibid::fw
