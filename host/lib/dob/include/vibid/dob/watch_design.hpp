// The design of the board's residual test (vibid::fixed::ResidualCusum, methods §13): from a
// calibration-day recording replayed through the bit-exact observer replay, the residual's scale,
// the window, the window mean's in-control mean and spread, and Page's CUSUM reference value and
// threshold from the false-alarm rate the user states.
//
// Run lengths: the CUSUM g = max(0, g + z - k) on independent N(mean, 1) increments reaches h after
// about ARL(mean) = (exp(-2 d b) + 2 d b - 1) / (2 d^2), d = mean - k, b = h + 1.166 windows
// (Siegmund, Sequential Analysis, Springer 1985; b^2 at d = 0). The in-control run length (mean 0)
// sets h for the stated false-alarm rate; at the shift the test is built for (mean =
// shift_spreads), k = shift_spreads / 2 is Page's optimal reference value.
// The window mean of r^2 is not Gaussian but skewed (a sum of squares), which Siegmund's h would
// turn into 2 to 3 times the stated false alarms; the design models it as a Pearson type III
// (shifted Gamma) variable of the calibration day's mean, spread and skew and takes h from the
// Brook-Evans Markov chain of the CUSUM on those increments (Brook & Evans, Biometrika 59, 1972),
// Siegmund's h kept for comparison.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "vibid/shared/fixed/filter_description.hpp"
#include "vibid/shared/fixed/residual_cusum.hpp"

