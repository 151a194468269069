#include "vibid/common/q31_decimal.hpp"
#include "vibid/bench/bench_files.hpp"
#include "vibid/bench/bench_board.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>

#include <unistd.h>

#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/device/acquire_plan.hpp"
#include "vibid/device/board_report.hpp"
#include "vibid/device/error.hpp"
#include "vibid/device/link_budget.hpp"
#include "vibid/device/log_facts.hpp"
#include "vibid/dob/compare.hpp"
#include "vibid/dob/lowpass.hpp"

namespace vibid::bench {
namespace {

using Clock = std::chrono::steady_clock;

/// The page's interval between blocks: 25 blocks a second keep the scope fluid.
constexpr std::chrono::milliseconds kBlockInterval{40};
constexpr int kBlocksPerState = 10;
/// The observer view's running fit: the last 5 s, recomputed every half second of samples.
constexpr double kFitWindowS = 5.0;
constexpr double kFitEveryS = 0.5;

const char* UnitText(wire::Unit u) {
  switch (u) {
    case wire::Unit::kNewton: return "N";
    case wire::Unit::kMeterPerSecond2: return "m/s²";
    case wire::Unit::kMeter: return "m";
    case wire::Unit::kMeterPerSecond: return "m/s";
    default: return "counts";
  }
}

const char* CalStateText(wire::CalState s) {
  switch (s) {
    case wire::CalState::kCalibrated: return "calibrated";
    case wire::CalState::kUncalibrated: return "uncalibrated";
    default: return "other";
  }
}

/// Numbers with 7 significant digits: what a float of the board carries, a third of the bytes.
void AppendNumber(std::string& out, double v) {
  if (!std::isfinite(v)) {
    out += "null";
    return;
  }
  char b[32];
  std::snprintf(b, sizeof b, "%.7g", v);
  out += b;
}

nlohmann::json Finite(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

}  // namespace

BenchBoard::BenchBoard(device::Connection& connection, std::string out_dir, LiveHub& hub,
                       const std::atomic<bool>* interrupt)
    : c_(connection), out_dir_(PrepareDirectory(out_dir)), hub_(hub), interrupt_(interrupt) {
  state_ = {{"running", false}, {"records", 0}};
  ReadCalibration();
  PublishState();
}

BenchBoard::~BenchBoard() { Shutdown(); }

void BenchBoard::ReadCalibration() {
  has_calibration_ = false;
  info_ = c_.GetInfo();
  instants_ = c_.GetSamplingInfo();
  if (info_.cal_state != wire::CalState::kCalibrated) return;
  calibration_ = device::DecodeBoardRecord(c_.CalGet());
  has_calibration_ = true;
}

nlohmann::json BenchBoard::Describe() {
  // The board's own status when no acquisition runs: an acquisition that just ended still holds
  // the lock for the few statements after its last state event, which the page answers at once.
  std::unique_lock lock(board_mutex_, std::defer_lock);
  while (!lock.try_lock() && !running_) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const wire::InfoResponse& info = info_;
  nlohmann::json j;
  char fw[32];
  std::snprintf(fw, sizeof fw, "%u.%u.%u", info.fw_major, info.fw_minor, info.fw_patch);
  char build[16];
  std::snprintf(build, sizeof build, "%08x", info.build_id);
  j["identity"] = {
      {"device", c_.Describe()},
      {"firmware", fw},
      {"build_id", build},
      {"protocol", std::to_string(info.protocol_major) + "." + std::to_string(info.protocol_minor)},
      {"adc_bits", info.adc_bits},
      {"min_sample_period_us", info.min_sample_period_us},
      {"log_capacity_bytes", info.log_capacity_bytes},
      {"link_reports_per_s", info.link_reports_per_s},
      {"emulator", (info.capabilities & wire::kCapScenarioSelect) != 0}};
  nlohmann::json channels = nlohmann::json::array();
  for (std::size_t ch = 0; ch < wire::kChannelCount; ++ch) {
    const wire::ChannelScaling s =
        has_calibration_ ? calibration_.channels[ch] : wire::DefaultScaling();
    channels.push_back(
        {{"name", device::ChannelStem(static_cast<wire::Channel>(ch))},
         {"column", std::string(device::ChannelStem(static_cast<wire::Channel>(ch))) + "_" +
                        device::UnitSuffix(s.unit)},
         {"unit", UnitText(s.unit)},
         {"full_scale",
          s.unit == wire::Unit::kCounts ? nlohmann::json() : nlohmann::json(s.full_scale)}});
  }
  nlohmann::json cal = {
      {"state", CalStateText(info.cal_state)},
      {"slot", info.cal_slot},
      {"crc", info.cal_crc},
      {"has_observer", has_calibration_ && (calibration_.flags & wire::kCalFlagHasDob) != 0}};
  if (has_calibration_) {
    cal["label"] = std::string(calibration_.label.data(),
                               strnlen(calibration_.label.data(), calibration_.label.size()));
    cal["created_unix_s"] = calibration_.created_unix_s;
    cal["dof_count"] = calibration_.dof_count;
    nlohmann::json masses = nlohmann::json::array();
    for (std::size_t i = 0; i < calibration_.dof_count; ++i)
      masses.push_back(calibration_.mass_kg[i * wire::kMaxDof + i]);
    cal["masses_kg"] = masses;
  }
  j["calibration"] = cal;
  j["channels"] = channels;
  if (lock.owns_lock()) {
    const wire::StatusResponse st = c_.GetStatus();
    // Sampling only while armed or acquiring: a finished acquisition ("done") is stopped, as
    // `vibid monitor` says.
    j["status"] = {{"sampling", device::IsSampling(st.acq_state)},
                   {"text", device::DescribeAcquisitionState(st)},
                   {"observer_running", st.dob_running != 0},
                   {"records_written", st.records_written},
                   {"dropped_records", st.dropped_records},
                   {"overrun_count", st.overrun_count},
                   {"uptime_s", static_cast<double>(st.uptime_us) * 1e-6}};
  } else {
    j["status"] = nullptr;  // the acquisition owns the link: its state event says the rest
  }
  return j;
}

nlohmann::json BenchBoard::Budget(const nlohmann::json& body) {
  const AcquisitionAsk ask = ParseAcquisitionAsk(body);
  const wire::AcqConfigureRequest cfg = ConfigFor(ask, c_.info());
  const device::LinkBudget b = device::ComputeLinkBudget(c_.info(), cfg);
  nlohmann::json lines = nlohmann::json::array();
  for (const auto& [label, text] : device::DescribeBudget(b, ask.seconds))
    lines.push_back({label, text});
  nlohmann::json j = {{"lines", lines},
                      {"decimation", cfg.decimation},
                      {"auto_log_rate", ask.auto_log_rate},
                      {"record_bytes", b.record_bytes},
                      {"records_per_report", b.records_per_report},
                      {"sample_rate_hz", b.sample_rate_hz},
                      {"log_rate_hz", b.log_rate_hz},
                      {"data_bytes_per_s", b.data_bytes_per_s},
                      {"link_bytes_per_s", b.link_bytes_per_s},
                      {"link_records_per_s", b.link_records_per_s},
                      {"capacity_records", b.capacity_records},
                      {"keeps_up", b.KeepsUp()},
                      {"overflow_after_s", Finite(b.overflow_after_s)}};
  if (b.overflow_after_s < ask.seconds)
    j["refusal"] = device::DescribeOverflow(b, ask.seconds, device::AdviceWords::kBenchPage);
  return j;
}

nlohmann::json BenchBoard::Start(const nlohmann::json& body, const std::string& view) {
  const AcquisitionAsk ask = ParseAcquisitionAsk(body);
  const wire::AcqConfigureRequest cfg = ConfigFor(ask, c_.info());
  // The preflight `vibid acquire` makes: refuse before the board starts if the log would overflow.
  const device::LinkBudget budget = device::ComputeLinkBudget(c_.info(), cfg);
  Require(budget.overflow_after_s >= ask.seconds,
          device::DescribeOverflow(budget, ask.seconds, device::AdviceWords::kBenchPage));
  Require(ask.fit_lowpass_hz < 0.5 * budget.log_rate_hz,
          "'fit_lowpass_hz' must lie below half the log rate (" +
              std::to_string(0.5 * budget.log_rate_hz) + " Hz)");
  Require(ask.scenario.empty() || (c_.info().capabilities & wire::kCapScenarioSelect) != 0,
          "'scenario': this board is not the emulator (scenarios select its simulated rig)");
  std::unique_lock lock(board_mutex_, std::try_to_lock);
  if (!lock.owns_lock() || running_) throw Busy("an acquisition is running: stop it first");
  // Under the board's lock: a commit between acquisitions rereads the calibration.
  Require(!ask.log_dob || (has_calibration_ && (calibration_.flags & wire::kCalFlagHasDob) != 0),
          "'log_dob': the board holds no observer (upload and commit a calibration with one)");
  if (thread_.joinable()) thread_.join();
  // A name no file has (nor its recording): two acquisitions in one second get two files, and a
  // planted file or link is never written through.
  const NewFile journal = CreateNewFile(out_dir_, "bench-" + TimeStamp(), ".partial.csv", ".csv");
  std::FILE* journal_file = ::fdopen(journal.fd, "w");
  if (journal_file == nullptr) {
    ::close(journal.fd);
    ::unlink(journal.path.c_str());
    throw InputError("cannot write the journal " + journal.path);
  }
  running_ = true;
  stop_ = false;
  const std::string name = journal.stem;
  {
    std::lock_guard s(state_mutex_);
    state_ = {{"running", true},
              {"name", name},
              {"records", 0},
              {"ask", body},
              {"sample_period_us", cfg.sample_period_us},
              {"log_rate_hz", budget.log_rate_hz},
              {"journal", out_dir_ + "/" + name + ".partial.csv"}};
    if (!view.empty()) state_["view"] = view;
  }
  hub_.ResetHistory();
  PublishState();
  lock.unlock();
  thread_ =
      std::thread([this, ask, cfg, name, journal_file] { Run(ask, cfg, name, journal_file); });
  return State();
}

void BenchBoard::Run(AcquisitionAsk ask, wire::AcqConfigureRequest cfg, std::string name,
                     std::FILE* journal) {
  std::lock_guard lock(board_mutex_);
  ask_ = ask;
  cfg_ = cfg;
  pending_.clear();
  next_index_ = 0;
  live_records_ = 0;
  fit_estimate_.clear();
  fit_measured_.clear();
  fit_samples_since_ = 0;
  journal_path_ = out_dir_ + "/" + name + ".partial.csv";
  journal_header_ = false;
  journal_ = journal;
  std::string error;
  std::string warning;
  device::LogPull pull;
  bool have_pull = false;
  listener_failed_.assign(acquisition_listeners_.size(), false);
  listener_warning_.clear();
  NotifyListeners([&](AcquisitionListener& l) {
    if (l.started) l.started(ask, cfg);
  });
  // What the recording's sidecar states of how it was asked for, and when it started (UTC).
  ident::AcquisitionFacts asked;
  asked.seconds = ask.seconds;
  asked.scenario = ask.scenario;
  for (float p : ask.scenario_params) asked.scenario_params.push_back(ShortestFloat32Decimal(p));
  const std::string start_timestamp = ident::UtcTimestampNow();
  try {
    if (journal_ == nullptr) throw InputError("cannot write the journal " + journal_path_);
    if (!ask.scenario.empty()) c_.SelectScenario(ask.scenario, ask.scenario_params);
    c_.Configure(cfg);
    pull = c_.AcquireStreamed(
        {},
        [this](const wire::LogTrailer*) {
          return stop_.load() || (interrupt_ != nullptr && interrupt_->load());
        },
        [this](std::uint32_t first, std::span<const wire::LogRecord> r) { OnRecords(first, r); });
    have_pull = true;
  } catch (const device::IncompleteLog& e) {
    pull = e.pull();
    have_pull = true;
    warning = e.what();
  } catch (const std::exception& e) {
    error = e.what();
    try {
      c_.StopAcquisition();
    } catch (const std::exception&) {
    }
  }
  Flush();
  if (journal_ != nullptr) std::fclose(journal_);
  journal_ = nullptr;
  nlohmann::json done = {{"running", false}, {"name", name}, {"records", live_records_}};
  if (have_pull && !pull.records.empty()) {
    try {
      // Never over an existing file: name.csv, or name-2.csv if one appeared meanwhile.
      const std::string path = PublishNewFile(
          out_dir_, name, ".csv", device::FormatLogCsv(pull, calibration_, has_calibration_));
      ident::WriteRecordingFacts(
          path, device::LogFacts(pull, pull.records.size(), calibration_, has_calibration_,
                                 device::ContextOf(c_), asked, start_timestamp));
      std::filesystem::remove(journal_path_);
      done["file"] = path;
      done["records"] = pull.records.size();
      done["stopped"] = pull.stopped;
    } catch (const std::exception& e) {
      error = std::string("the recording could not be written (the journal ") + journal_path_ +
              " keeps the data): " + e.what();
      done["journal"] = journal_path_;
    }
  } else if (live_records_ > 0) {
    done["journal"] = journal_path_;  // the only copy: kept
  } else {
    std::filesystem::remove(journal_path_);
  }
  if (!listener_warning_.empty()) warning += (warning.empty() ? "" : "; ") + listener_warning_;
  if (!warning.empty()) done["warning"] = warning;
  if (!error.empty()) done["error"] = error;
  {
    std::lock_guard s(state_mutex_);
    done["ask"] = state_.value("ask", nlohmann::json());
    done["sample_period_us"] = cfg.sample_period_us;
    state_ = done;
  }
  NotifyListeners([&](AcquisitionListener& l) {
    if (l.ended) l.ended(done);
  });
  running_ = false;
  PublishState();
}

void BenchBoard::NotifyListeners(const std::function<void(AcquisitionListener&)>& call) {
  for (std::size_t i = 0; i < acquisition_listeners_.size(); ++i) {
    if (listener_failed_[i]) continue;
    try {
      call(acquisition_listeners_[i]);
    } catch (const std::exception& e) {
      listener_failed_[i] = true;
      listener_warning_ += (listener_warning_.empty() ? "" : "; ") + std::string(e.what());
    }
  }
}

void BenchBoard::OnRecords(std::uint32_t first, std::span<const wire::LogRecord> records) {
  // A resumed stream may hand over again what a broken one already did: from next_index_ on only.
  std::size_t skip = first < next_index_ ? next_index_ - first : 0;
  if (skip >= records.size()) return;
  const std::span<const wire::LogRecord> fresh = records.subspan(skip);
  pending_.insert(pending_.end(), fresh.begin(), fresh.end());
  NotifyListeners([&](AcquisitionListener& l) {
    if (l.records) l.records(fresh);
  });
  next_index_ = first + static_cast<std::uint32_t>(records.size());
  if (Clock::now() - last_flush_ >= kBlockInterval) {
    last_flush_ = Clock::now();
    Flush();
  }
}

double BenchBoard::LogPeriodS() const {
  return cfg_.sample_period_us * 1e-6 * std::max<std::uint16_t>(cfg_.decimation, 1);
}

void BenchBoard::Flush() {
  if (pending_.empty()) return;
  device::LogPull block;
  block.records.swap(pending_);
  block.layout = wire::LogLayout{cfg_.channel_mask, cfg_.flags};
  block.trailer.sample_period_us = cfg_.sample_period_us;
  block.trailer.decimation = cfg_.decimation;
  const device::LogTable table = device::MakeLogTable(block, calibration_, has_calibration_);
  // The journal first: what reaches the page is on disk already.
  if (journal_ != nullptr) {
    std::string csv = FormatCsv(table.names, table.columns);
    if (journal_header_) csv.erase(0, csv.find('\n') + 1);
    journal_header_ = true;
    std::fwrite(csv.data(), 1, csv.size(), journal_);
    std::fflush(journal_);
  }
  live_records_ += block.records.size();
  std::string j = "{\"first\":" + std::to_string(next_index_ - block.records.size()) + ",\"dt\":";
  AppendNumber(j, LogPeriodS());
  j += ",\"names\":[";
  for (std::size_t i = 0; i < table.names.size(); ++i)
    j += (i ? ",\"" : "\"") + table.names[i] + "\"";
  j += "],\"columns\":[";
  for (std::size_t i = 0; i < table.columns.size(); ++i) {
    j += i ? ",[" : "[";
    const Eigen::VectorXd& v = table.columns[i];
    for (Eigen::Index k = 0; k < v.size(); ++k) {
      if (k) j += ',';
      AppendNumber(j, v(k));
    }
    j += ']';
  }
  j += "]}";
  hub_.Publish("block", j, true);
  for (const BlockListener& l : listeners_) l(table);
  UpdateFit(table);
  {
    std::lock_guard s(state_mutex_);
    state_["records"] = live_records_;
  }
  // The records so far, a few times a second (a page that reloads gets the newest).
  if (++blocks_since_state_ >= kBlocksPerState) {
    blocks_since_state_ = 0;
    PublishState();
  }
}

void BenchBoard::UpdateFit(const device::LogTable& table) {
  if (ask_.fit_measured.empty()) return;
  const double fs_hz = 1.0 / LogPeriodS();
  const Eigen::VectorXd* est = nullptr;
  const Eigen::VectorXd* meas = nullptr;
  for (std::size_t i = 0; i < table.names.size(); ++i) {
    if (table.names[i] == "d_hat_n") est = &table.columns[i];
    if (table.names[i].rfind(ask_.fit_measured + "_", 0) == 0) meas = &table.columns[i];
  }
  if (est == nullptr || meas == nullptr) return;
  fit_estimate_.insert(fit_estimate_.end(), est->data(), est->data() + est->size());
  fit_measured_.insert(fit_measured_.end(), meas->data(), meas->data() + meas->size());
  const auto window = static_cast<std::size_t>(kFitWindowS * fs_hz);
  if (fit_estimate_.size() > window) {
    const auto drop = static_cast<std::ptrdiff_t>(fit_estimate_.size() - window);
    fit_estimate_.erase(fit_estimate_.begin(), fit_estimate_.begin() + drop);
    fit_measured_.erase(fit_measured_.begin(), fit_measured_.begin() + drop);
  }
  fit_samples_since_ += static_cast<std::uint64_t>(est->size());
  if (static_cast<double>(fit_samples_since_) < kFitEveryS * fs_hz || fit_estimate_.size() < 2)
    return;
  fit_samples_since_ = 0;
  const Eigen::Map<const Eigen::VectorXd> e(fit_estimate_.data(),
                                            static_cast<Eigen::Index>(fit_estimate_.size()));
  const Eigen::Map<const Eigen::VectorXd> m(fit_measured_.data(),
                                            static_cast<Eigen::Index>(fit_measured_.size()));
  nlohmann::json j = {{"window_s", static_cast<double>(fit_estimate_.size()) / fs_hz},
                      {"measured", ask_.fit_measured}};
  if (ask_.fit_lowpass_hz > 0.0) j["lowpass_hz"] = ask_.fit_lowpass_hz;
  try {
    const dob::Agreement g =
        ask_.fit_lowpass_hz > 0.0
            ? dob::CompareSignals(
                  dob::FiltFilt(dob::ButterworthLowpass(4, ask_.fit_lowpass_hz, fs_hz), e), m,
                  fs_hz)
            : dob::CompareSignals(e, m, fs_hz);
    j["fit_percent"] = Finite(g.fit_percent);
    j["correlation"] = Finite(g.correlation);
    j["delay_s"] = Finite(g.delay_s);
    j["rmse_n"] = Finite(g.rmse_n);
  } catch (const std::exception& ex) {
    j["refusal"] = ex.what();  // e.g. a constant measured force: no fit to state
  }
  hub_.Publish("fit", j.dump());
}

nlohmann::json BenchBoard::Stop(const std::string& view) {
  if (!view.empty()) {
    // A view's Stop ends that view's run only: the board's other work is not its to end.
    std::lock_guard s(state_mutex_);
    if (!running_ || !state_.value("running", false)) return state_;
    const std::string runs = state_.value("view", std::string());
    if (runs != view) {
      throw Busy("no " + view + " runs: the board runs " +
                 (runs.empty() ? std::string("an acquisition") : "a " + runs) +
                 " (stop it from its own view, or with the page's Stop)");
    }
  }
  stop_ = true;
  return State();
}

nlohmann::json BenchBoard::SetObserver(const nlohmann::json& body) {
  Require(body.is_object(), "the request must be a JSON object");
  RequireKnownKeys(body, {"run"}, "the observer request");
  Require(body.contains("run") && body["run"].is_boolean(), "'run' must be true or false");
  const bool run = body["run"].get<bool>();
  Require(!run || (has_calibration_ && (calibration_.flags & wire::kCalFlagHasDob) != 0),
          "the board holds no observer (upload and commit a calibration with one)");
  WithIdleBoard([&](device::Connection& c) { c.DobControl(run); });
  return {{"observer_running", run}};
}

void BenchBoard::WithIdleBoard(const std::function<void(device::Connection&)>& body) {
  std::unique_lock lock(board_mutex_, std::try_to_lock);
  if (!lock.owns_lock() || running_) throw Busy("an acquisition is running: stop it first");
  body(c_);
}

void BenchBoard::StartTask(nlohmann::json state, TaskBody body) {
  std::unique_lock lock(board_mutex_, std::try_to_lock);
  if (!lock.owns_lock() || running_) throw Busy("an acquisition is running: stop it first");
  if (thread_.joinable()) thread_.join();
  running_ = true;
  stop_ = false;
  state["running"] = true;
  {
    std::lock_guard s(state_mutex_);
    state_ = state;
  }
  PublishState();
  lock.unlock();
  thread_ = std::thread([this, state, body = std::move(body)] {
    std::lock_guard board(board_mutex_);
    nlohmann::json done;
    try {
      done = body(c_,
                  [this] { return stop_.load() || (interrupt_ != nullptr && interrupt_->load()); });
    } catch (const std::exception& e) {
      done = {{"error", e.what()}};
      try {
        c_.StopAcquisition();
      } catch (const std::exception&) {
      }
    }
    for (const auto& [k, v] : state.items())
      if (!done.contains(k)) done[k] = v;
    done["running"] = false;
    {
      std::lock_guard s(state_mutex_);
      state_ = done;
    }
    running_ = false;
    PublishState();
  });
}

void BenchBoard::ReadCalibrationAgain() {
  WithIdleBoard([this](device::Connection&) { ReadCalibration(); });
}

const wire::CalibrationRecord* BenchBoard::ActiveCalibration() const {
  return has_calibration_ ? &calibration_ : nullptr;
}

nlohmann::json BenchBoard::State() const {
  std::lock_guard s(state_mutex_);
  return state_;
}

void BenchBoard::PublishState() { hub_.Publish("state", State().dump()); }

void BenchBoard::Shutdown() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void BenchBoard::AddBlockListener(BlockListener listener) {
  listeners_.push_back(std::move(listener));
}

void BenchBoard::AddAcquisitionListener(AcquisitionListener listener) {
  acquisition_listeners_.push_back(std::move(listener));
}

}  // namespace vibid::bench
