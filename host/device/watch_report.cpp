#include "vibid/device/watch_report.hpp"

#include <cstdio>

namespace vibid::device {
namespace {

constexpr double kQ16 = 65536.0;

bool HasTest(const std::optional<wire::WatchInfoResponse>& w) {
  return w && w->state != wire::WatchState::kNone;
}

std::string Fixed2(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

}  // namespace

nlohmann::json WatchJson(const std::optional<wire::WatchInfoResponse>& watch,
                         std::uint32_t sample_period_us) {
  if (!HasTest(watch)) return nullptr;
  const wire::WatchInfoResponse& w = *watch;
  const bool stale = w.stale != 0;
  return {
      {"state", w.state == wire::WatchState::kWatching ? "watching" : "idle"},
      {"stale", stale},
      {"statistic", w.statistic / kQ16},
      {"threshold", w.threshold / kQ16},
      {"last_z", w.last_z / kQ16},
      {"windows", w.windows},
      {"window_samples", w.window_samples},
      {"tripped_at_tick", stale ? nlohmann::json(w.trip_tick) : nlohmann::json(nullptr)},
      {"tripped_at_s",
       stale ? nlohmann::json(w.trip_tick * (sample_period_us * 1e-6)) : nlohmann::json(nullptr)},
      {"trip_statistic", stale ? nlohmann::json(w.trip_statistic / kQ16) : nlohmann::json(nullptr)},
      {"clamps", w.clamps}};
}

std::string WatchText(const std::optional<wire::WatchInfoResponse>& watch,
                      std::uint32_t sample_period_us, bool observer_on) {
  if (!watch) return "none (this firmware has no residual test)";
  if (watch->state == wire::WatchState::kNone) {
    return "none (the calibration carries no residual test)";
  }
  const wire::WatchInfoResponse& w = *watch;
  // The board's test runs with its observer, which runs while the board samples: right after
  // `dob start` on an idle board the observer is on and the test waits for the sampling.
  const std::string run = w.state == wire::WatchState::kWatching ? ""
                          : observer_on ? " (observer on: the test runs while the board samples)"
                                        : " (observer stopped)";
  if (w.stale != 0) {
    return "STALE since tick " + std::to_string(w.trip_tick) + " (" +
           Fixed2(w.trip_tick * (sample_period_us * 1e-6)) + " s, g " +
           Fixed2(w.trip_statistic / kQ16) + " > h " + Fixed2(w.threshold / kQ16) + "); g now " +
           Fixed2(w.statistic / kQ16) + run;
  }
  return "in control: g " + Fixed2(w.statistic / kQ16) + " of h " + Fixed2(w.threshold / kQ16) +
         " after " + std::to_string(w.windows) + " windows of " + std::to_string(w.window_samples) +
         " samples" + run;
}

}  // namespace vibid::device
