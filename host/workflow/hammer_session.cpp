#include "vibid/workflow/hammer_session.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <utility>

#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/device/log_facts.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/ident/frf_io.hpp"
#include "vibid/ident/ringdown.hpp"
#include "vibid/ident/sample_instants.hpp"
#include "vibid/workflow/result_json.hpp"

namespace vibid::workflow {

namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// The columns a recording of this acquisition has, as MakeLogTable names them.
std::vector<std::string> ColumnNames(const device::LogPull& format,
                                     const wire::CalibrationRecord& calibration, bool has_record) {
  device::LogPull empty;
  empty.layout = format.layout;
  empty.trailer = format.trailer;
  return device::MakeLogTable(empty, calibration, has_record).names;
}

std::size_t ColumnIndex(const std::vector<std::string>& names, const std::string& name,
                        const std::string& option) {
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return i;
  }
  std::string known;
  for (std::size_t i = 1; i < names.size(); ++i) known += (i > 1 ? ", " : "") + names[i];
  throw InputError(option + ": the recording has no column '" + name + "' (its channels: " + known +
                   "); name one of them");
}

ident::ImpactOptions ImpactOptionsOf(const EstimationOptions& o) {
  ident::ImpactOptions io = o.impact_options;
  io.reject_bad_hits = !o.keep_bad_hits;  // as Estimate does
  return io;
}

// The verdict the page shows: the first check that failed.
std::string VerdictOf(const ident::Hit& h) {
  if (h.truncated) return "truncated";
  if (h.clipped) return "clipped";
  if (h.double_hit) return "double hit";
  if (h.weak) return "too weak";
  return "ok";
}

}  // namespace

void HammerSessionOptions::Validate() const {
  Require(layout.Valid(), "hammer session: the acquisition's channel mask or flags are not valid");
  Require(sample_period_us > 0, "hammer session: sample_period_us must be > 0 (the board's tick)");
  Require(decimation >= 1, "hammer session: decimation must be >= 1");
  Require(!estimation.force.empty(), "hammer session: --force (the hammer's column) is required");
  Require(!estimation.responses.empty(),
          "hammer session: --response (the response columns) is required");
  Require(!estimation.welch, "hammer session: a hammer test is processed per hit; drop --welch");
  Require(estimation.use_hits.empty() && estimation.hits_file.empty(),
          "hammer session: the session chooses the hits (verdicts, Accept, Reject); drop "
          "--use-hits/--hits");
  Require(estimation.impact_options.use_hits.empty(),
          "hammer session: the session chooses the hits; leave impact_options.use_hits empty");
  Require(std::isfinite(estimation.impact_options.record_s) &&
              estimation.impact_options.record_s >= 0.0,
          "hammer session: --record-s (the record of one hit, s) must be >= 0 (0: the shortest "
          "spacing between hits)");
  Require(estimation.impact_options.record_s == 0.0 ||
              estimation.impact_options.pretrigger_s < 0.5 * estimation.impact_options.record_s,
          "hammer session: --pretrigger-s must be shorter than half of --record-s");
  estimation.Validate();
  (void)ResponseQuantities(ParseColumnList(estimation.responses), estimation.sensor);
  (void)ident::ParseModeMethod(modes.method);
  if (!modes.orders.empty()) {
    ident::StabilizationOptions s;
    ident::ParseOrders(modes.orders, s);
  }
  Require(!live_csv_path.empty(),
          "hammer session: live_csv_path (where the recording grows) is required");
}

// The recording's channels as the estimation reads them, with room to grow: the force and each
// response scaled by its column spec, as EstimateFromRecording scales a file's columns.
struct HammerSession::Channels {
  Eigen::VectorXd force;
  Eigen::MatrixXd responses;
  std::size_t n = 0;
  double t_first_s = 0.0;
  double t_last_s = 0.0;

