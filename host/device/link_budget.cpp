#include "vibid/device/link_budget.hpp"

#include <cmath>
#include <deque>
#include <limits>
#include <sstream>

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

std::string DescribeOverflow(const LinkBudget& b, double seconds) {
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
  o << "; use --log-rate-hz " << fitting
    << " or lower, or fewer channels (or --allow-drops to accept the loss)";
  return o.str();
}

}  // namespace vibid::device
