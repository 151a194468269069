#include "vibid/fw/sampler.hpp"

#include <climits>

#include "vibid/shared/board_profile.hpp"
#include "vibid/shared/wire/byte_order.hpp"

namespace vibid::fw {
namespace {

/// The converter's top code: a sample there (or at 0) is the end of the ADC's range, where the
/// signal may be anywhere beyond it.
constexpr std::int32_t kAdcTopCode = (std::int32_t{1} << kBoardProfile.adc_bits) - 1;

}  // namespace

void Sampler::SetScaling(const std::array<wire::ChannelScaling, wire::kChannelCount>& scaling) {
  scaling_ = scaling;
  for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
    if (wire::KindOf(static_cast<wire::Channel>(c)) == wire::ChannelKind::kEncoder) {
      // An encoder count has no range of its own: only its calibration saturates.
      lowest_unclipped_[c] = INT32_MIN;
      highest_unclipped_[c] = INT32_MAX;
      continue;
    }
    // A converter code at either end of the ADC's range is a clip, except the bottom end on a
    // channel calibrated with its zero at code 0 or below (a unipolar amplifier idling at 0 V):
    // code 0 is its rest, where it sits sample after sample, not a signal cut off.
    const bool zero_at_bottom =
        scaling[c].unit != wire::Unit::kCounts && scaling[c].offset_counts <= 0;
    lowest_unclipped_[c] = zero_at_bottom ? 0 : 1;
    highest_unclipped_[c] = kAdcTopCode - 1;
  }
}

Status Sampler::Arm(const wire::AcqConfigureRequest& config) {
  layout_ = wire::LogLayout{config.channel_mask, config.flags};
  Status s =
      decimator_.Init(config.decimation, layout_.ChannelCount() + (layout_.HasDob() ? 1 : 0));
  if (s != Status::kOk) return s;
  // Twice the delay, rounded up to an output tick: records before it would hold the filter's
  // start from rest (zeros before the acquisition) rather than the signal.
  const std::uint32_t d = config.decimation;
  settle_ticks_ = d == 1 ? 0 : (2 * fixed::DecimatorDelayTicks(d) + d - 1) / d * d;
  watch_lag_ = d == 1 ? 0 : (fixed::DecimatorDelayTicks(d) + d - 1) / d;
  if (watch_lag_ > kMaxWatchLag) return Status::kInvalidArgument;
  watch_words_.fill(0);  // the test starts from rest with the acquisition
  watch_head_ = 0;
  s = ring_.Reset(layout_.StoredRecordBytes(), config.pretrigger_records);
  if (s != Status::kOk) return s;
  config_ = config;
  expected_tick_ = 0;
  post_trigger_records_ = 0;
  dob_rate_ok_ =
      dob_.loaded() &&
      static_cast<std::uint64_t>(config.sample_period_us) * dob_.sample_rate_hz() == 1000000u;
  dob_in_acquisition_ = dob_rate_ok_ && layout_.HasDob();
  dob_was_running_ = false;
  dob_.Reset();
  ticks_.store(0, std::memory_order_relaxed);
  overruns_.store(0, std::memory_order_relaxed);
  dropped_.store(0, std::memory_order_relaxed);
  clips_.store(0, std::memory_order_relaxed);
  for (auto& c : channel_clips_) c.store(0, std::memory_order_relaxed);
  if (config.trigger_mode == wire::TriggerMode::kImmediate) {
    ring_.MarkTrigger();
    state_.store(wire::AcqState::kAcquiring, std::memory_order_release);
  } else {
    state_.store(wire::AcqState::kArmed, std::memory_order_release);
  }
  return Status::kOk;
}

void Sampler::Disarm() {
  const wire::AcqState s = state_.load(std::memory_order_acquire);
  if (s == wire::AcqState::kArmed || s == wire::AcqState::kAcquiring) {
    state_.store(wire::AcqState::kIdle, std::memory_order_release);
  }
  dob_in_acquisition_ = false;
}

