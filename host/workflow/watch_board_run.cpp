#include "vibid/workflow/watch_board_run.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <exception>
#include <utility>

#include "vibid/common/option_text.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/device/error.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/device/watch_report.hpp"
#include "vibid/workflow/watch_columns.hpp"

namespace vibid::workflow {
namespace {

/// The index of `name` in `names`, or -1.
long IndexOf(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<long>(it - names.begin());
}

}  // namespace

Eigen::MatrixXd LoadWatchReference(const std::string& path, const std::vector<std::string>& columns,
                                   double fs_hz, OptionSpelling spelling) {
  RecordingOptions ro;
  ro.channels = columns;
  const Recording ref = LoadRecording(path, ro);
  Require(std::abs(ref.fs_hz / fs_hz - 1.0) < 1e-6,
          WatchOptionName("reference", spelling) + " " + path + ": sampled at " +
              OptionNumber(ref.fs_hz) + " Hz, the watched " + "responses at " +
              OptionNumber(fs_hz) + " Hz; record both at one rate");
  Eigen::MatrixXd y(static_cast<Eigen::Index>(ref.samples()),
                    static_cast<Eigen::Index>(columns.size()));
  for (std::size_t j = 0; j < columns.size(); ++j)
    y.col(static_cast<Eigen::Index>(j)) = ref.table.Column(columns[j]);
  return y;
}

WatchJournal::WatchJournal(const std::string& path, std::string option)
    : path_(path), option_(std::move(option)) {
  if (path.empty()) return;
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) {
    throw InputError(option_ + " " + path + ": cannot create the journal: " + std::strerror(errno) +
                     "; give a writable path");
  }
}

WatchJournal::WatchJournal(std::FILE* file, std::string path, std::string option)
    : path_(std::move(path)), option_(std::move(option)), file_(file) {}

WatchJournal::~WatchJournal() {
  if (file_ != nullptr) std::fclose(file_);
}

WatchJournal::WatchJournal(WatchJournal&& other) noexcept
    : path_(std::move(other.path_)),
      option_(std::move(other.option_)),
      file_(std::exchange(other.file_, nullptr)) {}

WatchJournal& WatchJournal::operator=(WatchJournal&& other) noexcept {
  if (this != &other) {
    if (file_ != nullptr) std::fclose(file_);
    path_ = std::move(other.path_);
    option_ = std::move(other.option_);
    file_ = std::exchange(other.file_, nullptr);
  }
  return *this;
}

void WatchJournal::Append(const std::string& line) {
  if (file_ == nullptr) return;
  if (std::fputs((line + "\n").c_str(), file_) < 0 || std::fflush(file_) != 0)
    throw InputError(option_ + " " + path_ +
                     ": cannot append to the journal: " + std::strerror(errno));
}

