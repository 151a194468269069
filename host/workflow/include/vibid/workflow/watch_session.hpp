// A running rig watched from its responses alone (`vibid watch`, the bench's Watch view, Python):
// the responses fed as they arrive, a reference phase (the first reference_s seconds, or a
// reference recording) that builds the subspace change test, then per block of block_s seconds:
// the modes over the last modes_s seconds (SSI-cov, 95 % intervals), the block's subspace
// statistic against its threshold, and the test accumulated over a window of blocks (the mean of
// the blocks' residuals, Hotelling's two-sample T² against the reference's: oma::AccumulatedTest).
//
// The alarm is the window's: each full window is one test at the rate asked for (per hour of
// watching) times its length, its threshold the exact F quantile, so the expected number of false
// alarms over any stretch is the rate times its length, whatever the reference drawn (the windows
// share it, so the count's spread over one reference is wider than Poisson's). The mean of a
// window's residuals is close to Gaussian; one block's residual is not quite (its T² exceeds the
// F law's quantile about twice as often as it should on the demo rig), so a block over its own
// threshold (at the same rate per hour) is shown, not counted as an alarm. A 3 % mass on the demo
// rig (mode 1 about 1 % lower) is flagged within two windows after a 30-minute reference
// (docs/watch.md).
#pragma once

#include <chrono>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "vibid/oma/accumulated_test.hpp"
#include "vibid/oma/sequential_test.hpp"
#include "vibid/oma/ssi_cov.hpp"
#include "vibid/oma/subspace_test.hpp"

namespace vibid::workflow {

/// How messages name the options: as `vibid watch` spells them (`--reference-s`) or as Python's
/// `vibid.watch` does (`reference_s`), so a refusal names what the user typed.
enum class OptionSpelling { kCli, kPython };

/// An option's name in a spelling: `key` is the Python name (reference_s, block_s, responses...).
std::string WatchOptionName(const std::string& key, OptionSpelling spelling);

/// The smallest false-alarm rate a watch takes (per hour) and the longest modes span (s).
inline constexpr double kMinFalseAlarmPerHour = 1e-6;
inline constexpr double kMaxModesS = 3600.0;

struct WatchOptions {
  double fs_hz = 0.0;         ///< Sample rate of the responses fed (> 0).
  int channels = 0;           ///< Response columns fed (≥ 1).
  double reference_s = 1800;  ///< The first seconds watched are the reference (unless one given).
  double block_s = 10.0;      ///< One tested block.
  int window_blocks = 60;     ///< Blocks whose residuals the accumulated test averages.
  /// The sequential test's longest onset, in blocks (oma::SequentialTest's L; 1 … 720).
  int sequential_blocks = 60;
  /// False alarms per hour asked of each test (the window's and the sequential one's; the watch's
  /// alarm is either's, so its own rate is at most their sum, each stated with the reference).
  double false_alarm_per_hour = 0.01;
  double fmax_hz = 25.0;   ///< Top of the band analysed (above the highest mode watched).
  double modes_s = 120.0;  ///< Modes over the last modes_s seconds at each block; 0: none.
  int order = 0;           ///< Model order of the test (2 × modes); 0: from the reference's modes.
  /// Share of the reference that gives the test's null space (the rest its statistics).
  double null_space_share = 0.2;
  OptionSpelling spelling = OptionSpelling::kCli;  ///< How refusals name the options.

