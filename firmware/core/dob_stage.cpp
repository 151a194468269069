#include "vibid/fw/dob_stage.hpp"

namespace vibid::fw {

Status DobStage::Load(const wire::CalibrationRecord& record) {
  filter_ = fixed::DobFilter{};
  watch_ = fixed::ResidualCusum{};
  watch_channel_ = wire::kNoChannel;
  Reset();
  if ((record.flags & wire::kCalFlagHasDob) == 0) return Status::kOk;
  fixed::FilterDescription description;
  (void)fixed::DecodeDescription(record.dob, description);
  const Status s = filter_.Init(description);
  if (s != Status::kOk) return s;
  channels_ = record.dob_input_channel;
  if ((record.flags & wire::kCalFlagHasWatch) == 0) return Status::kOk;
  const Status w = watch_.Init(record.watch);
  if (w != Status::kOk) return w;
  watch_channel_ = record.watch_reference_channel;
  return Status::kOk;
}

wire::WatchInfoResponse DobStage::WatchInfo(bool observer_running) const {
  wire::WatchInfoResponse out;
  if (!watch_.initialised()) return out;
  // The sampling context may end a window while we copy; retry until the count is unchanged (it
  // only ever runs between our reads, never concurrently on one core).
  for (int attempt = 0; attempt < 4; ++attempt) {
    const std::uint32_t before = watch_windows_.load(std::memory_order_acquire);
    out.stale = watch_.tripped() ? 1 : 0;
    out.windows = watch_.windows();
    out.statistic = watch_.statistic();
    out.last_z = watch_.last_z();
    out.trip_tick = trip_tick_;
    out.trip_statistic = watch_.trip_statistic();
    out.clamps = watch_.clamp_count();
    std::atomic_thread_fence(std::memory_order_acquire);
    if (watch_windows_.load(std::memory_order_relaxed) == before) break;
  }
  out.state = observer_running ? wire::WatchState::kWatching : wire::WatchState::kIdle;
  out.window_samples = watch_.params().window_samples;
  out.threshold = watch_.params().h;
  return out;
}

std::int32_t DobStage::Step(const std::array<std::int32_t, wire::kChannelCount>& calibrated) {
  if (!loaded()) return 0;
  fixed::InputFrame inputs{};
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    // Validated routing: a used input names a channel, an unused one kNoChannel (input ignored).
    if (channels_[i] < wire::kChannelCount) inputs[i] = calibrated[channels_[i]];
  }
  return filter_.Step(inputs);
}

}  // namespace vibid::fw