bool Sampler::dob_running() const {
  const wire::AcqState s = state();
  return (s == wire::AcqState::kArmed || s == wire::AcqState::kAcquiring) &&
         (dob_in_acquisition_ || (dob_rate_ok_ && dob_requested_.load(std::memory_order_acquire)));
}

bool Sampler::TriggerFires(const std::array<std::int32_t, wire::kChannelCount>& calibrated) const {
  const std::int32_t v = calibrated[config_.trigger_channel];
  switch (config_.trigger_mode) {
    case wire::TriggerMode::kImmediate: return true;
    case wire::TriggerMode::kRising: return v >= config_.trigger_threshold;
    case wire::TriggerMode::kFalling: return v <= config_.trigger_threshold;
  }
  return false;
}

void Sampler::OnFrame(const SampleFrame& frame) {
  std::uint32_t clips = 0;
  std::uint8_t clipped_channels = 0;  // bit c: channel c clipped in this frame
  std::array<std::int32_t, wire::kChannelCount> calibrated{};
  for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
    std::uint32_t saturated = 0;
    calibrated[c] = wire::ScaleChannel(frame.raw[c], scaling_[c], saturated);
    if (saturated != 0 || frame.raw[c] < lowest_unclipped_[c] ||
        frame.raw[c] > highest_unclipped_[c]) {
      clipped_channels = static_cast<std::uint8_t>(clipped_channels | (1u << c));
      ++clips;
    }
  }
  const wire::AcqState state = state_.load(std::memory_order_relaxed);
  const bool sampling = state == wire::AcqState::kArmed || state == wire::AcqState::kAcquiring;
  // The DOB steps on every frame at the sampling rate whatever the log rate, so the host can
  // replay it from a log kept at the sampling rate. A run switched on mid-acquisition starts
  // from rest.
  const bool run_dob =
      sampling &&
      (dob_in_acquisition_ || (dob_rate_ok_ && dob_requested_.load(std::memory_order_relaxed)));
  if (run_dob && !dob_was_running_) dob_.Reset();
  dob_was_running_ = run_dob;
  const std::int32_t d_hat = run_dob ? dob_.Step(calibrated) : 0;
  if (run_dob) dob_.StepWatch(d_hat, calibrated, frame.tick);
  // A frame the port delivers after the acquisition ended (before the main loop stopped it)
  // belongs to no acquisition: read-latest keeps the acquisition's last frame and its tick.
  if (!sampling) return;
  PublishLatest(frame, calibrated, d_hat);

  ticks_.store(ticks_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  if (clips != 0) {
    clips_.store(clips_.load(std::memory_order_relaxed) + clips, std::memory_order_relaxed);
    for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
      if ((clipped_channels & (1u << c)) == 0) continue;
      channel_clips_[c].store(channel_clips_[c].load(std::memory_order_relaxed) + 1,
                              std::memory_order_relaxed);
    }
  }
  // Ticks count from 0 at Start; a jump means the port lost frames before they reached us.
  if (frame.tick != expected_tick_) {
    const std::uint32_t missed = frame.tick - expected_tick_;
    if (missed < 0x80000000u) {
      overruns_.store(overruns_.load(std::memory_order_relaxed) + missed,
                      std::memory_order_relaxed);
    }
  }
  expected_tick_ = frame.tick + 1;

  wire::AcqState next = state;
  if (state == wire::AcqState::kArmed && TriggerFires(calibrated)) {
    ring_.MarkTrigger();
    next = wire::AcqState::kAcquiring;
  }

  const Logged logged = LogFrame(frame, d_hat);
  if (logged != Logged::kNoRecord && next == wire::AcqState::kAcquiring) {
    if (logged == Logged::kRefused) {
      dropped_.store(dropped_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    }
    ++post_trigger_records_;
    if (config_.record_limit != 0 && post_trigger_records_ >= config_.record_limit) {
      next = wire::AcqState::kDone;
    }
  }
  if (next != state) state_.store(next, std::memory_order_release);
}

