#include "vibid/workflow/watch_session.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "vibid/common/option_text.hpp"
#include "vibid/common/error.hpp"

namespace vibid::workflow {

namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

std::vector<WatchMode> ModesOf(const oma::SsiCovResult& r) {
  std::vector<WatchMode> modes;
  for (const oma::OmaMode& m : r.modes) {
    WatchMode w{m.omega_rad_s, m.zeta, m.omega_ci95_rad_s, m.zeta_ci95, {}, {}};
    if (m.shape_ci95.size() == m.shape.size()) {
      w.shape.assign(m.shape.data(), m.shape.data() + m.shape.size());
      w.shape_ci95.assign(m.shape_ci95.data(), m.shape_ci95.data() + m.shape_ci95.size());
    }
    modes.push_back(std::move(w));
  }
  return modes;
}

oma::SubspaceTestOptions TestOptions(const WatchOptions& o, int order) {
  oma::SubspaceTestOptions t;
  t.fs_hz = o.fs_hz;
  t.fmax_hz = o.fmax_hz;
  t.order = order;
  t.block_s = o.block_s;
  t.false_alarm = o.BlockFalseAlarm();
  t.null_space_share = o.null_space_share;
  return t;
}

// |change| over its combined 95 % half-width (0 where both intervals are 0 and nothing moved).
double Significance(double change, double ci95) {
  if (ci95 > 0.0) return std::abs(change) / ci95;
  return change == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
}

// Each mode against the reference's (WatchMove): its frequency, damping ratio and shape.
WatchMove Compare(int mode, const WatchMode& m, const WatchMode& r) {
  WatchMove move;
  move.mode = mode;
  move.omega_ref_rad_s = r.omega_rad_s;
  move.omega_rad_s = m.omega_rad_s;
  move.change_rad_s = m.omega_rad_s - r.omega_rad_s;
  move.ci95_rad_s = std::hypot(m.omega_ci95_rad_s, r.omega_ci95_rad_s);
  move.relative = move.change_rad_s / r.omega_rad_s;
  move.omega_significance = Significance(move.change_rad_s, move.ci95_rad_s);
  move.zeta_ref = r.zeta;
  move.zeta = m.zeta;
  move.zeta_change = m.zeta - r.zeta;
  move.zeta_ci95 = std::hypot(m.zeta_ci95, r.zeta_ci95);
  move.zeta_significance = Significance(move.zeta_change, move.zeta_ci95);
  if (!m.shape.empty() && m.shape.size() == r.shape.size()) {
    // Both are real-normalised (largest entry +1), so their entries compare directly.
    double dot = 0.0, mm = 0.0, rr = 0.0;
    for (std::size_t i = 0; i < m.shape.size(); ++i) {
      dot += m.shape[i] * r.shape[i];
      mm += m.shape[i] * m.shape[i];
      rr += r.shape[i] * r.shape[i];
      const double change = m.shape[i] - r.shape[i];
      const double ci95 = std::hypot(m.shape_ci95[i], r.shape_ci95[i]);
      const double z = Significance(change, ci95);
      if (move.shape_entry < 0 || z > move.shape_significance) {
        move.shape_entry = static_cast<int>(i);
        move.shape_change = change;
        move.shape_ci95 = ci95;
        move.shape_significance = z;
      }
    }
    move.mac = mm > 0.0 && rr > 0.0 ? dot * dot / (mm * rr) : 0.0;
  }
  move.quantity = "omega";
  move.significance = move.omega_significance;
  if (move.zeta_significance > move.significance) {
    move.quantity = "zeta";
    move.significance = move.zeta_significance;
  }
  if (move.shape_significance > move.significance) {
    move.quantity = "shape";
    move.significance = move.shape_significance;
  }
  return move;
}

// The mode whose frequency, damping ratio or shape moved most, in units of its interval: each
// mode now matched to the reference's nearest in frequency (within 20 %).
std::optional<WatchMove> MovedMost(const std::vector<WatchMode>& now,
                                   const std::vector<WatchMode>& ref) {
  std::optional<WatchMove> best;
  for (const WatchMode& m : now) {
    int j = -1;
    double gap = 0.2;
    for (std::size_t k = 0; k < ref.size(); ++k) {
      const double g = std::abs(m.omega_rad_s / ref[k].omega_rad_s - 1.0);
      if (g < gap) {
        gap = g;
        j = static_cast<int>(k);
      }
    }
    if (j < 0) continue;
    const WatchMove move = Compare(j + 1, m, ref[static_cast<std::size_t>(j)]);
    if (!best || move.significance > best->significance) best = move;
  }
  return best;
}

}  // namespace