  void Reserve(std::size_t rows) {
    if (rows <= static_cast<std::size_t>(force.size())) return;
    const auto cap = static_cast<Eigen::Index>(
        std::max<std::size_t>(rows, 2 * static_cast<std::size_t>(force.size())));
    force.conservativeResize(cap);
    responses.conservativeResize(cap, Eigen::NoChange);
  }
  auto Force() const { return force.head(static_cast<Eigen::Index>(n)); }
  auto Responses() const { return responses.topRows(static_cast<Eigen::Index>(n)); }
  // As MakeRecording derives it from the time column: 1 / mean step.
  double FsHz() const { return 1.0 / ((t_last_s - t_first_s) / static_cast<double>(n - 1)); }
};

HammerSession::HammerSession(HammerSessionOptions options) : options_(std::move(options)) {
  options_.estimation.impact = true;
  options_.Validate();
  format_.layout = options_.layout;
  format_.trailer.sample_period_us = options_.sample_period_us;
  format_.trailer.decimation = options_.decimation;
  format_.trailer.channel_mask = options_.layout.channel_mask;
  format_.trailer.acq_flags = options_.layout.flags;
  columns_ = ColumnNames(format_, options_.calibration, options_.has_calibration);
  const ColumnSpec fspec = ParseColumnSpec(options_.estimation.force);
  force_column_ = ColumnIndex(columns_, fspec.name, "--force");
  force_scale_ = fspec.scale;
  force_name_ = fspec.name;
  const std::vector<ColumnSpec> rspecs = ParseColumnList(options_.estimation.responses);
  for (const ColumnSpec& spec : rspecs) {
    response_columns_.push_back(ColumnIndex(columns_, spec.name, "--response"));
    response_scales_.push_back(spec.scale);
    response_names_.push_back(spec.name);
  }
  // The converters' rails from the board's calibration, as the recording's sidecar states them:
  // a hit is clipped where a sample sits on one.
  if (options_.estimation.impact_options.converter_limits.empty()) {
    const ident::RecordingFacts facts = device::LogFacts(
        format_, 0, options_.calibration, options_.has_calibration, {}, {}, std::string());
    auto& limits = options_.estimation.impact_options.converter_limits;
    limits.push_back(ConverterLimitsOf(fspec, &facts));
    for (const ColumnSpec& spec : rspecs) limits.push_back(ConverterLimitsOf(spec, &facts));
  }
  {
    ident::Frf names_only;
    names_only.h.resize(0, static_cast<Eigen::Index>(response_names_.size()));
    names_only.response_names = response_names_;
    if (!options_.modes.driving_point.empty())
      (void)ResolveDrivingPoint(names_only, options_.modes.driving_point);
  }
  header_ = device::FormatLogCsvHeader(format_, options_.calibration, options_.has_calibration);
  // The instants as a reader of the file gets them (whole nanoseconds, us x 1e-6).
  if (options_.instants) {
    device::LogPull empty;
    empty.layout = format_.layout;
    empty.trailer = format_.trailer;
    const ident::SampleInstants instants{device::SampleInstantsUs(
        device::MakeLogTable(empty, options_.calibration, options_.has_calibration), empty,
        *options_.instants)};
    instants_s_.push_back(*instants.Of(force_name_));
    for (const std::string& name : response_names_) instants_s_.push_back(*instants.Of(name));
  }
  data_ = std::make_unique<Channels>();
  data_->responses.resize(0, static_cast<Eigen::Index>(response_names_.size()));
  live_ = std::fopen(options_.live_csv_path.c_str(), "wb");
  if (live_ == nullptr) {
    throw InputError("hammer session: cannot create '" + options_.live_csv_path +
                     "': " + std::strerror(errno) + "; give a writable path");
  }
  if (std::fwrite(header_.data(), 1, header_.size(), live_) != header_.size() ||
      std::fflush(live_) != 0) {
    std::fclose(live_);
    live_ = nullptr;
    throw InputError("hammer session: cannot write '" + options_.live_csv_path + "'");
  }
  // The recording's sidecar states the instants; the live file gets its own at once (after the
  // file itself, whose refusal says what to do), so that it reads as the saved one does.
  try {
    device::WriteLogSidecar(options_.live_csv_path, format_, options_.calibration,
                            options_.has_calibration, options_.instants);
  } catch (...) {
    std::fclose(live_);
    live_ = nullptr;
    throw;
  }
  Publish(0.0);
}