namespace vibid::dob {

/// Siegmund's approximation of the one-sided CUSUM's average run length (windows) for N(mean, 1)
/// increments, reference value k and threshold h.
double CusumRunLength(double mean, double k, double h);

/// The threshold h whose in-control run length (mean 0) is arl0_windows at reference value k.
/// InputError unless arl0_windows > 1 and k >= 0.
double CusumThreshold(double arl0_windows, double k);

/// The regularized lower incomplete gamma function P(a, x).
double RegularizedGammaLower(double a, double x);

/// The CUSUM's average run length (windows) when the standardized window mean z = (e - mu0) /
/// sigma0 is in control a Pearson type III variable (G - shape) / sqrt(shape), G ~ Gamma(shape, 1),
/// of skew 2 / sqrt(shape), and e is scaled by `ratio` (1: in control; mean_over_spread = mu0 /
/// sigma0 is then unused) (Brook-Evans Markov chain).
double CusumRunLengthGamma(double shape, double ratio, double mean_over_spread, double k, double h);

/// The same for increments scale z + offset, z the Pearson III variable above (Brook-Evans).
double CusumRunLengthGammaAffine(double shape, double scale, double offset, double k, double h);

/// The threshold whose in-control run length is arl0_windows for Gamma window means of `shape`.
double CusumThresholdGamma(double arl0_windows, double shape, double k);

/// The threshold whose run length is arl0_windows for increments scale z + offset.
double CusumThresholdGammaAffine(double arl0_windows, double shape, double scale, double offset,
                                 double k);

struct WatchOptions {
  /// The false alarms per hour of in-control running the user accepts (the default: one in
  /// 1000 hours).
  double false_alarms_per_hour = 1.0e-3;
  /// The shift of the window mean, in its in-control spreads, the test is tuned to catch fastest
  /// (k = shift / 2). Half a spread: with one spread (k 0.5) the threshold that keeps the rate
  /// for a 500 s calibration day on the built-in rig (h 26 at the default rate, the centre known
  /// to about 0.02 spreads a side) left its 3 % mass step unflagged 900 s after it; at half a
  /// spread the same day flags it within about 5 minutes (hil ModelStaleTest).
  double shift_spreads = 0.5;
  /// Samples per window; 0 chooses it from the residual's correlation time.
  std::uint32_t window_samples = 0;
  /// The largest pole radius of the observer whose residual is watched (SlowestPoleRadius of the
  /// quantized observer the record carries), for the hold-off after its start; 0 for an observer
  /// without feedback.
  double observer_pole_radius = 0.0;
};

struct WatchDesign {
  fixed::ResidualCusumParams params;  ///< What the board runs (calibration record, Watch block).
  double fs_hz = 0.0;
  double window_s = 0.0;
  double residual_scale = 0.0;       ///< r = residual_scale (d_hat - reference_ratio reference).
  double reference_ratio = 0.0;      ///< Reference full scale / d_hat full scale; 0: r = d_hat.
  double correlation_samples = 0.0;  ///< The residual's integral correlation time.
  std::size_t calibration_windows = 0;
  double mu0 = 0.0;          ///< In-control mean of the window mean of r^2 (kernel units).
  double sigma0 = 0.0;       ///< Its in-control spread.
  double window_lag1 = 0.0;  ///< Lag-1 correlation of the calibration windows' means.
  double window_skew = 0.0;  ///< Skewness of their standardized means (0 for Gaussian).
  double gamma_shape = 0.0;  ///< 4 / skew^2: the window mean's Pearson III model.
  double k = 0.0;
  double h = 0.0;           ///< From the Gamma model's run length (what the board uses).
  double h_gaussian = 0.0;  ///< Siegmund's for Gaussian increments, for comparison.
  /// The calibration's in-control run length: at its own estimates of the window mean's centre
  /// and spread, with the long-run variance of the window means.
  double arl0_windows = 0.0;
  double false_alarms_per_hour = 0.0;  ///< The rate asked: the band's upper end.
  /// Long-run over single-window variance of the window means (batch means, at least 1).
  double window_long_run_ratio = 1.0;
  std::size_t batch_windows = 0;  ///< Windows per batch of the batch means.
  /// Variance ratio of the window means' partial sums over h / k windows (the stretch a false
  /// trip takes): the model's increments are scaled by its square root.
  double path_variance_ratio = 1.0;
  double centre_se_spreads = 0.0;     ///< Standard error of the centre, in window spreads.
  double log_spread_se = 0.0;         ///< Standard error of the spread's logarithm.
  double false_alarms_low = 0.0;      ///< This calibration's rate: 2.5 % point (per hour).
  double false_alarms_high = 0.0;     ///< 97.5 % point (the rate asked, to the iteration).
  double detection_windows = 0.0;     ///< Run length at shift_spreads (Gamma model).
  double observer_pole_radius = 0.0;  ///< The options' (the observer's slowest pole).
  /// The samples after the observer's start until its start transient can add at most
  /// kHoldoffSpreads to g (HoldoffSamples); params.holdoff_windows is this in windows.
  double holdoff_samples = 0.0;
};

/// What a start transient may still add to g, in the window mean's spreads, once the hold-off ends.
inline constexpr double kHoldoffSpreads = 0.1;

/// The largest |z| over the poles of every section of every path of the quantized observer (the
/// roots of z^2 + a1 z + a2 with the sections' integer a1, a2 as the board runs them); 0 for an
/// observer of pure gains or FIR sections.
double SlowestPoleRadius(const fixed::FilterDescription& description);

/// The samples n after the observer's start beyond which its start transient, decaying no slower
/// than A rho^n from the largest residual the kernel can form, A = 2^31 (|residual_gain| +
/// |reference_gain|) / 2^32, adds at most kHoldoffSpreads to g: the transient's r^2 summed over
/// every window after n, A^2 rho^(2n) / (1 - rho^2), is that many window-sum spreads:
///   n = ln(A^2 / ((1 - rho^2) sum_spread kHoldoffSpreads)) / (-2 ln rho),   0 when the log is <= 0
/// sum_spread = W sigma0 (the in-control spread of a window's sum of r^2, kernel units).
/// InputError for rho >= 1 (the transient never decays); 0 for rho = 0.
double HoldoffSamples(double pole_radius, double max_residual, double sum_spread);

/// Designs the test from the calibration day's replayed d_hat (Q31 of the observer's output full
/// scale) and, with a reference load cell, its calibrated samples (Q31 of its channel's full
/// scale; empty for r = d_hat) with reference_ratio = its full scale over d_hat's.
/// InputError naming the cause and the way out: fewer than 50 windows in the recording (a longer
/// one), a residual that is zero, window means correlated beyond 0.3 at lag 1 (a longer window),
/// options out of range.
WatchDesign DesignWatch(std::span<const std::int32_t> d_hat_q31,
                        std::span<const std::int32_t> reference_q31, double reference_ratio,
                        double fs_hz, const WatchOptions& options);

/// The windows of the calibration recording as the board computes them: the window sums of r^2
/// (the kernel's integers), for the design and its tests.
std::vector<std::int64_t> WindowSums(std::span<const std::int32_t> d_hat_q31,
                                     std::span<const std::int32_t> reference_q31,
                                     std::int32_t residual_gain, std::int32_t reference_gain,
                                     std::uint32_t window_samples);

}  // namespace vibid::dob
