#include "vibid/device/log_table.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>

#include "vibid/common/csv.hpp"
#include "vibid/common/q31_decimal.hpp"
#include "vibid/common/enum_names.hpp"
#include "vibid/device/log_facts.hpp"
#include "vibid/ident/recording_facts.hpp"
#include "vibid/shared/fixed/decimator.hpp"
#include "vibid/shared/fixed/filter_description.hpp"

namespace vibid::device {
namespace {

constexpr double kQ31 = 2147483648.0;

constexpr EnumNames<wire::Channel, wire::kChannelCount> kChannelStems{{
    {wire::Channel::kForce1, "force1"},
    {wire::Channel::kForce2, "force2"},
    {wire::Channel::kAccel1, "acc1"},
    {wire::Channel::kAccel2, "acc2"},
    {wire::Channel::kEncoder1, "x1"},
    {wire::Channel::kEncoder2, "x2"},
}};

constexpr EnumNames<wire::Unit, 5> kUnitSuffixes{{
    {wire::Unit::kNewton, "n"},
    {wire::Unit::kMeterPerSecond2, "m_s2"},
    {wire::Unit::kMeter, "m"},
    {wire::Unit::kMeterPerSecond, "m_s"},
    {wire::Unit::kCounts, "counts"},
}};

}  // namespace

const char* ChannelStem(wire::Channel channel) { return NameOf(kChannelStems, channel, "?"); }

const char* UnitSuffix(wire::Unit unit) { return NameOf(kUnitSuffixes, unit, "counts"); }

bool ChannelFromStem(const std::string& stem, wire::Channel& channel) {
  const std::optional<wire::Channel> found = FindByName(kChannelStems, stem);
  if (found) channel = *found;
  return found.has_value();
}

namespace {

/// The calibrated value (Q31 of full scale, as a double) of one logged value. A raw sample
/// (a whole converter code) goes through the board's own integer arithmetic, so the host
/// recovers the Q31 value the board's observer saw; a decimated value carries fraction bits and
/// goes through the same formula in double.
double Calibrated(std::int32_t logged, wire::Channel channel, const wire::ChannelScaling& s) {
  std::int32_t raw = logged;
  if (wire::LogValueBytes(channel) == 2) {
    constexpr std::int32_t kOne = 1 << wire::kLogAdcFractionBits;
    if (logged % kOne != 0) {
      const double code = static_cast<double>(logged) / kOne;
      const double v = (code - static_cast<double>(s.offset_counts)) * static_cast<double>(s.gain) /
                       std::ldexp(1.0, s.gain_shift);
      return std::clamp(v, -kQ31, kQ31 - 1.0);
    }
    raw = logged / kOne;
  }
  std::uint32_t clips = 0;
  return wire::ScaleChannel(raw, s, clips);
}

}  // namespace

LogTable MakeLogTable(const LogPull& pull, const wire::CalibrationRecord& calibration,
                      bool has_record) {
  LogTable t;
  const auto n = static_cast<Eigen::Index>(pull.records.size());
  // A decimated record stands for the signal its linear-phase filter delays by a fixed number
  // of ticks: its time is moved back by that delay, so events keep their time at any log rate.
  const auto delay_ticks =
      static_cast<std::int64_t>(fixed::DecimatorDelayTicks(pull.trailer.decimation));
  const auto period_us = static_cast<std::int64_t>(pull.trailer.sample_period_us);
  Eigen::VectorXd time(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    // Whole microseconds (exact below 2^53) over 10^6, one correctly rounded division: the
    // double nearest the exact decimal, which the CSV writes as that decimal (0.4002, never
    // 0.40019999999999994 as index x period in double gives).
    const std::int64_t us =
        (static_cast<std::int64_t>(pull.records[static_cast<std::size_t>(i)].sample_index) -
         delay_ticks) *
        period_us;
    time(i) = static_cast<double>(us) / 1e6;
  }
  t.names.push_back("t_s");
  t.columns.push_back(time);
  for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
    if ((pull.layout.channel_mask & (1u << c)) == 0) continue;
    const wire::ChannelScaling s = has_record ? calibration.channels[c] : wire::DefaultScaling();
    const double scale =
        s.unit == wire::Unit::kCounts ? 1.0 : static_cast<double>(s.full_scale) / kQ31;
    Eigen::VectorXd v(n);
    const double full_scale =
        s.unit == wire::Unit::kCounts ? 0.0 : static_cast<double>(s.full_scale);
    // A raw sample's value is q x full_scale / 2^31: held as its shortest decimal that keeps q
    // (0.0064, not 0.006400000003539024), the same in memory and in the file. The last value's
    // decimal is kept: a resting channel repeats it.
    double last_in = std::numeric_limits<double>::quiet_NaN();
    double last_out = 0.0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double x = Calibrated(pull.records[static_cast<std::size_t>(i)].raw[c],
                                  static_cast<wire::Channel>(c), s) *
                       scale;
      if (x != last_in) {
        last_in = x;
        last_out = ShortestQ31Decimal(x, full_scale);
      }
      v(i) = last_out;
    }
    t.names.push_back(std::string(ChannelStem(static_cast<wire::Channel>(c))) + "_" +
                      UnitSuffix(s.unit));
    t.columns.push_back(v);
  }
  if (pull.layout.HasDob()) {
    double out_fs = 0.0;
    if (has_record && (calibration.flags & wire::kCalFlagHasDob) != 0) {
      fixed::FilterDescription d;
      if (fixed::DecodeDescription(calibration.dob, d) == Status::kOk) {
        out_fs = static_cast<double>(fixed::FullScaleValue(d.output_full_scale_bits));
      }
    }
    Eigen::VectorXd q(n);
    for (Eigen::Index i = 0; i < n; ++i) q(i) = pull.records[static_cast<std::size_t>(i)].d_hat;
    t.names.push_back("d_hat_q31");
    t.columns.push_back(q);
    if (out_fs > 0.0) {
      t.names.push_back("d_hat_n");
      t.columns.push_back(q * (out_fs / kQ31));
    }
  }
  if (pull.layout.HasWatch()) {
    // The board's residual test: its CUSUM g (in spreads of the window mean, as `vibid info`
    // shows it) and the latched model-stale flag, as they stood at the row's time (the board
    // takes the decimator's delay into account: wire::kAcqFlagLogWatch).
    Eigen::VectorXd g(n);
    Eigen::VectorXd stale(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const std::uint32_t w = pull.records[static_cast<std::size_t>(i)].watch;
      g(i) = static_cast<double>(w & wire::kLogWatchStatisticMask) / 65536.0;
      stale(i) = (w & wire::kLogWatchStaleBit) != 0 ? 1.0 : 0.0;
    }
    t.names.push_back("model_g");
    t.columns.push_back(g);
    t.names.push_back("model_stale");
    t.columns.push_back(stale);
  }
  return t;
}