HammerSession::~HammerSession() {
  if (live_ != nullptr) std::fclose(live_);
}

void HammerSession::Feed(std::span<const wire::LogRecord> records) {
  if (records.empty()) return;
  const std::lock_guard<std::mutex> lock(work_);
  Require(!finished_, "hammer session: the acquisition was finished; start a new session");
  const std::uint32_t step = options_.decimation;
  for (std::size_t i = 0; i < records.size(); ++i) {
    const std::uint32_t expected =
        started_ ? next_sample_index_ + static_cast<std::uint32_t>(i) * step : 0;
    Require(!started_ || records[i].sample_index == expected,
            "hammer session: record of sample " + std::to_string(records[i].sample_index) +
                " where sample " + std::to_string(expected) +
                " was due; records must come in order, none missing");
  }
  device::LogPull block = format_;
  block.records.assign(records.begin(), records.end());
  const device::LogTable table =
      device::MakeLogTable(block, options_.calibration, options_.has_calibration);
  const std::string rows = FormatCsvRows(table.columns);
  if (std::fwrite(rows.data(), 1, rows.size(), live_) != rows.size() || std::fflush(live_) != 0) {
    throw InputError("hammer session: cannot append to '" + options_.live_csv_path +
                     "': " + std::strerror(errno));
  }
  rows_ += rows;
  Channels& d = *data_;
  const std::size_t n0 = d.n;
  const std::size_t add = records.size();
  d.Reserve(n0 + add);
  const auto rows_add = static_cast<Eigen::Index>(add);
  const auto at = static_cast<Eigen::Index>(n0);
  d.force.segment(at, rows_add) = table.columns[force_column_] * force_scale_;
  for (std::size_t j = 0; j < response_columns_.size(); ++j) {
    d.responses.col(static_cast<Eigen::Index>(j)).segment(at, rows_add) =
        table.columns[response_columns_[j]] * response_scales_[j];
  }
  if (!started_) d.t_first_s = table.columns[0][0];
  d.t_last_s = table.columns[0][rows_add - 1];
  d.n += add;
  started_ = true;
  next_sample_index_ = records.back().sample_index + step;

  // A new pulse: its record is complete a record length after it starts. With the automatic
  // record (the shortest spacing), the new pulse completes the record of the hit before it: it is
  // looked at once its rebounds (the double-hit window) are in.
  const double fs_nominal = 1e6 / (static_cast<double>(options_.sample_period_us) * step);
  const auto record = static_cast<std::size_t>(
      std::llround(options_.estimation.impact_options.record_s * fs_nominal));
  const auto settle =
      static_cast<std::size_t>(
          std::ceil(2.0 * options_.estimation.impact_options.double_hit_window_s * fs_nominal)) +
      1;
  if (detected_once_) {
    const double level = 0.5 * detection_.trigger_level;
    for (std::size_t i = scanned_; i < d.n; ++i) {
      if (std::abs(d.force[static_cast<Eigen::Index>(i)] - detection_.baseline) >= level) {
        // Complete a record after the pretrigger's start (exactly: the analysis says when).
        const std::size_t pre = std::min(detection_.pretrigger_samples, i);
        next_check_ = std::min(next_check_, record > 0 ? i - pre + record : i + settle);
        candidate_ = true;
        break;
      }
    }
  } else if (next_check_ == 0) {
    next_check_ = static_cast<std::size_t>(fs_nominal / 4.0);
  }
  scanned_ = d.n;
  if (d.n >= next_check_) {
    const Clock::time_point start = Clock::now();
    Analyze();
    if (!detected_once_) next_check_ = d.n + static_cast<std::size_t>(fs_nominal / 4.0);
    Publish(MsSince(start));
    Keep();
  } else {
    Publish(-1.0);
  }
}

void HammerSession::Finish() {
  const std::lock_guard<std::mutex> lock(work_);
  if (finished_) return;
  finished_ = true;
  const Clock::time_point start = Clock::now();
  Analyze();
  Publish(MsSince(start));
  Keep();
}