std::string WatchOptionName(const std::string& key, OptionSpelling spelling) {
  if (spelling == OptionSpelling::kPython) return key;
  // The CLI names each of these lists in the singular.
  if (key == "responses") return "--response";
  if (key == "scenario_params") return "--scenario-param";
  std::string out = "--" + key;
  std::replace(out.begin(), out.end(), '_', '-');
  return out;
}

void WatchOptions::Validate() const {
  const auto name = [this](const char* key) { return WatchOptionName(key, spelling); };
  // An option with its value, as the user wrote it: "--block-s 2" or "block_s=2".
  const auto given = [&](const char* key, double v) {
    return name(key) + (spelling == OptionSpelling::kPython ? "=" : " ") + OptionNumber(v);
  };
  Require(std::isfinite(fs_hz) && fs_hz > 0.0,
          "watch: the sample rate must be positive" +
              std::string(spelling == OptionSpelling::kPython ? " (fs_hz)" : ""));
  Require(channels >= 1,
          "watch: at least one response channel (" +
              std::string(spelling == OptionSpelling::kPython ? "" : "--channels or ") +
              name("responses") + ")");
  Require(std::isfinite(fmax_hz) && fmax_hz > 0.0 && fmax_hz <= fs_hz / 2.5,
          "watch: " + name("fmax_hz") + " must lie in (0, " + OptionNumber(fs_hz / 2.5) +
              "] (the sample rate over 2.5); raise the sample rate or lower " + name("fmax_hz"));
  Require(std::isfinite(block_s) && block_s > 0.0,
          "watch: " + name("block_s") + " must be positive");
  Require(window_blocks >= 1 && window_blocks <= 100000,
          "watch: " + name("window_blocks") + " must lie in 1 … 100000");
  // Below one false alarm in a million hours the thresholds' tail probabilities underflow.
  Require(std::isfinite(false_alarm_per_hour) && false_alarm_per_hour >= kMinFalseAlarmPerHour,
          "watch: " + name("false_alarm_per_hour") + " must be at least " +
              OptionNumber(kMinFalseAlarmPerHour) + " (one false alarm in a million hours)");
  Require(WindowFalseAlarm() < 0.5,
          "watch: " + given("false_alarm_per_hour", false_alarm_per_hour) +
              " is too high for a window of " + OptionNumber(window_blocks * block_s) +
              " s (the rate times the window must stay below 0.5); lower it or " +
              name("window_blocks"));
  Require(
      sequential_blocks >= 1 && sequential_blocks <= 720,
      "watch: " + name("sequential_blocks") + " must lie in 1 … 720 (two hours of 10 s blocks)");
  Require(BlockFalseAlarm() <= 0.05,
          "watch: " + given("false_alarm_per_hour", false_alarm_per_hour) +
              " is too high for blocks of " + OptionNumber(block_s) +
              " s (the rate times the block must stay at or below 0.05); lower it or " +
              name("block_s"));
  Require(order == 0 || (order >= 2 && order % 2 == 0 && order <= 40),
          "watch: " + name("order") +
              " must be even, 2 to 40 (twice the modes in the band), or 0 (from the "
              "reference's modes)");
  Require(null_space_share >= 0.1 && null_space_share <= 0.9,
          "watch: the null space's share of the reference must lie in [0.1, 0.9]");
  Require(std::isfinite(modes_s) && (modes_s == 0.0 || modes_s >= block_s),
          "watch: " + name("modes_s") + " must be 0 (no modes) or at least " + name("block_s"));
  // The blocks kept for the modes are refitted at every block: their count is bounded.
  Require(modes_s <= kMaxModesS, "watch: " + given("modes_s", modes_s) + " is longer than " +
                                     OptionNumber(kMaxModesS) +
                                     " s (an hour): the modes are fitted over the last " +
                                     name("modes_s") + " at every block; shorten it");
  const oma::SubspaceTestSize size =
      oma::SubspaceTestSizeOf(TestOptions(*this, order > 0 ? order : 2 * channels), channels);
  Require(block_s >= size.min_block_s, "watch: " + given("block_s", block_s) +
                                           " is too short for the band: at least " +
                                           OptionNumber(std::ceil(size.min_block_s * 10.0) / 10.0) +
                                           " s (or raise " + name("fmax_hz") + ")");
  Require(std::isfinite(reference_s) && reference_s >= MinimumReferenceS(*this, order),
          "watch: " + given("reference_s", reference_s) +
              " is too short: the test needs at least " +
              OptionNumber(std::ceil(MinimumReferenceS(*this, order))) +
              " s of the rig unchanged at " + given("block_s", block_s) + " (shorten " +
              name("block_s") + ", or give a longer reference)");
}

