#include "vibid/dob/watch_design.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "vibid/common/error.hpp"

namespace vibid::dob {
namespace {

constexpr std::size_t kMinWindows = 50;
constexpr double kMaxWindowLag1 = 0.3;
constexpr std::uint32_t kMinWindowSamples = 64;
// The window holds this many correlation times of the residual, so its means are nearly
// independent and (by the central limit theorem over about 40 independent stretches) close to
// Gaussian, the increments Siegmund's approximation assumes.
constexpr double kWindowCorrelationTimes = 40.0;

std::int32_t Q32(double gain) {
  return static_cast<std::int32_t>(std::lround(std::ldexp(gain, 32)));
}

// Integral correlation time (samples) of x: 1 + 2 sum of the autocorrelation up to its first
// zero crossing (or max_lag).
double CorrelationSamples(std::span<const double> x, std::size_t max_lag) {
  const std::size_t n = x.size();
  double var = 0.0;
  for (const double v : x) var += v * v;
  if (var <= 0.0) return 1.0;
  double tau = 1.0;
  for (std::size_t lag = 1; lag < std::min(max_lag, n / 4); ++lag) {
    double c = 0.0;
    for (std::size_t i = lag; i < n; ++i) c += x[i] * x[i - lag];
    const double rho = c / var;
    if (rho <= 0.0) break;
    tau += 2.0 * rho;
  }
  return tau;
}

}  // namespace

double SlowestPoleRadius(const fixed::FilterDescription& description) {
  double radius = 0.0;
  for (std::size_t i = 0; i < description.input_count && i < fixed::kMaxInputs; ++i) {
    const fixed::Path& path = description.paths[i];
    for (std::size_t j = 0; j < path.section_count && j < fixed::kMaxSections; ++j) {
      const fixed::Section& s = path.sections[j];
      const double one = std::ldexp(1.0, 31 - s.shift);  // Q(31 - shift)
      const double a1 = s.a1 / one;
      const double a2 = s.a2 / one;
      // z^2 + a1 z + a2: complex roots have |z|^2 = a2, real ones (-a1 +- sqrt(disc)) / 2.
      const double disc = a1 * a1 - 4.0 * a2;
      const double r =
          disc < 0.0 ? std::sqrt(a2) : 0.5 * (std::fabs(a1) + std::sqrt(disc));  // the larger root
      radius = std::max(radius, r);
    }
  }
  return radius;
}

double HoldoffSamples(double pole_radius, double max_residual, double sum_spread) {
  if (!(pole_radius >= 0.0) || !(max_residual > 0.0) || !(sum_spread > 0.0)) {
    throw InputError("watch hold-off: the pole radius, residual bound and spread must be positive");
  }
  if (pole_radius >= 1.0) {
    throw InputError(
        "watch design: the observer has a pole on or outside the unit circle (radius " +
        std::to_string(pole_radius) +
        "): its start transient never decays, so the test cannot tell it from a stale model; "
        "design a stable observer");
  }
  if (pole_radius == 0.0) return 0.0;
  const double ratio = max_residual * max_residual /
                       ((1.0 - pole_radius * pole_radius) * sum_spread * kHoldoffSpreads);
  return ratio <= 1.0 ? 0.0 : std::log(ratio) / (-2.0 * std::log(pole_radius));
}

double RegularizedGammaLower(double a, double x) {
  // Numerical Recipes (3rd ed., section 6.2): the series below a + 1, the continued fraction
  // (modified Lentz) above.
  if (x <= 0.0) return 0.0;
  const double log_prefix = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a;
    double sum = term;
    for (int n = 1; n < 100000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::fabs(term) < std::fabs(sum) * 1e-15) break;
    }
    return std::min(1.0, sum * std::exp(log_prefix));
  }
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double f = d;
  for (int i = 1; i < 100000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    f *= delta;
    if (std::fabs(delta - 1.0) < 1e-15) break;
  }
  return std::max(0.0, 1.0 - std::exp(log_prefix) * f);
}

