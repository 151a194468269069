// The rig watched on the board (`vibid watch --device`, the bench's Watch view, Python): the
// streamed acquisition planned, preflighted and started as `vibid acquire` starts it, its records
// fed to a WatchSession as they arrive (gaps included), each block's JSON line journaled and
// flushed as it comes, the board's own model test read before and after, and the acquisition
// stopped on request, keeping what was journaled. The front ends only say what to watch and show
// what comes back.
//
// When the board logs its model test beside the data (the log columns `model_g` and
// `model_stale`), every block carries the board's flag at its end (WatchBlock::board) with the
// threshold get-info states; without them, the blocks carry none and the board's `model_stale`
// as read before the start is the only word from it (a request while the log streams would hold
// the link).
#pragma once

#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "vibid/device/acquire_plan.hpp"
#include "vibid/device/connection.hpp"
#include "vibid/workflow/watch_session.hpp"

namespace vibid::workflow {

/// The reference recording's `columns` (as acquire writes a recording), checked to be sampled at
/// `fs_hz`. InputError naming `path` (and the option, as `spelling` spells it) otherwise.
Eigen::MatrixXd LoadWatchReference(const std::string& path, const std::vector<std::string>& columns,
                                   double fs_hz, OptionSpelling spelling = OptionSpelling::kCli);

/// The journal: JSON lines appended and flushed as the blocks come, so a crash leaves every
/// whole line. `option` is how the front end names it in a refusal (`-o PATH`).
class WatchJournal {
 public:
  WatchJournal() = default;
  /// Created or truncated now (InputError when it cannot be); an empty path journals nothing.
  WatchJournal(const std::string& path, std::string option);
  /// A file the caller created (owned from here, closed by the journal).
  WatchJournal(std::FILE* file, std::string path, std::string option);
  ~WatchJournal();
  WatchJournal(WatchJournal&& other) noexcept;
  WatchJournal& operator=(WatchJournal&& other) noexcept;
  WatchJournal(const WatchJournal&) = delete;
  WatchJournal& operator=(const WatchJournal&) = delete;

  void Append(const std::string& line);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::string option_;
  std::FILE* file_ = nullptr;
};

struct WatchBoardSettings {
  /// The acquisition, as `vibid acquire` takes it; seconds 0: until stopped. Channels empty:
  /// acc1, acc2.
  device::AcquireSettings acquire;
  std::string scenario;  ///< Emulator only: the excitation to select (operate); empty: none.
  std::vector<float> scenario_params;
  std::vector<std::string> responses;  ///< Log columns watched; empty: acc… and x… columns.
  std::string reference;               ///< A reference recording; empty: a reference phase.
  WatchOptions watch;                  ///< fs_hz and channels are the run's (the log's).
};

/// The board about to start.
struct WatchBoardStart {
  std::vector<std::string> responses;  ///< The log's watched columns.
  double log_rate_hz = 0.0;
  bool board_columns = false;  ///< The board's model test is logged with the data.
  nlohmann::json model_stale;  ///< The board's `model_stale` (info --json's; null: no test).
  std::string model_text;      ///< The same in words (device::WatchText); empty: no observer.
};

/// What the run says as it goes (each called in the caller's thread, the one that runs Run).
struct WatchBoardEvents {
  std::function<void(const WatchBoardStart& start)> starting;
  /// After each batch of records fed (the reference's progress: session.reference_left_s()).
  std::function<void(const WatchSession& session, double t_s)> fed;
  /// Once, when the reference is built (at the start with a reference recording).
  std::function<void(const WatchSession& session)> reference;
  /// Then the journal's first line (WatchHeaderJson, with the board's model test at the start
  /// as "model_stale"), as journaled.
  std::function<void(const std::string& line)> header;
  /// Each block with its JSON line as journaled.
  std::function<void(const WatchBlock& block, const std::string& line)> block;
};

struct WatchBoardResult {
  bool stopped = false;         ///< Ended by the stop request (not by its length).
  std::string warning;          ///< The log came back incomplete (records overwritten).
  nlohmann::json model_stale;   ///< The board's `model_stale` at the end (null without a test).
  std::string model_text;       ///< The same in words; empty without an observer running.
  nlohmann::json model_before;  ///< And before the start.
  bool reference_built = false;
  double reference_left_s = 0.0;  ///< Seconds of reference still to come when it ended.
  int blocks = 0;
  double log_rate_hz = 0.0;
};

class WatchBoardRun {
 public:
  /// Checks everything that can be checked without the board (the acquisition's settings, the
  /// watch's options, that the run lasts past the reference): InputError naming the option,
  /// before anything is created or the board touched. The journal is the caller's, made after.
  explicit WatchBoardRun(WatchBoardSettings settings);

  /// Runs on the board until its length, or until `stop` (asked at every report) returns true;
  /// the board is stopped on an error too. Throws what the board or the session refuses.
  WatchBoardResult Run(device::Connection& c, WatchJournal& journal, const WatchBoardEvents& events,
                       const std::function<bool()>& stop);

  const WatchBoardSettings& settings() const { return s_; }
  const WatchOptions& options() const { return options_; }
  bool until_stopped() const { return until_stopped_; }

 private:
  WatchBoardSettings s_;
  WatchOptions options_;
  bool until_stopped_ = false;
  double log_rate_hz_ = 0.0;
};

}  // namespace vibid::workflow
