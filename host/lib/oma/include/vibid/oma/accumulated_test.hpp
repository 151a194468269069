// A test of a mean shift accumulated over several observations: Hotelling's two-sample T² of the
// mean of the last `window` observations against the mean and covariance of `m` reference
// observations (the subspace residuals of reference blocks). A small shift that one observation
// does not show grows with the window: the mean of K observations has 1/K of one's covariance,
// so the shift's noncentrality is K times one block's.
//
// Windows do not overlap: each complete window is one test. With the reference's own mean and
// covariance S (m − 1 degrees of freedom) and d the difference of the two means,
// d ~ N(0, Σ (1/K + 1/m)) while nothing changed, so T² = dᵀ [S (1/K + 1/m)]⁻¹ d ~
// (m − 1) p / (m − p) · F(p, m − p) (p: the dimension) over references; but the windows share
// the reference, and one reference's own probability spreads around that average (a factor 0.3
// to 9 at the watch's sizes). The threshold is the one for which the reference's own probability
// stays at or below the one asked for with 97.5 % probability, and the band it gives is stated
// (WindowCalibration). It holds when the observations are independent and Gaussian.
#pragma once

#include <Eigen/Core>

#include "vibid/oma/window_calibration.hpp"

namespace vibid::oma {

struct AccumulatedTestResult {
  double statistic = 0.0;  ///< T² of the window so far (blocks observations).
  double threshold = 0.0;  ///< Over it, a complete window alarms (WindowCalibration).
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
  /// The threshold's derivation and the false-alarm probability per window the reference gives.
  const WindowCalibration& calibration() const { return calibration_; }
  /// T² of the mean of `observations` (columns) against the reference, whatever their count.
  double Statistic(Eigen::Ref<const Eigen::MatrixXd> observations) const;

 private:
  int window_ = 1;
  int m_ = 0;
  Eigen::VectorXd mean_;
  Eigen::MatrixXd precision_;  // inverse of the reference covariance
  WindowCalibration calibration_;
  double threshold_ = 0.0;  // of T² = dᵀ [S (1/K + 1/m)]⁻¹ d
  Eigen::VectorXd sum_;
  int count_ = 0;
};

}  // namespace vibid::oma