double CusumRunLengthGamma(double shape, double ratio, double mean_over_spread, double k,
                           double h) {
  // In control z = (G - shape) / sqrt(shape), G ~ Gamma(shape, 1) (Pearson type III of skew
  // 2 / sqrt(shape)); e = mu0 + sigma0 z scaled by `ratio` gives z' = ratio z + (ratio - 1) mu0 /
  // sigma0.
  return CusumRunLengthGammaAffine(shape, ratio, (ratio - 1.0) * mean_over_spread, k, h);
}

double CusumRunLengthGammaAffine(double shape, double scale, double offset, double k, double h) {
  // Brook & Evans (Biometrika 59, 1972): g on a grid of kStates points 0, w, 2w, .. below h; a
  // step moves it by the increment z' - k, rounded to the grid (to 0 at or below half a step);
  // above h it stops. The run length from each state solves (I - R) L = 1.
  // z' = scale z + offset, so P(z' <= x) = P(shape, shape + sqrt(shape) (x - offset) / scale).
  constexpr int kStates = 240;
  const double w = h / (kStates - 0.5);
  const double sqrt_shape = std::sqrt(shape);
  auto cdf = [&](double x) {
    return RegularizedGammaLower(shape, shape + sqrt_shape * (x - offset) / scale);
  };
  // The CDF at the grid's cell edges: the edge k + (j + 0.5 - i) w depends on j - i only.
  std::vector<double> edge(2 * kStates);
  for (int m = 0; m < 2 * kStates; ++m) {
    edge[static_cast<std::size_t>(m)] = cdf(k + (m - kStates + 0.5) * w);
  }
  Eigen::MatrixXd a = Eigen::MatrixXd::Identity(kStates, kStates);
  for (int i = 0; i < kStates; ++i) {
    double below = edge[static_cast<std::size_t>(kStates - i)];
    a(i, 0) -= below;
    for (int j = 1; j < kStates; ++j) {
      const double upto = edge[static_cast<std::size_t>(kStates + j - i)];
      a(i, j) -= upto - below;
      below = upto;
    }
  }
  const Eigen::VectorXd run = a.partialPivLu().solve(Eigen::VectorXd::Ones(kStates));
  return run(0);
}

double CusumThresholdGamma(double arl0_windows, double shape, double k) {
  return CusumThresholdGammaAffine(arl0_windows, shape, 1.0, 0.0, k);
}

double CusumThresholdGammaAffine(double arl0_windows, double shape, double scale, double offset,
                                 double k) {
  if (!(arl0_windows > 1.0) || !(k >= 0.0) || !(shape > 0.0) || !(scale > 0.0) ||
      !std::isfinite(arl0_windows)) {
    throw InputError(
        "CUSUM threshold: the in-control run length must exceed one window, k be >= 0");
  }
  auto run = [&](double h) { return CusumRunLengthGammaAffine(shape, scale, offset, k, h); };
  double lo = 0.0;
  double hi = 1.0;
  while (run(hi) < arl0_windows) {
    hi *= 2.0;
    if (hi > 1e4) throw InputError("CUSUM threshold: no threshold reaches this run length");
  }
  for (int i = 0; i < 60 && hi - lo > 1e-6 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (run(mid) < arl0_windows ? lo : hi) = mid;
  }
  return hi;
}

double CusumRunLength(double mean, double k, double h) {
  const double d = mean - k;
  const double b = h + 1.166;
  if (std::fabs(d) < 1e-9) return b * b;
  return (std::exp(-2.0 * d * b) + 2.0 * d * b - 1.0) / (2.0 * d * d);
}

double CusumThreshold(double arl0_windows, double k) {
  if (!(arl0_windows > 1.0) || !(k >= 0.0) || !std::isfinite(arl0_windows)) {
    throw InputError(
        "CUSUM threshold: the in-control run length must exceed one window and k be >= 0");
  }
  double lo = 0.0;
  double hi = 1.0;
  while (CusumRunLength(0.0, k, hi) < arl0_windows) hi *= 2.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (CusumRunLength(0.0, k, mid) < arl0_windows ? lo : hi) = mid;
  }
  return hi;
}