  /// InputError naming the option (as `spelling` spells it) and the way out.
  void Validate() const;
  /// Probability that an unchanged block is over its threshold (shown), and that an unchanged
  /// window alarms.
  double BlockFalseAlarm() const;
  double WindowFalseAlarm() const;
};

/// The shortest reference the test accepts for `channels` responses at model order `order` (0:
/// twice the channels), in seconds.
double MinimumReferenceS(const WatchOptions& options, int order = 0);

struct WatchMode {
  double omega_rad_s = 0.0;
  double zeta = 0.0;
  double omega_ci95_rad_s = 0.0;  ///< 95 % half-widths.
  double zeta_ci95 = 0.0;
  /// Real-normalised shape (largest entry +1) and its entries' 95 % half-widths (SSI-cov's);
  /// empty where not known.
  std::vector<double> shape;
  std::vector<double> shape_ci95;
};

/// What moved most against the reference, in units of its interval: each mode now matched to the
/// reference's nearest in frequency, and for each its frequency, its damping ratio and its shape
/// compared, each change over the 95 % half-width of the change (both intervals combined). The
/// quantity with the largest such ratio names the move: a damper that drifts shows as ζ, a spring
/// or a mass as ω, a change that redistributes the motion as the shape.
struct WatchMove {
  int mode = 0;  ///< 1-based, of the reference's modes.
  /// "omega", "zeta" or "shape": the quantity that moved most significantly.
  std::string quantity;
  double significance = 0.0;  ///< |change| / ci95 of that quantity (> 1: outside its interval).
  double omega_ref_rad_s = 0.0;
  double omega_rad_s = 0.0;
  double change_rad_s = 0.0;  ///< ω − ω_ref.
  double ci95_rad_s = 0.0;    ///< 95 % half-width of the change (both intervals combined).
  double relative = 0.0;      ///< change / ω_ref.
  double omega_significance = 0.0;
  double zeta_ref = 0.0;
  double zeta = 0.0;
  double zeta_change = 0.0;  ///< ζ − ζ_ref.
  double zeta_ci95 = 0.0;    ///< Its combined 95 % half-width.
  double zeta_significance = 0.0;
  /// The shape: the entry that moved most against its combined interval (0-based channel), its
  /// change, that half-width, and the modal assurance criterion of the two shapes (1: the same).
  int shape_entry = -1;  ///< -1 where shapes are not known (then shape_significance is 0).
  double shape_change = 0.0;
  double shape_ci95 = 0.0;
  double shape_significance = 0.0;
  double mac = 0.0;
};

/// The board's own test on its observer's residual (its "model stale" flag, docs/dob.md), as its
/// log carries it with every record (the `model_g` and `model_stale` columns).
struct WatchBoardModel {
  bool stale = false;      ///< The flag at the block's last record (latched once tripped).
  double statistic = 0.0;  ///< The board's CUSUM g there.
  double threshold = 0.0;  ///< Its threshold h (0 where not known: SetBoardThreshold).
  std::optional<double> stale_since_t_s;  ///< Time of the first record logged stale.
};

struct WatchBlock {
  int index = 0;     ///< 1-based, counted from the first block after the reference.
  double t_s = 0.0;  ///< End of the block, seconds from the first sample fed (or its time stamp).
  std::vector<WatchMode> modes;
  std::string modes_message;  ///< Why modes are missing, or empty.
  /// The block's T², and the F quantile at the per-block rate: not a calibrated threshold (one
  /// block's T² is heavier-tailed than F: it exceeds the quantile 7 to 9 times as often).
  double statistic = 0.0;
  double f_quantile = 0.0;
  bool block_over = false;  ///< The block's T² is over that quantile (shown, not an alarm).
  double accumulated_statistic = 0.0;  ///< T² of the window's blocks so far, and its threshold.
  double accumulated_threshold = 0.0;
  int window_count = 0;  ///< Blocks in the window so far (the window is tested when full).
  int window_blocks = 0;
  bool window_alarm = false;
  /// The sequential test (oma::SequentialTest): its statistic g, its threshold h, the onset k
  /// that maximised g (the change's estimated start, blocks back), the blocks it holds, its alarm.
  double sequential_statistic = 0.0;
  double sequential_threshold = 0.0;
  int sequential_onset_blocks = 0;
  int sequential_blocks = 0;
  bool sequential_alarm = false;
  bool alarm = false;  ///< This block completed a window that alarmed, or the sequential test did.
  std::optional<double> first_alarm_t_s;  ///< When the first alarm came (kept from then on).
  std::optional<WatchMove> moved;
  /// The board's flag at the block's end; absent where the responses came without it.
  std::optional<WatchBoardModel> board;
  double analysis_ms = 0.0;  ///< Wall time of this block's analysis.
};

/// The reference as the session built it.
struct WatchReference {
  /// Where it came from: "watched" (the first reference_s seconds fed) or "recording" (given).
  std::string source;
  /// Its span: the first and last sample's times (the session's clock for a watched one, the
  /// recording's own from 0 for a given one).
  double from_t_s = 0.0;
  double to_t_s = 0.0;
  double seconds = 0.0;
  std::vector<WatchMode> modes;
  int order = 0;
  int dof = 0;                    ///< Residuals of the test.
  int reference_blocks = 0;       ///< Blocks that give their mean and covariance.
  double block_f_quantile = 0.0;  ///< A block's F quantile (not a calibrated threshold).
  double window_threshold = 0.0;  ///< oma::WindowCalibration's threshold.
  /// The false alarms per hour this reference gives (95 %: the 2.5 % and 97.5 % points, the
  /// latter the rate asked for) and their mean over references.
  double false_alarms_per_hour_low = 0.0;
  double false_alarms_per_hour_high = 0.0;
  double false_alarms_per_hour_mean = 0.0;
  /// The reference that would give a band whose low end reaches a fifth of the rate asked
  /// (oma::AdviseReference), in whole minutes, and that band's low end; the reference's own
  /// length where it does, 0 where not even 8 times as long would.
  double advised_reference_s = 0.0;
  double advised_false_alarms_per_hour_low = 0.0;
  /// The sequential test's threshold for this reference (oma::SequentialCalibration), the one an
  /// exact reference would have, and the false alarms per hour this reference gives at it (95 %,
  /// the latter the rate asked) and their mean over references.
  double sequential_threshold = 0.0;
  double sequential_exact_threshold = 0.0;
  double sequential_false_alarms_per_hour_low = 0.0;
  double sequential_false_alarms_per_hour_high = 0.0;
  double sequential_false_alarms_per_hour_mean = 0.0;
  double analysis_ms = 0.0;
};

class WatchSession {
 public:
  /// Validates the options.
  explicit WatchSession(WatchOptions options);
  ~WatchSession();
  WatchSession(const WatchSession&) = delete;
  WatchSession& operator=(const WatchSession&) = delete;