WatchBoardRun::WatchBoardRun(WatchBoardSettings settings) : s_(std::move(settings)) {
  device::AcquireSettings& a = s_.acquire;
  until_stopped_ = a.seconds == 0.0;
  if (a.channels.empty()) a.channels = {"acc1", "acc2"};
  const int decimation = device::DecimationFor(a.rate_hz, a.log_rate_hz, a.decimation);
  log_rate_hz_ = a.rate_hz / decimation;
  device::AcquireSettings planned = a;
  // Until stopped: as long as the board counts records (about 50 days at 1 kHz, capped at 30).
  if (until_stopped_) planned.seconds = std::min(30.0 * 86400.0, 4.0e9 / log_rate_hz_);
  device::Trigger trig;
  (void)device::PlanAcquisition(planned, trig);  // its refusals before the board is asked
  const auto name = [this](const char* key) { return WatchOptionName(key, s_.watch.spelling); };
  Require(s_.scenario_params.size() <= 4, name("scenario_params") + " takes at most 4 values");
  // The board takes a name of 1 to 16 characters and four binary32 values: refused here, not
  // after the journal is made and the board is taken.
  Require(s_.scenario.size() <= 16, name("scenario") + " '" + s_.scenario.substr(0, 16) +
                                        "...' has " + std::to_string(s_.scenario.size()) +
                                        " characters; the board takes at most 16");
  for (const float p : s_.scenario_params)
    Require(std::isfinite(p), name("scenario_params") +
                                  " holds a value a float cannot hold (beyond 3.4e38, or not a "
                                  "number)");
  Require(s_.scenario_params.empty() || !s_.scenario.empty(),
          name("scenario_params") + " needs a " + name("scenario"));
  // A response is a log column: a channel acquired, its unit after an underscore (acc1_m_s2,
  // x1_m), or the observer's d_hat. The board's calibration gives the unit; the stem and the
  // characters are known now.
  for (const std::string& r : s_.responses) {
    const bool chars = !r.empty() && std::all_of(r.begin(), r.end(), [](char c) {
      return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
    });
    const bool acquired = r.rfind("d_hat_", 0) == 0 ||
                          std::any_of(a.channels.begin(), a.channels.end(),
                                      [&](const auto& ch) { return r.rfind(ch + "_", 0) == 0; });
    Require(chars && acquired, name("responses") + ": '" + r.substr(0, 40) +
                                   "' is not a column of the log (a channel acquired with its "
                                   "unit: acc1_m_s2, x1_m)");
  }
  if (!s_.reference.empty()) {
    std::FILE* f = std::fopen(s_.reference.c_str(), "rb");
    if (f == nullptr) {
      throw InputError(name("reference") + " '" + s_.reference +
                       "' cannot be read: " + std::strerror(errno));
    }
    std::fclose(f);
  }
  // The options checked against the channels asked for (the log's names, with their units,
  // come from the board's calibration; their count does not).
  options_ = s_.watch;
  options_.fs_hz = log_rate_hz_;
  int responses = static_cast<int>(s_.responses.size());
  if (responses == 0)
    for (const std::string& c : a.channels) responses += IsWatchResponse(c) ? 1 : 0;
  options_.channels = std::max(1, responses);
  options_.Validate();
  Require(until_stopped_ ||
              a.seconds > (s_.reference.empty() ? options_.reference_s : 0.0) + options_.block_s,
          name("seconds") + (s_.watch.spelling == OptionSpelling::kPython ? "=" : " ") +
              OptionNumber(a.seconds) + " ends before the first block after the reference (" +
              OptionNumber(options_.reference_s + options_.block_s) +
              " s); watch longer or shorten " + name("reference_s"));
}