double WatchOptions::BlockFalseAlarm() const { return false_alarm_per_hour * block_s / 3600.0; }

double WatchOptions::WindowFalseAlarm() const {
  return false_alarm_per_hour * window_blocks * block_s / 3600.0;
}

double MinimumReferenceS(const WatchOptions& options, int order) {
  const int n = order > 0 ? order : 2 * std::max(1, options.channels);
  return oma::SubspaceTestSizeOf(TestOptions(options, n), std::max(1, options.channels))
      .min_reference_s;
}

WatchSession::WatchSession(WatchOptions options) : options_(std::move(options)) {
  options_.Validate();
  block_samples_ = std::lround(options_.block_s * options_.fs_hz);
  reference_samples_ = std::lround(options_.reference_s * options_.fs_hz);
  pending_.resize(reference_samples_, options_.channels);
}

WatchSession::~WatchSession() = default;

double WatchSession::reference_left_s() const {
  if (detector_) return 0.0;
  return static_cast<double>(reference_samples_ - pending_rows_) / options_.fs_hz;
}

void WatchSession::SetReference(Eigen::Ref<const Eigen::MatrixXd> reference) {
  Require(fed_ == 0 && !detector_, "watch: the reference is given before the watched responses");
  Require(reference.cols() == options_.channels,
          "watch: the reference has " + std::to_string(reference.cols()) + " channels, not " +
              std::to_string(options_.channels));
  BuildReference(reference);
  reference_.source = "recording";
  reference_.from_t_s = 0.0;
  reference_.to_t_s = static_cast<double>(reference.rows() - 1) / options_.fs_hz;
}

