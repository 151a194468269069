// 95 % intervals of identified parameters: an uncertainty (a variance with the degrees of freedom
// it was estimated with), its propagation through a smooth map to first order (the delta method),
// and the mean of repeated tests, whose uncertainty comes from the tests' own intervals or from
// their scatter.
//
// How repeats combine (MeanOfRepeats): each test brings its own variance (the modal model's or a
// fit's covariance). When the tests agree within those (chi-square of their deviations from the
// mean below its 95 % point with T - 1 degrees of freedom), the mean's variance is the average of
// theirs over T; when they disagree beyond them (the rig changed between tests, or a test's own
// variance is too small), it is the scatter's s^2 / T with T - 1 degrees of freedom, and the
// interval takes Student's t. Why not always the larger of the two: with three tests the scatter
// exceeds the tests' own variance by chance in a third of the cases, and a t interval with two
// degrees of freedom is then 2.2 times wider than the truth needs; the interval would cover at
// 99 % instead of 95 %. When a test has no variance of its own, the scatter alone gives one (t
// with T - 1 degrees of freedom); one test without one gives no interval, and says why.
//
// Degrees of freedom of a sum of independent terms: Welch-Satterthwaite (an infinite term, from a
// large-sample covariance, adds nothing to the denominator).
#pragma once

#include <cmath>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace vibid::ident {

/// A value's uncertainty. Not known when `missing` says why (no estimate was possible) or the
/// variance is not a positive number; an interval is never made of a zero variance.
struct Uncertainty {
  double variance = std::numeric_limits<double>::quiet_NaN();
  double dof = std::numeric_limits<double>::infinity();
  std::string basis;    ///< How it was estimated, for the report.
  std::string missing;  ///< Why there is none (empty when there is).

  bool Known() const { return missing.empty() && std::isfinite(variance) && variance > 0.0; }
  /// A value taken as exact (a mass the user gives): it adds nothing to a propagated variance.
  bool Exact() const { return missing.empty() && variance == 0.0; }
  static Uncertainty Missing(std::string why);
  static Uncertainty ExactValue(std::string basis);
};

/// A 95 % interval [lo, hi], or the reason there is none.
struct Interval95 {
  double lo = std::numeric_limits<double>::quiet_NaN();
  double hi = std::numeric_limits<double>::quiet_NaN();
  std::string basis;
  std::string missing;
  /// With the sensors' calibration in it (AddCalibration): the half-widths of its two parts, the
  /// statistical one (the tests' scatter and fits) and the calibration one; NaN without.
  double statistical_half_width = std::numeric_limits<double>::quiet_NaN();
  double calibration_half_width = std::numeric_limits<double>::quiet_NaN();

  bool HasCalibration() const { return std::isfinite(calibration_half_width); }

  bool Known() const {
    return missing.empty() && std::isfinite(lo) && std::isfinite(hi) && hi > lo;
  }
  double HalfWidth() const { return 0.5 * (hi - lo); }
};

/// value +- t(dof) sqrt(variance); the reason when the uncertainty is not known.
Interval95 IntervalOf(double value, const Uncertainty& u);

/// "+- HALF (P %)" of `value`, or "n/a (reason)": never an interval of zero. With a calibration
/// part: "+- HALF (P %) = stat +- S, cal +- C".
std::string FormatInterval(const Interval95& ci, double value);

/// Adds the sensors' calibration to the interval of `value` (methods §16): a quantity that scales
/// with a product of sensitivities (a mass with the load cell's and the accelerometer's) carries
/// their relative variances added, `relative_u` the root of that sum (a relative standard
/// uncertainty). Its 95 % half-width 1.96 x relative_u x |value| adds to the statistical one in
/// quadrature, about the same centre; both parts are kept. `what` names the sensors in the basis.
/// An interval that is not known stays so (a calibration alone says nothing of the scatter);
/// relative_u of 0 leaves it as it is.
void AddCalibration(Interval95& ci, double value, double relative_u, const std::string& what);

/// Two-sided 95 % point of Student's t with `dof` degrees of freedom (the normal's 1.95996 for an
/// infinite dof). A fractional dof (Welch-Satterthwaite) is rounded down: the wider interval.
double StudentT95(double dof);

/// 95 % point of the chi-square distribution with `dof` (>= 1) degrees of freedom.
double ChiSquare95(int dof);

/// Uncertainty of sum_i g_i x_i for independent x_i (first order: g is the gradient of a map).
/// Terms with g_i == 0 and exact terms do not count; a term that counts and is not known makes
/// the result not known, with its reason. `basis` describes the result.
Uncertainty Propagate(const std::vector<double>& gradient, const std::vector<Uncertainty>& parts,
                      std::string basis);

/// The mean of repeated tests of one quantity and its uncertainty (see the file comment).
/// `what` names the tests in the basis ("modal tests").
struct MeanOfTests {
  double mean = 0.0;
  Uncertainty uncertainty;
};
MeanOfTests MeanOfRepeats(const std::vector<double>& values, const std::vector<Uncertainty>& each,
                          std::string_view what);

}  // namespace vibid::ident
