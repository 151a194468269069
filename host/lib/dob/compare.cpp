#include "vibid/dob/compare.hpp"

#include <cmath>
#include <limits>

#include "vibid/common/error.hpp"

namespace vibid::dob {

Agreement CompareSignals(const Eigen::Ref<const Eigen::VectorXd>& estimate,
                         const Eigen::Ref<const Eigen::VectorXd>& measured, double fs_hz,
                         double max_delay_s) {
  Require(estimate.size() == measured.size(), "estimate and measurement differ in length");
  Require(estimate.size() >= 2, "need at least 2 samples to compare");
  Require(estimate.allFinite() && measured.allFinite(),
          "estimate or measurement has non-finite values");
  Require(std::isfinite(fs_hz) && fs_hz > 0.0, "sample rate must be > 0");
  const Eigen::Index n = estimate.size();
  Agreement a;
  const Eigen::VectorXd diff = measured - estimate;
  a.rmse_n = std::sqrt(diff.squaredNorm() / static_cast<double>(n));
  const Eigen::VectorXd mc = measured.array() - measured.mean();
  const Eigen::VectorXd ec = estimate.array() - estimate.mean();
  const double spread = mc.norm();
  a.fit_percent = spread > 0.0
                      ? 100.0 * (1.0 - diff.norm() / spread)
                      : (diff.norm() == 0.0 ? 100.0 : -std::numeric_limits<double>::infinity());
  const double denom = mc.norm() * ec.norm();
  a.correlation = denom > 0.0 ? mc.dot(ec) / denom : 0.0;
  const auto max_lag = static_cast<Eigen::Index>(
      max_delay_s > 0.0
          ? std::min<double>(std::round(max_delay_s * fs_hz), static_cast<double>(n - 1))
          : static_cast<double>(n / 10));
  double best = -std::numeric_limits<double>::infinity();
  Eigen::Index best_lag = 0;
  for (Eigen::Index lag = -max_lag; lag <= max_lag; ++lag) {
    // estimate[k] ~ measured[k - lag]: a positive lag means the estimate trails.
    const Eigen::Index len = n - std::abs(lag);
    const double c =
        lag >= 0 ? ec.segment(lag, len).dot(mc.head(len)) : ec.head(len).dot(mc.segment(-lag, len));
    if (c > best) {
      best = c;
      best_lag = lag;
    }
  }
  a.delay_s = static_cast<double>(best_lag) / fs_hz;
  return a;
}

}  // namespace vibid::dob