std::vector<std::pair<std::string, double>> SampleInstantsUs(
    const LogTable& table, const LogPull& pull, const wire::SamplingInfoResponse& instants) {
  // The table's channel columns follow t_s in channel order.
  std::vector<std::pair<std::string, double>> out;
  std::size_t column = 1;
  for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
    if ((pull.layout.channel_mask & (1u << c)) == 0) continue;
    // Whole nanoseconds over 1000: the double nearest the decimal (2.667), which the sidecar
    // writes back as that decimal.
    out.emplace_back(table.names[column], instants.sample_instant_ns[c] / 1000.0);
    ++column;
  }
  return out;
}

std::string FormatLogCsvHeader(const LogPull& format, const wire::CalibrationRecord& calibration,
                               bool has_record) {
  LogPull empty;
  empty.layout = format.layout;
  empty.trailer = format.trailer;
  return FormatCsvHeader(MakeLogTable(empty, calibration, has_record).names);
}

std::string FormatLogCsvRows(const LogPull& block, const wire::CalibrationRecord& calibration,
                             bool has_record) {
  return FormatCsvRows(MakeLogTable(block, calibration, has_record).columns);
}

std::string FormatLogCsv(const LogPull& pull, const wire::CalibrationRecord& calibration,
                         bool has_record) {
  return FormatLogCsvHeader(pull, calibration, has_record) +
         FormatLogCsvRows(pull, calibration, has_record);
}

void WriteLogSidecar(const std::string& csv_path, const LogPull& format,
                     const wire::CalibrationRecord& calibration, bool has_record,
                     const std::optional<wire::SamplingInfoResponse>& instants) {
  BoardContext board;
  board.instants = instants;
  ident::WriteRecordingFacts(csv_path, LogFacts(format, format.records.size(), calibration,
                                                has_record, board, std::nullopt, std::string()));
}

}  // namespace vibid::device