  /// A reference recording (one column per channel, at fs_hz) in place of the first reference_s
  /// seconds: every sample fed is then watched. Before the first Feed only.
  void SetReference(Eigen::Ref<const Eigen::MatrixXd> reference);

  /// Responses in order (one row per sample, `channels` columns); `t_first_s` the time of the
  /// first of them (kept from the first call: later times follow from the count). Returns the
  /// blocks they complete.
  std::vector<WatchBlock> Feed(Eigen::Ref<const Eigen::MatrixXd> samples,
                               std::optional<double> t_first_s = std::nullopt);
  /// As Feed, with the board's model test logged beside each sample: `board` has a row per
  /// sample and two columns, the board's statistic g and its flag (0 or 1). Each block then
  /// carries the board's state at its last sample and the time the flag was first seen.
  std::vector<WatchBlock> Feed(Eigen::Ref<const Eigen::MatrixXd> samples,
                               Eigen::Ref<const Eigen::MatrixXd> board,
                               std::optional<double> t_first_s = std::nullopt);
  /// The board's threshold h (from its calibration), shown beside its statistic.
  void SetBoardThreshold(double h) { board_threshold_ = h; }
  /// Samples were lost (the board dropped records): the block under way is dropped and the next
  /// starts with the next sample fed, `missing` samples later. A gap in the reference is refused.
  void Gap(long missing);

  bool has_reference() const { return detector_ != nullptr; }
  /// Seconds of reference still to come (0 once built).
  double reference_left_s() const;
  const WatchReference& reference() const { return reference_; }
  const WatchOptions& options() const { return options_; }

 private:
  void BuildReference(Eigen::Ref<const Eigen::MatrixXd> reference);
  WatchBlock TestBlock(Eigen::Ref<const Eigen::MatrixXd> block);

  WatchOptions options_;
  long block_samples_ = 0;
  long reference_samples_ = 0;
  std::optional<double> t0_s_;
  long fed_ = 0;  // samples fed (and skipped over gaps): the time of the next is t0 + fed/fs
  Eigen::MatrixXd pending_;  // the reference or block under way
  long pending_rows_ = 0;
  std::deque<Eigen::MatrixXd> recent_;  // the last blocks, for the modes
  std::unique_ptr<oma::SubspaceDetector> detector_;
  std::unique_ptr<oma::AccumulatedTest> window_;
  std::unique_ptr<oma::SequentialTest> sequential_;
  WatchReference reference_;
  int blocks_ = 0;
  std::optional<double> first_alarm_t_s_;
  double board_threshold_ = 0.0;
  std::optional<WatchBoardModel> board_;  // as of the last sample fed with the board's columns
};

/// One block as a JSON object (a line of `vibid watch --json` and of its journal): t_s, block,
/// modes [{omega_rad_s, zeta, ci95: {omega_rad_s, zeta}}], statistic, threshold, alarm,
/// block_over, accumulated {statistic, threshold, blocks, window_blocks, tested (the window is
/// full: this block tested it), alarm}, sequential {statistic, threshold, onset_blocks, blocks,
/// alarm},
/// first_alarm_t_s (null before), moved (null or {mode, quantity, significance, omega_ref_rad_s,
/// omega_rad_s, change_rad_s, ci95_rad_s, relative, omega_significance, zeta {ref, now, change,
/// ci95, significance}, shape {entry, change, ci95, significance, mac} (null without shapes)}),
/// board (null without the board's columns, or {stale,
/// statistic, threshold, stale_since_t_s}), modes_message, analysis_ms.
nlohmann::json WatchBlockJson(const WatchBlock& block);
/// The reference's summary: source, span {from_t_s, to_t_s}, seconds, modes, order, dof,
/// reference_blocks, thresholds.
nlohmann::json WatchReferenceJson(const WatchReference& reference);
/// The options as JSON (fs_hz, channels, reference_s, block_s, window_blocks,
/// false_alarm_per_hour, block_false_alarm and window_false_alarm (per test), fmax_hz, modes_s,
/// order, null_space_share).
nlohmann::json WatchOptionsJson(const WatchOptions& options);
/// The journal's first line (and `vibid watch --json`'s), once the reference is built: {"header":
/// "vibid watch", "version": 1, "options": WatchOptionsJson, "reference": WatchReferenceJson}. A
/// block's line never has a "header" key, so a reader tells them apart by it.
nlohmann::json WatchHeaderJson(const WatchSession& session);
/// One line of text: time, modes (Hz, ζ %), T² against its threshold, the window's (a full
/// window's statistic against its threshold; a partial one's count of blocks only: it is tested
/// when full), the sequential test's g/h and onset k, what moved, the verdict.
std::string WatchBlockText(const WatchBlock& block);

}  // namespace vibid::workflow