// Judges the hits of the recording so far exactly as EstimateImpactFrf would on it, then averages
// the accepted ones' spectra (kept from earlier analyses while their inputs are the same bits).
void HammerSession::Analyze() {
  Channels& d = *data_;
  if (d.n < 16) return;
  const double fs_hz = d.FsHz();
  const auto force = d.Force();
  const auto responses = d.Responses();
  const ident::ImpactOptions io = ImpactOptionsOf(options_.estimation);
  if (!detected_once_ && !ident::ClassifyExcitation(force, fs_hz).impact) return;
  ident::ImpactDetection det;
  try {
    det = ident::DetectImpactHits(force, responses, fs_hz, io);
  } catch (const InputError& e) {
    // No hit yet (a constant force): said, and the next block may bring one.
    warnings_ = {e.what()};
    return;
  }
  detected_once_ = true;
  candidate_ = false;
  next_check_ = std::numeric_limits<std::size_t>::max();
  // Hits whose record runs past the samples so far are not judged until it is complete. With
  // the automatic record the last hit waits for the next one (or the end): the spacing to it may
  // still shorten every record.
  judged_ = det.hits.size();
  if (!finished_) {
    for (std::size_t g = 0; g < det.hits.size(); ++g) {
      const std::size_t end = det.spans[g].start + det.record_samples;
      if (end > d.n) {
        judged_ = std::min(judged_, g);
        next_check_ = std::min(next_check_, end);
      }
    }
    if (io.record_s == 0.0 && !det.hits.empty()) judged_ = std::min(judged_, det.hits.size() - 1);
  }
  // The choice: the operator's where given, else the verdict; unjudged hits are not used.
  for (std::size_t g = 0; g < det.hits.size(); ++g) {
    ident::Hit& h = det.hits[g];
    const auto choice = operator_choice_.find(h.peak_index);
    if (g >= judged_) {
      h.used = false;
    } else if (choice != operator_choice_.end()) {
      h.used = choice->second && !h.truncated;
    }
  }
  // Kept spectra stay valid while the record layout and the exponential window are the same bits
  // and the hit's span (and the baseline, where the offset falls back on it) is.
  if (det.record_samples != spectra_record_ || last_exp_window_.size() != det.exp_window.size() ||
      !last_exp_window_.cwiseEqual(det.exp_window).all() || det.pretrigger_samples != last_pre_) {
    spectra_.clear();
    spectra_record_ = det.record_samples;
    last_exp_window_ = det.exp_window;
    last_pre_ = det.pretrigger_samples;
  }
  std::vector<const ident::HitSpectra*> used(det.hits.size(), nullptr);
  std::unique_ptr<ident::RealFft> fft;
  for (std::size_t g = 0; g < det.hits.size(); ++g) {
    if (!det.hits[g].used) continue;
    const ident::HitSpan& span = det.spans[g];
    const std::size_t quiet =
        det.pretrigger_samples > span.taper ? det.pretrigger_samples - span.taper : 0;
    const double baseline = quiet >= 4 ? 0.0 : det.baseline;
    auto it = spectra_.find(span.start);
    if (it == spectra_.end() || it->second.span.keep != span.keep ||
        it->second.span.taper != span.taper || it->second.baseline != baseline) {
      if (!fft) fft = std::make_unique<ident::RealFft>(det.record_samples);
      KeptSpectra kept{span, baseline, ident::ImpactHitSpectra(force, responses, det, g, *fft)};
      it = spectra_.insert_or_assign(span.start, std::move(kept)).first;
    }
    used[g] = &it->second.spectra;
  }
  const ident::Estimator est = ident::ParseEstimator(options_.estimation.estimator);
  // Accelerometers and encoders may share the test: each column as its unit says.
  const std::vector<ident::Quantity> measured = ResponseQuantities(
      ParseColumnList(options_.estimation.responses), options_.estimation.sensor);
  warnings_ = det.warnings;
  detection_ = std::move(det);
  bool any_used = false;
  for (const ident::Hit& h : detection_.hits) any_used = any_used || h.used;
  if (!any_used) {
    frf_ = {};
    receptance_ = {};
    modes_.reset();
    modes_error_ = "no hit accepted yet";
    return;
  }
  ident::ImpactDetection choice = detection_;
  choice.warnings.clear();  // the hit choice is explicit, as `--hits` makes it
  ident::ImpactResult r =
      ident::AverageHitSpectra(choice, used, fs_hz, io, est, CommonQuantity(measured));
  warnings_.insert(warnings_.end(), r.warnings.begin(), r.warnings.end());
  // The used hits' ring-downs, for the amplitude check `vibid modes` makes on the recording.
  const ident::RingDowns ringdowns =
      ident::RingDownsOf(r, force, responses, fs_hz, CommonQuantity(measured));
  ident::Frf frf = std::move(r.frf);
  AlignMeasuredQuantities(frf, measured);
  frf.response_names = response_names_;
  frf.force_name = force_name_;
  if (!instants_s_.empty()) {
    ident::CompensateSampleInstants(
        frf, instants_s_.front(), std::vector<double>(instants_s_.begin() + 1, instants_s_.end()));
  }
  frf_ = ident::ConvertFrf(frf, ident::ParseQuantity(options_.estimation.kind));
  ident::Frf receptance = ident::ConvertFrf(frf, ident::Quantity::kDisplacement);
  const bool same = receptance_.h.size() == receptance.h.size() &&
                    receptance_.h.cwiseEqual(receptance.h).all() &&
                    receptance_.coherence.cwiseEqual(receptance.coherence).all();
  receptance_ = std::move(receptance);
  if (same && (modes_ || !modes_error_.empty())) return;
  const Clock::time_point start = Clock::now();
  try {
    modes_ = IdentifyModes(receptance_, options_.modes, &ringdowns);
    modes_error_.clear();
  } catch (const InputError& e) {
    modes_.reset();
    modes_error_ = e.what();
  }
  modes_ms_ = MsSince(start);
}

