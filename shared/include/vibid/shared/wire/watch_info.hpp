// get-info page kInfoPageWatch (protocol 2.1): the observer's residual test as the board runs it
// (vibid::fixed::ResidualCusum, parameters from the calibration record's Watch block). A board
// whose firmware has no such page refuses it (invalid-argument, unknown-info-page).
//
//   0  u8  state             WatchState
//   1  u8  stale             1 once the statistic exceeded the threshold in this run (latched
//                            until the next run of the observer starts), else 0
//   2  u16 reserved          0
//   4  u32 window_samples    W, samples per window (0 without a test)
//   8  u32 windows           windows completed in this run
//   12 i32 statistic         the CUSUM g, Q16 (g / 65536 in spreads of the window mean)
//   16 i32 threshold         h, Q16
//   20 i32 last_z            the last window's standardized residual power, Q16
//   24 u32 trip_tick         the acquisition tick (get-status ticks, log record tick) of the frame
//                            that ended the window that tripped; 0 while not stale
//   28 i32 trip_statistic    g at that window, Q16
//   32 u32 clamps            residual samples, window excesses and statistics clamped (0 while
//                            the residual stays within 48 dB of the calibration day's)
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/shared/status.hpp"

namespace vibid::wire {

inline constexpr std::uint8_t kInfoPageWatch = 3;

enum class WatchState : std::uint8_t {
  kNone = 0,      ///< The calibration carries no residual test (or no observer).
  kIdle = 1,      ///< Loaded; the observer is not running (the figures are the last run's).
  kWatching = 2,  ///< The observer runs and the test with it.
};

struct WatchInfoResponse {
  static constexpr std::size_t kBytes = 36;
  WatchState state = WatchState::kNone;
  std::uint8_t stale = 0;
  std::uint32_t window_samples = 0;
  std::uint32_t windows = 0;
  std::int32_t statistic = 0;
  std::int32_t threshold = 0;
  std::int32_t last_z = 0;
  std::uint32_t trip_tick = 0;
  std::int32_t trip_statistic = 0;
  std::uint32_t clamps = 0;
};

void Encode(const WatchInfoResponse& v, std::span<std::uint8_t> out);
/// @returns kOk; kInvalidArgument for another size, an unknown state, a stale byte other than
///          0 or 1, or a nonzero reserved field.
Status Decode(std::span<const std::uint8_t> in, WatchInfoResponse& v);

}  // namespace vibid::wire