void WatchSession::BuildReference(Eigen::Ref<const Eigen::MatrixXd> reference) {
  const Clock::time_point start = Clock::now();
  Require(reference.allFinite(), "watch: the reference holds a non-finite value");
  oma::SsiCovOptions so;
  so.fs_hz = options_.fs_hz;
  so.fmax_hz = options_.fmax_hz;
  const oma::SsiCovResult modes = oma::SsiCov(reference, so);
  reference_.modes = ModesOf(modes);
  int order = options_.order;
  if (order == 0) {
    const auto name = [this](const char* key) { return WatchOptionName(key, options_.spelling); };
    Require(!modes.modes.empty(), "watch: the reference shows no mode below " + name("fmax_hz") +
                                      " " + OptionNumber(options_.fmax_hz) + " Hz (" +
                                      modes.message + "); give " + name("order") +
                                      ", or check the excitation");
    order = std::min(40, 2 * static_cast<int>(modes.modes.size()));
  }
  detector_ = std::make_unique<oma::SubspaceDetector>(reference, TestOptions(options_, order));
  window_ = std::make_unique<oma::AccumulatedTest>(
      detector_->reference_residuals(), options_.window_blocks, options_.WindowFalseAlarm());
  reference_.seconds = static_cast<double>(reference.rows()) / options_.fs_hz;
  reference_.order = order;
  reference_.dof = detector_->dof();
  reference_.reference_blocks = detector_->reference_blocks();
  reference_.block_f_quantile = detector_->threshold();
  reference_.window_threshold = window_->threshold();
  const double windows_per_hour = 3600.0 / (options_.window_blocks * options_.block_s);
  reference_.false_alarms_per_hour_low = window_->calibration().low * windows_per_hour;
  reference_.false_alarms_per_hour_high = window_->calibration().high * windows_per_hour;
  reference_.false_alarms_per_hour_mean = window_->calibration().mean * windows_per_hour;
  const oma::ReferenceAdvice advice =
      oma::AdviseReference(detector_->dof(), detector_->reference_blocks(), options_.window_blocks,
                           options_.WindowFalseAlarm());
  if (advice.observations == detector_->reference_blocks()) {
    reference_.advised_reference_s = reference_.seconds;
  } else if (advice.observations > 0) {
    // The blocks after the null space's share of the reference give the statistics.
    const double s = advice.observations * options_.block_s / (1.0 - options_.null_space_share);
    reference_.advised_reference_s = 60.0 * std::ceil(s / 60.0);
  }
  reference_.advised_false_alarms_per_hour_low = advice.calibration.low * windows_per_hour;
  sequential_ = std::make_unique<oma::SequentialTest>(
      detector_->reference_residuals(), options_.sequential_blocks, options_.BlockFalseAlarm());
  const oma::SequentialCalibration& sc = sequential_->calibration();
  const double blocks_per_hour = 3600.0 / options_.block_s;
  reference_.sequential_threshold = sc.threshold;
  reference_.sequential_exact_threshold = sc.exact_threshold;
  reference_.sequential_false_alarms_per_hour_low = sc.low * blocks_per_hour;
  reference_.sequential_false_alarms_per_hour_high = sc.high * blocks_per_hour;
  reference_.sequential_false_alarms_per_hour_mean = sc.mean * blocks_per_hour;
  reference_.analysis_ms = MsSince(start);
  pending_.resize(block_samples_, options_.channels);
  pending_rows_ = 0;
}

void WatchSession::Gap(long missing) {
  Require(missing >= 0, "watch: a gap of a negative number of samples");
  if (missing == 0) return;
  Require(detector_ != nullptr,
          "watch: samples were lost during the reference (" + std::to_string(missing) +
              " missing); lower the sample rate or the channels so the link carries them");
  pending_rows_ = 0;
  recent_.clear();
  fed_ += missing;
}

std::vector<WatchBlock> WatchSession::Feed(Eigen::Ref<const Eigen::MatrixXd> samples,
                                           Eigen::Ref<const Eigen::MatrixXd> board,
                                           std::optional<double> t_first_s) {
  Require(board.cols() == 2 && board.rows() == samples.rows(),
          "watch: the board's model columns must be two (statistic, flag) with a row per sample");
  if (!t0_s_) t0_s_ = t_first_s.value_or(0.0);
  // Fed a piece at a time so that each block sees the board's state at its own last sample.
  std::vector<WatchBlock> out;
  Eigen::Index at = 0;
  while (at < samples.rows()) {
    const long to_block = pending_.rows() - pending_rows_;
    const Eigen::Index take = std::min<Eigen::Index>(to_block, samples.rows() - at);
    WatchBoardModel state = board_.value_or(WatchBoardModel{});
    for (Eigen::Index i = at; i < at + take; ++i) {
      if (board(i, 1) != 0.0 && !state.stale_since_t_s) {
        state.stale_since_t_s = *t0_s_ + static_cast<double>(fed_ + (i - at)) / options_.fs_hz;
      }
    }
    state.statistic = board(at + take - 1, 0);
    state.stale = board(at + take - 1, 1) != 0.0;
    state.threshold = board_threshold_;
    board_ = state;
    for (WatchBlock& b : Feed(samples.middleRows(at, take))) out.push_back(std::move(b));
    at += take;
  }
  return out;
}