void HammerSession::Publish(double update_ms) {
  HammerSnapshot s;
  s.samples = data_->n;
  s.fs_hz = data_->n >= 2 ? data_->FsHz() : 0.0;
  s.finished = finished_;
  for (std::size_t g = 0; g < detection_.hits.size(); ++g) {
    const ident::Hit& h = detection_.hits[g];
    if (g >= judged_) {
      ++s.pending_hits;
      continue;
    }
    SessionHit out;
    out.index = g + 1;
    out.t_s = h.t_s;
    out.peak_n = h.peak_n;
    out.verdict = VerdictOf(h);
    out.reason = h.note;
    out.accepted = h.used;
    out.by_operator = operator_choice_.count(h.peak_index) != 0;
    s.accepted += h.used ? 1 : 0;
    s.hits.push_back(std::move(out));
  }
  if (candidate_ && s.pending_hits == 0) s.pending_hits = 1;  // a pulse since the last analysis
  s.frf = frf_;
  s.warnings = warnings_;
  if (modes_) {
    s.warnings.insert(s.warnings.end(), modes_->warnings.begin(), modes_->warnings.end());
    if (modes_->has_diagram) {
      s.band_min_hz = modes_->diagram.freq_min_hz;
      s.band_max_hz = modes_->diagram.freq_max_hz;
    } else if (modes_->fitted) {
      s.band_min_hz = modes_->fit.freq_min_hz;
      s.band_max_hz = modes_->fit.freq_max_hz;
    }
  }
  s.modes = modes_;
  s.modes_error = modes_error_;
  s.last_modes_ms = modes_ms_;
  const std::lock_guard<std::mutex> lock(published_mutex_);
  s.last_update_ms = update_ms >= 0.0 ? update_ms : published_.last_update_ms;
  s.version = published_.version + 1;
  published_ = std::move(s);
}

std::size_t HammerSession::HitOf(std::size_t index) const {
  Require(index >= 1 && index <= judged_,
          "hammer session: no hit " + std::to_string(index) +
              (judged_ == 0 ? std::string(" (no hit judged yet)")
                            : " (hits judged so far: 1.." + std::to_string(judged_) + ")"));
  return index - 1;
}

