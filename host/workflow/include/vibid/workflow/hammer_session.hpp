// A hammer test run live: the board's records fed in as they arrive, the recording appended to disk
// as `vibid acquire` writes it, each hit judged as soon as its record is complete, the operator's
// accept or reject, and the FRF and modes over the accepted hits after each change. Every number is
// the one `vibid frf-estimate` / `vibid modes` give on the recording so far with the same hits
// (`--hits` with the saved hit list): the same detection, per-hit spectra and average
// (ident::DetectImpactHits, ImpactHitSpectra, AverageHitSpectra), the spectra of each hit kept so
// that a new choice only re-sums them.
//
// Threads: Feed, Finish, Accept, Reject, Save and Traces may be called from any thread (they take
// the session's lock in turn); Snapshot and Version only wait for the published state, never for
// the processing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "vibid/device/connection.hpp"
#include "vibid/ident/impact.hpp"
#include "vibid/ident/modes.hpp"
#include "vibid/shared/wire/calibration_record.hpp"
#include "vibid/shared/wire/log_record.hpp"
#include "vibid/workflow/estimate.hpp"
#include "vibid/workflow/hammer_snapshot.hpp"
#include "vibid/workflow/modes_request.hpp"

namespace vibid::workflow {

struct HammerSessionOptions {
  /// The acquisition as the board runs it: layout (channel mask, flags), tick period and
  /// decimation (the trailer fields `sample_period_us`, `decimation`); the recording's columns and
  /// time follow from them as `vibid acquire` writes them.
  wire::LogLayout layout;
  std::uint32_t sample_period_us = 0;
  std::uint16_t decimation = 1;
  /// The board's active calibration record (has_calibration false: columns in counts).
  wire::CalibrationRecord calibration;
  bool has_calibration = false;
  /// The board's sampling instants (the recording's header states them; the FRF is compensated).
  std::optional<wire::SamplingInfoResponse> instants;
  /// Force and response columns (NAME[:UNIT|*FACTOR], as the recording names them: force1_n,
  /// acc1_m_s2, ...), estimator, sensor, FRF kind and the hit options: trigger, pretrigger, force
  /// and exponential windows, double-hit and weak-hit limits, with `vibid frf-estimate`'s
  /// defaults. `impact_options.record_s`, the record of one hit: given, a hit is judged as soon
  /// as that much of it is sampled; 0 (the default, as the CLI's: the shortest spacing between
  /// hits), a hit is judged when the next one comes (its record ends before it) or the test ends.
  /// `impact` is implied; `welch`, `use_hits` and `hits_file` are refused (the session chooses).
  EstimationOptions estimation;
  /// Modes after each change of the accepted hits: method, orders, driving point (the hammer
  /// point: a response column or its 1-based index), as `vibid modes` takes them.
  ModeRequest modes;
  /// The growing recording, appended as records arrive (created or truncated at the start).
  std::string live_csv_path;
  /// Where the test is kept whole as it goes (empty: only Save writes it): hits.json rewritten at
  /// every change of the hits or of a choice (the operator's choices journaled as they are made),
  /// and when the acquisition finishes (its end, a stop, Ctrl-C) and after every later choice the
  /// whole test as Save writes it (frf.csv and frf.uff removed while no hit is accepted).
  std::string test_dir;

  /// InputError naming the option and the way out.
  void Validate() const;
};

class HammerSession {
 public:
  /// Validates the options and creates the growing recording (header written).
  explicit HammerSession(HammerSessionOptions options);
  ~HammerSession();
  HammerSession(const HammerSession&) = delete;
  HammerSession& operator=(const HammerSession&) = delete;

  /// Records in the order the board's stream delivers them (consecutive samples; a gap is
  /// refused). Appends them to the growing recording, then judges every hit whose record they
  /// complete and updates FRF and modes when the accepted hits change.
  void Feed(std::span<const wire::LogRecord> records);
  /// The acquisition ended: hits still incomplete are judged truncated, the last state published.
  void Finish();

  /// The operator's choice for hit `index` (1-based), over its verdict.
  void Accept(std::size_t index);
  void Reject(std::size_t index);

  HammerSnapshot Snapshot() const;
  std::uint64_t Version() const;
  HitTraces Traces(std::size_t index) const;

  /// Writes into `dir` (each file whole or not at all): recording.csv (the recording as
  /// `vibid acquire` writes it), hits.json (every hit: index, t_s, peak_n, verdict, reason,
  /// accepted, decided_by auto/operator; `--hits` reads it), frf.csv and frf.uff (the FRF over the
  /// accepted hits, as `frf-estimate -o` writes them). The growing recording is kept.
  void Save(const std::string& dir) const;

 private:
  struct Channels;
  void Analyze();
  void Publish(double update_ms);
  /// The test kept in options_.test_dir (under work_): see HammerSessionOptions::test_dir.
  void Keep();
  /// Save's files into `dir` (under work_); without an accepted hit: an InputError when
  /// `require_frf`, else the FRF files removed.
  void WriteTest(const std::string& dir, bool require_frf) const;
  std::size_t HitOf(std::size_t index) const;

  HammerSessionOptions options_;
  device::LogPull format_;            // layout and trailer of every block
  std::vector<std::string> columns_;  // the recording's column names
  std::size_t force_column_ = 0;
  std::vector<std::size_t> response_columns_;
  double force_scale_ = 1.0;
  std::vector<double> response_scales_;
  std::vector<std::string> response_names_;
  std::string force_name_;
  std::vector<double> instants_s_;  // force first; empty when the board states none

  mutable std::mutex work_;  // everything below up to `published_`
  std::FILE* live_ = nullptr;
  std::string header_;
  std::string rows_;  // every row written (Save writes header_ + rows_)
  std::unique_ptr<Channels> data_;
  std::uint32_t next_sample_index_ = 0;
  bool started_ = false;
  bool finished_ = false;
  std::size_t next_check_ = 0;  // samples at which a hit's record may be complete
  std::size_t scanned_ = 0;     // force samples looked at for a new pulse
  bool detected_once_ = false;
  bool candidate_ = false;  // a pulse seen since the last analysis
  ident::ImpactDetection detection_;
  std::size_t judged_ = 0;                       // hits of detection_ with a complete record
  std::map<std::size_t, bool> operator_choice_;  // by peak sample: accepted?
  struct KeptSpectra {
    ident::HitSpan span;
    double baseline = 0.0;  // the offset's fallback when the pretrigger is too short; else 0
    ident::HitSpectra spectra;
  };
  std::map<std::size_t, KeptSpectra> spectra_;  // by record start
  std::size_t spectra_record_ = 0;
  std::size_t last_pre_ = 0;
  Eigen::VectorXd last_exp_window_;
  ident::Frf receptance_;  // what the modes were identified from
  std::optional<ident::ModeIdentification> modes_;
  std::string modes_error_;
  double modes_ms_ = 0.0;
  ident::Frf frf_;  // in the options' kind
  std::vector<std::string> warnings_;
  std::string kept_hits_;  // hits.json as last kept in test_dir

  mutable std::mutex published_mutex_;
  HammerSnapshot published_;
};

}  // namespace vibid::workflow
