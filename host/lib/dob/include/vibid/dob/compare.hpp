// Agreement between an estimated and a measured disturbance (the `dob compare` figures).
#pragma once

#include <Eigen/Core>

namespace vibid::dob {

struct Agreement {
  double fit_percent =
      0.0;  ///< 100 (1 - ||m - e|| / ||m - mean(m)||) (NRMSE fit, as MATLAB's compare).
  double correlation = 0.0;  ///< Pearson correlation coefficient.
  double delay_s =
      0.0;  ///< Lag of the estimate behind the measurement at the cross-correlation peak.
  double rmse_n = 0.0;  ///< Root-mean-square difference.
};

/// InputError unless both have the same length >= 2, are finite and fs_hz > 0. `max_delay_s`
/// bounds the lag search (0: a tenth of the record).
Agreement CompareSignals(const Eigen::Ref<const Eigen::VectorXd>& estimate,
                         const Eigen::Ref<const Eigen::VectorXd>& measured, double fs_hz,
                         double max_delay_s = 0.0);

}  // namespace vibid::dob
