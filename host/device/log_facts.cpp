#include "vibid/device/log_facts.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>

#include "vibid/common/q31_decimal.hpp"
#include "vibid/device/info_json.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/shared/board_profile.hpp"

namespace vibid::device {
namespace {

constexpr double kQ31 = 2147483648.0;

const char* UnitString(wire::Unit unit) {
  switch (unit) {
    case wire::Unit::kNewton: return "N";
    case wire::Unit::kMeterPerSecond2: return "m/s2";
    case wire::Unit::kMeter: return "m";
    case wire::Unit::kMeterPerSecond: return "m/s";
    case wire::Unit::kCounts: break;
  }
  return "counts";
}

std::pair<double, double> CodeRange(wire::Channel channel, unsigned adc_bits) {
  if (wire::LogValueBytes(channel) == 2)
    return {0.0, std::ldexp(1.0, static_cast<int>(adc_bits)) - 1.0};
  return {static_cast<double>(std::numeric_limits<std::int32_t>::min()),
          static_cast<double>(std::numeric_limits<std::int32_t>::max())};
}

}  // namespace

std::pair<double, double> ChannelRails(wire::Channel channel, const wire::ChannelScaling& s,
                                       unsigned adc_bits) {
  const auto [lo_code, hi_code] = CodeRange(channel, adc_bits);
  // The column's value of a code, as MakeLogTable computes it (the board's ScaleChannel, then x
  // full scale / 2^31), so a clipped sample equals its rail exactly.
  const auto value = [&](double code) {
    std::uint32_t clips = 0;
    const double q = wire::ScaleChannel(static_cast<std::int32_t>(code), s, clips);
    if (s.unit == wire::Unit::kCounts) return q;
    const double fs = static_cast<double>(s.full_scale);
    return ShortestQ31Decimal(q * (fs / kQ31), fs);
  };
  const double a = value(lo_code);
  const double b = value(hi_code);
  return {std::min(a, b), std::max(a, b)};
}

std::optional<std::uint64_t> EmulatorSeedOfSerial(const std::string& serial) {
  if (serial.size() != 19 || serial.compare(0, 3, "EMU") != 0) return std::nullopt;
  std::uint64_t seed = 0;
  for (std::size_t i = 3; i < serial.size(); ++i) {
    const char c = serial[i];
    const int d = c >= '0' && c <= '9' ? c - '0' : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
    if (d < 0) return std::nullopt;
    seed = (seed << 4) | static_cast<std::uint64_t>(d);
  }
  return seed;
}

BoardContext ContextOf(Connection& c) {
  BoardContext b;
  b.info = c.info();
  b.serial = c.SerialNumber();
  b.instants = c.GetSamplingInfo();
  b.clips = c.GetClips();
  return b;
}

ident::RecordingFacts LogFacts(const LogPull& format, std::uint64_t records,
                               const wire::CalibrationRecord& calibration, bool has_record,
                               const BoardContext& board,
                               std::optional<ident::AcquisitionFacts> asked,
                               const std::string& start_timestamp) {
  ident::AcquisitionFacts acquisition = asked.value_or(ident::AcquisitionFacts{});
  LogPull empty;
  empty.layout = format.layout;
  empty.trailer = format.trailer;
  const LogTable table = MakeLogTable(empty, calibration, has_record);
  ident::RecordingFacts f;
  f.columns = table.names;
  f.start_timestamp = start_timestamp;
  const double period_us = format.trailer.sample_period_us;
  const double decimation = std::max<double>(1.0, format.trailer.decimation);
  if (period_us > 0.0) {
    f.fs = 1e6 / period_us / decimation;
    acquisition.sample_rate_hz = 1e6 / period_us;
  }
  acquisition.decimation = static_cast<std::uint32_t>(decimation);
  acquisition.records = records;
  acquisition.dropped_records = format.trailer.dropped_records;
  acquisition.overrun_ticks = format.trailer.overrun_count;
  const unsigned adc_bits = board.info && board.info->adc_bits != 0
                                ? board.info->adc_bits
                                : static_cast<unsigned>(kBoardProfile.adc_bits);
  if (board.info) {
    const wire::InfoResponse& i = *board.info;
    ident::BoardFacts b;
    b.board = BoardName(i.board_id);
    b.serial = board.serial;
    b.firmware = std::to_string(i.fw_major) + "." + std::to_string(i.fw_minor) + "." +
                 std::to_string(i.fw_patch);
    b.protocol = std::to_string(i.protocol_major) + "." + std::to_string(i.protocol_minor);
    b.build_id = i.build_id;
    b.adc_bits = adc_bits;
    f.board = b;
    if (i.board_id == wire::BoardId::kEmulator)
      acquisition.emulator_seed = EmulatorSeedOfSerial(board.serial);
  }
  if (has_record) {
    ident::CalibrationFacts c;
    c.label = std::string(calibration.label.data(),
                          std::find(calibration.label.begin(), calibration.label.end(), '\0'));
    std::array<std::uint8_t, wire::kCalRecordBytes> bytes{};
    wire::EncodeCalibrationRecord(calibration, bytes);
    c.crc32 = wire::StoredRecordCrc(bytes);
    c.created_unix_s = calibration.created_unix_s;
    f.calibration = c;
  }
  if (asked) f.acquisition = acquisition;
  // The channel columns follow t_s in channel order (MakeLogTable).
  std::size_t column = 1;
  for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
    if ((format.layout.channel_mask & (1u << c)) == 0) continue;
    const auto channel = static_cast<wire::Channel>(c);
    const wire::ChannelScaling s = has_record ? calibration.channels[c] : wire::DefaultScaling();
    ident::ChannelFacts ch;
    ch.name = table.names[column++];
    ch.unit_str = UnitString(s.unit);
    if (s.unit != wire::Unit::kCounts) {
      // value = (code - offset) x gain / 2^shift x full_scale / 2^31: counts per unit inverts it.
      ch.counts_per_unit = std::ldexp(1.0, 31 + s.gain_shift) /
                           (static_cast<double>(s.gain) * static_cast<double>(s.full_scale));
      ch.offset_counts = s.offset_counts;
      ch.full_scale = ShortestFloat32Decimal(s.full_scale);
    }
    ch.code_range = CodeRange(channel, adc_bits);
    ch.rails = ChannelRails(channel, s, adc_bits);
    if (board.instants) ch.sample_instant_us = board.instants->sample_instant_ns[c] / 1000.0;
    if (board.clips) ch.clipped_samples = board.clips->clipped[c];
    f.channels.push_back(ch);
  }
  return f;
}

}  // namespace vibid::device