WatchBoardResult WatchBoardRun::Run(device::Connection& c, WatchJournal& journal,
                                    const WatchBoardEvents& events,
                                    const std::function<bool()>& stop) {
  device::AcquireSettings settings = s_.acquire;
  if (until_stopped_) settings.seconds = std::min(30.0 * 86400.0, 4.0e9 / log_rate_hz_);
  device::Trigger trig;
  wire::AcqConfigureRequest cfg = device::PlanAcquisition(settings, trig);
  bool has_record = false;
  const wire::CalibrationRecord rec = device::ActiveRecord(c, has_record);
  const bool dob_running = c.GetStatus().dob_running != 0;
  device::ApplyCalibration(rec, has_record, dob_running, settings.no_dob, trig, cfg);
  (void)device::Preflight(c.info(), cfg, settings);
  cfg.flags = static_cast<std::uint8_t>(cfg.flags | wire::kAcqFlagStream);
  device::LogPull format;
  format.layout = wire::LogLayout{cfg.channel_mask, cfg.flags};
  format.trailer.sample_period_us = cfg.sample_period_us;
  format.trailer.decimation = cfg.decimation;
  format.trailer.channel_mask = cfg.channel_mask;
  format.trailer.acq_flags = cfg.flags;
  device::LogPull empty = format;
  const std::vector<std::string> names = device::MakeLogTable(empty, rec, has_record).names;
  const WatchColumns columns =
      ChooseWatchColumns(names, s_.responses, "the log", s_.watch.spelling);
  const std::vector<std::string>& responses = columns.responses;
  std::vector<std::size_t> index;
  for (const std::string& n : responses)
    index.push_back(static_cast<std::size_t>(IndexOf(names, n)));
  // The board's model test logged with the data: its statistic and flag at every record.
  const bool board_columns = columns.board_statistic.has_value();
  const long g_column = board_columns ? IndexOf(names, *columns.board_statistic) : -1;
  const long flag_column = board_columns ? IndexOf(names, *columns.board_flag) : -1;
  WatchOptions o = options_;
  o.channels = static_cast<int>(responses.size());
  WatchSession session(o);
  if (!s_.reference.empty())
    session.SetReference(LoadWatchReference(s_.reference, responses, o.fs_hz, s_.watch.spelling));
  WatchBoardResult result;
  result.log_rate_hz = log_rate_hz_;
  result.model_before = nullptr;
  result.model_stale = nullptr;
  WatchBoardStart start{responses, log_rate_hz_, board_columns, nullptr, ""};
  if (dob_running) {
    const std::optional<wire::WatchInfoResponse> watch = c.GetWatchInfo();
    start.model_stale = device::WatchJson(watch, cfg.sample_period_us);
    start.model_text = device::WatchText(watch, cfg.sample_period_us, /*observer_on=*/true);
  }
  result.model_before = start.model_stale;
  if (board_columns && start.model_stale.is_object() &&
      start.model_stale.value("threshold", nlohmann::json()).is_number())
    session.SetBoardThreshold(start.model_stale["threshold"].get<double>());
  if (events.starting) events.starting(start);
  if (!s_.scenario.empty()) c.SelectScenario(s_.scenario, s_.scenario_params);
  c.Configure(cfg);

  bool reference_said = false;
  const auto emit = [&](const std::vector<WatchBlock>& blocks) {
    if (session.has_reference() && !reference_said) {
      reference_said = true;
      if (events.reference) events.reference(session);
      nlohmann::json header = WatchHeaderJson(session);
      header["model_stale"] = result.model_before;
      if (!s_.reference.empty()) header["reference"]["file"] = s_.reference;
      const std::string line = header.dump();
      journal.Append(line);
      if (events.header) events.header(line);
    }
    for (const WatchBlock& b : blocks) {
      nlohmann::json j = WatchBlockJson(b);
      if (!result.model_before.is_null()) j["model_stale"] = result.model_before;
      const std::string line = j.dump();
      journal.Append(line);
      ++result.blocks;
      if (events.block) events.block(b, line);
    }
  };
  emit({});

  std::uint32_t next = 0;  // the next log index expected
  std::exception_ptr failed;
  const auto live = [&](std::uint32_t first, std::span<const wire::LogRecord> records) {
    if (failed) return;
    try {
      // A resumed stream may hand over again what came before: from `next` on only.
      const std::size_t skip = first < next ? next - first : 0;
      if (skip >= records.size()) return;
      if (first > next) session.Gap(static_cast<long>(first - next));
      device::LogPull block = format;
      block.records.assign(records.begin() + static_cast<std::ptrdiff_t>(skip), records.end());
      const device::LogTable table = device::MakeLogTable(block, rec, has_record);
      const auto rows = static_cast<Eigen::Index>(block.records.size());
      Eigen::MatrixXd y(rows, static_cast<Eigen::Index>(index.size()));
      for (std::size_t j = 0; j < index.size(); ++j)
        y.col(static_cast<Eigen::Index>(j)) = table.columns[index[j]];
      next = first + static_cast<std::uint32_t>(records.size());
      const double t_s = table.columns[0][0];
      if (board_columns) {
        Eigen::MatrixXd board(rows, 2);
        board.col(0) = table.columns[static_cast<std::size_t>(g_column)];
        board.col(1) = table.columns[static_cast<std::size_t>(flag_column)];
        emit(session.Feed(y, board, t_s));
      } else {
        emit(session.Feed(y, t_s));
      }
      if (events.fed) events.fed(session, table.columns[0][rows - 1]);
    } catch (...) {
      failed = std::current_exception();
    }
  };
  try {
    (void)c.AcquireStreamed(
        {},
        [&](const wire::LogTrailer*) {
          if (failed != nullptr) return true;
          if (!result.stopped && stop && stop()) result.stopped = true;
          return result.stopped;
        },
        live);
  } catch (const device::IncompleteLog& e) {
    result.warning = e.what();
  } catch (...) {
    try {
      c.StopAcquisition();
    } catch (const device::DeviceError&) {
    }
    throw;
  }
  if (failed) std::rethrow_exception(failed);
  if (dob_running) {
    const std::optional<wire::WatchInfoResponse> watch = c.GetWatchInfo();
    result.model_stale = device::WatchJson(watch, cfg.sample_period_us);
    result.model_text = device::WatchText(watch, cfg.sample_period_us);
  }
  result.reference_built = session.has_reference();
  result.reference_left_s = session.reference_left_s();
  return result;
}

}  // namespace vibid::workflow
