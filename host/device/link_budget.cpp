#include "vibid/device/link_budget.hpp"

#include <cmath>
#include <deque>
#include <limits>
#include <sstream>
#include <string>

#include "vibid/shared/fixed/decimator.hpp"

namespace vibid::device {

double LinkBudget::FittingLogRateHz() const {
  for (std::uint32_t d = 1; d <= fixed::kDecimatorMaxFactor; ++d) {
    if (fixed::IsSupportedDecimation(d) && sample_rate_hz / d <= link_records_per_s)
      return sample_rate_hz / d;
  }
  return 0.0;
}

StreamPrediction PredictStream(std::uint64_t records, std::uint32_t ticks_per_frame,
                               std::uint32_t capacity, std::uint32_t per_report) {
  std::deque<std::uint64_t> log;  // ticks of the records in the log
  bool armed = true;              // acq-start's answer, armed in frame 0
  bool built = false;
  StreamPrediction p;
  auto main_loop = [&] {
    if (!armed && built) {
      armed = true;
      built = false;
    }
    if (built || log.empty()) return;
    const std::uint64_t first = log.front();
    for (std::uint32_t n = 0; !log.empty() && n < per_report && log.front() == first + n; ++n)
      log.pop_front();
    built = true;
  };
  for (std::uint64_t tick = 0; tick < records;) {
    for (std::uint32_t k = 0; k < ticks_per_frame && tick < records; ++k, ++tick) {
      if (log.size() < capacity) {
        log.push_back(tick);
        ++p.kept;
      } else {
        ++p.dropped;
      }
    }
    main_loop();
    armed = false;  // the frame's IN transaction
    main_loop();
  }
  return p;
}

LinkBudget ComputeLinkBudget(const wire::InfoResponse& info,
                             const wire::AcqConfigureRequest& config) {
  LinkBudget b;
  const wire::LogLayout layout{config.channel_mask, config.flags};
  b.record_bytes = layout.RecordBytes();
  b.stored_record_bytes = layout.StoredRecordBytes();
  b.records_per_report = layout.RecordsPerReport();
  b.sample_rate_hz = 1e6 / config.sample_period_us;
  b.log_rate_hz = b.sample_rate_hz / std::max<std::uint16_t>(config.decimation, 1);
  b.data_bytes_per_s = b.log_rate_hz * static_cast<double>(b.record_bytes);
  b.link_bytes_per_s = static_cast<double>(info.link_reports_per_s) * wire::kReportBytes;
  b.link_records_per_s =
      static_cast<double>(info.link_reports_per_s) * static_cast<double>(b.records_per_report);
  b.log_bytes = info.log_capacity_bytes;
  b.capacity_records = static_cast<std::uint32_t>(info.log_capacity_bytes / b.stored_record_bytes);
  const double free_records = static_cast<double>(b.capacity_records) - config.pretrigger_records;
  b.overflow_after_s = b.KeepsUp() ? std::numeric_limits<double>::infinity()
                                   : free_records / (b.log_rate_hz - b.link_records_per_s);
  return b;
}

std::string DescribeOverflow(const LinkBudget& b, double seconds, AdviceWords words) {
  std::ostringstream o;
  o.setf(std::ios::fixed);
  o.precision(0);
  o << b.data_bytes_per_s << " B/s of log records (" << b.log_rate_hz << " records/s of "
    << b.record_bytes << " B) exceed the link's "
    << b.link_records_per_s * static_cast<double>(b.record_bytes) << " B/s ("
    << b.records_per_report << " records per 64-byte report, "
    << b.link_bytes_per_s / wire::kReportBytes << " reports/s); the " << b.log_bytes / 1024
    << " KiB log overflows after ";
  o.precision(1);
  o << b.overflow_after_s << " s of the " << seconds << " s";
  const double fitting = b.FittingLogRateHz();
  o.precision(0);
  if (words == AdviceWords::kBenchPage) {
    o << "; choose a log rate of " << fitting
      << " Hz or lower (auto takes the highest that fits), fewer channels, or ";
    o.precision(1);
    o << std::floor(b.overflow_after_s * 10.0) / 10.0 << " seconds or less";
    return o.str();
  }
  o << "; use --log-rate-hz " << fitting
    << " or lower, or fewer channels (or --allow-drops to accept the loss)";
  return o.str();
}

std::uint16_t DecimationThatFits(const wire::InfoResponse& info, wire::AcqConfigureRequest config,
                                 double seconds) {
  for (std::uint32_t d = 1; d <= fixed::kDecimatorMaxFactor; ++d) {
    if (!fixed::IsSupportedDecimation(d)) continue;
    config.decimation = static_cast<std::uint16_t>(d);
    if (ComputeLinkBudget(info, config).overflow_after_s >= seconds)
      return static_cast<std::uint16_t>(d);
  }
  return 0;
}

namespace {

std::string Fixed(double v, int digits) {
  std::ostringstream o;
  o.setf(std::ios::fixed);
  o.precision(digits);
  o << v;
  return o.str();
}

// "every sample", "every 2nd sample", "every 10th sample".
std::string EverySample(double ratio) {
  const long n = std::lround(ratio);
  if (n <= 1) return "every sample";
  const long tens = n % 100;
  const char* suffix = (tens >= 11 && tens <= 13) ? "th"
                       : n % 10 == 1              ? "st"
                       : n % 10 == 2              ? "nd"
                       : n % 10 == 3              ? "rd"
                                                  : "th";
  return "every " + std::to_string(n) + suffix + " sample";
}

}  // namespace

std::vector<std::pair<std::string, std::string>> DescribeBudget(const LinkBudget& b,
                                                                double seconds) {
  std::vector<std::pair<std::string, std::string>> rows;
  rows.emplace_back("record", std::to_string(b.record_bytes) + " bytes, " +
                                  std::to_string(b.records_per_report) + " per 64-byte report");
  rows.emplace_back("logged", Fixed(b.log_rate_hz, 0) + " records/s (" +
                                  EverySample(b.sample_rate_hz / b.log_rate_hz) + " of " +
                                  Fixed(b.sample_rate_hz, 0) + " Hz)");
  rows.emplace_back("link carries", Fixed(b.link_records_per_s, 0) + " records/s (" +
                                        Fixed(b.link_bytes_per_s / wire::kReportBytes, 0) +
                                        " reports/s)");
  rows.emplace_back("log holds", std::to_string(b.capacity_records) + " records (" +
                                     std::to_string(b.log_bytes / 1024) +
                                     " KiB): " + Fixed(b.capacity_records / b.log_rate_hz, 2) +
                                     " s at the log rate");
  if (b.KeepsUp()) {
    rows.emplace_back("log fills", "never: the link keeps up");
  } else {
    rows.emplace_back("log fills", "after " + Fixed(b.overflow_after_s, 1) + " s (it gains " +
                                       Fixed(b.log_rate_hz - b.link_records_per_s, 0) +
                                       " records/s)");
  }
  const std::string length = Fixed(seconds, seconds < 10.0 ? 2 : 1) + " s";
  rows.emplace_back("this acquisition", b.overflow_after_s >= seconds
                                            ? length + ": fits, nothing dropped"
                                            : length + ": does not fit (records would be dropped)");
  return rows;
}

}  // namespace vibid::device
