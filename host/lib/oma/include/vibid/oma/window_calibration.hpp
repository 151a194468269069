// The window test's threshold for the one reference a user has, and the false-alarm rate that
// reference gives (a band, 95 %).
//
// Hotelling's F quantile gives each window the asked probability on average over references; a
// given reference's mean and covariance (m observations) are estimates, and its own probability,
// the same for every window it judges, spreads around the asked one: a factor 0.3 to 9 for
// p = 12 residuals over m = 144 blocks at a probability of 1e-3. Whitened by the true covariance,
// the reference's covariance S is Wishart(m − 1, I)/(m − 1) and its mean's error e is
// N(0, I/m), independent: the probability a reference gives, P(T² > h | S, e) with
// T² = c dᵀ S⁻¹ d, d ~ N(−e, I/K) and c = 1/(1/K + 1/m), is a quadratic form's tail
// (numerics::QuadraticFormTail) whose law over references depends on p, m and K alone. It is
// drawn (a fixed seed: the same options give the same threshold), the threshold chosen so that
// the probability stays at or below the asked one for 97.5 % of references, and the band
// between its 2.5 % and 97.5 % points stated with the reference: the reference the user has
// gives a rate within it with 95 % probability. The same law is the Bayesian one of the true
// mean and covariance given the reference (the Jeffreys prior), so the statement also reads
// "given this reference".
#pragma once

namespace vibid::oma {

struct WindowCalibration {
  double threshold = 0.0;  ///< Of T²: the probability ≤ the asked one for 97.5 % of references.
  double low = 0.0;        ///< The per-window false-alarm probability a reference gives at it:
  double high = 0.0;       ///< 2.5 % and 97.5 % points over references (high ≈ the asked one),
  double mean = 0.0;       ///< and its mean over references.
  double f_threshold = 0.0;  ///< Hotelling's F quantile (the asked probability on average),
  double f_low = 0.0;        ///< and the band a reference gives at it.
  double f_high = 0.0;
};

/// p residuals, m reference observations (≥ p + 2), windows of `window` ≥ 1 observations,
/// `false_alarm` per window in (0, 0.5). InputError otherwise.
WindowCalibration CalibrateWindow(int p, int m, int window, double false_alarm);

/// A reference long enough that the rate it gives is not far below the one asked: the fewest
/// observations, m × 1, 1.5, 2, 3, 4, 6 or 8, whose band's low end reaches a fifth of
/// `false_alarm` (a test no more than about five times as cautious as asked), with that band;
/// `observations` 0 where even 8 m does not.
struct ReferenceAdvice {
  int observations = 0;
  WindowCalibration calibration;
};
ReferenceAdvice AdviseReference(int p, int m, int window, double false_alarm);

}  // namespace vibid::oma