std::vector<std::int64_t> WindowSums(std::span<const std::int32_t> d_hat_q31,
                                     std::span<const std::int32_t> reference_q31,
                                     std::int32_t residual_gain, std::int32_t reference_gain,
                                     std::uint32_t window_samples) {
  // The kernel's own arithmetic (residual_cusum.hpp), so the centre and spread are those of the
  // integers the board sums.
  std::vector<std::int64_t> sums;
  std::int64_t sum = 0;
  std::uint32_t left = window_samples;
  for (std::size_t n = 0; n < d_hat_q31.size(); ++n) {
    const std::int32_t ref = reference_q31.empty() ? 0 : reference_q31[n];
    const std::int64_t acc = std::int64_t{d_hat_q31[n]} * residual_gain +
                             std::int64_t{ref} * reference_gain + (std::int64_t{1} << 31);
    const auto r = std::clamp(static_cast<std::int32_t>(acc >> 32), fixed::kMinScaledResidual,
                              fixed::kMaxScaledResidual);
    sum += std::int64_t{r} * r;
    if (--left == 0) {
      sums.push_back(sum);
      sum = 0;
      left = window_samples;
    }
  }
  return sums;
}

WatchDesign DesignWatch(std::span<const std::int32_t> d_hat_q31,
                        std::span<const std::int32_t> reference_q31, double reference_ratio,
                        double fs_hz, const WatchOptions& options) {
  if (!(fs_hz > 0.0) || !(options.false_alarms_per_hour > 0.0) || !(options.shift_spreads > 0.0) ||
      options.window_samples > fixed::kMaxWindowSamples) {
    throw InputError(
        "watch design: the sample rate, the false-alarm rate and the shift must be positive and "
        "the window at most 65536 samples");
  }
  if (!reference_q31.empty() && reference_q31.size() != d_hat_q31.size()) {
    throw InputError("watch design: the reference and d_hat differ in length");
  }
  if (!reference_q31.empty() &&
      !(std::fabs(reference_ratio) > 0.0 && std::fabs(reference_ratio) < 2.0)) {
    throw InputError("watch design: the reference's full scale over d_hat's must be in (0, 2)");
  }
  WatchDesign d;
  d.fs_hz = fs_hz;
  d.reference_ratio = reference_q31.empty() ? 0.0 : reference_ratio;

  // The residual in d_hat's Q31 units, its RMS and correlation time.
  std::vector<double> r(d_hat_q31.size());
  double power = 0.0;
  for (std::size_t n = 0; n < r.size(); ++n) {
    r[n] = d_hat_q31[n] - (reference_q31.empty() ? 0.0 : d.reference_ratio * reference_q31[n]);
    power += r[n] * r[n];
  }
  const double rms = r.empty() ? 0.0 : std::sqrt(power / static_cast<double>(r.size()));
  if (!(rms > 0.0)) {
    throw InputError(
        "watch design: the residual of the calibration recording is zero (is the observer "
        "running in it?); record the rig running with the observer's inputs logged");
  }
  d.correlation_samples = CorrelationSamples(r, 20000);
  std::uint32_t w = options.window_samples;
  if (w == 0) {
    const double want =
        std::max<double>(kMinWindowSamples, kWindowCorrelationTimes * d.correlation_samples);
    w = static_cast<std::uint32_t>(std::min<double>(fixed::kMaxWindowSamples, std::ceil(want)));
  }
  d.params.window_samples = w;
  d.window_s = w / fs_hz;
  d.calibration_windows = d_hat_q31.size() / w;
  if (d.calibration_windows < kMinWindows) {
    throw InputError("watch design: the calibration recording holds " +
                     std::to_string(d.calibration_windows) + " windows of " + std::to_string(w) +
                     " samples; at least " + std::to_string(kMinWindows) +
                     " are needed to measure their spread: record at least " +
                     std::to_string(static_cast<int>(std::ceil(kMinWindows * d.window_s))) + " s");
  }

  // The scale: the residual's RMS near 2^15 (at most a gain of 1/2, see residual_cusum.hpp).
  d.residual_scale = std::min(0.5, std::ldexp(1.0, 15) / rms);
  d.params.residual_gain = Q32(d.residual_scale);
  d.params.reference_gain = reference_q31.empty() ? 0 : Q32(-d.reference_ratio * d.residual_scale);
  if (!reference_q31.empty() && d.params.reference_gain == 0) {
    throw InputError("watch design: the reference's gain rounds to zero");
  }

  const std::vector<std::int64_t> sums =
      WindowSums(d_hat_q31, reference_q31, d.params.residual_gain, d.params.reference_gain, w);
  double mean_sum = 0.0;
  for (const auto s : sums) mean_sum += static_cast<double>(s);
  mean_sum /= static_cast<double>(sums.size());
  double var = 0.0;
  double third = 0.0;
  double lag1 = 0.0;
  for (std::size_t i = 0; i < sums.size(); ++i) {
    const double e = static_cast<double>(sums[i]) - mean_sum;
    var += e * e;
    third += e * e * e;
    if (i > 0) lag1 += e * (static_cast<double>(sums[i - 1]) - mean_sum);
  }
  const double n = static_cast<double>(sums.size());
  const double sd_sum = std::sqrt(var / (n - 1.0));
  d.mu0 = mean_sum / w;
  d.sigma0 = sd_sum / w;
  d.window_lag1 = lag1 / var;
  d.window_skew = (third / n) / std::pow(var / n, 1.5);
  if (!(sd_sum > 0.0)) throw InputError("watch design: the calibration windows do not vary");
  if (d.window_lag1 > kMaxWindowLag1) {
    throw InputError("watch design: successive windows of " + std::to_string(w) +
                     " samples are correlated (" + std::to_string(d.window_lag1) +
                     " at lag 1, at most 0.3): the residual varies slower than the window; "
                     "choose a longer window");
  }

  // The kernel's integers: S >> sum_shift near 2^24, z_gain in [2^30, 2^31) (residual_cusum.hpp).
  const int sum_shift = std::clamp(static_cast<int>(std::floor(std::log2(mean_sum))) - 24, 0,
                                   static_cast<int>(fixed::kMaxSumShift));
  d.params.sum_shift = static_cast<std::uint8_t>(sum_shift);
  d.params.center = static_cast<std::int32_t>(std::lround(std::ldexp(mean_sum, -sum_shift)));
  const double unit = std::ldexp(1.0, 16 + sum_shift) / sd_sum;
  int z_shift = 0;
  while (z_shift < fixed::kMaxZShift && unit * std::ldexp(1.0, z_shift + 1) < 2147483647.0)
    ++z_shift;
  d.params.z_shift = static_cast<std::uint8_t>(z_shift);
  d.params.z_gain = static_cast<std::int32_t>(std::lround(std::ldexp(unit, z_shift)));

  // k and h: the stated false-alarm rate as the in-control run length in windows. The window
  // mean of r^2 is a sum of squares, skewed to the right: a Gaussian z understates its upper tail
  // (Siegmund's h gave 2.6 times the stated false alarms at 40 correlation times a window, and a
  // Gamma fitted to the mean and spread alone 1.6 times: a coloured residual's weighted sum of
  // chi-squares is more skewed than the two-moment Gamma). So z is modelled as a Pearson type III
  // variable (a shifted Gamma) of the measured skew, never below the two-moment Gamma's
  // 2 sigma0 / mu0, and the run lengths come from the Brook-Evans Markov chain of the CUSUM on
  // those increments.
  const double skew = std::max(d.window_skew, 2.0 * d.sigma0 / d.mu0);
  d.gamma_shape = 4.0 / (skew * skew);
  d.k = options.shift_spreads / 2.0;
  d.false_alarms_per_hour = options.false_alarms_per_hour;
  d.h_gaussian = CusumThreshold(3600.0 / d.window_s / options.false_alarms_per_hour, d.k);

  // The rate on the hours after the calibration day, not on the day itself. The kernel's centre
  // and spread are the day's estimates: a centre off by delta spreads adds delta to every
  // increment, a spread off by a factor scales them, and either moves the rate several-fold at
  // these thresholds. And the window means correlate weakly over many lags (the lag-1 check lets
  // that through), which both widens those estimates' errors and makes the CUSUM's partial sums
  // vary more than independent windows would. Batch means of the standardized window means give
  // honest standard errors: the centre's from the long-run variance ratio (batches of about
  // sqrt(n) windows), the spread's from the batches of z^2; a variance ratio below one is read
  // as noise. The CUSUM is modelled on independent increments c e^eps z + delta, delta ~ N(0,
  // se_centre), eps ~ N(0, se_log_spread), c^2 the variance ratio over the stretch a false trip
  // takes: the likeliest path of g to h rises by about k a window for h / k windows, so the
  // partial sums over that many windows are what must vary as much as the model's (the
  // correlated CUSUM is governed by its partial sums' variance: Johnson & Bagshaw,
  // Technometrics 16, 1974). The log of the rate is taken as linear over one standard error
  // each side. h puts the rate's 97.5 % point at the rate asked, and the band [2.5 %, 97.5 %]
  // is what this calibration is stated to give.
  std::vector<double> z(sums.size());
  for (std::size_t i = 0; i < sums.size(); ++i) {
    z[i] = (static_cast<double>(sums[i]) - mean_sum) / sd_sum;
  }
  // Sample variance of the means of successive batches of `batch` values of x (or of x^2).
  auto batch_variance = [](const std::vector<double>& x, std::size_t batch, bool squared) {
    const std::size_t batches = x.size() / batch;
    std::vector<double> m(batches, 0.0);
    for (std::size_t i = 0; i < batches * batch; ++i) {
      m[i / batch] += (squared ? x[i] * x[i] : x[i]) / static_cast<double>(batch);
    }
    double mean = 0.0;
    for (const double v : m) mean += v;
    mean /= static_cast<double>(batches);
    double q = 0.0;
    for (const double v : m) q += (v - mean) * (v - mean);
    return q / static_cast<double>(batches - 1);
  };
  const std::size_t batch = std::max<std::size_t>(
      1, static_cast<std::size_t>(std::floor(std::sqrt(static_cast<double>(z.size())))));
  const auto batches = static_cast<double>(z.size() / batch);
  d.batch_windows = batch;
  d.window_long_run_ratio =
      std::max(1.0, static_cast<double>(batch) * batch_variance(z, batch, false));
  d.centre_se_spreads = std::sqrt(d.window_long_run_ratio / n);
  d.log_spread_se = 0.5 * std::sqrt(batch_variance(z, batch, true) / batches);
  auto path_ratio = [&](double h) {
    const auto m = static_cast<std::size_t>(
        std::clamp(std::round(h / std::max(d.k, 1e-3)), 1.0, static_cast<double>(batch)));
    return m == 1 ? 1.0 : std::max(1.0, static_cast<double>(m) * batch_variance(z, m, false));
  };

  const double windows_per_hour = 3600.0 / d.window_s;
  double scale = 1.0;
  auto log_rate = [&](double h, double delta, double eps) {
    return std::log(windows_per_hour /
                    CusumRunLengthGammaAffine(d.gamma_shape, scale * std::exp(eps), delta, d.k, h));
  };
  auto log_rate_spread = [&](double h) {
    const double by_centre =
        0.5 * (log_rate(h, d.centre_se_spreads, 0.0) - log_rate(h, -d.centre_se_spreads, 0.0));
    const double by_spread =
        0.5 * (log_rate(h, 0.0, d.log_spread_se) - log_rate(h, 0.0, -d.log_spread_se));
    return std::hypot(by_centre, by_spread);
  };
  constexpr double kZ975 = 1.959964;  // the standard normal's 97.5 % point
  // The fixed point h = threshold(rate asked / e^(1.96 spread(h))): the partial sums' ratio is
  // taken at the h of the first steps, then held (its window count is a whole number, which
  // could leave the iteration alternating), and the spread, which grows slowly with h, iterated
  // until h settles.
  double spread = 0.0;
  d.h = CusumThresholdGamma(windows_per_hour / options.false_alarms_per_hour, d.gamma_shape, d.k);
  for (int iteration = 0; iteration < 30; ++iteration) {
    if (iteration < 3) {
      d.path_variance_ratio = path_ratio(d.h);
      scale = std::sqrt(d.path_variance_ratio);
    }
    spread = log_rate_spread(d.h);
    const double h = CusumThresholdGammaAffine(
        windows_per_hour / options.false_alarms_per_hour * std::exp(kZ975 * spread), d.gamma_shape,
        scale, 0.0, d.k);
    const bool settled = iteration >= 3 && std::fabs(h - d.h) < 1e-4 * d.h;
    d.h = h;
    if (settled) break;
  }
  spread = log_rate_spread(d.h);
  const double centre = log_rate(d.h, 0.0, 0.0);
  d.arl0_windows = windows_per_hour / std::exp(centre);
  d.false_alarms_low = std::exp(centre - kZ975 * spread);
  d.false_alarms_high = std::exp(centre + kZ975 * spread);
  if (d.h >= fixed::kMaxStatistic / 65536.0) {
    throw InputError("watch design: the threshold for this false-alarm rate exceeds the board's");
  }
  d.params.k = static_cast<std::int32_t>(std::lround(d.k * 65536.0));
  d.params.h = static_cast<std::int32_t>(std::lround(d.h * 65536.0));
  // The power raised by shift_spreads spreads: the Gamma scaled by 1 + shift sigma0 / mu0.
  d.detection_windows = CusumRunLengthGamma(
      d.gamma_shape, 1.0 + options.shift_spreads * d.sigma0 / d.mu0, d.mu0 / d.sigma0, d.k, d.h);
  // The hold-off: the observer starts from rest while a running rig's inputs do not, so its
  // residual opens with a transient that decays with the observer's slowest pole. Before its
  // clamp, |r| is at most d_hat (and the reference) at full scale times the gains, so a transient
  // of A rho^n with A that bound covers any start (the clamp only lowers it); the windows until
  // that transient can add at most kHoldoffSpreads to g (HoldoffSamples) are computed but not
  // judged. At least one: the first window always holds the observer's fill from rest. A repeated
  // pole's n rho^n envelope is not covered; the margin of a full-scale transient (far beyond any
  // measured start) covers its factor.
  d.observer_pole_radius = options.observer_pole_radius;
  const double max_residual =
      std::ldexp(std::fabs(static_cast<double>(d.params.residual_gain)) +
                     std::fabs(static_cast<double>(d.params.reference_gain)),
                 -1);  // 2^31 |gain| / 2^32
  d.holdoff_samples = HoldoffSamples(options.observer_pole_radius, max_residual, sd_sum);
  const double holdoff_windows = std::max(1.0, std::ceil(d.holdoff_samples / w));
  if (holdoff_windows > 255.0) {
    throw InputError(
        "watch design: the observer's slowest pole (radius " +
        std::to_string(options.observer_pole_radius) + ", time constant " +
        std::to_string(-1.0 / std::log(options.observer_pole_radius) / fs_hz) +
        " s) settles after its start in " + std::to_string(static_cast<long>(holdoff_windows)) +
        " windows of " + std::to_string(w) +
        " samples, more than the 255 the record can hold off: design a faster observer (a "
        "higher Q bandwidth)");
  }
  d.params.holdoff_windows = static_cast<std::uint8_t>(holdoff_windows);
  if (fixed::ValidateResidualCusum(d.params) != Status::kOk) {
    throw InputError("watch design: the parameters do not fit the board's kernel");
  }
  return d;
}

}  // namespace vibid::dob
