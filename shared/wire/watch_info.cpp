#include "vibid/shared/wire/watch_info.hpp"

#include "vibid/shared/wire/byte_order.hpp"

namespace vibid::wire {

void Encode(const WatchInfoResponse& v, std::span<std::uint8_t> out) {
  StoreU8(out, 0, static_cast<std::uint8_t>(v.state));
  StoreU8(out, 1, v.stale);
  StoreU16(out, 2, 0);
  StoreU32(out, 4, v.window_samples);
  StoreU32(out, 8, v.windows);
  StoreI32(out, 12, v.statistic);
  StoreI32(out, 16, v.threshold);
  StoreI32(out, 20, v.last_z);
  StoreU32(out, 24, v.trip_tick);
  StoreI32(out, 28, v.trip_statistic);
  StoreU32(out, 32, v.clamps);
}

Status Decode(std::span<const std::uint8_t> in, WatchInfoResponse& v) {
  if (in.size() != WatchInfoResponse::kBytes) return Status::kInvalidArgument;
  const std::uint8_t state = LoadU8(in, 0);
  const std::uint8_t stale = LoadU8(in, 1);
  if (state > static_cast<std::uint8_t>(WatchState::kWatching) || stale > 1 ||
      LoadU16(in, 2) != 0) {
    return Status::kInvalidArgument;
  }
  v.state = static_cast<WatchState>(state);
  v.stale = stale;
  v.window_samples = LoadU32(in, 4);
  v.windows = LoadU32(in, 8);
  v.statistic = LoadI32(in, 12);
  v.threshold = LoadI32(in, 16);
  v.last_z = LoadI32(in, 20);
  v.trip_tick = LoadU32(in, 24);
  v.trip_statistic = LoadI32(in, 28);
  v.clamps = LoadU32(in, 32);
  return Status::kOk;
}

}  // namespace vibid::wire
