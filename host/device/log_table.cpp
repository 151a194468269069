#include "vibid/device/log_table.hpp"

#include <cstring>

#include "vibid/common/csv.hpp"
#include "vibid/shared/fixed/filter_description.hpp"

namespace vibid::device {
namespace {

constexpr double kQ31 = 2147483648.0;

}  // namespace

const char* ChannelStem(wire::Channel channel) {
  switch (channel) {
    case wire::Channel::kForce1: return "force1";
    case wire::Channel::kForce2: return "force2";
    case wire::Channel::kAccel1: return "acc1";
    case wire::Channel::kAccel2: return "acc2";
    case wire::Channel::kEncoder1: return "x1";
    case wire::Channel::kEncoder2: return "x2";
  }
  return "?";
}

const char* UnitSuffix(wire::Unit unit) {
  switch (unit) {
    case wire::Unit::kNewton: return "n";
    case wire::Unit::kMeterPerSecond2: return "m_s2";
    case wire::Unit::kMeter: return "m";
    case wire::Unit::kMeterPerSecond: return "m_s";
    case wire::Unit::kCounts: return "counts";
  }
  return "counts";
}

bool ChannelFromStem(const std::string& stem, wire::Channel& channel) {
  for (std::size_t i = 0; i < wire::kChannelCount; ++i) {
    if (stem == ChannelStem(static_cast<wire::Channel>(i))) {
      channel = static_cast<wire::Channel>(i);
      return true;
    }
  }
  return false;
}

LogTable MakeLogTable(const LogPull& pull, const wire::CalibrationRecord& calibration, bool has_record) {
  LogTable t;
  const auto n = static_cast<Eigen::Index>(pull.records.size());
  const double period_s = pull.trailer.sample_period_us * 1e-6;
  Eigen::VectorXd time(n);
  for (Eigen::Index i = 0; i < n; ++i) time(i) = pull.records[static_cast<std::size_t>(i)].sample_index * period_s;
  t.names.push_back("t_s");
  t.columns.push_back(time);
  for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
    if ((pull.layout.channel_mask & (1u << c)) == 0) continue;
    const wire::ChannelScaling s = has_record ? calibration.channels[c] : wire::DefaultScaling();
    const double scale = s.unit == wire::Unit::kCounts ? 1.0 : static_cast<double>(s.full_scale) / kQ31;
    Eigen::VectorXd v(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      std::uint32_t clips = 0;
      v(i) = wire::ScaleChannel(pull.records[static_cast<std::size_t>(i)].raw[c], s, clips) * scale;
    }
    t.names.push_back(std::string(ChannelStem(static_cast<wire::Channel>(c))) + "_" + UnitSuffix(s.unit));
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
  return t;
}

std::string FormatLogCsv(const LogPull& pull, const wire::CalibrationRecord& calibration, bool has_record) {
  const LogTable t = MakeLogTable(pull, calibration, has_record);
  return FormatCsv(t.names, t.columns);
}

}  // namespace vibid::device