std::vector<WatchBlock> WatchSession::Feed(Eigen::Ref<const Eigen::MatrixXd> samples,
                                           std::optional<double> t_first_s) {
  Require(samples.cols() == options_.channels, "watch: " + std::to_string(samples.cols()) +
                                                   " channels fed, not " +
                                                   std::to_string(options_.channels));
  if (!t0_s_) t0_s_ = t_first_s.value_or(0.0);
  std::vector<WatchBlock> out;
  Eigen::Index at = 0;
  while (at < samples.rows()) {
    const auto want = static_cast<Eigen::Index>(pending_.rows() - pending_rows_);
    const Eigen::Index take = std::min(want, samples.rows() - at);
    pending_.middleRows(pending_rows_, take) = samples.middleRows(at, take);
    pending_rows_ += take;
    at += take;
    fed_ += take;
    if (pending_rows_ < pending_.rows()) break;
    if (!detector_) {
      BuildReference(pending_);
      reference_.source = "watched";
      reference_.from_t_s = *t0_s_;
      reference_.to_t_s = *t0_s_ + static_cast<double>(fed_ - 1) / options_.fs_hz;
      continue;
    }
    out.push_back(TestBlock(pending_));
    pending_rows_ = 0;
  }
  return out;
}

WatchBlock WatchSession::TestBlock(Eigen::Ref<const Eigen::MatrixXd> block) {
  const Clock::time_point start = Clock::now();
  WatchBlock b;
  b.index = ++blocks_;
  b.t_s = *t0_s_ + static_cast<double>(fed_) / options_.fs_hz;
  const Eigen::VectorXd residual = detector_->BlockResidual(block);
  const oma::SubspaceTestResult single = detector_->Test(block);
  b.statistic = single.statistic;
  b.f_quantile = single.threshold;
  b.block_over = single.alarm;
  const oma::AccumulatedTestResult acc = window_->Add(residual);
  b.accumulated_statistic = acc.statistic;
  b.accumulated_threshold = acc.threshold;
  b.window_count = acc.count;
  b.window_blocks = options_.window_blocks;
  b.window_alarm = acc.alarm;
  const oma::SequentialTestResult seq = sequential_->Add(residual);
  b.sequential_statistic = seq.statistic;
  b.sequential_threshold = seq.threshold;
  b.sequential_onset_blocks = seq.onset_blocks;
  b.sequential_blocks = seq.blocks;
  b.sequential_alarm = seq.alarm;
  b.alarm = b.window_alarm || b.sequential_alarm;
  if (b.alarm && !first_alarm_t_s_) first_alarm_t_s_ = b.t_s;
  b.first_alarm_t_s = first_alarm_t_s_;
  b.board = board_;

  if (options_.modes_s > 0.0) {
    recent_.emplace_back(block);
    const auto keep =
        static_cast<std::size_t>(std::ceil(options_.modes_s / options_.block_s - 1e-9));
    while (recent_.size() > keep) recent_.pop_front();
    Eigen::MatrixXd y(static_cast<Eigen::Index>(recent_.size()) * block.rows(), block.cols());
    Eigen::Index row = 0;
    for (const Eigen::MatrixXd& r : recent_) {
      y.middleRows(row, r.rows()) = r;
      row += r.rows();
    }
    oma::SsiCovOptions so;
    so.fs_hz = options_.fs_hz;
    so.fmax_hz = options_.fmax_hz;
    try {
      const oma::SsiCovResult r = oma::SsiCov(y, so);
      b.modes = ModesOf(r);
      b.modes_message = r.message;
      b.moved = MovedMost(b.modes, reference_.modes);
    } catch (const InputError& e) {
      // Too little data since the start or the last gap: the modes come once there is enough.
      b.modes_message = e.what();
    }
  }
  b.analysis_ms = MsSince(start);
  return b;
}

}  // namespace vibid::workflow