Sampler::Logged Sampler::LogFrame(const SampleFrame& frame, std::int32_t d_hat) {
  // The logged values in their log format, in record order: converter codes as 12.4, encoder
  // counts, d_hat. All of them pass the same decimator, so a ratio of two channels (an FRF)
  // keeps its value in the passband.
  std::array<std::int32_t, fixed::kDecimatorMaxChannels> in{};
  std::size_t n = 0;
  for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
    if ((layout_.channel_mask & (1u << c)) == 0) continue;
    const bool converter = wire::LogValueBytes(static_cast<wire::Channel>(c)) == 2;
    in[n++] = converter ? static_cast<std::int32_t>(static_cast<std::uint32_t>(frame.raw[c])
                                                    << wire::kLogAdcFractionBits)
                        : frame.raw[c];
  }
  if (layout_.HasDob()) in[n++] = d_hat;
  std::array<std::int32_t, fixed::kDecimatorMaxChannels> out{};
  if (!decimator_.Push(in.data(), out.data())) return Logged::kNoRecord;
  std::uint32_t watch = 0;
  if (layout_.HasWatch()) {
    constexpr std::uint32_t kWords = kMaxWatchLag + 1;
    watch_words_[watch_head_] = dob_in_acquisition_ ? dob_.WatchWord() : 0u;
    watch = watch_words_[(watch_head_ + kWords - watch_lag_) % kWords];
    watch_head_ = (watch_head_ + 1) % kWords;
  }
  if (frame.tick < settle_ticks_) return Logged::kNoRecord;

  wire::LogRecord record;
  n = 0;
  for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
    if ((layout_.channel_mask & (1u << c)) != 0) record.raw[c] = out[n++];
  }
  if (layout_.HasDob()) record.d_hat = out[n];
  record.watch = watch;
  std::array<std::uint8_t, wire::kLogIndexBytes + wire::kMaxLogRecordBytes> bytes{};
  wire::StoreU32(bytes, 0, frame.tick);
  wire::EncodeLogRecord(layout_, record,
                        std::span<std::uint8_t>(bytes).subspan(wire::kLogIndexBytes));
  const bool kept =
      ring_.Push(std::span<const std::uint8_t>(bytes).first(layout_.StoredRecordBytes()));
  return kept ? Logged::kKept : Logged::kRefused;
}

void Sampler::PublishLatest(const SampleFrame& frame,
                            const std::array<std::int32_t, wire::kChannelCount>& calibrated,
                            std::int32_t d_hat) {
  const std::uint32_t v = latest_version_.load(std::memory_order_relaxed);
  latest_version_.store(v + 1, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);
  latest_tick_ = frame.tick;
  latest_calibrated_ = calibrated;
  latest_d_hat_ = d_hat;
  latest_version_.store(v + 2, std::memory_order_release);
}

wire::ClipResponse Sampler::Clips() const {
  wire::ClipResponse r;
  r.ticks = ticks();
  for (std::size_t c = 0; c < wire::kChannelCount; ++c)
    r.clipped[c] = channel_clips_[c].load(std::memory_order_relaxed);
  return r;
}

bool Sampler::Latest(wire::LatestResponse& out) const {
  // The sampling context may overwrite the snapshot while we copy it; retry until the version
  // is even and unchanged (it only ever runs between our reads, never concurrently on one core).
  for (int attempt = 0; attempt < 4; ++attempt) {
    const std::uint32_t before = latest_version_.load(std::memory_order_acquire);
    if (before == 0) return false;
    out.tick = latest_tick_;
    out.calibrated = latest_calibrated_;
    out.d_hat = latest_d_hat_;
    std::atomic_thread_fence(std::memory_order_acquire);
    if ((before & 1u) == 0 && latest_version_.load(std::memory_order_relaxed) == before) break;
  }
  out.acq_state = state();
  out.dob_running = dob_running() ? 1 : 0;
  return true;
}

}  // namespace vibid::fw
