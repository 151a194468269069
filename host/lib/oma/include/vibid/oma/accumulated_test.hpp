// A test of a mean shift accumulated over several observations: Hotelling's two-sample T² of the
// mean of the last `window` observations against the mean and covariance of `m` reference
// observations (the subspace residuals of reference blocks). A small shift that one observation
// does not show grows with the window: the mean of K observations has 1/K of one's covariance,
// so the shift's noncentrality is K times one block's.
//
// Windows do not overlap: each complete window is one test, and its threshold is the exact
// prediction quantile. With the reference's own mean and covariance S (m − 1 degrees of freedom)
// and d the difference of the two means, d ~ N(0, Σ (1/K + 1/m)) while nothing changed, so
// T² = dᵀ [S (1/K + 1/m)]⁻¹ d ~ (m − 1) p / (m − p) · F(p, m − p) (p: the dimension). Every
// window's false-alarm probability is the one asked for, whatever the reference drawn: the expected
// number of false alarms over N windows is N times it, although the windows share the reference. It
// holds when the observations are independent and Gaussian.
#pragma once

#include <Eigen/Core>

namespace vibid::oma {

struct AccumulatedTestResult {
  double statistic = 0.0;  ///< T² of the window so far (blocks observations).
  double threshold = 0.0;  ///< Its (1 − false_alarm) quantile while nothing changed.
  int count = 0;           ///< Observations in the window so far, 1 … window.
  bool complete = false;   ///< The window is full: this is a test (the next one starts afresh).
  bool alarm = false;      ///< complete and statistic > threshold.
};

class AccumulatedTest {
 public:
  /// `reference`: one column per reference observation (p rows, m columns, m ≥ p + 2).
  /// `window` ≥ 1 observations per test; `false_alarm` in (0, 0.5): per window. InputError
  /// naming what is wrong otherwise.
  AccumulatedTest(Eigen::Ref<const Eigen::MatrixXd> reference, int window, double false_alarm);

  /// Adds one observation to the window; the result is that of the window so far (a test when
  /// it is complete, the statistic of an incomplete window against the same threshold otherwise:
  /// the F law does not depend on the count).
  AccumulatedTestResult Add(Eigen::Ref<const Eigen::VectorXd> observation);

  int window() const { return window_; }
  double threshold() const { return threshold_; }
  /// T² of the mean of `observations` (columns) against the reference, whatever their count.
  double Statistic(Eigen::Ref<const Eigen::MatrixXd> observations) const;

 private:
  int window_ = 1;
  int m_ = 0;
  Eigen::VectorXd mean_;
  Eigen::MatrixXd precision_;  // inverse of the reference covariance
  double threshold_ = 0.0;     // of T² = dᵀ [S (1/K + 1/m)]⁻¹ d
  Eigen::VectorXd sum_;
  int count_ = 0;
};

}  // namespace vibid::oma
