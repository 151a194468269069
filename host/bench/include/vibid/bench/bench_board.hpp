// The board behind the bench: one open connection (held for the bench's life, which locks the
// board as any CLI command does), what the page may ask of it, and the acquisition it runs.
//
// An acquisition runs in its own thread on the board's stream that follows it: every data report
// is converted to SI units by the library's own table (device::MakeLogTable), appended to a
// journal file on disk and published on the live channel as it arrives; when the acquisition
// ends, the CRC-checked log is written as the recording (the same CSV `vibid acquire` writes) and
// the journal removed. Closing or reloading the page changes nothing of this.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <optional>
#include <span>
#include <mutex>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "vibid/bench/acquisition_ask.hpp"
#include "vibid/bench/live_hub.hpp"
#include "vibid/device/connection.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/shared/wire/calibration_record.hpp"

namespace vibid::bench {

/// The board is busy with the running acquisition (the server answers 409).
class Busy : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Gets each block of a running acquisition as the page does (SI columns, after the journal).
using BlockListener = std::function<void(const device::LogTable& block)>;

/// Follows every acquisition the bench runs, in the acquisition's thread: `started` before the
/// board starts (the request and the board's configuration), `records` with the board's records
/// as they arrive (in log order, each once: a resumed stream's repeats are dropped), `ended`
/// with the final state (file, records, error). An exception from a listener is reported in
/// the state's "warning" and stops that listener only; the acquisition and its files go on.
struct AcquisitionListener {
  std::function<void(const AcquisitionAsk& ask, const wire::AcqConfigureRequest& config)> started;
  std::function<void(std::span<const wire::LogRecord> records)> records;
  std::function<void(const nlohmann::json& state)> ended;
};

class BenchBoard {
 public:
  /// `out_dir` receives the journals and recordings (created private when missing, refused when
  /// another user may write into it: PrepareDirectory); `interrupt` (may be null) stops a running
  /// acquisition when it becomes true (Ctrl-C), keeping what it recorded.
  BenchBoard(device::Connection& connection, std::string out_dir, LiveHub& hub,
             const std::atomic<bool>* interrupt = nullptr);
  ~BenchBoard();
  BenchBoard(const BenchBoard&) = delete;
  BenchBoard& operator=(const BenchBoard&) = delete;

  /// The bench's directory, resolved once when the board opened (PrepareDirectory): the one path
  /// every view's files are read from and written to.
  const std::string& directory() const { return out_dir_; }
  /// Identity, calibration state and channel units; the board's status when it is idle.
  nlohmann::json Describe();
  /// The link budget `vibid acquire` checks before it starts (device::ComputeLinkBudget).
  nlohmann::json Budget(const nlohmann::json& ask);
  /// Starts an acquisition (InputError: a bad request, or one the link would drop records of;
  /// Busy while one runs). `view` ("hammer") names the view whose run it is, in the state's
  /// "view" (as StartTask's state names it). Returns the state.
  nlohmann::json Start(const nlohmann::json& ask, const std::string& view = "");
  /// Asks the running acquisition to stop, keeping what it recorded (a no-op when none runs).
  /// With `view`: only a run of that view is stopped; another's is refused (Busy, naming it).
  nlohmann::json Stop(const std::string& view = "");
  /// {"run": bool}: dob start / stop on the board.
  nlohmann::json SetObserver(const nlohmann::json& body);
  /// Running or not, records so far, the files.
  nlohmann::json State() const;
  /// Stops a running acquisition keeping its data, and waits until its recording is written.
  void Shutdown();

  /// After the board's calibration changed (a commit): its record and units read again.
  void ReadCalibrationAgain();
  /// The active calibration record as last read (null: uncalibrated).
  const wire::CalibrationRecord* ActiveCalibration() const;

  /// The hammer-test session and any other view take the blocks from here.
  void AddBlockListener(BlockListener listener);
  /// The hammer-test session takes the raw records from here (workflow::HammerSession::Feed).
  void AddAcquisitionListener(AcquisitionListener listener);
  /// The board's profile (get-info when the bench opened it): log size, link rate.
  const wire::InfoResponse& BoardInfo() const { return c_.info(); }
  /// The board's sampling instants as get-info stated them (empty from a protocol 2.0 board).
  const std::optional<wire::SamplingInfoResponse>& SamplingInstants() const { return instants_; }

  /// A view's own run on the board (the Watch view's acquisition, started by the library): `body`
  /// runs in the acquisition's thread with the connection and a stop request (true after Stop or
  /// Ctrl-C), the board busy meanwhile as during an acquisition (Busy for every other start).
  /// `state` is the running state published (its "name" and the view's keys); the body's return,
  /// or its error, is the final state. Busy when an acquisition runs.
  using TaskBody =
      std::function<nlohmann::json(device::Connection& c, const std::function<bool()>& stop)>;
  void StartTask(nlohmann::json state, TaskBody body);

  /// Runs `body` with the connection while no acquisition runs (Busy otherwise), serialized with
  /// every other request: the way a view reaches the board.
  void WithIdleBoard(const std::function<void(device::Connection&)>& body);

 private:
  void Run(AcquisitionAsk ask, wire::AcqConfigureRequest cfg, std::string name, std::FILE* journal);
  void OnRecords(std::uint32_t first, std::span<const wire::LogRecord> records);
  void Flush();
  double LogPeriodS() const;  ///< Between two logged records of the running acquisition.
  void PublishState();
  void UpdateFit(const device::LogTable& table);
  void ReadCalibration();
  void NotifyListeners(const std::function<void(AcquisitionListener&)>& call);

  device::Connection& c_;
  std::string out_dir_;
  LiveHub& hub_;
  const std::atomic<bool>* interrupt_;

  std::mutex board_mutex_;     // held by the acquisition thread for its whole run
  wire::InfoResponse info_{};  // get-info when the calibration was last read
  wire::CalibrationRecord calibration_{};
  bool has_calibration_ = false;

  mutable std::mutex state_mutex_;
  nlohmann::json state_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> running_{false};
  std::thread thread_;
  std::vector<BlockListener> listeners_;
  std::vector<AcquisitionListener> acquisition_listeners_;
  std::vector<bool> listener_failed_;  // per acquisition listener, for the running acquisition
  std::string listener_warning_;
  std::optional<wire::SamplingInfoResponse> instants_;

  // Owned by the acquisition thread while it runs.
  AcquisitionAsk ask_;
  wire::AcqConfigureRequest cfg_{};
  std::vector<wire::LogRecord> pending_;
  std::uint32_t next_index_ = 0;
  std::string journal_path_;
  std::FILE* journal_ = nullptr;
  bool journal_header_ = false;
  std::uint64_t live_records_ = 0;
  std::vector<double> fit_estimate_;
  std::vector<double> fit_measured_;
  std::uint64_t fit_samples_since_ = 0;
  std::chrono::steady_clock::time_point last_flush_{};
  int blocks_since_state_ = 0;
};

}  // namespace vibid::bench
