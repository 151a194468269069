// A sequential test of the block residuals: a window-limited generalized likelihood ratio (GLR)
// for a shift of their mean, in the reference's metric. After block n,
//
//   g_n = max over k = k₀ … L of  k/(1 + k/m) · (ȳ_k − μ̂)ᵀ Ŝ⁻¹ (ȳ_k − μ̂),
//
// ȳ_k the mean of the last k residuals, μ̂ and Ŝ the reference's mean and covariance from m
// blocks: twice the log likelihood ratio of "the mean moved k blocks ago, to whatever value"
// against "unchanged", maximised over the onset (Willsky & Jones, IEEE TAC 21 1976; Lai, JRSS B
// 57 1995), each onset's term in its two-sample form (ȳ_k − μ̂ has covariance Σ (1/k + 1/m):
// the reference's own mean error weighs on the long onsets as on the window test; at the
// watch's defaults, onsets from one block, it needs h 53 where k · (…) needs 65 for the same
// rate, and alarms a known step sooner). The shortest onset k₀ is 6 blocks (L where shorter):
// one block's residual is a ratio of covariances, heavier-tailed than Gaussian far out (its T²
// exceeds the F law's quantile 7 to 9 times as often as it should at the rates the watch asks),
// where a mean of six is close to Gaussian (the window test's windows of 6 hold their band:
// docs/watch.md); with onsets from one block the unchanged rig of the delay study alarmed 3
// times in 10.7 h at 0.01 per hour asked. It alarms
// when g_n > h, and the k that maximised it is the change's estimated onset. Unlike the window
// test it waits for no window to fill: a shift of noncentrality δ² per block is alarmed about
// 2 ln(ARL)/δ² blocks after it (Lorden, Ann. Math. Stat. 42 1971), whenever it comes. L bounds
// the memory (and the reference's own mean error, which acts on k blocks as a shift k times its
// square: below). After an alarm the test starts afresh, so alarms are counted as renewals.
//
// h is set by the run-length law for the one reference a user has (SequentialCalibration): the
// rate at which g crosses h per block, for a reference with covariance error S and mean error e
// (whitened by the truth), is taken as A · Σₖ qₖ(h) Pₖ(h), Pₖ(h) the probability that
// k/(1 + k/m) (z̄ₖ − e)ᵀ S⁻¹ (z̄ₖ − e) exceeds h (a quadratic form in Gaussian variables,
// numerics::QuadraticFormTail) and qₖ(h) = (b²/2k)² ν(b/√k)² the local clumping of a Gaussian
// scan over onsets (Siegmund & Venkatraman, Ann. Stat. 23 1995: for an exact reference this is
// their C · h^{p/2} e^{−h/2}; ν Siegmund's overshoot correction; b² the level h in units of the
// form's heaviest weights, h itself for an exact reference). A, one constant per (p, m, L),
// is fitted by simulating the exact reference's GLR at a moderate rate (a fixed seed). Plausible
// references given the one in hand are drawn as for the window test; h is the one at which
// 97.5 % of them give at most the rate asked, and the band between their 2.5 % and 97.5 % points
// is stated. It holds when the residuals are independent and Gaussian.
#pragma once

#include <Eigen/Core>

namespace vibid::oma {

/// The shortest onset the sequential test weighs (blocks; L where L is shorter).
inline constexpr int kSequentialMinOnsetBlocks = 6;

struct SequentialCalibration {
  double threshold = 0.0;  ///< h: the rate ≤ the asked one for 97.5 % of references.
  double low = 0.0;        ///< The false-alarm probability per block a reference gives at h:
  double high = 0.0;       ///< 2.5 % and 97.5 % points over references (high ≈ the asked one),
  double mean = 0.0;       ///< and its mean over references.
  /// h for an exact reference (no estimation error), and the band references give at it.
  double exact_threshold = 0.0;
  double exact_low = 0.0;
  double exact_high = 0.0;
  double crossing_constant = 0.0;  ///< A, fitted by simulation.
  double fit_rate = 0.0;           ///< The simulated rate per block A was fitted at,
  double fit_threshold = 0.0;      ///< at this h.
};

/// p residuals, m reference observations (≥ p + 2), onsets up to `max_blocks` (1 … 720) blocks
/// back, `false_alarm` per block in (0, 0.05]. InputError otherwise. Cached per sizes; about
/// 1 s of CPU the first time at the watch's defaults.
SequentialCalibration CalibrateSequential(int p, int m, int max_blocks, double false_alarm);

/// The rate per block at which the GLR crosses h for a reference whose covariance (whitened by
/// the truth) has `eigenvalues` and whose mean's error, in those eigenvectors, is `mean_error`
/// (both from CalibrateSequential's model; A its crossing constant). For the tests.
double SequentialCrossingRate(const Eigen::VectorXd& eigenvalues, const Eigen::VectorXd& mean_error,
                              int m, int max_blocks, double h, double crossing_constant);

struct SequentialTestResult {
  double statistic = 0.0;  ///< g_n.
  double threshold = 0.0;  ///< h.
  /// The k that maximised g_n: the change began k blocks back (0 while fewer than k₀ are held).
  int onset_blocks = 0;
  int blocks = 0;      ///< Blocks the statistic holds (since the start or the last alarm, ≤ L).
  bool alarm = false;  ///< g_n > h (the test then starts afresh).
};

class SequentialTest {
 public:
  /// `reference`: one column per reference observation (p rows, m ≥ p + 2 columns);
  /// `max_blocks` L; `false_alarm` per block. InputError naming what is wrong otherwise.
  SequentialTest(Eigen::Ref<const Eigen::MatrixXd> reference, int max_blocks, double false_alarm);

  SequentialTestResult Add(Eigen::Ref<const Eigen::VectorXd> observation);

  int max_blocks() const { return max_blocks_; }
  double threshold() const { return calibration_.threshold; }
  const SequentialCalibration& calibration() const { return calibration_; }
  /// Judges at another h from now on (a study's: the exact reference's, to compare).
  void set_threshold(double h) { calibration_.threshold = h; }

 private:
  int max_blocks_ = 1;
  int m_ = 0;
  Eigen::VectorXd mean_;
  Eigen::MatrixXd whiten_;  // L⁻¹ of the reference covariance's Cholesky factor
  SequentialCalibration calibration_;
  Eigen::MatrixXd recent_;  // whitened residuals, a ring of max_blocks columns
  int newest_ = 0;          // its newest column
  int held_ = 0;            // residuals held since the start or the last alarm
  Eigen::VectorXd sum_;
};

}  // namespace vibid::oma