void HammerSession::Accept(std::size_t index) {
  const std::lock_guard<std::mutex> lock(work_);
  const ident::Hit& h = detection_.hits[HitOf(index)];
  Require(!h.truncated, "hammer session: hit " + std::to_string(index) +
                            " cannot be used: " + h.note + "; its record does not fit");
  operator_choice_[h.peak_index] = true;
  const Clock::time_point start = Clock::now();
  Analyze();
  Publish(MsSince(start));
  Keep();
}

void HammerSession::Reject(std::size_t index) {
  const std::lock_guard<std::mutex> lock(work_);
  operator_choice_[detection_.hits[HitOf(index)].peak_index] = false;
  const Clock::time_point start = Clock::now();
  Analyze();
  Publish(MsSince(start));
  Keep();
}

HammerSnapshot HammerSession::Snapshot() const {
  const std::lock_guard<std::mutex> lock(published_mutex_);
  return published_;
}

std::uint64_t HammerSession::Version() const {
  const std::lock_guard<std::mutex> lock(published_mutex_);
  return published_.version;
}

HitTraces HammerSession::Traces(std::size_t index) const {
  const std::lock_guard<std::mutex> lock(work_);
  const std::size_t g = HitOf(index);
  const ident::HitSpan& span = detection_.spans[g];
  const std::size_t record = detection_.record_samples;
  const std::size_t length = std::min(record, data_->n - span.start);
  const auto rows = static_cast<Eigen::Index>(length);
  const double fs_hz = data_->FsHz();
  HitTraces t;
  t.index = index;
  const auto trigger = static_cast<double>(detection_.hits[g].trigger_index - span.start);
  t.t_s = (Eigen::VectorXd::LinSpaced(rows, 0.0, static_cast<double>(rows - 1)).array() - trigger) /
          fs_hz;
  t.force = data_->force.segment(static_cast<Eigen::Index>(span.start), rows);
  t.force_window = ident::ImpactForceWindow(detection_, g).head(rows);
  t.responses = data_->responses.middleRows(static_cast<Eigen::Index>(span.start), rows);
  t.response_names = response_names_;
  return t;
}

void HammerSession::Save(const std::string& dir) const {
  const std::lock_guard<std::mutex> lock(work_);
  WriteTest(dir, true);
}

void HammerSession::Keep() {
  if (options_.test_dir.empty()) return;
  if (finished_) {
    WriteTest(options_.test_dir, false);
    return;
  }
  // While it runs: the hits and the choices, each change as it is made (recording.csv and the FRF
  // follow from live.csv and them; they are written whole when the acquisition ends).
  std::string hits = HitListJson(Snapshot().hits).dump(2) + "\n";
  if (hits == kept_hits_) return;
  WriteFileAtomic(options_.test_dir + "/hits.json", hits);
  kept_hits_ = std::move(hits);
}

void HammerSession::WriteTest(const std::string& dir, bool require_frf) const {
  device::WriteLogSidecar(dir + "/recording.csv", format_, options_.calibration,
                          options_.has_calibration, options_.instants);
  WriteFileAtomic(dir + "/recording.csv", header_ + rows_);
  const HammerSnapshot s = Snapshot();
  WriteFileAtomic(dir + "/hits.json", HitListJson(s.hits).dump(2) + "\n");
  if (frf_.lines() == 0 && !require_frf) {
    // No FRF over no hit: an earlier one would contradict hits.json.
    std::error_code ignored;
    std::filesystem::remove(dir + "/frf.csv", ignored);
    std::filesystem::remove(dir + "/frf.csv.json", ignored);
    std::filesystem::remove(dir + "/frf.uff", ignored);
    return;
  }
  Require(frf_.lines() > 0, "hammer session: recording.csv and hits.json written to " + dir +
                                ", but no hit is accepted: no FRF to write; accept a hit");
  const int reference = static_cast<int>(frf_.responses());
  ident::WriteFrf(frf_, dir + "/frf.csv", reference);
  ident::WriteFrf(frf_, dir + "/frf.uff", reference);
}

}  // namespace vibid::workflow
